#include <hysteron/base/checkpoint.h>
#include <hysteron/base/exceptions.h>

namespace hysteron
{
  void
  CheckpointReader::refuse(const std::string &problem) const
  {
    throw InputError("--resume", filename + ": " + problem);
  }

  void
  CheckpointReader::read(char *data, const std::size_t n)
  {
    in.read(data, n);
    if (static_cast<std::size_t>(in.gcount()) != n)
      refuse("the checkpoint is truncated");
  }

  std::size_t
  CheckpointReader::get_size()
  {
    const auto n = get<std::uint64_t>();
    if (n > (std::uint64_t(1) << 40))
      refuse("the checkpoint is damaged (a length of " + std::to_string(n) + ")");
    return n;
  }

  void
  CheckpointReader::section(const std::string &name, const std::uint32_t version)
  {
    std::string tag;
    const auto  n = get<std::uint64_t>();
    if (n > 256)
      refuse("the checkpoint is damaged or of another version (expected the section '" + name +
             "')");
    tag.resize(n);
    read(tag.data(), n);
    if (tag == section_tag(name, version))
      return;
    // The same section in another format: name both versions (before versions: 1).
    const std::string same = "section:" + name;
    if (tag == same || tag.rfind(same + " v", 0) == 0)
      refuse("its '" + name + "' state is in format version " +
             (tag == same ? std::string("1") : tag.substr(same.size() + 2)) + ", this build of hysteron reads version " +
             std::to_string(version) + ": resume it with the version of hysteron that wrote it, or start the run anew");
    refuse("expected the section '" + name + "', found '" + tag +
           "': the checkpoint is of another method or version of hysteron");
  }
} // namespace hysteron

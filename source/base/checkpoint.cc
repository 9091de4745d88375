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
  CheckpointReader::section(const std::string &name)
  {
    std::string tag;
    const auto  n = get<std::uint64_t>();
    if (n > 256)
      refuse("the checkpoint is damaged or of another version (expected the section '" + name +
             "')");
    tag.resize(n);
    read(tag.data(), n);
    if (tag != "section:" + name)
      refuse("expected the section '" + name + "', found '" + tag +
             "': the checkpoint is of another method or version of hysteron");
  }
} // namespace hysteron

#include <hysteron/base/output.h>
#include "base/run_record.h"

#include <algorithm>
#include <filesystem>

namespace hysteron
{
  namespace Output
  {
    void
    RunRecord::begin(const std::string &dir, const bool is_root, std::function<void()> files_changed)
    {
      recording = true;
      root      = is_root;
      directory = dir;
      changed   = std::move(files_changed);
      written.clear();
    }

    void
    RunRecord::end()
    {
      recording = false;
      changed   = nullptr;
    }

    std::string
    RunRecord::relative(const std::string &path) const
    {
      namespace fs = std::filesystem;
      if (directory.empty())
        return "";
      std::error_code ec;
      const fs::path  base = fs::absolute(directory, ec).lexically_normal();
      const fs::path  file = fs::absolute(path, ec).lexically_normal();
      const fs::path  rel  = file.lexically_relative(base);
      if (rel.empty() || *rel.begin() == "..")
        return "";
      return rel.generic_string();
    }

    void
    RunRecord::add_file(const std::string &path)
    {
      if (!recording || !root)
        return;
      const std::string rel = relative(path);
      if (rel.empty() || !written.insert(rel).second)
        return;
      if (changed)
        changed();
    }

    void
    RunRecord::add_directory(const std::string &path)
    {
      if (!recording || !root)
        return;
      const std::string rel = relative(path);
      if (rel.empty() || !written.insert(rel + "/").second)
        return;
      if (changed)
        changed();
    }

    void
    RunRecord::remove(const std::string &path)
    {
      if (!recording || !root)
        return;
      const std::string rel = relative(path);
      if (written.erase(rel) + written.erase(rel + "/") > 0 && changed)
        changed();
    }

    void
    RunRecord::register_table(TimeTable *table)
    {
      tables.push_back(table);
    }

    void
    RunRecord::unregister_table(TimeTable *table)
    {
      tables.erase(std::remove(tables.begin(), tables.end(), table), tables.end());
    }

    void
    RunRecord::flush_tables()
    {
      for (auto *table : tables)
        table->flush();
    }

    void
    RunRecord::sync_tables()
    {
      for (auto *table : tables)
        table->sync();
    }

    std::map<std::string, std::uint64_t>
    RunRecord::table_sizes() const
    {
      std::map<std::string, std::uint64_t> sizes;
      for (const auto *table : tables)
        sizes[relative(table->filename())] = table->size();
      return sizes;
    }

    void
    RunRecord::set_resume_sizes(const std::map<std::string, std::uint64_t> &sizes)
    {
      resume_sizes = sizes;
    }

    std::int64_t
    RunRecord::resume_size(const std::string &path) const
    {
      if (path.empty())
        return -1;
      const auto it = resume_sizes.find(path);
      return it == resume_sizes.end() ? -1 : static_cast<std::int64_t>(it->second);
    }
  } // namespace Output
} // namespace hysteron

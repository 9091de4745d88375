#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/config.h>
#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>
#include "base/run_record.h"

#include "run/output_directory.h"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <sys/file.h>
#include <unistd.h>

namespace hysteron
{
  namespace Run
  {
    namespace fs = std::filesystem;

    namespace
    {
      const char *lock_name     = ".hysteron.lock";
      const char *manifest_name = "manifest.json";

      std::string
      now_utc()
      {
        const std::time_t now = std::time(nullptr);
        char              text[32];
        std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
        return text;
      }

      std::string
      host_name()
      {
        char name[256] = {0};
        ::gethostname(name, sizeof(name) - 1);
        return name;
      }

      std::string
      json(const std::string &text)
      {
        std::string out = "\"";
        for (const unsigned char c : text)
          if (c == '"' || c == '\\')
            (out += '\\') += c;
          else if (c == '\n')
            out += "\\n";
          else if (c < 0x20)
            {
              char escaped[8];
              std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
              out += escaped;
            }
          else
            out += c;
        return out + "\"";
      }

      /// The inverse of json() for one quoted string at the start of @p text.
      std::string
      unquote(const std::string &text)
      {
        std::string out;
        for (std::size_t i = 1; i < text.size() && text[i] != '"'; ++i)
          if (text[i] == '\\' && i + 1 < text.size())
            {
              const char c = text[++i];
              if (c == 'n')
                out += '\n';
              else if (c == 'u' && i + 4 < text.size())
                {
                  out += static_cast<char>(std::stoi(text.substr(i + 1, 4), nullptr, 16));
                  i += 4;
                }
              else
                out += c;
            }
          else
            out += text[i];
        return out;
      }

      /// The commit of the source tree (read from .git, no process started), or "unknown".
      std::string
      source_commit()
      {
        const fs::path git = fs::path(HYSTERON_SOURCE_DIR) / ".git";
        std::ifstream  head(git / "HEAD");
        std::string    line;
        if (!std::getline(head, line))
          return "unknown";
        if (line.rfind("ref: ", 0) != 0)
          return line;
        const std::string ref = line.substr(5);
        std::ifstream     loose(git / ref);
        if (std::getline(loose, line))
          return line;
        std::ifstream packed(git / "packed-refs");
        while (std::getline(packed, line))
          if (line.size() > 41 && line.compare(41, std::string::npos, ref) == 0)
            return line.substr(0, 40);
        return "unknown";
      }

      /// Who holds the lock of @p directory ("" if nobody). Creates nothing.
      std::string
      lock_holder(const std::string &directory)
      {
        const std::string path = directory + "/" + lock_name;
        const int         fd   = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0)
          return "";
        std::string holder;
        if (::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK)
          {
            std::ifstream in(path);
            std::getline(in, holder);
            if (holder.empty())
              holder = "another process";
          }
        ::close(fd);
        return holder;
      }

      /// The files of the manifest in @p directory (relative paths).
      std::vector<std::string>
      previous_files(const std::string &directory)
      {
        std::ifstream            in(directory + "/" + manifest_name);
        std::vector<std::string> files;
        std::string              line;
        bool                     in_list = false;
        while (std::getline(in, line))
          {
            const auto first = line.find_first_not_of(' ');
            if (first == std::string::npos)
              continue;
            const std::string item = line.substr(first);
            if (!in_list)
              in_list = item.rfind("\"files\": [", 0) == 0;
            else if (item[0] == ']')
              break;
            else if (item[0] == '"')
              files.push_back(unquote(item));
          }
        return files;
      }

      /// Remove what a previous run wrote (files of its manifest inside @p directory only).
      void
      remove_previous_run(const std::string &directory)
      {
        std::error_code ec;
        for (const auto &name : previous_files(directory))
          {
            const fs::path relative(name);
            if (name.empty() || relative.is_absolute() ||
                std::any_of(relative.begin(), relative.end(), [](const fs::path &p) {
                  return p == "..";
                }))
              continue;
            const fs::path path = fs::path(directory) / relative;
            if (name.back() == '/')
              {
                if (path.filename().empty() &&
                    path.parent_path().filename().string().rfind("checkpoint-", 0) == 0)
                  fs::remove_all(path, ec);
              }
            else if (fs::is_regular_file(fs::symlink_status(path, ec)))
              fs::remove(path, ec);
          }
        // Incomplete checkpoints of a run that was killed while writing one.
        for (const auto &entry : fs::directory_iterator(directory, ec))
          {
            const std::string n = entry.path().filename().string();
            if (n.rfind("checkpoint-", 0) == 0 && n.size() > 4 &&
                n.compare(n.size() - 4, 4, ".tmp") == 0)
              fs::remove_all(entry.path(), ec);
          }
      }
    } // namespace

    void
    OutputDirectory::check_usable(const std::string &directory, MPI_Comm comm)
    {
      std::string problem;
      if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        {
          // The directory, or the nearest existing folder it would be created in, must be
          // a writable directory: found before the set-up, with nothing created.
          std::error_code ec;
          fs::path        existing = fs::absolute(directory, ec);
          while (!existing.empty() && !fs::exists(existing, ec) && existing != existing.parent_path())
            existing = existing.parent_path();
          if (!fs::is_directory(existing, ec))
            problem = "'" + existing.string() + "' is not a directory, so '" + directory +
                      "' cannot be created";
          else if (::access(existing.c_str(), W_OK | X_OK) != 0)
            {
              const int error = errno;
              problem = "'" + existing.string() + "' is not writable (" + std::strerror(error) +
                        "), so '" + directory + "' cannot be " +
                        (existing == fs::absolute(directory, ec) ? "written" : "created");
            }
          else if (const std::string holder = lock_holder(directory); !holder.empty())
            problem = "'" + directory + "' is in use by " + holder +
                      "; wait for it to finish, stop it, or choose another directory";
        }
      problem = dealii::Utilities::MPI::broadcast(comm, problem, 0);
      if (!problem.empty())
        throw InputError("Output/Directory", problem);
    }

    std::string
    OutputDirectory::describe(const std::string &directory)
    {
      std::ifstream in(directory + "/" + manifest_name);
      if (!in)
        throw InputError("command line",
                         "'" + directory + "' holds no " + manifest_name + " (not an output directory of hysteron)");
      // The manifest's own lines (write_manifest()): "  \"key\": value,".
      std::map<std::string, std::string> field;
      std::string                        line;
      while (std::getline(in, line))
        for (const char *key : {"status", "message", "pid", "host", "started", "command"})
          {
            const std::string prefix = "  \"" + std::string(key) + "\": ";
            if (line.rfind(prefix, 0) == 0)
              {
                std::string value = line.substr(prefix.size());
                if (!value.empty() && value.back() == ',')
                  value.pop_back();
                field[key] = !value.empty() && value[0] == '"' ? unquote(value) : value;
              }
          }
      const std::string status = field["status"];
      if (status != "running")
        return status + (field["message"].empty() ? "" : ": " + field["message"]);
      if (const std::string holder = lock_holder(directory); !holder.empty())
        return "running: " + holder.substr(0, holder.find('\n'));
      return "interrupted: the manifest says running, but no process holds the lock of the directory: "
             "the run (hysteron process " +
             field["pid"] + " on " + field["host"] + " since " + field["started"] +
             ") was killed before it could record its end (SIGKILL, a lost MPI rank or node). Its tables "
             "hold whole rows and its files are complete; hysteron --resume continues it from its newest "
             "checkpoint";
    }

    void
    OutputDirectory::open(const std::string    &dir,
                          const RunDescription &description,
                          const bool            resume,
                          MPI_Comm              comm)
    {
      directory = dir;
      run       = description;
      root      = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
      started   = now_utc();
      std::string problem;
      std::vector<std::string> kept;
      if (root)
        try
          {
            Output::prepare_directory(directory, "Output/Directory");
            const std::string path = directory + "/" + lock_name;
            lock_fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
            if (lock_fd < 0)
              throw InputError("Output/Directory",
                               "cannot create '" + path + "': " + std::strerror(errno));
            if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0)
              {
                ::close(lock_fd);
                lock_fd = -1;
                const std::string holder = lock_holder(directory);
                throw InputError("Output/Directory",
                                 "'" + directory + "' is in use by " +
                                   (holder.empty() ? "another process" : holder) +
                                   "; wait for it to finish, stop it, or choose another "
                                   "directory");
              }
            std::ostringstream who;
            who << "hysteron process " << ::getpid() << " on " << host_name() << " since "
                << started << " (" << run.command << ")\n";
            const std::string text = who.str();
            if (::ftruncate(lock_fd, 0) != 0 || ::write(lock_fd, text.data(), text.size()) < 0)
              throw InputError("Output/Directory",
                               "cannot write '" + path + "': " + std::strerror(errno));
            if (resume)
              kept = previous_files(directory);
            else
              remove_previous_run(directory);
          }
        catch (const InputError &e)
          {
            problem = e.problem();
          }
      problem = dealii::Utilities::MPI::broadcast(comm, problem, 0);
      if (!problem.empty())
        throw InputError("Output/Directory", problem);

      record.begin(directory, root, [this]() { write_manifest(); });
      if (resume)
        {
          resumed = started;
          for (const auto &f : kept)
            if (!f.empty() && f.back() == '/')
              record.add_directory(directory + "/" + f.substr(0, f.size() - 1));
            else
              record.add_file(directory + "/" + f);
        }
      if (root)
        write_manifest();
    }

    void
    OutputDirectory::write_manifest() const
    {
      if (!root)
        return;
      std::ostringstream m;
      m << "{\n"
        << "  \"program\": " << json("hysteron " HYSTERON_VERSION) << ",\n"
        << "  \"commit\": " << json(source_commit()) << ",\n"
        << "  \"command\": " << json(run.command) << ",\n"
        << "  \"parameter_file\": " << json(run.parameter_file) << ",\n"
        << "  \"method\": " << json(run.method) << ",\n"
        << "  \"mpi_ranks\": " << run.n_ranks << ",\n"
        << "  \"host\": " << json(host_name()) << ",\n"
        << "  \"pid\": " << ::getpid() << ",\n"
        << "  \"started\": " << json(started) << ",\n";
      if (!resumed.empty())
        m << "  \"resumed\": " << json(resumed) << ",\n";
      m << "  \"inputs\": [\n";
      for (std::size_t k = 0; k < run.inputs.size(); ++k)
        {
          char crc[16];
          std::snprintf(crc, sizeof(crc), "%08x", run.inputs[k].crc);
          m << "    {\"path\": " << json(run.inputs[k].path) << ", \"bytes\": " << run.inputs[k].bytes
            << ", \"crc32\": " << json(crc) << "}" << (k + 1 < run.inputs.size() ? ",\n" : "\n");
        }
      m << "  ],\n";
      m << "  \"status\": " << json(status) << ",\n"
        << "  \"message\": " << json(message) << ",\n"
        << "  \"files\": [\n";
      const auto &files = record.files();
      std::size_t i     = 0;
      for (const auto &f : files)
        m << "    " << json(f) << (++i < files.size() ? ",\n" : "\n");
      m << "  ]\n}\n";
      // Atomic, and not itself a file of the run (so not an Output::AtomicFile, which
      // records its file here).
      const std::string path = directory + "/" + manifest_name;
      std::ofstream     out(path + ".tmp");
      out << m.str();
      out.close();
      const int error = errno;
      if (!out || std::rename((path + ".tmp").c_str(), path.c_str()) != 0)
        {
          const int reason = out ? errno : error;
          std::remove((path + ".tmp").c_str());
          throw RuntimeError("cannot write '" + path + "': " + (reason != 0 ? std::strerror(reason) : "an input/output error"));
        }
    }

    void
    OutputDirectory::close(const std::string &final_status, const std::string &final_message)
    {
      if (directory.empty())
        return;
      status  = final_status;
      message = final_message;
      std::string failure;
      try
        {
          write_manifest();
        }
      catch (const RuntimeError &e)
        {
          failure = e.what();
        }
      record.end();
      if (lock_fd >= 0)
        {
          ::flock(lock_fd, LOCK_UN);
          ::close(lock_fd);
          lock_fd = -1;
        }
      directory.clear();
      // A run that finished fails on it; a run that failed already keeps its own error.
      if (!failure.empty())
        {
          if (final_status == "finished")
            throw RuntimeError(failure);
          std::cerr << "hysteron: warning: " << failure << std::endl;
        }
    }

    OutputDirectory::~OutputDirectory()
    {
      if (!directory.empty())
        close("failed", "the run ended without a status");
    }
  } // namespace Run
} // namespace hysteron

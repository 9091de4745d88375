#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/run_record.h>
#include <hysteron/base/checkpoint.h>

#include "run/checkpoint_files.h"

#include <algorithm>
#include <cstdio>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace hysteron
{
  namespace Run
  {
    namespace fs = std::filesystem;

    std::string
    CheckpointFile::rank_file(const unsigned int rank) const
    {
      return directory + "/rank-" + dealii::Utilities::int_to_string(rank, 4) + ".bin";
    }

    namespace
    {
      const std::string prefix = "checkpoint-";

      /// The step of a directory named checkpoint-<digits>, or -1.
      long
      step_of(const std::string &name)
      {
        if (name.rfind(prefix, 0) != 0 || name.size() == prefix.size())
          return -1;
        const std::string digits = name.substr(prefix.size());
        if (!std::all_of(digits.begin(), digits.end(), [](const char c) { return std::isdigit(c); }))
          return -1;
        return std::stol(digits);
      }

      std::optional<CheckpointFile>
      read_info(const fs::path &directory)
      {
        std::ifstream in(directory / "info.txt");
        std::string   magic, key;
        CheckpointFile file;
        file.directory = directory.string();
        if (!std::getline(in, magic) || magic != "hysteron checkpoint 1")
          return std::nullopt;
        std::string time_text;
        if (!(in >> key >> file.step) || key != "step" || !(in >> key >> time_text) ||
            key != "time" || !(in >> key >> file.ranks) || key != "ranks")
          return std::nullopt;
        file.time = std::strtod(time_text.c_str(), nullptr); // hexadecimal: exact
        return file;
      }

      /// Make the file's data durable before the rename that publishes it.
      void
      sync_file(const fs::path &path)
      {
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd >= 0)
          {
            ::fsync(fd);
            ::close(fd);
          }
      }
      /// The lines of the effective parameters that a resumed run must share with
      /// the checkpoint: all but `subsection Checkpoint` and the progress interval.
      std::string
      parameters_without_checkpoint(const std::string &text)
      {
        std::istringstream in(text);
        std::string        line, out;
        int                depth = 0, skip_depth = -1;
        while (std::getline(in, line))
          {
            const auto        first = line.find_first_not_of(" \t");
            const std::string item  = first == std::string::npos ? "" : line.substr(first);
            if (item.rfind("subsection ", 0) == 0)
              {
                if (skip_depth < 0 && item == "subsection Checkpoint")
                  skip_depth = depth;
                ++depth;
                if (skip_depth < 0)
                  out += item + '\n';
                continue;
              }
            if (item == "end")
              {
                --depth;
                if (skip_depth < 0)
                  out += item + '\n';
                if (depth == skip_depth)
                  skip_depth = -1;
                continue;
              }
            if (skip_depth >= 0 || item.empty() || item[0] == '#' ||
                item.rfind("set Progress interval", 0) == 0)
              continue;
            out += item + '\n';
          }
        return out;
      }

      /// The first line where @p a and @p b differ.
      std::string
      first_difference(const std::string &a, const std::string &b)
      {
        std::istringstream in_a(a), in_b(b);
        std::string        line_a, line_b;
        while (true)
          {
            const bool has_a = static_cast<bool>(std::getline(in_a, line_a));
            const bool has_b = static_cast<bool>(std::getline(in_b, line_b));
            if (!has_a && !has_b)
              return "";
            if (!has_a || !has_b || line_a != line_b)
              return "checkpoint '" + (has_a ? line_a : std::string("(nothing)")) +
                     "', scene '" + (has_b ? line_b : std::string("(nothing)")) + "'";
          }
      }
    } // namespace

    std::optional<CheckpointFile>
    find_latest_checkpoint(const std::string &directory)
    {
      std::optional<CheckpointFile> latest;
      std::error_code               ec;
      for (const auto &entry : fs::directory_iterator(directory, ec))
        {
          const long step = step_of(entry.path().filename().string());
          if (step < 0 || !entry.is_directory(ec))
            continue;
          const auto info = read_info(entry.path());
          if (info && (!latest || info->step > latest->step))
            latest = info;
        }
      return latest;
    }

    std::string
    resumable_parameters(const std::string &text)
    {
      return parameters_without_checkpoint(text);
    }

    void
    write_resume_header(CheckpointWriter &out, const std::string &method, const std::string &parameters)
    {
      out.section("driver");
      out.put(method);
      out.put(resumable_parameters(parameters));
    }

    ResumeSource
    open_resume(const std::string &directory,
                const std::string &method,
                const std::string &parameters,
                MPI_Comm           comm)
    {
      const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      const unsigned int rank    = dealii::Utilities::MPI::this_mpi_process(comm);
      std::string        found;
      if (rank == 0)
        if (const auto latest = find_latest_checkpoint(directory))
          found = latest->directory;
      found = dealii::Utilities::MPI::broadcast(comm, found, 0);
      if (found.empty())
        throw InputError("--resume",
                         "no checkpoint in '" + directory +
                           "' (a run writes them with Checkpoint/Interval or Checkpoint/"
                           "Wall-clock interval, and when SIGINT or SIGTERM stops it)");
      ResumeSource source;
      const auto   latest = find_latest_checkpoint(directory);
      if (!latest || latest->directory != found)
        throw InputError("--resume",
                         "the checkpoints in '" + directory + "' changed while the run started");
      source.file = *latest;
      if (latest->ranks != n_ranks)
        throw InputError("--resume",
                         "'" + latest->directory + "' was written by " +
                           std::to_string(latest->ranks) + " MPI rank(s); resume it with " +
                           (latest->ranks == 1 ? std::string("one rank") :
                                                 "mpirun -np " + std::to_string(latest->ranks)) +
                           " (this run has " + std::to_string(n_ranks) + ")");
      const std::string file = latest->rank_file(rank);
      source.stream = std::make_unique<std::ifstream>(file, std::ios::binary);
      if (!*source.stream)
        throw InputError("--resume", "cannot read '" + file + "'");
      source.reader = std::make_unique<CheckpointReader>(*source.stream, file);
      auto &reader  = *source.reader;
      reader.section("driver");
      std::string written_by, written_parameters;
      reader.get(written_by);
      if (written_by != method)
        reader.refuse("written by the method '" + written_by + "', not '" + method + "'");
      reader.get(written_parameters);
      const std::string difference =
        first_difference(written_parameters, resumable_parameters(parameters));
      if (!difference.empty())
        reader.refuse("the scene's parameters differ from the checkpoint's (only `subsection "
                      "Checkpoint` and Output/Progress interval may change): " +
                      difference);
      return source;
    }

    void
    write_checkpoint(const std::string                              &directory,
                     const unsigned long                             step,
                     const double                                    t,
                     MPI_Comm                                        comm,
                     const unsigned int                              keep,
                     const std::function<void(CheckpointWriter &)> &write)
    {
      const unsigned int rank    = dealii::Utilities::MPI::this_mpi_process(comm);
      const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      char               digits[32];
      std::snprintf(digits, sizeof(digits), "%09lu", step);
      const fs::path final_dir = fs::path(directory) / (prefix + digits);
      const fs::path temporary = fs::path(directory) / (prefix + digits + ".tmp");

      std::string problem;
      if (rank == 0)
        {
          std::error_code ec;
          fs::remove_all(temporary, ec);
          fs::create_directories(temporary, ec);
          if (ec)
            problem = "cannot create '" + temporary.string() + "': " + ec.message();
        }
      problem = dealii::Utilities::MPI::broadcast(comm, problem, 0);
      if (!problem.empty())
        throw RuntimeError("checkpoint: " + problem);

      CheckpointFile file;
      file.directory = temporary.string();
      try
        {
          std::ofstream out(file.rank_file(rank), std::ios::binary);
          CheckpointWriter writer(out);
          write(writer);
          out.close();
          if (!out)
            throw RuntimeError("cannot write '" + file.rank_file(rank) + "'");
          sync_file(file.rank_file(rank));
        }
      catch (const std::exception &e)
        {
          problem = e.what();
        }
      // Every rank learns of a failure on any rank.
      const auto all = dealii::Utilities::MPI::all_gather(comm, problem);
      for (const auto &p : all)
        if (!p.empty())
          {
            if (rank == 0)
              {
                std::error_code ec;
                fs::remove_all(temporary, ec);
              }
            throw RuntimeError("checkpoint at step " + std::to_string(step) + ": " + p);
          }

      if (rank == 0)
        {
          std::error_code ec;
          {
            std::ofstream info(temporary / "info.txt");
            char          time_text[64];
            std::snprintf(time_text, sizeof(time_text), "%a", t);
            info << "hysteron checkpoint 1\nstep " << step << "\ntime " << time_text << "\nranks "
                 << n_ranks << "\n";
            info.close();
            if (!info)
              problem = "cannot write '" + (temporary / "info.txt").string() + "'";
          }
          sync_file(temporary / "info.txt");
          if (problem.empty())
            {
              fs::remove_all(final_dir, ec);
              fs::rename(temporary, final_dir, ec);
              if (ec)
                problem = "cannot rename '" + temporary.string() + "': " + ec.message();
            }
          if (problem.empty())
            {
              auto &record = Output::RunRecord::get();
              record.add_directory(final_dir.string());
              // Keep the newest `keep`.
              std::vector<std::pair<long, fs::path>> existing;
              for (const auto &entry : fs::directory_iterator(directory, ec))
                {
                  const long s = step_of(entry.path().filename().string());
                  if (s >= 0 && entry.is_directory(ec))
                    existing.emplace_back(s, entry.path());
                }
              std::sort(existing.begin(), existing.end());
              for (std::size_t i = 0; i + keep < existing.size(); ++i)
                {
                  fs::remove_all(existing[i].second, ec);
                  record.remove(existing[i].second.string());
                }
            }
        }
      problem = dealii::Utilities::MPI::broadcast(comm, problem, 0);
      if (!problem.empty())
        throw RuntimeError("checkpoint at step " + std::to_string(step) + ": " + problem);
    }
  } // namespace Run
} // namespace hysteron

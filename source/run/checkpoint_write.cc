// Writing a checkpoint: the state into a temporary directory, the digests of its files and
// of the tables into info.txt, everything made durable, then published by a rename; the
// newest ones kept.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/checkpoint.h>
#include <hysteron/base/exceptions.h>
#include "base/run_record.h"

#include "run/checkpoint_info.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace hysteron
{
  namespace Run
  {
    namespace fs = std::filesystem;

    namespace
    {
      /// Make the file's (or directory's) data durable.
      void
      sync_path(const fs::path &path, const bool directory = false)
      {
        const int fd = ::open(path.c_str(), (directory ? O_DIRECTORY : 0) | O_RDONLY | O_CLOEXEC);
        if (fd >= 0)
          {
            ::fsync(fd);
            ::close(fd);
          }
      }

      /// Rank 0 makes @p temporary a new empty directory; a failure is every rank's.
      void
      create_temporary(const fs::path &temporary, MPI_Comm comm)
      {
        std::string problem;
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
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
      }

      /// The state by @p write: global.bin (rank 0's) and each rank's rank-<r>.bin into
      /// @p file's directory, the method's distributed files beside them. Every rank takes
      /// part in the method's collective writes, even after a local error, and every rank
      /// learns of a failure on any rank (the directory is then removed).
      void
      write_state(
        const CheckpointFile                                                                           &file,
        MPI_Comm                                                                                        comm,
        const std::function<void(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &)> &write)
      {
        const unsigned int  rank = dealii::Utilities::MPI::this_mpi_process(comm);
        CheckpointDirectory place;
        place.path        = file.directory;
        place.saved_ranks = file.ranks;
        place.n_ranks     = file.ranks;
        std::string        problem;
        std::ostringstream global_bytes, rank_bytes;
        try
          {
            CheckpointWriter global(global_bytes), own(rank_bytes);
            write(global, own, place);
            for (const auto &[name, bytes] :
                 {std::make_pair(std::string("global.bin"), &global_bytes),
                  std::make_pair(fs::path(file.rank_file(rank)).filename().string(), &rank_bytes)})
              {
                if (name == "global.bin" && rank != 0)
                  continue;
                const std::string path = file.directory + "/" + name;
                std::ofstream     out(path, std::ios::binary);
                const std::string text = bytes->str();
                out.write(text.data(), text.size());
                out.close();
                if (!out)
                  throw RuntimeError("cannot write '" + path + "': " + std::strerror(errno));
              }
          }
        catch (const std::exception &e)
          {
            problem = e.what();
          }
        for (const auto &p : dealii::Utilities::MPI::all_gather(comm, problem))
          if (!p.empty())
            {
              if (rank == 0)
                {
                  std::error_code ec;
                  fs::remove_all(file.directory, ec);
                }
              throw RuntimeError("checkpoint at step " + std::to_string(file.step) + ": " + p);
            }
      }

      /// The digests of every file of the checkpoint (its contents once all ranks wrote),
      /// each computed by all ranks of @p comm on their shares.
      void
      digest_files(CheckpointFile &file, MPI_Comm comm)
      {
        std::vector<std::pair<std::string, std::uint64_t>> written;
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
          {
            std::error_code ec;
            for (const auto &entry : fs::directory_iterator(file.directory, ec))
              if (entry.is_regular_file(ec))
                written.emplace_back(entry.path().filename().string(), entry.file_size(ec));
            std::sort(written.begin(), written.end());
          }
        written = dealii::Utilities::MPI::broadcast(comm, written, 0);
        for (const auto &[name, bytes] : written)
          {
            const std::uint32_t crc = crc32_of_file(file.directory + "/" + name, bytes, comm);
            file.files.push_back(FileDigest{name, bytes, crc});
          }
      }

      /// Rank 0: info.txt, everything durable, then the rename to @p final_dir; returns the
      /// problem ("" if published). Nothing incomplete stays.
      std::string
      publish(const CheckpointFile &file, const fs::path &final_dir, const std::string &directory)
      {
        const fs::path temporary(file.directory);
        std::string    problem;
        std::error_code ec;
        {
          std::ofstream info(temporary / "info.txt");
          info << CheckpointInfo::text(file);
          info.close();
          if (!info)
            problem = "cannot write '" + (temporary / "info.txt").string() + "': " + std::strerror(errno);
        }
        // Everything on disk before the rename publishes it.
        for (const auto &f : file.files)
          sync_path(temporary / f.path);
        sync_path(temporary / "info.txt");
        sync_path(temporary, true);
        if (problem.empty())
          {
            fs::remove_all(final_dir, ec);
            fs::rename(temporary, final_dir, ec);
            if (ec)
              problem = "cannot rename '" + temporary.string() + "': " + ec.message();
            sync_path(directory, true);
          }
        else
          fs::remove_all(temporary, ec);
        return problem;
      }

      /// Rank 0: @p published goes into the run's @p record (the manifest lists it); of the
      /// checkpoints in @p directory the newest @p keep stay.
      void
      keep_newest(const std::string &directory,
                  const unsigned int keep,
                  const fs::path    &published,
                  Output::RunRecord &record)
      {
        record.add_directory(published.string());
        std::error_code                        ec;
        std::vector<std::pair<long, fs::path>> existing;
        for (const auto &entry : fs::directory_iterator(directory, ec))
          {
            const long s = CheckpointInfo::step_of(entry.path().filename().string());
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
    } // namespace



    void
    write_checkpoint(
      const std::string                                                         &directory,
      const unsigned long                                                        step,
      const double                                                               t,
      MPI_Comm                                                                   comm,
      const unsigned int                                                         keep,
      const std::map<std::string, std::uint64_t>                                &tables,
      const std::vector<FileDigest>                                             &inputs,
      Output::RunRecord                                                         &record,
      const std::function<void(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &)> &write)
    {
      const fs::path final_dir = fs::path(directory) / CheckpointInfo::name(step);
      const fs::path temporary = fs::path(directory) / (CheckpointInfo::name(step) + ".tmp");
      create_temporary(temporary, comm);

      CheckpointFile file;
      file.directory = temporary.string();
      file.step      = step;
      file.time      = t;
      file.ranks     = dealii::Utilities::MPI::n_mpi_processes(comm);
      file.inputs    = inputs;
      write_state(file, comm, write);
      digest_files(file, comm);

      std::string problem;
      if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        {
          // The tables' rows up to the checkpoint, by their paths in the directory.
          for (const auto &[path, bytes] : tables)
            file.tables.push_back(CheckpointInfo::digest(directory + "/" + path, bytes));
          for (auto &d : file.tables)
            d.path = fs::path(d.path).lexically_relative(directory).string();
          problem = publish(file, final_dir, directory);
          if (problem.empty())
            try
              {
                // The manifest lists the checkpoint (its write may fail too).
                keep_newest(directory, keep, final_dir, record);
              }
            catch (const RuntimeError &e)
              {
                problem = e.what();
              }
        }
      problem = dealii::Utilities::MPI::broadcast(comm, problem, 0);
      if (!problem.empty())
        throw RuntimeError("checkpoint at step " + std::to_string(step) + ": " + problem);
    }
  } // namespace Run
} // namespace hysteron

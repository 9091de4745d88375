// Resuming a run: the newest intact checkpoint of the same scene and inputs (its files
// and the tables checked against their digests), and the parts of it that a rank reads.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/checkpoint.h>
#include <hysteron/base/exceptions.h>

#include "run/checkpoint_info.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace hysteron
{
  namespace Run
  {
    namespace fs = std::filesystem;

    namespace
    {
      /// Why the checkpoint @p file cannot be used ("" if it can): its files' sizes and
      /// CRCs (collective), the tables' rows up to it (rank 0).
      std::string
      damage(const CheckpointFile &file, const std::string &output_directory, MPI_Comm comm)
      {
        const bool  root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
        std::string why;
        for (const auto &f : file.files)
          {
            const std::string path = file.directory + "/" + f.path;
            std::uint64_t     size = 0;
            if (root)
              {
                std::error_code ec;
                size = fs::file_size(path, ec);
                if (ec)
                  size = std::uint64_t(-1);
              }
            size = dealii::Utilities::MPI::broadcast(comm, size, 0);
            if (size == std::uint64_t(-1))
              return f.path + " is missing";
            if (size != f.bytes)
              return f.path + " has " + std::to_string(size) + " bytes instead of " + std::to_string(f.bytes);
            const std::uint32_t crc = crc32_of_file(path, f.bytes, comm);
            if (root && crc != f.crc)
              why = f.path + " is damaged (CRC-32 " + CheckpointInfo::hex(crc) + " instead of " + CheckpointInfo::hex(f.crc) + ")";
            why = dealii::Utilities::MPI::broadcast(comm, why, 0);
            if (!why.empty())
              return why;
          }
        if (root)
          for (const auto &t : file.tables)
            {
              const FileDigest now = CheckpointInfo::digest(output_directory + "/" + t.path, t.bytes);
              if (now.bytes < t.bytes)
                why = "the table " + t.path + " is shorter (" + std::to_string(now.bytes) +
                      " bytes) than at the checkpoint (" + std::to_string(t.bytes) + ")";
              else if (now.crc != t.crc)
                why = "the table " + t.path + " was changed after the checkpoint";
              if (!why.empty())
                break;
            }
        return dealii::Utilities::MPI::broadcast(comm, why, 0);
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



    namespace
    {
      /// The bytes of @p path (throws InputError if it cannot be read).
      std::string
      read_bytes(const std::string &path)
      {
        std::ifstream in(path, std::ios::binary);
        if (!in)
          throw InputError("--resume", "cannot read '" + path + "'");
        std::ostringstream bytes;
        bytes << in.rdbuf();
        return bytes.str();
      }
    } // namespace



    CheckpointParts::CheckpointParts(const CheckpointDirectory &directory, MPI_Comm comm)
    {
      const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(comm);
      CheckpointFile     file;
      file.directory = directory.path;
      // global.bin: one read, then an MPI broadcast of its bytes.
      std::string   bytes = rank == 0 ? read_bytes(file.global_file()) : std::string();
      std::uint64_t size  = bytes.size();
      int           ierr  = MPI_Bcast(&size, 1, MPI_UINT64_T, 0, comm);
      AssertThrowMPI(ierr);
      bytes.resize(size);
      for (std::uint64_t done = 0; done < size;)
        {
          const int n = static_cast<int>(std::min<std::uint64_t>(size - done, 1u << 30));
          ierr        = MPI_Bcast(bytes.data() + done, n, MPI_CHAR, 0, comm);
          AssertThrowMPI(ierr);
          done += n;
        }
      global_stream.str(bytes);
      global_reader = std::make_unique<CheckpointReader>(global_stream, file.global_file());
      std::vector<unsigned int> parts;
      if (directory.same_ranks())
        parts.push_back(rank);
      else
        for (unsigned int r = 0; r < directory.saved_ranks; ++r)
          parts.push_back(r);
      for (const unsigned int r : parts)
        {
          rank_streams.push_back(std::make_unique<std::istringstream>(read_bytes(file.rank_file(r))));
          rank_readers.emplace_back(*rank_streams.back(), file.rank_file(r));
        }
    }



    std::string
    resumable_parameters(const std::string &text)
    {
      return parameters_without_checkpoint(text);
    }



    void
    write_resume_header(CheckpointWriter &out, const std::string &method, const std::string &parameters)
    {
      out.section("driver", 2);
      out.put(method);
      out.put(resumable_parameters(parameters));
    }



    namespace
    {
      /// The checkpoints in @p directory, newest first (rank 0 lists them, every rank
      /// of @p comm gets the list).
      std::vector<std::string>
      newest_first(const std::string &directory, MPI_Comm comm)
      {
        std::vector<std::string> candidates;
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
          {
            std::vector<std::pair<long, std::string>> found;
            std::error_code                           ec;
            for (const auto &entry : fs::directory_iterator(directory, ec))
              if (const long step = CheckpointInfo::step_of(entry.path().filename().string());
                  step >= 0 && entry.is_directory(ec))
                found.emplace_back(step, entry.path().string());
            std::sort(found.rbegin(), found.rend());
            for (const auto &f : found)
              candidates.push_back(f.second);
          }
        return dealii::Utilities::MPI::broadcast(comm, candidates, 0);
      }

      /// Why the intact checkpoint @p file is of another run than this one (its inputs,
      /// method or parameters differ; "" if none).
      std::string
      stale_reason(const CheckpointFile            &file,
                   const std::string               &name,
                   const std::vector<FileDigest>   &inputs,
                   const std::string               &method,
                   const std::string               &parameters)
      {
        for (const auto &recorded : file.inputs)
          {
            const auto now = std::find_if(inputs.begin(), inputs.end(), [&](const FileDigest &d) {
              return d.path == recorded.path;
            });
            if (now == inputs.end() || !(*now == recorded))
              return "the input file '" + recorded.path + "' changed since " + name + " was written (" +
                     std::to_string(recorded.bytes) + " bytes, CRC-32 " + CheckpointInfo::hex(recorded.crc) + "; now " +
                     (now == inputs.end() ? std::string("not read by the scene") :
                                            std::to_string(now->bytes) + " bytes, CRC-32 " + CheckpointInfo::hex(now->crc)) +
                     "): a resumed run must read the inputs of the run it continues";
          }
        std::ifstream    in(file.global_file(), std::ios::binary);
        CheckpointReader reader(in, file.global_file());
        std::string      written_by, written_parameters;
        try
          {
            reader.section("driver", 2);
            reader.get(written_by);
            reader.get(written_parameters);
          }
        catch (const InputError &e)
          {
            return e.what(); // intact by its digest, but not a checkpoint of this program
          }
        const std::string difference = first_difference(written_parameters, resumable_parameters(parameters));
        if (written_by != method)
          return name + " was written by the method '" + written_by + "', not '" + method + "'";
        if (!difference.empty())
          return "the scene's parameters differ from " + name +
                 "'s (only `subsection Checkpoint` and Output/Progress interval may change): " + difference;
        return "";
      }
    } // namespace



    CheckpointFile
    find_resumable_checkpoint(const std::string             &directory,
                              const std::string             &method,
                              const std::string             &parameters,
                              const std::vector<FileDigest> &inputs,
                              MPI_Comm                       comm,
                              std::ostream                  &notes)
    {
      const bool                     root       = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
      const std::vector<std::string> candidates = newest_first(directory, comm);
      if (candidates.empty())
        throw InputError("--resume",
                         "no checkpoint in '" + directory +
                           "' (a run writes them with Checkpoint/Interval or Checkpoint/"
                           "Wall-clock interval, and when SIGINT or SIGTERM stops it)");

      std::vector<std::string> refused;
      for (const auto &candidate : candidates)
        {
          const std::string name = fs::path(candidate).filename().string();
          CheckpointFile    file;
          std::string       why;
          // First whether the checkpoint is intact (every file against its digest): a
          // damaged one is skipped for an older one, whatever its damaged bytes say.
          if (root)
            CheckpointInfo::read(candidate, file, why);
          why = dealii::Utilities::MPI::broadcast(comm, why, 0);
          if (why.empty())
            {
              file = dealii::Utilities::MPI::broadcast(comm, file, 0);
              why  = damage(file, directory, comm);
            }
          if (why.empty())
            {
              // An intact checkpoint of another run (other inputs, method or parameters):
              // an older one is of that run too, so the resume is refused.
              const std::string stale =
                dealii::Utilities::MPI::broadcast(comm, root ? stale_reason(file, name, inputs, method, parameters) : "", 0);
              if (!stale.empty())
                throw InputError("--resume", stale);
              if (root && !refused.empty())
                notes << "hysteron: --resume: " << refused.size() << " newer checkpoint"
                      << (refused.size() > 1 ? "s are" : " is") << " not usable (" << refused.front()
                      << (refused.size() > 1 ? "; ..." : "") << "); resuming from " << name << std::endl;
              return file;
            }
          refused.push_back(name + ": " + why);
        }
      std::string all;
      for (const auto &r : refused)
        all += (all.empty() ? "" : "; ") + r;
      throw InputError("--resume", "no usable checkpoint in '" + directory + "': " + all);
    }
  } // namespace Run
} // namespace hysteron

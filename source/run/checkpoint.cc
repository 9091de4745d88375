// Checkpoints on disk: writing one (temporary directory, digests, publication by rename),
// finding the newest intact one on resume, and the digests (CRC-32) that tell a damaged
// checkpoint, a changed input or a cut table.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/run_record.h>
#include <hysteron/base/checkpoint.h>

#include "run/checkpoint_files.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
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
      const std::string magic  = "hysteron checkpoint 2";

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

      /// CRC-32 of the bytes [first, first + n) of the open file @p fd; @p n is reduced
      /// to what could be read.
      std::uint32_t
      crc32_of_range(const int fd, const std::uint64_t first, std::uint64_t &n)
      {
        uLong              crc = crc32(0L, Z_NULL, 0);
        std::vector<Bytef> buffer(1u << 20);
        std::uint64_t      done = 0;
        while (done < n)
          {
            const std::size_t want = std::min<std::uint64_t>(buffer.size(), n - done);
            const ssize_t     got  = ::pread(fd, buffer.data(), want, first + done);
            if (got < 0 && errno == EINTR)
              continue;
            if (got <= 0)
              break;
            crc = crc32(crc, buffer.data(), static_cast<uInt>(got));
            done += got;
          }
        n = done;
        return static_cast<std::uint32_t>(crc);
      }

      std::string
      hex(const std::uint32_t crc)
      {
        char text[16];
        std::snprintf(text, sizeof(text), "%08x", crc);
        return text;
      }



      /// The CRC-32 of @p text.
      std::uint32_t
      text_crc(const std::string &text)
      {
        return static_cast<std::uint32_t>(
          crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef *>(text.data()), static_cast<uInt>(text.size())));
      }

      /// "<kind> <bytes> <crc> <path>" lines of info.txt (the path last: it may hold spaces).
      void
      write_digests(std::ostream &out, const std::string &kind, const std::vector<FileDigest> &list)
      {
        for (const auto &d : list)
          out << kind << ' ' << d.bytes << ' ' << hex(d.crc) << ' ' << d.path << '\n';
      }

      /// info.txt, or "" and the reason in @p why.
      bool
      read_info(const fs::path &directory, CheckpointFile &file, std::string &why)
      {
        file           = CheckpointFile();
        file.directory = directory.string();
        std::string text;
        {
          std::ifstream     whole(directory / "info.txt", std::ios::binary);
          std::stringstream buffer;
          buffer << whole.rdbuf();
          text = buffer.str();
        }
        if (text.empty())
          {
            why = "info.txt is missing or empty";
            return false;
          }
        // The last line, "end <CRC-32 of the text before it>", guards info.txt itself.
        const std::size_t end = text.rfind("end ");
        if (end == std::string::npos || (end > 0 && text[end - 1] != '\n') ||
            text.substr(end) != "end " + hex(text_crc(text.substr(0, end))) + "\n")
          {
            why = text.rfind("hysteron checkpoint", 0) == 0 && text.compare(0, magic.size(), magic) != 0 ?
                    "it was written by another version of hysteron" :
                    "info.txt is damaged (its CRC-32 does not match)";
            return false;
          }
        std::istringstream in(text.substr(0, end));
        std::string        line;
        std::getline(in, line);
        if (line != magic)
          {
            why = line.rfind("hysteron checkpoint", 0) == 0 ?
                    "it was written by another version of hysteron ('" + line + "')" :
                    "info.txt is damaged";
            return false;
          }
        bool has_step = false, has_time = false, has_ranks = false;
        while (std::getline(in, line))
          {
            std::istringstream fields(line);
            std::string        key;
            fields >> key;
            if (key == "step")
              has_step = static_cast<bool>(fields >> file.step);
            else if (key == "time")
              {
                std::string text;
                has_time  = static_cast<bool>(fields >> text);
                file.time = std::strtod(text.c_str(), nullptr); // hexadecimal: exact
              }
            else if (key == "ranks")
              has_ranks = static_cast<bool>(fields >> file.ranks) && file.ranks > 0;
            else if (key == "file" || key == "table" || key == "input")
              {
                FileDigest  d;
                std::string crc;
                if (!(fields >> d.bytes >> crc) || crc.size() != 8)
                  {
                    why = "info.txt is damaged";
                    return false;
                  }
                d.crc = static_cast<std::uint32_t>(std::stoul(crc, nullptr, 16));
                std::getline(fields >> std::ws, d.path);
                (key == "file" ? file.files : key == "table" ? file.tables : file.inputs).push_back(d);
              }
            else
              {
                why = "info.txt is damaged";
                return false;
              }
          }
        if (!has_step || !has_time || !has_ranks)
          {
            why = "info.txt is damaged";
            return false;
          }
        return true;
      }

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

      /// The digest of the first @p bytes of @p path (rank 0 reads it all; small files).
      FileDigest
      digest(const std::string &path, const std::uint64_t bytes)
      {
        FileDigest d;
        d.path    = path;
        d.bytes   = bytes;
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0)
          {
            d.bytes = 0;
            return d;
          }
        d.crc = crc32_of_range(fd, 0, d.bytes);
        ::close(fd);
        return d;
      }

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
              why = f.path + " is damaged (CRC-32 " + hex(crc) + " instead of " + hex(f.crc) + ")";
            why = dealii::Utilities::MPI::broadcast(comm, why, 0);
            if (!why.empty())
              return why;
          }
        if (root)
          for (const auto &t : file.tables)
            {
              const FileDigest now = digest(output_directory + "/" + t.path, t.bytes);
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
    } // namespace



    std::vector<FileDigest>
    digest_inputs(const std::vector<std::string> &paths, MPI_Comm comm)
    {
      std::vector<FileDigest> digests;
      std::string             missing;
      if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        for (const auto &path : paths)
          {
            std::error_code     ec;
            const std::uint64_t size = fs::file_size(path, ec);
            if (ec)
              {
                missing = path;
                break;
              }
            digests.push_back(digest(path, size));
          }
      missing = dealii::Utilities::MPI::broadcast(comm, missing, 0);
      if (!missing.empty())
        throw InputError("Output/Directory", "cannot read the input file '" + missing + "'");
      return dealii::Utilities::MPI::broadcast(comm, digests, 0);
    }



    std::uint32_t
    crc32_of_file(const std::string &path, const std::uint64_t bytes, MPI_Comm comm)
    {
      const unsigned int  rank    = dealii::Utilities::MPI::this_mpi_process(comm);
      const unsigned int  n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      const std::uint64_t first   = bytes / n_ranks * rank + std::min<std::uint64_t>(rank, bytes % n_ranks);
      std::uint64_t       n       = bytes / n_ranks + (rank < bytes % n_ranks ? 1 : 0);
      std::uint32_t       crc     = static_cast<std::uint32_t>(crc32(0L, Z_NULL, 0));
      const int           fd      = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
      if (fd >= 0)
        {
          crc = crc32_of_range(fd, first, n);
          ::close(fd);
        }
      else
        n = 0;
      // The shares in rank order: crc(A B) = crc32_combine(crc(A), crc(B), |B|).
      const auto parts =
        dealii::Utilities::MPI::gather(comm, std::array<std::uint64_t, 2>{{crc, n}}, 0);
      uLong whole = crc32(0L, Z_NULL, 0);
      for (const auto &part : parts)
        whole = crc32_combine(whole, static_cast<uLong>(part[0]), static_cast<z_off_t>(part[1]));
      return static_cast<std::uint32_t>(whole);
    }



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
      out.section("driver");
      out.put(method);
      out.put(resumable_parameters(parameters));
    }



    namespace
    {
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
                     std::to_string(recorded.bytes) + " bytes, CRC-32 " + hex(recorded.crc) + "; now " +
                     (now == inputs.end() ? std::string("not read by the scene") :
                                            std::to_string(now->bytes) + " bytes, CRC-32 " + hex(now->crc)) +
                     "): a resumed run must read the inputs of the run it continues";
          }
        std::ifstream    in(file.global_file(), std::ios::binary);
        CheckpointReader reader(in, file.global_file());
        std::string      written_by, written_parameters;
        try
          {
            reader.section("driver");
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
      const bool root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
      // The checkpoints, newest first (rank 0 lists them).
      std::vector<std::string> candidates;
      if (root)
        {
          std::vector<std::pair<long, std::string>> found;
          std::error_code                           ec;
          for (const auto &entry : fs::directory_iterator(directory, ec))
            if (const long step = step_of(entry.path().filename().string()); step >= 0 && entry.is_directory(ec))
              found.emplace_back(step, entry.path().string());
          std::sort(found.rbegin(), found.rend());
          for (const auto &f : found)
            candidates.push_back(f.second);
        }
      candidates = dealii::Utilities::MPI::broadcast(comm, candidates, 0);
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
            read_info(candidate, file, why);
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
      CheckpointDirectory place;
      place.path        = file.directory;
      place.saved_ranks = n_ranks;
      place.n_ranks     = n_ranks;
      // Every rank takes part in the method's collective writes, even after a local error.
      std::ostringstream global_bytes, rank_bytes;
      try
        {
          CheckpointWriter global(global_bytes), own(rank_bytes);
          write(global, own, place);
          for (const auto &[name, bytes] : {std::make_pair(std::string("global.bin"), &global_bytes),
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
      // Every rank learns of a failure on any rank.
      for (const auto &p : dealii::Utilities::MPI::all_gather(comm, problem))
        if (!p.empty())
          {
            if (rank == 0)
              {
                std::error_code ec;
                fs::remove_all(temporary, ec);
              }
            throw RuntimeError("checkpoint at step " + std::to_string(step) + ": " + p);
          }

      // The digests of every file of the checkpoint (its contents once all ranks wrote).
      std::vector<std::pair<std::string, std::uint64_t>> written;
      if (rank == 0)
        {
          std::error_code ec;
          for (const auto &entry : fs::directory_iterator(temporary, ec))
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

      if (rank == 0)
        {
          for (const auto &[path, bytes] : tables)
            file.tables.push_back(digest(directory + "/" + path, bytes));
          for (auto &d : file.tables)
            d.path = fs::path(d.path).lexically_relative(directory).string();
          std::error_code ec;
          {
            std::ostringstream text;
            char               time_text[64];
            std::snprintf(time_text, sizeof(time_text), "%a", t);
            text << magic << "\nstep " << step << "\ntime " << time_text << "\nranks " << n_ranks << "\n";
            write_digests(text, "file", file.files);
            write_digests(text, "table", file.tables);
            write_digests(text, "input", inputs);
            std::ofstream info(temporary / "info.txt");
            info << text.str() << "end " << hex(text_crc(text.str())) << "\n";
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
            fs::remove_all(temporary, ec); // nothing incomplete stays
          if (problem.empty())
            try
              {
                // The manifest lists the checkpoint (its write may fail too).
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

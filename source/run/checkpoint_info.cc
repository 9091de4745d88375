// The description of a checkpoint on disk: its name, info.txt (written and read) and the
// CRC-32 digests of its files, of the time tables and of the run's inputs.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>

#include "run/checkpoint_info.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <fcntl.h>
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
          out << kind << ' ' << d.bytes << ' ' << CheckpointInfo::hex(d.crc) << ' ' << d.path << '\n';
      }
    } // namespace



    namespace CheckpointInfo
    {
      std::string
      name(const unsigned long step)
      {
        char digits[32];
        std::snprintf(digits, sizeof(digits), "%09lu", step);
        return prefix + digits;
      }



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



      std::string
      hex(const std::uint32_t crc)
      {
        char text[16];
        std::snprintf(text, sizeof(text), "%08x", crc);
        return text;
      }



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



      std::string
      text(const CheckpointFile &file)
      {
        std::ostringstream text;
        char               time_text[64];
        std::snprintf(time_text, sizeof(time_text), "%a", file.time);
        text << magic << "\nstep " << file.step << "\ntime " << time_text << "\nranks " << file.ranks << "\n";
        write_digests(text, "file", file.files);
        write_digests(text, "table", file.tables);
        write_digests(text, "input", file.inputs);
        return text.str() + "end " + hex(text_crc(text.str())) + "\n";
      }



      bool
      read(const fs::path &directory, CheckpointFile &file, std::string &why)
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
    } // namespace CheckpointInfo



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
            digests.push_back(CheckpointInfo::digest(path, size));
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
  } // namespace Run
} // namespace hysteron

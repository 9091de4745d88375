#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>

#include "run/keyed_records.h"

#include <algorithm>
#include <numeric>

namespace hysteron
{
  namespace Run
  {
    namespace
    {
      /// The largest piece one MPI-IO call moves (its count is an int).
      constexpr std::uint64_t max_piece = std::uint64_t(1) << 30;

      class File
      {
      public:
        File(const std::string &path, const int mode, MPI_Comm comm)
          : path(path)
        {
          check(MPI_File_open(comm, path.c_str(), mode, MPI_INFO_NULL, &handle), "open");
        }

        ~File()
        {
          if (handle != MPI_FILE_NULL)
            MPI_File_close(&handle);
        }

        void
        write(std::uint64_t offset, const char *data, std::uint64_t n)
        {
          for (std::uint64_t done = 0; done < n;)
            {
              const int  piece = static_cast<int>(std::min(max_piece, n - done));
              MPI_Status status;
              check(MPI_File_write_at(handle, offset + done, data + done, piece, MPI_BYTE, &status), "write");
              done += piece;
            }
        }

        void
        read(std::uint64_t offset, char *data, std::uint64_t n)
        {
          for (std::uint64_t done = 0; done < n;)
            {
              const int  piece = static_cast<int>(std::min(max_piece, n - done));
              MPI_Status status;
              check(MPI_File_read_at(handle, offset + done, data + done, piece, MPI_BYTE, &status), "read");
              int count = 0;
              MPI_Get_count(&status, MPI_BYTE, &count);
              if (count != piece)
                throw RuntimeError("checkpoint: '" + path + "' is shorter than its index says");
              done += piece;
            }
        }

        /// Collective: the file's data on disk, then closed.
        void
        close()
        {
          check(MPI_File_sync(handle), "sync");
          check(MPI_File_close(&handle), "close");
          handle = MPI_FILE_NULL;
        }

      private:
        void
        check(const int code, const char *what) const
        {
          if (code == MPI_SUCCESS)
            return;
          char text[MPI_MAX_ERROR_STRING];
          int  length = 0;
          MPI_Error_string(code, text, &length);
          throw RuntimeError("checkpoint: cannot " + std::string(what) + " '" + path + "': " +
                             std::string(text, length));
        }

        std::string path;
        MPI_File    handle = MPI_FILE_NULL;
      };

      /// The runs of consecutive keys in sorted @p keys: [begin, end) positions.
      std::vector<std::pair<std::size_t, std::size_t>>
      runs(const std::vector<std::uint64_t> &keys)
      {
        std::vector<std::pair<std::size_t, std::size_t>> result;
        for (std::size_t i = 0; i < keys.size();)
          {
            std::size_t j = i + 1;
            while (j < keys.size() && keys[j] == keys[j - 1] + 1)
              ++j;
            result.emplace_back(i, j);
            i = j;
          }
        return result;
      }
    } // namespace



    void
    write_records(const std::string                                  &path,
                  const std::uint64_t                                 n_keys,
                  std::vector<std::pair<std::uint64_t, std::string>> &records,
                  MPI_Comm                                            comm)
    {
      std::sort(records.begin(), records.end(), [](const auto &a, const auto &b) { return a.first < b.first; });
      std::uint64_t bytes = 0;
      for (const auto &r : records)
        {
          if (r.first >= n_keys)
            throw RuntimeError("checkpoint: a record of '" + path + "' has a key beyond the index");
          bytes += r.second.size();
        }
      std::uint64_t first = 0;
      int           ierr  = MPI_Exscan(&bytes, &first, 1, MPI_UINT64_T, MPI_SUM, comm);
      AssertThrowMPI(ierr);
      if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        first = 0;

      // Every rank's records and index entries, then both files closed (collectively).
      std::string                   error;
      std::string                   data;
      std::vector<std::uint64_t>    keys, index;
      data.reserve(bytes);
      for (const auto &r : records)
        {
          keys.push_back(r.first);
          index.push_back(first + data.size());
          index.push_back(r.second.size());
          data += r.second;
        }
      const bool last_key_held =
        dealii::Utilities::MPI::logical_or(!keys.empty() && keys.back() == n_keys - 1, comm);
      File records_file(path, MPI_MODE_CREATE | MPI_MODE_WRONLY, comm);
      File index_file(path + ".index", MPI_MODE_CREATE | MPI_MODE_WRONLY, comm);
      try
        {
          records_file.write(first, data.data(), data.size());
          // The index's last entry fixes its size: rank 0 writes it empty if no rank holds
          // that key (and only then: two ranks writing the same bytes race).
          if (dealii::Utilities::MPI::this_mpi_process(comm) == 0 && n_keys > 0 && !last_key_held)
            {
              const std::uint64_t none[2] = {0, 0};
              index_file.write(16 * (n_keys - 1), reinterpret_cast<const char *>(none), 16);
            }
          for (const auto &[begin, end] : runs(keys))
            index_file.write(16 * keys[begin],
                             reinterpret_cast<const char *>(index.data() + 2 * begin),
                             16 * (end - begin));
        }
      catch (const RuntimeError &e)
        {
          error = e.what();
        }
      records_file.close();
      index_file.close();
      for (const auto &e : dealii::Utilities::MPI::all_gather(comm, error))
        if (!e.empty())
          throw RuntimeError(e);
    }



    std::vector<std::string>
    read_records(const std::string &path, const std::vector<std::uint64_t> &keys, MPI_Comm comm)
    {
      // The keys in order; their index entries run by run, then the records.
      std::vector<std::size_t> order(keys.size());
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(), [&](const std::size_t a, const std::size_t b) { return keys[a] < keys[b]; });
      std::vector<std::uint64_t> sorted(keys.size());
      for (std::size_t i = 0; i < order.size(); ++i)
        sorted[i] = keys[order[i]];

      std::vector<std::string> result(keys.size());
      std::string              error;
      {
        File records_file(path, MPI_MODE_RDONLY, comm);
        File index_file(path + ".index", MPI_MODE_RDONLY, comm);
        try
          {
            std::vector<std::uint64_t> index(2 * sorted.size());
            for (const auto &[begin, end] : runs(sorted))
              index_file.read(16 * sorted[begin], reinterpret_cast<char *>(index.data() + 2 * begin), 16 * (end - begin));
            // Records that follow each other in the file are read in one piece.
            std::string buffer;
            for (std::size_t i = 0; i < sorted.size();)
              {
                std::size_t   j   = i + 1;
                std::uint64_t end = index[2 * i] + index[2 * i + 1];
                while (j < sorted.size() && index[2 * j] == end)
                  end += index[2 * j++ + 1];
                buffer.resize(end - index[2 * i]);
                records_file.read(index[2 * i], buffer.data(), buffer.size());
                for (std::size_t k = i; k < j; ++k)
                  result[order[k]] = buffer.substr(index[2 * k] - index[2 * i], index[2 * k + 1]);
                i = j;
              }
          }
        catch (const RuntimeError &e)
          {
            error = e.what();
          }
      }
      for (const auto &e : dealii::Utilities::MPI::all_gather(comm, error))
        if (!e.empty())
          throw RuntimeError(e);
      return result;
    }
  } // namespace Run
} // namespace hysteron

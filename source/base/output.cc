#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/output.h>
#include "base/run_record.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace hysteron
{
  namespace Output
  {
    void
    write_base64(std::ostream &out, const void *data, const std::size_t bytes)
    {
      // The byte count, then the bytes, as one base64 stream (3 bytes -> 4 characters).
      static const char  table[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
      const std::uint64_t count   = bytes;
      std::string         raw(sizeof(count) + bytes, '\0');
      std::memcpy(raw.data(), &count, sizeof(count));
      if (bytes > 0)
        std::memcpy(raw.data() + sizeof(count), data, bytes);
      std::string encoded;
      encoded.reserve(4 * ((raw.size() + 2) / 3));
      for (std::size_t i = 0; i < raw.size(); i += 3)
        {
          const std::size_t   n = std::min<std::size_t>(3, raw.size() - i);
          const std::uint32_t v = (std::uint32_t(static_cast<unsigned char>(raw[i])) << 16) |
                                  (n > 1 ? std::uint32_t(static_cast<unsigned char>(raw[i + 1])) << 8 : 0) |
                                  (n > 2 ? std::uint32_t(static_cast<unsigned char>(raw[i + 2])) : 0);
          encoded += table[(v >> 18) & 63];
          encoded += table[(v >> 12) & 63];
          encoded += n > 1 ? table[(v >> 6) & 63] : '=';
          encoded += n > 2 ? table[v & 63] : '=';
        }
      out << encoded;
    }



    void
    prepare_directory(const std::string &directory, const std::string &where)
    {
      namespace fs = std::filesystem;
      require(!directory.empty(), where, "the output directory name is empty");
      std::error_code ec;
      fs::create_directories(directory, ec);
      if (ec)
        throw InputError(where, "cannot create the directory '" + directory + "': " + ec.message());
      require(fs::is_directory(directory, ec),
              where,
              "'" + directory + "' exists and is not a directory");
      // errno right after the call (an argument list's order of evaluation is unspecified).
      if (::access(directory.c_str(), W_OK | X_OK) != 0)
        {
          const int error = errno;
          throw InputError(where,
                           "the directory '" + directory + "' is not writable: " +
                             std::strerror(error));
        }
    }

    AtomicFile::AtomicFile(const std::string &filename, RunRecord *const record)
      : final_name(filename)
      , temporary_name(filename + ".tmp")
      , record(record)
      , out(temporary_name)
    {
      if (!out)
        throw RuntimeError("cannot open '" + temporary_name + "' for writing: " +
                           std::strerror(errno));
    }

    AtomicFile::~AtomicFile()
    {
      if (!committed)
        {
          out.close();
          std::remove(temporary_name.c_str());
        }
    }

    void
    AtomicFile::commit()
    {
      if (committed)
        return;
      // The first failure's errno: a later call (close(), remove()) may overwrite it.
      if (!out && error == 0)
        error = errno;
      out.flush();
      if (!out && error == 0)
        error = errno;
      out.close();
      if (!out && error == 0)
        error = errno;
      if (!out || error != 0 || std::rename(temporary_name.c_str(), final_name.c_str()) != 0)
        {
          if (error == 0)
            error = errno;
          std::remove(temporary_name.c_str());
          throw RuntimeError("cannot write '" + final_name + "': " +
                             (error != 0 ? std::strerror(error) : "an input/output error"));
        }
      committed = true;
      if (record != nullptr)
        record->add_file(final_name);
    }

    void
    AtomicFile::write(const std::function<void(std::ostream &)> &writer)
    {
      try
        {
          writer(out);
        }
      catch (const std::exception &)
        {
          // Only a failed stream is the file's error (commit() reports it); anything
          // else is the writer's own and goes on.
          if (out)
            throw;
          error = errno;
        }
      commit();
    }

    void
    write_file(const std::string &filename, const std::string &content, RunRecord *const record)
    {
      AtomicFile file(filename, record);
      file.stream() << content;
      file.commit();
    }

    std::string
    format_row(const std::vector<double> &values)
    {
      std::string row;
      char        number[32];
      for (std::size_t i = 0; i < values.size(); ++i)
        {
          if (i > 0)
            row += ',';
          // %.15g: 15 significant digits; + 0.0 prints -0 as 0.
          const int n = std::snprintf(number, sizeof(number), "%.15g", values[i] + 0.0);
          row.append(number, n);
        }
      row += '\n';
      return row;
    }

    namespace
    {
      std::string
      header_line(const std::vector<std::string> &columns)
      {
        std::string line;
        for (std::size_t i = 0; i < columns.size(); ++i)
          line += (i == 0 ? "" : ",") + columns[i];
        return line + '\n';
      }

      void
      check_row(const std::vector<double> &values, const std::size_t n_columns)
      {
        if (values.size() != n_columns)
          throw std::logic_error("a table row of " + std::to_string(values.size()) +
                                 " values for " + std::to_string(n_columns) + " columns");
      }

      double
      wall_seconds()
      {
        return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
          .count();
      }
    } // namespace

    CsvWriter::CsvWriter(const std::string              &filename,
                         const std::vector<std::string> &columns,
                         RunRecord *const                record)
      : columns(columns)
      , file(filename, record)
    {
      file.stream() << header_line(columns);
    }

    void
    CsvWriter::add_row(const std::vector<double> &values)
    {
      check_row(values, columns.size());
      file.stream() << format_row(values);
    }

    TimeTable::TimeTable(const std::string              &filename,
                         const std::vector<std::string> &columns,
                         RunRecord                      &record)
      : name(filename)
      , record(record)
      , n_columns_(columns.size())
      , last_flush(wall_seconds())
    {
      std::int64_t keep    = record.resume_size(record.relative(filename));
      const bool   resumed = keep >= 0;
      if (!resumed)
        {
          // A new table: its header is written atomically (temporary file, then rename), so
          // the table never exists under its name without it (a run killed before its first
          // flush leaves a table with no rows, not an empty file).
          const std::string header = header_line(columns);
          write_file(filename, header, &record);
          keep = header.size();
        }
      // The rows follow the first keep bytes: the header, or on resume the rows up to the
      // checkpoint (the rest is cut off). A shorter file is refused: ftruncate would pad
      // it with NUL bytes (the resume checks the tables' rows before it gets here).
      fd = ::open(filename.c_str(), O_WRONLY | O_CLOEXEC);
      struct stat status;
      if (fd >= 0 && resumed && (::fstat(fd, &status) != 0 || status.st_size < keep))
        {
          ::close(fd);
          throw RuntimeError("cannot resume the table '" + filename + "': it has fewer than the " +
                             std::to_string(keep) + " bytes it had at the checkpoint");
        }
      if (fd < 0 || ::ftruncate(fd, keep) != 0 || ::lseek(fd, keep, SEEK_SET) != keep)
        throw RuntimeError(resumed ? "cannot resume the table '" + filename +
                                       "' (it should have at least " + std::to_string(keep) +
                                       " bytes from the checkpoint): " + std::strerror(errno) :
                                     "cannot write '" + filename + "': " + std::strerror(errno));
      written = keep;
      record.add_file(filename);
      record.register_table(this);
    }

    TimeTable::~TimeTable()
    {
      record.unregister_table(this);
      try
        {
          flush();
        }
      catch (...)
        {
          // A destructor must not throw; the error was reported by the run.
        }
      if (fd >= 0)
        ::close(fd);
    }

    void
    TimeTable::add_row(const std::vector<double> &values)
    {
      check_row(values, n_columns_);
      buffer += format_row(values);
      if (buffer.size() > (1u << 16))
        flush();
      else
        {
          const double now = wall_seconds();
          if (now - last_flush > 0.5)
            flush();
        }
    }

    void
    TimeTable::flush()
    {
      last_flush = wall_seconds();
      // The buffer holds whole rows only: one write() per flush keeps the file at a
      // row boundary whatever happens to the process.
      std::size_t done = 0;
      while (done < buffer.size())
        {
          const ssize_t n = ::write(fd, buffer.data() + done, buffer.size() - done);
          if (n < 0 && errno == EINTR)
            continue;
          if (n <= 0)
            {
              // A full disk may have taken part of a row: back to the last whole one.
              const int error = n < 0 ? errno : ENOSPC;
              if (done > 0 && ::ftruncate(fd, written) == 0)
                ::lseek(fd, written, SEEK_SET);
              throw RuntimeError("cannot write '" + name + "': " + std::strerror(error));
            }
          done += n;
        }
      written += buffer.size();
      buffer.clear();
    }

    void
    TimeTable::sync()
    {
      flush();
      if (::fsync(fd) != 0)
        throw RuntimeError("cannot write '" + name + "' to disk: " + std::strerror(errno));
    }

    namespace
    {
      /// Run @p write where @p writes and make its RuntimeError every rank's (the first
      /// failing rank's message): a rank that cannot write (a full disk) stops them all,
      /// instead of leaving the others waiting in the next collective operation.
      void
      collectively(const MPI_Comm comm, const bool writes, const std::function<void()> &write)
      {
        std::string failure;
        if (writes)
          try
            {
              write();
            }
          catch (const RuntimeError &e)
            {
              failure = e.what();
            }
        for (const auto &f : dealii::Utilities::MPI::all_gather(comm, failure))
          if (!f.empty())
            throw RuntimeError(f);
      }
    } // namespace

    FieldWriter::FieldWriter(const std::string &directory,
                             const std::string &base_name,
                             MPI_Comm           comm,
                             RunRecord *const   record)
      : directory(directory)
      , base_name(base_name)
      , comm(comm)
      , record(record)
    {}

    template <int dim, int spacedim>
    void
    FieldWriter::write(dealii::DataOutInterface<dim, spacedim> &data_out, const double time)
    {
      // zlib's fastest level: the default (best compression) made writing a particle
      // VTU cost about four times the 40 steps between two outputs
      // (doc/benchmarks/pay_for_use.md); the files are a little larger.
      dealii::DataOutBase::VtkFlags flags(time, counter, false); // no date: identical reruns
      flags.compression_level = dealii::DataOutBase::VtkFlags::best_speed;
      data_out.set_flags(flags);
      write_pieces([&](std::ostream &out) { data_out.write_vtu(out); },
                   [&](std::ostream &out, const std::vector<std::string> &pieces) {
                     data_out.write_pvtu_record(out, pieces);
                   },
                   time);
    }



    void
    FieldWriter::write_pieces(const std::function<void(std::ostream &)>                                   &piece,
                              const std::function<void(std::ostream &, const std::vector<std::string> &)> &record_writer,
                              const double                                                                time)
    {
      // A failing run writes its last good state, which may already be written.
      if (!times_and_names.empty() && times_and_names.back().first == time)
        return;
      const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      const unsigned int rank    = dealii::Utilities::MPI::this_mpi_process(comm);
      const std::string  stem    = base_name + "-" + dealii::Utilities::int_to_string(counter, 5);

      const std::string piece_name =
        n_ranks == 1 ? stem + ".vtu" : stem + "." + dealii::Utilities::int_to_string(rank, 4) + ".vtu";
      const std::string record_name = n_ranks == 1 ? piece_name : stem + ".pvtu";
      collectively(comm, true, [&]() { AtomicFile(directory + "/" + piece_name, record).write(piece); });

      // Every piece exists before the record that names it (collectively() waits for all).
      times_and_names.emplace_back(time, record_name);
      collectively(comm, rank == 0, [&]() {
        if (n_ranks > 1)
          {
            std::vector<std::string> pieces;
            for (unsigned int r = 0; r < n_ranks; ++r)
              pieces.push_back(stem + "." + dealii::Utilities::int_to_string(r, 4) + ".vtu");
            AtomicFile(directory + "/" + record_name, record).write([&](std::ostream &out) {
              record_writer(out, pieces);
            });
            // The pieces of the other ranks belong to this run too.
            if (record != nullptr)
              for (unsigned int r = 1; r < n_ranks; ++r)
                record->add_file(directory + "/" + pieces[r]);
          }
        write_pvd();
      });
      ++counter;
    }

    void
    FieldWriter::write_serial(const std::function<void(std::ostream &)> &writer, const double time)
    {
      if (!times_and_names.empty() && times_and_names.back().first == time)
        return;
      const std::string file = base_name + "-" + dealii::Utilities::int_to_string(counter, 5) + ".vtu";
      times_and_names.emplace_back(time, file);
      ++counter;
      collectively(comm, dealii::Utilities::MPI::this_mpi_process(comm) == 0, [&]() {
        AtomicFile(directory + "/" + file, record).write(writer);
        write_pvd();
      });
    }

    void
    FieldWriter::write_pvd() const
    {
      AtomicFile(directory + "/" + base_name + ".pvd", record).write([&](std::ostream &out) {
        dealii::DataOutBase::write_pvd_record(out, times_and_names);
      });
    }



    template void
    FieldWriter::write<1, 2>(dealii::DataOutInterface<1, 2> &, double);
    template void
    FieldWriter::write<2, 2>(dealii::DataOutInterface<2, 2> &, double);
    template void
    FieldWriter::write<3, 3>(dealii::DataOutInterface<3, 3> &, double);
    template void
    FieldWriter::write<0, 2>(dealii::DataOutInterface<0, 2> &, double);
    template void
    FieldWriter::write<0, 3>(dealii::DataOutInterface<0, 3> &, double);
  } // namespace Output
} // namespace hysteron

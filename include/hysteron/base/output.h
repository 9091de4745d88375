#ifndef hysteron_base_output_h
#define hysteron_base_output_h

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/mpi.h>

#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace Output
  {
    class RunRecord;

    /**
     * Create @p directory (with parents) and check that we can write into it.
     * Throws InputError at @p where ("Output/Directory") otherwise.
     */
    void
    prepare_directory(const std::string &directory, const std::string &where);

    /**
     * The inline binary form of a VTK XML DataArray (format="binary", header_type="UInt64"):
     * the base64 encoding of the array's byte count (8 bytes, little-endian) followed by
     * its bytes.
     */
    void
    write_base64(std::ostream &out, const void *data, std::size_t bytes);

    /// write_base64() of the values of @p values (a contiguous container).
    template <typename Container>
    void
    write_base64_array(std::ostream &out, const Container &values)
    {
      write_base64(out, values.data(), values.size() * sizeof(values[0]));
    }

    /**
     * A file that appears under its final name only when complete: the content
     * goes to "<name>.tmp", commit() closes and renames it. A file that is never
     * committed (an exception, a failed run) is removed, so a reader never sees
     * a half-written output. A file of a run is given the run's @p record, which
     * lists it once committed (null: a file outside a run).
     */
    class AtomicFile
    {
    public:
      explicit AtomicFile(const std::string &filename, RunRecord *record = nullptr);
      ~AtomicFile();

      AtomicFile(const AtomicFile &) = delete;
      AtomicFile &
      operator=(const AtomicFile &) = delete;

      std::ofstream &
      stream()
      {
        return out;
      }

      /// Flush, close and rename to the final name. Throws RuntimeError on an I/O error.
      void
      commit();

      /**
       * Write the content with @p writer into stream() and commit(). A writer that stops
       * on a failed stream (deal.II's VTU writers throw ExcIO; a full disk) is reported
       * as the RuntimeError of commit(): the file and the system's reason (strerror).
       */
      void
      write(const std::function<void(std::ostream &)> &writer);

      const std::string &
      filename() const
      {
        return final_name;
      }

    private:
      std::string   final_name;
      std::string   temporary_name;
      RunRecord    *record;
      std::ofstream out;
      bool          committed = false;
      int           error     = 0; ///< errno when the writer stopped on a failed stream
    };

    /// Write @p content to @p filename atomically (an AtomicFile of @p record).
    void
    write_file(const std::string &filename, const std::string &content, RunRecord *record = nullptr);

    /**
     * A CSV table written whole at the end of a run (particles.csv, springs.csv):
     * a header line, rows with 15 significant digits; an AtomicFile, so it
     * appears under its name on commit() and never half-written.
     */
    class CsvWriter
    {
    public:
      CsvWriter(const std::string              &filename,
                const std::vector<std::string> &columns,
                RunRecord                      *record = nullptr);

      std::size_t
      n_columns() const
      {
        return columns.size();
      }

      /// Append one row; its length must equal the number of columns.
      void
      add_row(const std::vector<double> &values);

      void
      commit()
      {
        file.commit();
      }

    private:
      std::vector<std::string> columns;
      AtomicFile               file;
    };

    /// One CSV row as text (15 significant digits, -0 printed as 0), with its newline.
    std::string
    format_row(const std::vector<double> &values);

    /**
     * A time table (probes, energies, reactions, Newton log, history): written
     * under its final name as the rows are produced, so that a run killed at any
     * moment (SIGKILL, a crash, a power cut) leaves a readable table of complete
     * rows. Rows are buffered and appended with one write() of whole lines at most
     * every half second of wall time (or 64 KiB), at flush(), at a checkpoint and
     * at the end of the run; the file never ends inside a row.
     *
     * Every open time table is known to the run's RunRecord: a checkpoint records the
     * length and CRC of each (after sync()), and a resumed run (hysteron --resume)
     * cuts each table back to that length and appends, so that its tables equal
     * an uninterrupted run's; a table shorter than that is refused, never padded.
     */
    class TimeTable
    {
    public:
      /// Open the table @p filename of the run of @p record (on resume: cut back to its
      /// length at the checkpoint).
      TimeTable(const std::string &filename, const std::vector<std::string> &columns, RunRecord &record);
      ~TimeTable();

      TimeTable(const TimeTable &) = delete;
      TimeTable &
      operator=(const TimeTable &) = delete;

      std::size_t
      n_columns() const
      {
        return n_columns_;
      }

      /// Append one row; its length must equal the number of columns.
      void
      add_row(const std::vector<double> &values);

      /// Write the buffered rows. Throws RuntimeError on an I/O error.
      void
      flush();

      /// flush() and make the rows durable (fsync).
      void
      sync();

      /// The length of the file once flushed [bytes].
      std::uint64_t
      size() const
      {
        return written + buffer.size();
      }

      const std::string &
      filename() const
      {
        return name;
      }

    private:
      std::string   name;
      RunRecord    &record;
      std::size_t   n_columns_ = 0;
      int           fd         = -1;
      std::string   buffer;
      std::uint64_t written    = 0;
      double        last_flush = 0;
    };
    /**
     * Field output for ParaView: every call to write() produces
     * "<base>-<step>.vtu" (on one rank) or "<base>-<step>.<rank>.vtu" plus a
     * ".pvtu" record (on several), and rewrites "<base>.pvd" with the list of
     * (time, file); a second call at the time of the last record writes nothing
     * (a failing run writes its last good state). All files are written
     * atomically. Works for any DataOutInterface: DataOut (FEM, background
     * grid), Particles::DataOut (MPM), or the custom patches of the RBSN cells.
     * The files are the run's of @p record (null: outside a run).
     */
    class FieldWriter
    {
    public:
      FieldWriter(const std::string &directory,
                  const std::string &base_name,
                  MPI_Comm           comm,
                  RunRecord         *record = nullptr);

      template <int dim, int spacedim>
      void
      write(dealii::DataOutInterface<dim, spacedim> &data_out, double time);

      /**
       * A VTU file that @p writer produces whole (a method's own cells, e.g. the
       * RBSN's polygons, the same on every rank): written by rank 0 as
       * "<base>-<step>.vtu", then the PVD.
       */
      void
      write_serial(const std::function<void(std::ostream &)> &writer, double time);

      /**
       * A field that a method writes itself (e.g. the RBSN's polygons): on one rank
       * @p piece writes "<base>-<step>.vtu"; on several, every rank writes its piece
       * "<base>-<step>.<rank>.vtu" and rank 0 the record "<base>-<step>.pvtu" with
       * @p record (given the pieces' names). Then the PVD. write() is this with DataOut.
       * A write that fails on any rank is a RuntimeError on every rank (as in
       * write_serial()).
       */
      void
      write_pieces(const std::function<void(std::ostream &)>                                   &piece,
                   const std::function<void(std::ostream &, const std::vector<std::string> &)> &record,
                   double                                                                      time);

      /// The (time, file) list written so far.
      const std::vector<std::pair<double, std::string>> &
      records() const
      {
        return times_and_names;
      }

      /// Resume: continue the series after these records (of a checkpoint).
      void
      restore(const std::vector<std::pair<double, std::string>> &records)
      {
        times_and_names = records;
        counter         = records.size();
      }

    private:
      /// Rank 0: "<base>.pvd" with the records so far.
      void
      write_pvd() const;

      std::string                                 directory;
      std::string                                 base_name;
      MPI_Comm                                    comm;
      RunRecord                                  *record;
      unsigned int                                counter = 0;
      std::vector<std::pair<double, std::string>> times_and_names;
    };
  } // namespace Output
} // namespace hysteron

#endif

#ifndef hysteron_base_run_record_h
#define hysteron_base_run_record_h

#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace hysteron
{
  namespace Output
  {
    class TimeTable;

    /**
     * What one run writes into its output directory. The run owns it
     * (Run::run_scene() creates it) and hands it by reference to the writers of
     * its files (AtomicFile, TimeTable, FieldWriter, the plotter), the output
     * directory and the checkpoints:
     *  - the files written, relative to the output directory, for the run's
     *    manifest (a later run removes them before it starts, so that no file
     *    of an earlier run looks current);
     *  - the time tables that are open, which a checkpoint flushes and
     *    measures, and which a resumed run cuts back to their length at the
     *    checkpoint before it appends.
     * Until begin() (and after end()) it records nothing; a file written outside
     * a run (unit tests, the compare tool on its own) is given no record at all.
     */
    class RunRecord
    {
    public:
      RunRecord() = default;

      RunRecord(const RunRecord &) = delete;
      RunRecord &
      operator=(const RunRecord &) = delete;

      /// Start recording the files under @p directory; only @p root writes the manifest.
      void
      begin(const std::string &directory, bool root, std::function<void()> files_changed);

      /// Stop recording (the end of the run).
      void
      end();

      bool
      active() const
      {
        return recording;
      }

      /// A file was written (any path; recorded relative to the output directory).
      void
      add_file(const std::string &path);

      /// A directory was written (checkpoints): recorded with a trailing '/'.
      void
      add_directory(const std::string &path);

      /// A recorded file or directory was removed (an old checkpoint).
      void
      remove(const std::string &path);

      /// The recorded files and directories, sorted.
      const std::set<std::string> &
      files() const
      {
        return written;
      }

      void
      register_table(TimeTable *table);
      void
      unregister_table(TimeTable *table);

      /// Flush every open time table.
      void
      flush_tables();

      /// Flush every open time table and make its rows durable (fsync): before a
      /// checkpoint that counts them is published.
      void
      sync_tables();

      /// The length of every open time table (after flush_tables()), by file path.
      std::map<std::string, std::uint64_t>
      table_sizes() const;

      /**
       * Resume: the tables' lengths at the checkpoint. A time table opened with
       * one of these names keeps its first @p size bytes and appends.
       */
      void
      set_resume_sizes(const std::map<std::string, std::uint64_t> &sizes);

      /// The length to keep of @p path on resume, or -1 (start the table anew).
      std::int64_t
      resume_size(const std::string &path) const;

      /// @p path relative to the output directory ("" when outside it).
      std::string
      relative(const std::string &path) const;

    private:
      bool                                 recording = false;
      bool                                 root      = false;
      std::string                          directory;
      std::function<void()>                changed;
      std::set<std::string>                written;
      std::vector<TimeTable *>             tables;
      std::map<std::string, std::uint64_t> resume_sizes;
    };
  } // namespace Output
} // namespace hysteron

#endif

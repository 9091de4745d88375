#ifndef hysteron_source_run_output_directory_h
#define hysteron_source_run_output_directory_h

#include <mpi.h>

#include <hysteron/base/checkpoint.h>
#include "base/run_record.h"

#include <string>

namespace hysteron
{
  namespace Run
  {
    /// What the manifest says of the run.
    struct RunDescription
    {
      std::string command;        ///< the command line
      std::string parameter_file;
      std::string method;
      unsigned int n_ranks = 1;
      std::vector<FileDigest> inputs; ///< the files the run read, as it read them
    };

    /**
     * The output directory of a run, kept safe from other runs:
     *  - a lock (`.hysteron.lock`, flock): a second run into a directory in use is
     *    refused with a message naming the running process; the lock goes with
     *    the process, even when it is killed;
     *  - a manifest (`manifest.json`): the command, version, commit, ranks, start,
     *    status and every file the run wrote, rewritten when a file is added;
     *  - hygiene: the files that the previous run's manifest lists are removed
     *    before a new run writes (not on --resume), so nothing stale looks current.
     * Rank 0 does the work; every rank learns of a problem (an InputError). The
     * files of the manifest are those of the run's @p record, which open() starts
     * and close() ends.
     */
    class OutputDirectory
    {
    public:
      explicit OutputDirectory(Output::RunRecord &record)
        : record(record)
      {}

      /// Before set-up: refuse a directory that cannot be created or written, or that a
      /// running process holds. Creates nothing.
      static void
      check_usable(const std::string &directory, MPI_Comm comm);

      /**
       * `hysteron --status DIR`: the state of the run in @p directory from its manifest. A
       * manifest says "running" from the start to the end of a run; a run killed in between
       * (SIGKILL, a lost MPI rank or node) cannot change it, but its lock went with it: a
       * manifest that says "running" while nobody holds the lock is reported as interrupted.
       * Throws InputError if @p directory holds no manifest.
       */
      static std::string
      describe(const std::string &directory);

      /// After set-up: create, lock, clean (a new run) and start the manifest.
      void
      open(const std::string &directory, const RunDescription &run, bool resume, MPI_Comm comm);

      /// The end of the run: "finished", "failed", "interrupted"; then unlock.
      void
      close(const std::string &status, const std::string &message);

      ~OutputDirectory();

    private:
      void
      write_manifest() const;

      Output::RunRecord &record;
      std::string        directory;
      RunDescription     run;
      bool               root    = false;
      int                lock_fd = -1;
      std::string        started, status = "running", message, resumed;
    };
  } // namespace Run
} // namespace hysteron

#endif

#ifndef hysteron_source_run_checkpoint_files_h
#define hysteron_source_run_checkpoint_files_h

#include <hysteron/base/checkpoint.h>

#include <mpi.h>

#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace hysteron
{
  namespace Run
  {
    /**
     * A checkpoint on disk: the directory `checkpoint-<step>` in the method's
     * output directory, with one file per MPI rank (`rank-<r>.bin`) and
     * `info.txt` (step, time, ranks). It is written as `checkpoint-<step>.tmp`
     * and renamed when every rank's file is complete, so a run killed while
     * writing leaves the previous checkpoints intact.
     */
    struct CheckpointFile
    {
      std::string   directory;
      unsigned long step  = 0;
      double        time  = 0;
      unsigned int  ranks = 1;

      std::string
      rank_file(unsigned int rank) const;
    };

    /// The newest complete checkpoint in @p directory (incomplete ones are ignored).
    std::optional<CheckpointFile>
    find_latest_checkpoint(const std::string &directory);

    /**
     * This rank's file of the newest checkpoint in @p directory, opened and
     * checked against the scene: written by @p method on as many ranks as this
     * run has, with the same parameters (all but `subsection Checkpoint` and
     * the progress interval, see resumable_parameters()). The reader stands
     * after that header. Throws InputError("--resume", ...) otherwise.
     */
    struct ResumeSource
    {
      CheckpointFile                    file;
      std::unique_ptr<std::ifstream>    stream;
      std::unique_ptr<CheckpointReader> reader;
    };

    ResumeSource
    open_resume(const std::string &directory,
                const std::string &method,
                const std::string &parameters,
                MPI_Comm           comm);

    /// The header open_resume() checks: @p method and the resumable parameters.
    void
    write_resume_header(CheckpointWriter &out, const std::string &method, const std::string &parameters);

    /// The effective parameters without what may change on resume.
    std::string
    resumable_parameters(const std::string &text);

    /**
     * Write a checkpoint of @p step (time @p t) in @p directory: every rank of
     * @p comm calls @p write with its own stream. Then keep the newest @p keep
     * checkpoints and delete the older ones. Collective; throws RuntimeError on
     * every rank if any rank failed.
     */
    void
    write_checkpoint(const std::string                              &directory,
                     unsigned long                                   step,
                     double                                          t,
                     MPI_Comm                                        comm,
                     unsigned int                                    keep,
                     const std::function<void(CheckpointWriter &)> &write);
  } // namespace Run
} // namespace hysteron

#endif

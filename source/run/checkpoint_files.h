#ifndef hysteron_source_run_checkpoint_files_h
#define hysteron_source_run_checkpoint_files_h

#include <hysteron/base/checkpoint.h>
#include "base/run_record.h"

#include <boost/serialization/string.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>
#include <mpi.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <ostream>
#include <string>
#include <vector>

namespace hysteron
{
  namespace Run
  {
    /// The digests of the input files @p paths, read on rank 0 (a missing file is
    /// an InputError naming it), broadcast to every rank of @p comm.
    std::vector<FileDigest>
    digest_inputs(const std::vector<std::string> &paths, MPI_Comm comm);

    /**
     * The CRC-32 (zlib's) of the first @p bytes of the file @p path, computed by
     * every rank of @p comm on its share of the bytes and combined in order
     * (crc32_combine), so that the work falls with the ranks. Collective; the
     * result is on rank 0. A file shorter than @p bytes gives a CRC that cannot
     * match (bytes are counted as read).
     */
    std::uint32_t
    crc32_of_file(const std::string &path, std::uint64_t bytes, MPI_Comm comm);

    /**
     * A checkpoint on disk (format 2): the directory `checkpoint-<step>` in the
     * method's output directory with
     *  - `global.bin`: the driver's state and what is the same on every rank;
     *  - `rank-<r>.bin`: rank r's own part (partial sums and the like);
     *  - the method's distributed files (a triangulation with its cells' data,
     *    records by cell), readable on any number of ranks;
     *  - `info.txt`, written last: step, time, ranks, and the size and CRC-32 of
     *    every file of the checkpoint, of every time table's rows up to the
     *    checkpoint, and of every input file of the run.
     * It is written as `checkpoint-<step>.tmp` and renamed when complete and on
     * disk (fsync), so a run killed while writing leaves the previous checkpoints
     * intact; a damaged one (a file cut or changed, a bit flipped) is detected by
     * its CRCs on resume and the previous one is taken.
     */
    struct CheckpointFile
    {
      std::string             directory;
      unsigned long           step  = 0;
      double                  time  = 0;
      unsigned int            ranks = 1;
      std::vector<FileDigest> files, tables, inputs;

      /// For deal.II's broadcast (Boost serialization).
      template <class Archive>
      void
      serialize(Archive &ar, const unsigned int)
      {
        ar &directory &step &time &ranks &files &tables &inputs;
      }

      std::string
      global_file() const
      {
        return directory + "/global.bin";
      }

      std::string
      rank_file(unsigned int rank) const;
    };

    /**
     * The newest intact checkpoint in @p directory for resuming the scene:
     * written by @p method, with the same resumable parameters, the same input
     * files (contents), its files and the tables' rows as recorded. A damaged
     * checkpoint is reported on @p notes (rank 0) and the previous one tried.
     * Throws InputError("--resume", ...) with the reasons if none can be used, or
     * at once if the scene's parameters or input files differ from the run's.
     * Collective.
     */
    CheckpointFile
    find_resumable_checkpoint(const std::string &directory, const std::string &method, const std::string &parameters,
                              const std::vector<FileDigest> &inputs, MPI_Comm comm, std::ostream &notes);

    /**
     * What the driver and the method read on resume: global.bin (read on rank 0,
     * sent to every rank) and the ranks' parts: this rank's own, or all of them
     * when the run has another number of ranks than the checkpoint's.
     */
    class CheckpointParts
    {
    public:
      CheckpointParts(const CheckpointDirectory &directory, MPI_Comm comm);

      CheckpointReader &
      global()
      {
        return *global_reader;
      }

      std::vector<CheckpointReader> &
      ranks()
      {
        return rank_readers;
      }

    private:
      std::istringstream                               global_stream;
      std::unique_ptr<CheckpointReader>                global_reader;
      std::vector<std::unique_ptr<std::istringstream>> rank_streams;
      std::vector<CheckpointReader>                    rank_readers;
    };

    /// The header of global.bin that find_resumable_checkpoint() checks: @p method and
    /// the resumable parameters.
    void
    write_resume_header(CheckpointWriter &out, const std::string &method, const std::string &parameters);

    /// The effective parameters without what may change on resume.
    std::string
    resumable_parameters(const std::string &text);

    /**
     * Write a checkpoint of @p step (time @p t) in @p directory: every rank of
     * @p comm calls @p write with the global stream (rank 0's is kept), its own
     * rank stream and the checkpoint's directory for distributed files; then the
     * digests of the files, of the time tables (@p tables: path relative to
     * @p directory and length, on rank 0) and of @p inputs go to info.txt and the
     * checkpoint is published, listed in the run's @p record. Keeps the newest
     * @p keep checkpoints. Collective; throws RuntimeError on every rank if any
     * rank failed. (checkpoint_info.cc: the names, info.txt and digests;
     * checkpoint_write.cc: this; checkpoint_resume.cc: finding and reading one.)
     */
    void
    write_checkpoint(
      const std::string                                                         &directory,
      unsigned long                                                              step,
      double                                                                     t,
      MPI_Comm                                                                   comm,
      unsigned int                                                               keep,
      const std::map<std::string, std::uint64_t>                                &tables,
      const std::vector<FileDigest>                                             &inputs,
      Output::RunRecord                                                         &record,
      const std::function<void(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &)> &write);
  } // namespace Run
} // namespace hysteron

#endif

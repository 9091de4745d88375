#ifndef hysteron_source_run_keyed_records_h
#define hysteron_source_run_keyed_records_h

#include <hysteron/base/exceptions.h>

#include <deal.II/base/mpi.h>

#include <mpi.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace Run
  {
    /**
     * Records by key in a checkpoint, for state that belongs to numbered things
     * the same on any number of ranks (the cells of a mesh, the cells of an RBSN):
     * every rank writes the records of its own keys, and any rank of a run with
     * any number of ranks reads back the records of the keys it owns then. Two
     * files, written and read with MPI-IO (each rank only its part):
     *  - @p path: the records, rank after rank, each rank's in the order of its keys;
     *  - @p path.index: 16 bytes per key 0 ... n_keys - 1, the record's offset and
     *    length (a key nobody wrote reads as an empty record).
     * Collective. Throws RuntimeError naming the file on an I/O error.
     */
    void
    write_records(const std::string                                  &path,
                  std::uint64_t                                       n_keys,
                  std::vector<std::pair<std::uint64_t, std::string>> &records,
                  MPI_Comm                                            comm);

    /// The records of @p keys (any order; each < the n_keys written), in that order.
    /// Collective. Throws RuntimeError naming the file if it cannot be read.
    std::vector<std::string>
    read_records(const std::string &path, const std::vector<std::uint64_t> &keys, MPI_Comm comm);

    /**
     * Runs @p read_records_of_this_rank (which parses this rank's records and may
     * throw InputError) on every rank, and throws the first rank's InputError on every
     * rank if any rank's threw: a damaged record refuses the resume everywhere, not on
     * one rank while the others wait in the next collective call. Collective.
     */
    template <typename Function>
    void
    parse_collectively(MPI_Comm comm, const Function &read_records_of_this_rank)
    {
      std::pair<std::string, std::string> error;
      try
        {
          read_records_of_this_rank();
        }
      catch (const InputError &e)
        {
          error = {e.where(), e.problem()};
        }
      for (const auto &[where, problem] : dealii::Utilities::MPI::all_gather(comm, error))
        if (!problem.empty())
          throw InputError(where, problem);
    }
  } // namespace Run
} // namespace hysteron

#endif

// Collective operations of the distributed network: the gather of plain values (one
// MPI_Allgatherv or MPI_Gatherv, without deal.II's serialization: see doc/architecture.md)
// and the same error on every rank.
#ifndef hysteron_rbsn_collective_h
#define hysteron_rbsn_collective_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/mpi.templates.h> // Utilities::MPI::sum/min/max of std::vector<T> for any T

#include <hysteron/base/exceptions.h>

#include <string>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    namespace Collective
    {
      /// Every rank's @p mine, concatenated in the order of the ranks, on every rank
      /// (@p root < 0) or on rank @p root only (empty elsewhere).
      template <typename T>
      std::vector<T>
      gather(const std::vector<T> &mine, const MPI_Comm comm, const int root = -1)
      {
        const MPI_Datatype type    = dealii::Utilities::MPI::mpi_type_id_for_type<T>;
        const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
        const int          n       = mine.size();
        std::vector<int>   counts(n_ranks), offsets(n_ranks, 0);
        int ierr = MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
        AssertThrowMPI(ierr);
        for (unsigned int r = 1; r < n_ranks; ++r)
          offsets[r] = offsets[r - 1] + counts[r - 1];
        const bool     here = root < 0 || int(dealii::Utilities::MPI::this_mpi_process(comm)) == root;
        std::vector<T> all(here ? offsets.back() + counts.back() : 0);
        if (root < 0)
          ierr = MPI_Allgatherv(mine.data(), n, type, all.data(), counts.data(), offsets.data(), type, comm);
        else
          ierr = MPI_Gatherv(mine.data(), n, type, all.data(), counts.data(), offsets.data(), type, root, comm);
        AssertThrowMPI(ierr);
        return all;
      }

      /**
       * Run @p f on every rank of @p comm and throw the same error on every rank if it
       * throws an InputError or a RuntimeError on any (the first rank's): the ranks of a
       * distributed set-up never diverge (each goes on to the same next collective).
       */
      template <typename Function>
      void
      collectively(const MPI_Comm comm, Function f)
      {
        std::string input_where, input_problem, runtime;
        try
          {
            f();
          }
        catch (const InputError &e)
          {
            input_where   = e.where();
            input_problem = e.problem();
          }
        catch (const RuntimeError &e)
          {
            runtime = e.what();
          }
        // One reduction when no rank failed; the messages only when one did.
        const int failed = input_problem.empty() && runtime.empty() ? 0 : 1;
        if (dealii::Utilities::MPI::n_mpi_processes(comm) == 1 || dealii::Utilities::MPI::max(failed, comm) == 0)
          {
            if (!input_problem.empty())
              throw InputError(input_where, input_problem);
            if (!runtime.empty())
              throw RuntimeError(runtime);
            return;
          }
        const auto wheres   = dealii::Utilities::MPI::all_gather(comm, input_where);
        const auto problems = dealii::Utilities::MPI::all_gather(comm, input_problem);
        const auto runtimes = dealii::Utilities::MPI::all_gather(comm, runtime);
        for (unsigned int r = 0; r < problems.size(); ++r)
          {
            if (!problems[r].empty())
              throw InputError(wheres[r], problems[r]);
            if (!runtimes[r].empty())
              throw RuntimeError(runtimes[r]);
          }
      }
    } // namespace Collective
  }   // namespace RBSN
} // namespace hysteron

#endif

// Collective operations of the distributed network on vectors of plain values (one
// MPI_Allgatherv or MPI_Gatherv, without serialization).
#ifndef hysteron_rbsn_collective_h
#define hysteron_rbsn_collective_h

#include <deal.II/base/mpi.h>

#include <type_traits>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    namespace Collective
    {
      /// The MPI type of double, unsigned int, unsigned long and unsigned long long.
      template <typename T>
      MPI_Datatype
      type()
      {
        if constexpr (std::is_same_v<T, double>)
          return MPI_DOUBLE;
        else if constexpr (std::is_same_v<T, unsigned int>)
          return MPI_UNSIGNED;
        else if constexpr (std::is_same_v<T, unsigned long>)
          return MPI_UNSIGNED_LONG;
        else
          {
            static_assert(std::is_same_v<T, unsigned long long>, "an unsupported type");
            return MPI_UNSIGNED_LONG_LONG;
          }
      }

      /// Every rank's @p mine, concatenated in the order of the ranks, on every rank
      /// (@p root < 0) or on rank @p root only (empty elsewhere).
      template <typename T>
      std::vector<T>
      gather(const std::vector<T> &mine, const MPI_Comm comm, const int root = -1)
      {
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
          ierr = MPI_Allgatherv(mine.data(), n, type<T>(), all.data(), counts.data(), offsets.data(), type<T>(), comm);
        else
          ierr = MPI_Gatherv(mine.data(), n, type<T>(), all.data(), counts.data(), offsets.data(), type<T>(), root, comm);
        AssertThrowMPI(ierr);
        return all;
      }

      /// Reduce @p values over @p comm in place (MPI_SUM, MPI_MIN or MPI_MAX).
      template <typename T>
      void
      all_reduce(std::vector<T> &values, const MPI_Op op, const MPI_Comm comm)
      {
        const int ierr = MPI_Allreduce(MPI_IN_PLACE, values.data(), values.size(), type<T>(), op, comm);
        AssertThrowMPI(ierr);
      }
    } // namespace Collective
  }   // namespace RBSN
} // namespace hysteron

#endif

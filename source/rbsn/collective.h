// Collective operations of the distributed network on vectors of plain values (one
// MPI_Allgatherv, MPI_Gatherv or MPI_Alltoallv, without serialization).
#ifndef hysteron_rbsn_collective_h
#define hysteron_rbsn_collective_h

#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>

#include <algorithm>
#include <map>
#include <string>
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

      /**
       * Point-to-point messages: @p send maps a rank to the values for it; returns the
       * values each rank sent to this one (ranks that sent nothing are left out). One
       * MPI_Alltoall of the counts (O(ranks) per rank) and one MPI_Alltoallv.
       */
      template <typename T>
      std::map<unsigned int, std::vector<T>>
      exchange(const std::map<unsigned int, std::vector<T>> &send, const MPI_Comm comm)
      {
        const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
        std::vector<int>   send_counts(n_ranks, 0), receive_counts(n_ranks, 0);
        std::vector<int>   send_offsets(n_ranks, 0), receive_offsets(n_ranks, 0);
        for (const auto &[r, values] : send)
          send_counts[r] = values.size();
        int ierr = MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, comm);
        AssertThrowMPI(ierr);
        for (unsigned int r = 1; r < n_ranks; ++r)
          {
            send_offsets[r]    = send_offsets[r - 1] + send_counts[r - 1];
            receive_offsets[r] = receive_offsets[r - 1] + receive_counts[r - 1];
          }
        std::vector<T> out(send_offsets.back() + send_counts.back());
        for (const auto &[r, values] : send)
          std::copy(values.begin(), values.end(), out.begin() + send_offsets[r]);
        std::vector<T> in(receive_offsets.back() + receive_counts.back());
        ierr = MPI_Alltoallv(out.data(), send_counts.data(), send_offsets.data(), type<T>(), in.data(),
                             receive_counts.data(), receive_offsets.data(), type<T>(), comm);
        AssertThrowMPI(ierr);
        std::map<unsigned int, std::vector<T>> result;
        for (unsigned int r = 0; r < n_ranks; ++r)
          if (receive_counts[r] > 0)
            result[r].assign(in.begin() + receive_offsets[r], in.begin() + receive_offsets[r] + receive_counts[r]);
        return result;
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

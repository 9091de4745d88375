// Benchmark: the RBSN's plain-value gathers (source/rbsn/collective.h: one MPI_Allgatherv /
// MPI_Gatherv of the values) and a plain MPI_Alltoallv against deal.II 9.4's serializing
// Utilities::MPI::all_gather / gather / some_to_some (boost::serialization of each rank's
// std::vector, then the concatenation the RBSN needs) at the RBSN's sizes.
//
//   mpirun -np 2 benchmarks/collectives [--repeats 21]
//
// Per size n (values per rank: the facets' cell pairs, output rows, nuclei of a block), the
// median wall time over the repeats (each after a barrier), on rank 0.
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include "rbsn/collective.h"

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  double
  median_time(const unsigned int repeats, const MPI_Comm comm, const std::function<void()> &f)
  {
    f();
    std::vector<double> times;
    for (unsigned int r = 0; r < repeats; ++r)
      {
        MPI_Barrier(comm);
        Timer timer;
        f();
        times.push_back(timer.wall_time());
      }
    std::sort(times.begin(), times.end());
    return Utilities::MPI::max(times[times.size() / 2], comm);
  }



  template <typename T>
  std::vector<T>
  concatenate(const std::vector<std::vector<T>> &parts)
  {
    std::vector<T> all;
    for (const auto &p : parts)
      all.insert(all.end(), p.begin(), p.end());
    return all;
  }

  /// The plain-value MPI_Alltoallv that Utilities::MPI::some_to_some replaced in the RBSN
  /// (kept here as the reference of the measurement).
  template <typename T>
  std::map<unsigned int, std::vector<T>>
  alltoallv(const std::map<unsigned int, std::vector<T>> &send, const MPI_Comm comm)
  {
    const unsigned int n_ranks = Utilities::MPI::n_mpi_processes(comm);
    const MPI_Datatype type    = Utilities::MPI::mpi_type_id_for_type<T>;
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
    ierr = MPI_Alltoallv(out.data(), send_counts.data(), send_offsets.data(), type, in.data(), receive_counts.data(),
                         receive_offsets.data(), type, comm);
    AssertThrowMPI(ierr);
    std::map<unsigned int, std::vector<T>> result;
    for (unsigned int r = 0; r < n_ranks; ++r)
      if (receive_counts[r] > 0)
        result[r].assign(in.begin() + receive_offsets[r], in.begin() + receive_offsets[r] + receive_counts[r]);
    return result;
  }
} // namespace



int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm                   comm    = MPI_COMM_WORLD;
  const unsigned int               rank    = Utilities::MPI::this_mpi_process(comm);
  const unsigned int               n_ranks = Utilities::MPI::n_mpi_processes(comm);
  unsigned int                     repeats = 21;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--repeats")
      repeats = std::atoi(argv[i + 1]);
  if (rank == 0)
    std::cout << "| values per rank | Collective::gather [ms] | Utilities::MPI::all_gather [ms] | "
                 "gather to rank 0 [ms] | Utilities::MPI::gather [ms] | MPI_Alltoallv [ms] | "
                 "Utilities::MPI::some_to_some [ms] |\n|---|---|---|---|---|---|---|"
              << std::endl;
  for (const unsigned int n : {10u, 1000u, 100000u, 1000000u})
    {
      const std::vector<double>                        mine(n, 1.0 + rank);
      std::map<unsigned int, std::vector<unsigned long>> send;
      for (unsigned int r = 0; r < n_ranks; ++r)
        if (r != rank)
          send[r] = std::vector<unsigned long>(n / std::max(1u, n_ranks - 1), rank);
      std::size_t check = 0;
      const double t[6] = {
        median_time(repeats, comm, [&]() { check += hysteron::RBSN::Collective::gather(mine, comm).size(); }),
        median_time(repeats, comm, [&]() { check += concatenate(Utilities::MPI::all_gather(comm, mine)).size(); }),
        median_time(repeats, comm, [&]() { check += hysteron::RBSN::Collective::gather(mine, comm, 0).size(); }),
        median_time(repeats, comm, [&]() { check += concatenate(Utilities::MPI::gather(comm, mine, 0)).size(); }),
        median_time(repeats, comm, [&]() { check += alltoallv(send, comm).size(); }),
        median_time(repeats, comm, [&]() { check += Utilities::MPI::some_to_some(comm, send).size(); })};
      if (rank == 0)
        {
          std::cout << "| " << n << std::fixed << std::setprecision(3);
          for (const double s : t)
            std::cout << " | " << 1e3 * s;
          std::cout << " |" << (check == 0 ? " (nothing moved)" : "") << std::endl;
        }
    }
}

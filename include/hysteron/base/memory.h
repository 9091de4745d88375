#ifndef hysteron_base_memory_h
#define hysteron_base_memory_h

#include <mpi.h>

#include <string>

namespace hysteron
{
  /**
   * The memory estimate of a run, made before its large allocations (the material
   * points, the Voronoi cells, the refined mesh) and compared with what the machine
   * has, so that a run that cannot fit is refused with an input error instead of
   * ending in the kernel's out-of-memory killer after minutes. The methods give the
   * bytes per item they measured (see their comments and doc/reliability.md).
   */
  namespace Memory
  {
    /// Resident size of the program before it holds any data (deal.II, Trilinos, MPI, the
    /// parsed scene): the intercepts of the fits of benchmarks/memory_estimate.py, 175 to
    /// 199 MB.
    inline constexpr double program_bytes = 180e6;

    /**
     * The share of @p count items (points, cells, DoFs) that the most loaded of
     * @p n_ranks ranks holds in a @p dim-dimensional partition: count / n_ranks with 10 %
     * for the imbalance, plus one layer of ghosts along its interfaces, about
     * 2 (count / n_ranks)^((dim-1)/dim) items (the two faces of a slab of its share).
     */
    double
    largest_share(double count, unsigned int n_ranks, unsigned int dim);

    /**
     * The bytes a rank of @p comm may use: MemAvailable of /proc/meminfo (the physical
     * memory where it cannot be read) over the ranks on its node (MPI_COMM_TYPE_SHARED),
     * the least over the nodes. Collective.
     */
    double
    available_per_rank(MPI_Comm comm);

    /// A count for the messages: whole below 1e7 ("64000"), else 3 digits ("2.62e+11").
    std::string
    count(double n);

    /**
     * Refuse the run (InputError at @p where, on every rank) unless the @p bytes this rank
     * is estimated to need (program_bytes included) fit into available_per_rank() on every
     * rank. The message says @p what is counted (e.g. "1e11 material points at 560 B
     * each"), the estimate of the largest rank, the memory available and @p advice (what
     * to change). Collective.
     */
    void
    require_fits(MPI_Comm comm, double bytes, const std::string &where, const std::string &what,
                 const std::string &advice);
  } // namespace Memory
} // namespace hysteron

#endif

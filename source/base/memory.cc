#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/memory.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace hysteron
{
  namespace Memory
  {
    namespace
    {
      /// MemAvailable of /proc/meminfo in bytes (the kernel's estimate of what can be
      /// allocated without swapping), or the physical memory where it is missing.
      double
      available_on_node()
      {
        std::ifstream meminfo("/proc/meminfo");
        std::string   key, unit;
        double        kib = 0;
        while (meminfo >> key >> kib)
          {
            std::getline(meminfo, unit);
            if (key == "MemAvailable:")
              return kib * 1024;
          }
        return static_cast<double>(sysconf(_SC_PHYS_PAGES)) * sysconf(_SC_PAGE_SIZE);
      }



      std::string
      gigabytes(const double bytes)
      {
        std::ostringstream s;
        s.precision(3);
        s << bytes / 1e9 << " GB";
        return s.str();
      }
    } // namespace



    std::string
    count(const double n)
    {
      std::ostringstream s;
      if (n < 1e7)
        s << std::llround(n);
      else
        {
          s.precision(3);
          s << n;
        }
      return s.str();
    }



    double
    largest_share(const double count, const unsigned int n_ranks, const unsigned int dim)
    {
      if (n_ranks <= 1)
        return count;
      const double share = count / n_ranks;
      return 1.1 * share + 2 * std::pow(share, (dim - 1.0) / dim);
    }



    double
    available_per_rank(const MPI_Comm comm)
    {
      MPI_Comm node;
      MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
      const unsigned int on_node = dealii::Utilities::MPI::n_mpi_processes(node);
      // One reading per node: the ranks that started first have already taken some.
      const double available = dealii::Utilities::MPI::broadcast(node, available_on_node(), 0);
      MPI_Comm_free(&node);
      return dealii::Utilities::MPI::min(available / on_node, comm);
    }



    void
    require_fits(const MPI_Comm     comm,
                 const double       bytes,
                 const std::string &where,
                 const std::string &what,
                 const std::string &advice)
    {
      const double need      = dealii::Utilities::MPI::max(program_bytes + bytes, comm);
      const double available = available_per_rank(comm);
      if (need <= available)
        return;
      const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      throw InputError(where,
                       what + ": about " + gigabytes(need) +
                         (n_ranks > 1 ? " on the most loaded of " + std::to_string(n_ranks) + " MPI ranks" : "") +
                         ", but " + gigabytes(available) + " are available" +
                         (n_ranks > 1 ? " per rank (MemAvailable shared by the ranks of a node)" :
                                        " (MemAvailable)") +
                         ": " + advice);
    }
  } // namespace Memory
} // namespace hysteron

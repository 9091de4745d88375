// The `hysteron` executable: MPI set-up, then the command line (run/application.h).
#include <deal.II/base/mpi.h>

#include <hysteron/run/application.h>

int
main(int argc, char **argv)
{
  // One thread per rank: the hot kernels are serial per rank, and TBB threads
  // would compete with MPI ranks on small machines.
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  return hysteron::run_application(argc, argv);
}

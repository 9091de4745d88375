// Benchmark: time per repeated factorization (one sparsity pattern, new values: Newton's
// tangents) of hysteron's direct solvers against deal.II 9.4's wrappers:
//   SparseLU (UMFPACK, analysis kept)       vs SparseDirectUMFPACK::factorize (analyses each time)
//   KeptDirectSolver (Amesos KLU or MUMPS, analysis kept, numeric factorization + solve)
//                                           vs TrilinosWrappers::SolverDirect initialize + solve
//
//   benchmarks/direct_solvers [--repeats 9]
//
// The matrices have the patterns the RBSN and the FEM factorize: RBSN-like, 3 (2D) or 6 (3D)
// DoFs per node coupled by blocks to the node's neighbours (FESystem(FE_Q(1), n) patterns on
// a square / cube grid: 8 resp. 26 neighbours, a Voronoi network has ~6 resp. ~14), and FEM
// elasticity (FESystem(FE_Q(p), dim)). The values are random, diagonally dominant; each repeat
// scales them (same pattern, new values). Output: the median wall time per factorization.
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include "base/direct_solver.h"
#include "base/sparse_lu.h"

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <iomanip>
#include <iostream>
#include <random>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  /// The median wall time of @p repeats calls of @p f (after one untimed call).
  double
  median_time(const unsigned int repeats, const std::function<void()> &f)
  {
    f();
    std::vector<double> times;
    for (unsigned int r = 0; r < repeats; ++r)
      {
        Timer timer;
        f();
        times.push_back(timer.wall_time());
      }
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
  }



  struct Case
  {
    std::string  name;
    int          dim, degree, components, subdivisions;
  };



  template <int dim>
  void
  make_pattern(const Case &c, SparsityPattern &pattern)
  {
    Triangulation<dim> tria;
    GridGenerator::subdivided_hyper_cube(tria, c.subdivisions);
    FESystem<dim>   fe(FE_Q<dim>(c.degree), c.components);
    DoFHandler<dim> dofs(tria);
    dofs.distribute_dofs(fe);
    DynamicSparsityPattern dsp(dofs.n_dofs());
    DoFTools::make_sparsity_pattern(dofs, dsp);
    pattern.copy_from(dsp);
  }



  void
  run(const Case &c, const unsigned int repeats)
  {
    SparsityPattern pattern;
    if (c.dim == 2)
      make_pattern<2>(c, pattern);
    else
      make_pattern<3>(c, pattern);
    SparseMatrix<double>                   A(pattern);
    std::mt19937                           random(1);
    std::uniform_real_distribution<double> uniform(-1, 1);
    for (unsigned int i = 0; i < A.m(); ++i)
      {
        double off = 0;
        for (auto e = A.begin(i); e != A.end(i); ++e)
          if (e->column() != i)
            {
              e->value() = uniform(random);
              off += std::abs(e->value());
            }
        A.set(i, i, 1 + off);
      }
    const auto step = [&](auto &matrix) { matrix *= 1.0001; };

    hysteron::SparseLU ours_umfpack;
    const double       t_ours_umfpack = median_time(repeats, [&]() {
      step(A);
      ours_umfpack.factorize(A);
    });
    SparseDirectUMFPACK deal_umfpack;
    const double        t_deal_umfpack = median_time(repeats, [&]() {
      step(A);
      deal_umfpack.factorize(A);
    });

    TrilinosWrappers::SparseMatrix T;
    T.reinit(A);
    TrilinosWrappers::MPI::Vector x(T.locally_owned_range_indices(), MPI_COMM_WORLD),
      b(T.locally_owned_range_indices(), MPI_COMM_WORLD);
    b = 1;
    std::vector<double> t_amesos;
    for (const std::string package : {"Amesos_Klu", "Amesos_Mumps"})
      {
        hysteron::KeptDirectSolver ours(package);
        t_amesos.push_back(median_time(repeats, [&]() {
          step(T);
          ours.solve(T, x, b);
        }));
        // A new SolverDirect per factorization, as the RBSN's parallel.cc makes it: deal.II
        // 9.4's initialize() of a used one crashes with MUMPS (in Amesos_Mumps::Destroy).
        SolverControl control;
        t_amesos.push_back(median_time(repeats, [&]() {
          step(T);
          TrilinosWrappers::SolverDirect deal(control, TrilinosWrappers::SolverDirect::AdditionalData(false, package));
          deal.initialize(T);
          deal.solve(x, b);
        }));
      }

    std::cout << "| " << c.name << " | " << A.m() << " | " << pattern.n_nonzero_elements() << std::fixed
              << std::setprecision(4) << " | " << t_ours_umfpack << " | " << t_deal_umfpack << " | " << t_amesos[0]
              << " | " << t_amesos[1] << " | " << t_amesos[2] << " | " << t_amesos[3] << " |" << std::endl;
  }
} // namespace



int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  unsigned int                     repeats = 9;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--repeats")
      repeats = std::atoi(argv[i + 1]);
  const std::vector<Case> cases{{"RBSN-like 2D, 3 DoFs/node", 2, 1, 3, 60},
                                {"RBSN-like 3D, 6 DoFs/node", 3, 1, 6, 10},
                                {"FEM 2D Q2 elasticity", 2, 2, 2, 50},
                                {"FEM 3D Q1 elasticity", 3, 1, 3, 12},
                                {"FEM 3D Q2 elasticity", 3, 2, 3, 6}};
  std::cout << "| matrix | rows | nonzeros | SparseLU [s] | SparseDirectUMFPACK [s] | KeptDirectSolver KLU [s] | "
               "SolverDirect KLU [s] | KeptDirectSolver MUMPS [s] | SolverDirect MUMPS [s] |\n|---|---|---|---|---|---|---|---|---|"
            << std::endl;
  for (const Case &c : cases)
    run(c, repeats);
}

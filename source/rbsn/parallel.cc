// The RBSN under MPI. The network (cells, facets, their geometry) and the DoF
// vectors are replicated: every rank builds the same network from the same seed.
// The work is shared: the cells are partitioned over the ranks by METIS on the
// cell graph (a facet belongs to the owner of its first cell), each rank
// evaluates the spring laws of its facets and assembles them into a distributed
// Trilinos matrix, which is factorized by UMFPACK on rank 0 (gathered) or by
// Trilinos Amesos (KLU on one rank, or MUMPS in parallel). After every converged step
// the facets' states go from their owners to every rank, so that outputs,
// fracture, fragments and checkpoints see the whole network on every rank.
#include <deal.II/base/mpi.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_index_access.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_vector.h>

#include <hysteron/rbsn/model.h>

#include "base/sparse_lu.h"

#include <Epetra_CrsMatrix.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    void
    Model::partition()
    {
      const MPI_Comm     comm    = scene.mpi_communicator();
      const unsigned int n_cells = network.cells.size();
      // Variable order integrates one serial vector (SUNDIALS IDA): every rank runs the
      // whole network, as does a network with fewer cells than ranks.
      const bool replicated = analysis == Analysis::variable_order ||
                              n_cells < dealii::Utilities::MPI::n_mpi_processes(comm);
      n_ranks = replicated ? 1 : dealii::Utilities::MPI::n_mpi_processes(comm);
      rank    = replicated ? 0 : dealii::Utilities::MPI::this_mpi_process(comm);
      cell_owner.assign(n_cells, 0);
      if (n_ranks > 1)
        {
          // METIS on the graph of the cells joined by facets: balanced parts with
          // few facets across the cut. The same input gives the same parts on every rank.
          dealii::DynamicSparsityPattern graph(n_cells, n_cells);
          for (const auto &f : network.facets)
            {
              graph.add(f.a, f.b);
              graph.add(f.b, f.a);
            }
          dealii::SparsityPattern pattern;
          pattern.copy_from(graph);
          dealii::SparsityTools::partition(pattern, n_ranks, cell_owner, dealii::SparsityTools::Partitioner::metis);
        }
      owned_facet.assign(network.facets.size(), false);
      owned_facets.clear();
      for (unsigned int e = 0; e < network.facets.size(); ++e)
        if (cell_owner[network.facets[e].a] == rank)
          {
            owned_facet[e] = true;
            owned_facets.push_back(e);
          }
      owned_dofs.set_size(3 * n_cells);
      for (unsigned int c = 0; c < n_cells; ++c)
        if (cell_owner[c] == rank)
          owned_dofs.add_range(3 * c, 3 * c + 3);
      owned_dofs.compress();
      if (!trilinos_system())
        return;

      // The matrix: the cell blocks of the owned cells and the couplings of the owned
      // facets (rows of other ranks' cells go to their owners).
      dealii::IndexSet relevant = owned_dofs;
      dealii::DynamicSparsityPattern dsp(3 * n_cells, 3 * n_cells);
      const auto block = [&](const unsigned int p, const unsigned int q) {
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            dsp.add(3 * p + i, 3 * q + j);
      };
      for (unsigned int c = 0; c < n_cells; ++c)
        if (cell_owner[c] == rank)
          block(c, c);
      for (const unsigned int e : owned_facets)
        {
          const Facet<2> &f = network.facets[e];
          for (const unsigned int p : {f.a, f.b})
            {
              relevant.add_range(3 * p, 3 * p + 3);
              for (const unsigned int q : {f.a, f.b})
                block(p, q);
            }
        }
      relevant.compress();
      dealii::SparsityTools::distribute_sparsity_pattern(dsp, owned_dofs, comm, relevant);
      parallel_matrix.reinit(owned_dofs, owned_dofs, dsp, comm);
      if (distributed())
        scene.console() << "rbsn: " << n_ranks << " MPI ranks, " << owned_facets.size() << " of "
                        << network.facets.size() << " facets on rank " << rank << std::endl;
    }



    void
    Model::sum_over_ranks(Vector &x) const
    {
      if (!distributed())
        return;
      const MPI_Comm comm = scene.mpi_communicator();
      // Then the root's sum to all: the same bits everywhere, whatever the reduction order.
      int ierr = MPI_Allreduce(MPI_IN_PLACE, x.data(), x.size(), MPI_DOUBLE, MPI_SUM, comm);
      AssertThrowMPI(ierr);
      ierr = MPI_Bcast(x.data(), x.size(), MPI_DOUBLE, 0, comm);
      AssertThrowMPI(ierr);
    }



    void
    Model::synchronize_springs()
    {
      if (!distributed())
        return;
      const MPI_Comm comm = scene.mpi_communicator();
      // Per facet: delta, force, trial delta, trial force (3 each), the tangent (9) and
      // the spring law's converged and trial states.
      const auto pack = [](const Springs &sp, std::vector<double> &buffer) {
        for (const auto *a : {&sp.delta, &sp.force, &sp.trial_delta, &sp.trial_force})
          buffer.insert(buffer.end(), a->begin(), a->end());
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            buffer.push_back(sp.tangent[i][j]);
        buffer.insert(buffer.end(), sp.state.begin(), sp.state.end());
        buffer.insert(buffer.end(), sp.trial_state.begin(), sp.trial_state.end());
      };
      std::vector<double> mine;
      for (const unsigned int e : owned_facets)
        pack(springs[e], mine);
      std::vector<int> counts(n_ranks), offsets(n_ranks, 0);
      const int        n_mine = mine.size();
      int ierr = MPI_Allgather(&n_mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
      AssertThrowMPI(ierr);
      for (unsigned int r = 1; r < n_ranks; ++r)
        offsets[r] = offsets[r - 1] + counts[r - 1];
      std::vector<double> all(offsets.back() + counts.back());
      ierr = MPI_Allgatherv(mine.data(), n_mine, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                            MPI_DOUBLE, comm);
      AssertThrowMPI(ierr);
      // Each rank's facets in increasing order, as that rank packed them.
      std::vector<std::size_t> position(n_ranks);
      for (unsigned int r = 0; r < n_ranks; ++r)
        position[r] = offsets[r];
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          const unsigned int owner = cell_owner[network.facets[e].a];
          const double      *p     = all.data() + position[owner];
          Springs           &sp    = springs[e];
          for (auto *a : {&sp.delta, &sp.force, &sp.trial_delta, &sp.trial_force})
            for (auto &x : *a)
              x = *p++;
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
              sp.tangent[i][j] = *p++;
          for (auto &x : sp.state)
            x = *p++;
          for (auto &x : sp.trial_state)
            x = *p++;
          position[owner] = p - all.data();
        }
    }



    void
    Model::add_local(const dealii::FullMatrix<double>                     &K,
                     const dealii::Vector<double>                         &r,
                     const std::vector<dealii::types::global_dof_index> &dofs,
                     const bool                                           with_matrix)
    {
      if (!with_matrix)
        constraints.distribute_local_to_global(r, dofs, rhs);
      else if (trilinos_system())
        constraints.distribute_local_to_global(K, r, dofs, parallel_matrix, rhs, true);
      else
        constraints.distribute_local_to_global(K, r, dofs, matrix, rhs, true);
    }



    void
    Model::add_local_rhs(const dealii::FullMatrix<double>                     &K,
                         const dealii::Vector<double>                         &r,
                         const std::vector<dealii::types::global_dof_index> &dofs)
    {
      // Free rows: r less the columns of the prescribed increments g (-K g).
      constraints.distribute_local_to_global(r, dofs, rhs, K);
      if (!constraints.has_inhomogeneities())
        return;
      // A constrained row gets its diagonal times g, as the assembly with the matrix gives
      // it (K_ii, or the mean |K_ii| of the local matrix where K_ii = 0): the predictor's
      // force level does not depend on how the matrix was assembled.
      const unsigned int n    = dofs.size();
      double             mean = 0;
      for (unsigned int i = 0; i < n; ++i)
        mean += std::abs(K(i, i));
      mean /= n;
      if (mean == 0)
        mean = K.l1_norm() / n;
      if (mean == 0)
        mean = 1;
      for (unsigned int i = 0; i < n; ++i)
        if (constraints.is_constrained(dofs[i]))
          rhs(dofs[i]) += (K(i, i) != 0 ? K(i, i) : mean) * constraints.get_inhomogeneity(dofs[i]);
    }



    void
    Model::add_local_change(dealii::FullMatrix<double> &K, const std::vector<dealii::types::global_dof_index> &dofs)
    {
      // The constrained rows and columns are empty but for the diagonal of the last full
      // assembly, which they keep.
      for (unsigned int i = 0; i < dofs.size(); ++i)
        if (constraints.is_constrained(dofs[i]))
          for (unsigned int j = 0; j < dofs.size(); ++j)
            K(i, j) = K(j, i) = 0;
      if (trilinos_system())
        parallel_matrix.add(dofs, K);
      else
        matrix.add(dofs, K);
    }



    void
    Model::solve_distributed(Vector &x)
    {
      using namespace dealii;
      const MPI_Comm comm = scene.mpi_communicator();
      const bool renew = renew_factors();
      if (linear_solver != "direct")
        return solve_iterative(x, renew);
      if (distributed_solver == "UMFPACK")
        return solve_gathered(x, renew);
      TrilinosWrappers::MPI::Vector b(owned_dofs, comm), y(owned_dofs, comm), r(owned_dofs, comm),
        d(owned_dofs, comm);
      try
        {
          if (renew)
            {
              // The factors belong to a copy, so that the assembly can go on in parallel_matrix.
              factored_parallel.copy_from(parallel_matrix);
              parallel_direct = std::make_unique<TrilinosWrappers::SolverDirect>(
                parallel_control, TrilinosWrappers::SolverDirect::AdditionalData(false, distributed_solver));
              parallel_direct->initialize(factored_parallel);
              factorized = true;
              ++n_factorizations;
            }
          for (const auto i : owned_dofs)
            b(i) = rhs(i);
          b.compress(VectorOperation::insert);
          parallel_direct->solve(y, b);
          // Iterative refinement against the factorized matrix (the rotations' stiffness
          // k l^2 / 12 is far below the translations' k: the pivots lose digits).
          const double target = 1e-14 * b.l2_norm();
          double       last   = std::numeric_limits<double>::infinity();
          for (unsigned int k = 0; k < 3; ++k)
            {
              const double norm = factored_parallel.residual(r, y, b);
              if (!(norm > target) || !(norm < 0.5 * last))
                break;
              last = norm;
              parallel_direct->solve(d, r);
              y += d;
            }
        }
      catch (const ExceptionBase &)
        {
          throw singular_tangent();
        }
      x = 0;
      for (const auto i : owned_dofs)
        x(i) = y(i);
      sum_over_ranks(x);
    }



    void
    Model::solve_gathered(Vector &x, const bool renew)
    {
      using namespace dealii;
      const MPI_Comm comm = scene.mpi_communicator();
      if (renew)
        {
          // Every rank's rows (global row, length, then column and value pairs) to rank 0,
          // which fills the serial matrix and factorizes it with the kept symbolic analysis.
          std::vector<double>     rows;
          const Epetra_CrsMatrix &A = parallel_matrix.trilinos_matrix();
          for (int i = 0; i < A.NumMyRows(); ++i)
            {
              int     n = 0;
              double *values = nullptr;
              int    *columns = nullptr;
              A.ExtractMyRowView(i, n, values, columns);
              rows.push_back(TrilinosWrappers::global_index(A.RowMap(), i));
              rows.push_back(n);
              for (int k = 0; k < n; ++k)
                {
                  rows.push_back(TrilinosWrappers::global_index(A.ColMap(), columns[k]));
                  rows.push_back(values[k]);
                }
            }
          int              n_mine = rows.size();
          std::vector<int> counts(n_ranks), offsets(n_ranks, 0);
          int ierr = MPI_Gather(&n_mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
          AssertThrowMPI(ierr);
          for (unsigned int r = 1; r < n_ranks; ++r)
            offsets[r] = offsets[r - 1] + counts[r - 1];
          std::vector<double> all(rank == 0 ? offsets.back() + counts.back() : 0);
          ierr = MPI_Gatherv(rows.data(), n_mine, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                             MPI_DOUBLE, 0, comm);
          AssertThrowMPI(ierr);
          int singular = 0;
          if (rank == 0)
            {
              matrix = 0;
              for (std::size_t p = 0; p < all.size();)
                {
                  const auto row = static_cast<types::global_dof_index>(all[p]);
                  const auto n   = static_cast<std::size_t>(all[p + 1]);
                  for (std::size_t k = 0; k < n; ++k)
                    matrix.set(row, static_cast<types::global_dof_index>(all[p + 2 + 2 * k]), all[p + 3 + 2 * k]);
                  p += 2 + 2 * n;
                }
              try
                {
                  direct->factorize(matrix);
                }
              catch (const std::runtime_error &)
                {
                  singular = 1;
                }
            }
          ierr = MPI_Bcast(&singular, 1, MPI_INT, 0, comm);
          AssertThrowMPI(ierr);
          if (singular)
            throw singular_tangent();
          factored_parallel.copy_from(parallel_matrix);
          factorized = true;
          ++n_factorizations;
        }
      // The right-hand side is replicated: rank 0 solves and sends the solution.
      if (rank == 0)
        direct->solve(x, rhs);
      const int ierr = MPI_Bcast(x.data(), x.size(), MPI_DOUBLE, 0, comm);
      AssertThrowMPI(ierr);
    }



    void
    Model::solve_iterative(Vector &x, const bool renew)
    {
      using namespace dealii;
      const MPI_Comm comm = scene.mpi_communicator();
      if (renew || !amg)
        {
          // ML aggregation with the null space of the network: per cell the translations
          // (1, 0, 0), (0, 1, 0) and the rotation (-(y - y_0), x - x_0, 1) about the centre.
          TrilinosWrappers::PreconditionAMG::AdditionalData data(true, false, 1, false, 1e-4, {}, 2, 0, false,
                                                                 "Chebyshev", "Amesos-KLU");
          Teuchos::ParameterList              list;
          std::unique_ptr<Epetra_MultiVector> constant_modes;
          data.set_parameters(list, constant_modes, parallel_matrix);
          const Epetra_Map &map     = parallel_matrix.trilinos_matrix().RowMap();
          const int         n_local = map.NumMyElements();
          dealii::Point<2>  lo(1e300, 1e300), hi(-1e300, -1e300);
          for (const auto &cell : network.cells)
            for (unsigned int d = 0; d < 2; ++d)
              {
                lo[d] = std::min(lo[d], cell.nucleus[d]);
                hi[d] = std::max(hi[d], cell.nucleus[d]);
              }
          const dealii::Point<2> centre = 0.5 * (lo + hi);
          null_space.assign(3 * n_local, 0.0);
          for (int i = 0; i < n_local; ++i)
            {
              const auto               g = TrilinosWrappers::global_index(map, i);
              const unsigned int       k = g % 3;
              const dealii::Tensor<1, 2> r = network.cells[g / 3].nucleus - centre;
              null_space[i]               = k == 0 ? 1.0 : 0.0;
              null_space[n_local + i]     = k == 1 ? 1.0 : 0.0;
              null_space[2 * n_local + i] = k == 0 ? -r[1] : k == 1 ? r[0] : 1.0;
            }
          list.set("PDE equations", 3);
          list.set("null space: type", "pre-computed");
          list.set("null space: dimension", 3);
          list.set("null space: vectors", null_space.data());
          amg = std::make_unique<TrilinosWrappers::PreconditionAMG>();
          amg->initialize(parallel_matrix.trilinos_matrix(), list);
          factored_parallel.copy_from(parallel_matrix);
          factorized = true;
          ++n_factorizations;
        }
      TrilinosWrappers::MPI::Vector b(owned_dofs, comm), y(owned_dofs, comm);
      for (const auto i : owned_dofs)
        b(i) = rhs(i);
      b.compress(VectorOperation::insert);
      SolverControl control(solver_max_iterations, std::max(1e-300, solver_tolerance * b.l2_norm()));
      try
        {
          if (linear_solver == "cg")
            SolverCG<TrilinosWrappers::MPI::Vector>(control).solve(parallel_matrix, y, b, *amg);
          else
            SolverGMRES<TrilinosWrappers::MPI::Vector>(control,
                                                       SolverGMRES<TrilinosWrappers::MPI::Vector>::AdditionalData(100, true))
              .solve(parallel_matrix, y, b, *amg);
        }
      catch (const SolverControl::NoConvergence &e)
        {
          std::ostringstream m;
          m << "rbsn: the " << linear_solver << " solver did not converge in " << e.last_step
            << " iterations (residual " << e.last_residual << ", target " << control.tolerance()
            << "); raise RBSN/Linear solver iterations or use Linear solver = direct";
          throw RuntimeError(m.str());
        }
      n_linear_iterations += control.last_step();
      x = 0;
      for (const auto i : owned_dofs)
        x(i) = y(i);
      sum_over_ranks(x);
    }
  } // namespace RBSN
} // namespace hysteron

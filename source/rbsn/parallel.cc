// The RBSN under MPI. The network is distributed (network.cc): each rank has its own
// cells (a share of the cells along the sampling blocks), the facets whose first cell
// is its own, and the neighbouring cells of other ranks as ghosts. The DoF vectors are
// distributed vectors over the owned and ghost cells' DoFs; each rank evaluates the
// spring laws of its facets and assembles them into a distributed Trilinos matrix (the
// rows of ghost cells travel to their owners), which is factorized by UMFPACK on rank 0
// (gathered), by Trilinos Amesos (KLU on one rank, or MUMPS in parallel), or solved by
// CG / GMRES with algebraic multigrid.
#include <deal.II/base/mpi.h>
#include <deal.II/lac/affine_constraints.templates.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_index_access.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_vector.h>

#include "rbsn/collective.h"
#include "rbsn/model.h"

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
    template <int dim>
    MPI_Comm
    Model<dim>::network_communicator() const
    {
      return distributed() ? scene().mpi_communicator() : MPI_COMM_SELF;
    }



    template <int dim>
    void
    Model<dim>::setup_parallel_system()
    {
      const MPI_Comm  comm = network_communicator();
      const dof_index n    = n_dofs * n_cells;
      // The owned DoFs are one range (the cells' blocks are numbered rank by rank); the
      // relevant ones add the ghost cells'.
      owned_dofs.clear();
      owned_dofs.set_size(n);
      if (n_owned_cells > 0)
        owned_dofs.add_range(n_dofs * cell_block[0], n_dofs * (cell_block[0] + n_owned_cells));
      owned_dofs.compress();
      relevant_dofs = owned_dofs;
      for (unsigned int c = n_owned_cells; c < cell_id.size(); ++c)
        relevant_dofs.add_range(n_dofs * cell_block[c], n_dofs * cell_block[c] + n_dofs);
      relevant_dofs.compress();
      partitioner = std::make_shared<dealii::Utilities::MPI::Partitioner>(owned_dofs, relevant_dofs, comm);
      for (Vector *w : {&u, &u_trial, &v, &a, &rhs, &f_int, &f_ext, &f_ext_old, &inertia, &reaction_old})
        w->reinit(partitioner);
      if (!trilinos_system())
        return;

      // The matrix: the cell blocks of the owned cells and the couplings of the owned
      // facets (rows of other ranks' cells go to their owners).
      dealii::DynamicSparsityPattern dsp(relevant_dofs);
      const auto block = [&](const unsigned int p, const unsigned int q) {
        for (unsigned int i = 0; i < n_dofs; ++i)
          for (unsigned int j = 0; j < n_dofs; ++j)
            dsp.add(n_dofs * cell_block[p] + i, n_dofs * cell_block[q] + j);
      };
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        block(c, c);
      for (const auto &f : network.facets)
        for (const unsigned int p : {f.a, f.b})
          for (const unsigned int q : {f.a, f.b})
            block(p, q);
      if (distributed())
        dealii::SparsityTools::distribute_sparsity_pattern(dsp, owned_dofs, comm, relevant_dofs);
      parallel_matrix.reinit(owned_dofs, owned_dofs, dsp, comm);
      if (distributed())
        scene().console() << "rbsn: " << n_parts << " MPI ranks, " << network.facets.size() << " of "
                        << n_global_facets << " facets and " << n_owned_cells << " of " << n_cells
                        << " cells on rank 0" << std::endl;
    }



    template <int dim>
    void
    Model<dim>::add_local(const dealii::FullMatrix<double> &K,
                          const dealii::Vector<double>     &r,
                          const std::vector<dof_index>     &dofs,
                          const bool                        with_matrix)
    {
      if (!with_matrix)
        constraints.distribute_local_to_global(r, dofs, rhs);
      else if (trilinos_system())
        constraints.distribute_local_to_global(K, r, dofs, parallel_matrix, rhs, true);
      else
        constraints.distribute_local_to_global(K, r, dofs, matrix, rhs, true);
    }



    template <int dim>
    void
    Model<dim>::add_local_rhs(const dealii::FullMatrix<double> &K,
                              const dealii::Vector<double>     &r,
                              const std::vector<dof_index>     &dofs)
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



    template <int dim>
    void
    Model<dim>::add_local_change(dealii::FullMatrix<double> &K, const std::vector<dof_index> &dofs)
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



    template <int dim>
    void
    Model<dim>::solve_distributed(Vector &x)
    {
      using namespace dealii;
      const MPI_Comm comm  = network_communicator();
      const bool     renew = renew_factors();
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
          std::copy(rhs.begin(), rhs.begin() + rhs.locally_owned_size(), b.begin());
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
      std::copy(y.begin(), y.end(), x.begin());
    }



    template <int dim>
    void
    Model<dim>::solve_gathered(Vector &x, const bool renew)
    {
      using namespace dealii;
      const MPI_Comm     comm    = network_communicator();
      const unsigned int n_ranks = Utilities::MPI::n_mpi_processes(comm);
      const bool         root    = Utilities::MPI::this_mpi_process(comm) == 0;
      if (renew)
        {
          // Every rank's rows (global row, length, then column and value pairs) to rank 0,
          // which fills the serial matrix and factorizes it with the kept symbolic analysis.
          std::vector<double>     rows;
          const Epetra_CrsMatrix &A = parallel_matrix.trilinos_matrix();
          for (int i = 0; i < A.NumMyRows(); ++i)
            {
              int     n       = 0;
              double *values  = nullptr;
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
          const std::vector<double> all      = Collective::gather(rows, comm, 0);
          int                       singular = 0;
          if (root)
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
          Utilities::MPI::broadcast(&singular, 1, 0, comm);
          if (singular)
            throw singular_tangent();
          factored_parallel.copy_from(parallel_matrix);
          factorized = true;
          ++n_factorizations;
        }
      // The right-hand side's ranges (rank by rank, in the order of the DoFs) to rank 0,
      // which solves and sends each rank its range of the solution.
      const int        n_mine = rhs.locally_owned_size();
      std::vector<int> counts(n_ranks), offsets(n_ranks, 0);
      int              ierr = MPI_Allgather(&n_mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
      AssertThrowMPI(ierr);
      for (unsigned int r = 1; r < n_ranks; ++r)
        offsets[r] = offsets[r - 1] + counts[r - 1];
      dealii::Vector<double> b(root ? rhs.size() : 0), y(root ? rhs.size() : 0);
      ierr = MPI_Gatherv(rhs.begin(), n_mine, MPI_DOUBLE, b.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, comm);
      AssertThrowMPI(ierr);
      if (root)
        direct->solve(y, b);
      ierr = MPI_Scatterv(y.data(), counts.data(), offsets.data(), MPI_DOUBLE, x.begin(), n_mine, MPI_DOUBLE, 0, comm);
      AssertThrowMPI(ierr);
    }



    template <int dim>
    void
    Model<dim>::solve_iterative(Vector &x, const bool renew)
    {
      using namespace dealii;
      const MPI_Comm comm = network_communicator();
      if (renew || !amg)
        {
          // ML aggregation with the null space of the network: per cell the translations
          // and the rotations about the centre of the network (2D: (-(y - y_0), x - x_0, 1);
          // 3D: the displacement e_j x r and the rotation e_j about each axis e_j).
          TrilinosWrappers::PreconditionAMG::AdditionalData data(true, false, 1, false, 1e-4, {}, 2, 0, false,
                                                                 "Chebyshev", "Amesos-KLU");
          Teuchos::ParameterList              list;
          std::unique_ptr<Epetra_MultiVector> constant_modes;
          data.set_parameters(list, constant_modes, parallel_matrix);
          const Epetra_Map        &map     = parallel_matrix.trilinos_matrix().RowMap();
          const int                n_local = map.NumMyElements();
          const dealii::Point<dim> centre  = 0.5 * (nuclei_box[0] + nuclei_box[1]);
          constexpr unsigned int   n_modes = n_dofs;
          null_space.assign(n_modes * n_local, 0.0);
          for (int i = 0; i < n_local; ++i)
            {
              const auto                   g = TrilinosWrappers::global_index(map, i);
              const unsigned int           k = g % n_dofs;
              const unsigned int           c = (g - owned_dofs.nth_index_in_set(0)) / n_dofs;
              const dealii::Tensor<1, dim> r = local_nuclei[c] - centre;
              for (unsigned int m = 0; m < dim; ++m)
                null_space[m * n_local + i] = k == m ? 1.0 : 0.0;
              if constexpr (dim == 2)
                null_space[2 * n_local + i] = k == 0 ? -r[1] : k == 1 ? r[0] : 1.0;
              else
                for (unsigned int j = 0; j < 3; ++j)
                  {
                    dealii::Tensor<1, 3> axis;
                    axis[j]                          = 1;
                    const dealii::Tensor<1, 3> moved = dealii::cross_product_3d(axis, r);
                    null_space[(3 + j) * n_local + i] = k < 3 ? moved[k] : (k - 3 == j ? 1.0 : 0.0);
                  }
            }
          list.set("PDE equations", int(n_dofs));
          list.set("null space: type", "pre-computed");
          list.set("null space: dimension", int(n_modes));
          list.set("null space: vectors", null_space.data());
          amg = std::make_unique<TrilinosWrappers::PreconditionAMG>();
          amg->initialize(parallel_matrix.trilinos_matrix(), list);
          factored_parallel.copy_from(parallel_matrix);
          factorized = true;
          ++n_factorizations;
        }
      TrilinosWrappers::MPI::Vector b(owned_dofs, comm), y(owned_dofs, comm);
      std::copy(rhs.begin(), rhs.begin() + rhs.locally_owned_size(), b.begin());
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
      std::copy(y.begin(), y.end(), x.begin());
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

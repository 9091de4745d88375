// The RBSN's linear system: the sparsity pattern, the factorizations and the solves.
#include <deal.II/base/mpi.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include "rbsn/model.h"

#include "base/sparse_lu.h"
#include "rbsn/collective.h"

#include <Epetra_CrsMatrix.h>

#include <cmath>
#include <limits>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::setup_system()
    {
      setup_parallel_system();
      // The serial matrix: one part, or rank 0 under the gathered UMFPACK solver.
      const bool gathered = distributed() && linear_solver == "direct" && distributed_solver == "UMFPACK";
      if (!trilinos_system() || (gathered && scene().is_root()))
        {
          const dof_index                n = n_dofs * n_cells;
          dealii::DynamicSparsityPattern dsp(n, n);
          const auto block = [&](const dof_index p, const dof_index q) {
            for (unsigned int i = 0; i < n_dofs; ++i)
              for (unsigned int j = 0; j < n_dofs; ++j)
                dsp.add(n_dofs * p + i, n_dofs * q + j);
          };
          if (!distributed())
            {
              for (unsigned int c = 0; c < cell_id.size(); ++c)
                block(c, c);
              for (const auto &f : network.facets)
                for (const unsigned int p : {f.a, f.b})
                  for (const unsigned int q : {f.a, f.b})
                    block(p, q);
            }
          else
            {
              // Rank 0 holds the whole pattern: the cells' blocks and every rank's facets'
              // pairs of blocks (gathered once).
              for (dof_index c = 0; c < n_cells; ++c)
                block(c, c);
              std::vector<unsigned long long> pairs;
              for (const auto &f : network.facets)
                pairs.insert(pairs.end(), {cell_block[f.a], cell_block[f.b]});
              const auto all = Collective::gather(pairs, scene().mpi_communicator(), 0);
              for (std::size_t k = 0; k < all.size(); k += 2)
                for (const auto p : {all[k], all[k + 1]})
                  for (const auto q : {all[k], all[k + 1]})
                    block(p, q);
            }
          pattern.copy_from(dsp);
          matrix.reinit(pattern);
          factored_matrix.reinit(pattern);
        }
      else if (gathered)
        {
          std::vector<unsigned long long> pairs;
          for (const auto &f : network.facets)
            pairs.insert(pairs.end(), {cell_block[f.a], cell_block[f.b]});
          Collective::gather(pairs, scene().mpi_communicator(), 0);
        }
      factorized = false;
      direct->clear();
    }



    template <int dim>
    bool
    Model<dim>::renew_factors()
    {
      // Refactorize only on change: an unchanged tangent (elastic steps, static analyses)
      // keeps its factors; with a reuse tolerance, a tangent within it of the factorized
      // one too (modified Newton), unless the last correction with stale factors reduced
      // the residual less than twofold. The change is ||K - K_f||_F / ||K_f||_F against the
      // copy K_f kept at the last factorization (summed over the ranks' rows).
      double change = std::numeric_limits<double>::infinity();
      if (factorized)
        {
          double sums[2] = {0, 0}; // ||K - K_f||^2, ||K_f||^2
          const auto add = [&](const double k, const double f) {
            sums[0] += (k - f) * (k - f);
            sums[1] += f * f;
          };
          if (trilinos_system())
            {
              // The two matrices share their graph (copy_from): compare the local rows.
              const Epetra_CrsMatrix &A = parallel_matrix.trilinos_matrix(),
                                     &F = factored_parallel.trilinos_matrix();
              for (int row = 0; row < A.NumMyRows(); ++row)
                {
                  int     n_a = 0, n_f = 0;
                  double *a = nullptr, *f = nullptr;
                  A.ExtractMyRowView(row, n_a, a);
                  F.ExtractMyRowView(row, n_f, f);
                  for (int k = 0; k < std::min(n_a, n_f); ++k)
                    add(a[k], f[k]);
                }
              dealii::Utilities::MPI::sum(sums, network_communicator(), sums);
            }
          else
            for (auto p = matrix.begin(), q = factored_matrix.begin(); p != matrix.end(); ++p, ++q)
              add(p->value(), q->value());
          change = std::sqrt(sums[0] / sums[1]);
        }
      const double residual = rhs.l2_norm();
      const bool   slow     = stale_factors && residual > 0.5 * previous_residual;
      const bool   renew    = !(change <= reuse_tolerance) || slow;
      stale_factors         = !renew && change > 0;
      previous_residual     = residual;
      return renew;
    }



    template <int dim>
    RuntimeError
    Model<dim>::singular_tangent()
    {
      return RuntimeError("rbsn: the tangent stiffness matrix is singular: the network is a "
                          "mechanism (springs without stiffness, e.g. perfectly plastic ones at "
                          "their limit, or a part that only such springs hold)");
    }



    template <int dim>
    void
    Model<dim>::solve_linear(Vector &x)
    {
      if (trilinos_system())
        return solve_distributed(x);
      try
        {
          if (renew_factors())
            {
              direct->factorize(matrix);
              factored_matrix.copy_from(matrix);
              factorized = true;
              ++n_factorizations;
            }
          // One part: the local entries are the global ones.
          dealii::Vector<double> b(rhs.begin(), rhs.begin() + rhs.locally_owned_size()), y(b.size());
          direct->solve(y, b);
          std::copy(y.begin(), y.end(), x.begin());
        }
      catch (const std::runtime_error &)
        {
          throw singular_tangent();
        }
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

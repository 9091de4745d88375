// The network's cells as points of a continuum, for the output column plugins
// (`Output/Additional columns`): every owned cell's average stress and strain.
//
// Stress (Love-Weber). A cell in equilibrium carries the mean stress
//   sigma_c = 1/V_c sum_f sym((p_f - x_c) (x) F_f),
// F_f the force facet f's springs exert on the cell at their location p_f, V_c the
// cell's volume (2D: area times thickness). For the forces sigma n_f A_f of a uniform
// stress at the facets' centroids this is sigma exactly, since
// sum_f A_f (p_f - x_c) (x) n_f = V_c I over a closed cell (divergence theorem). The
// facets' moments only balance the skew part, which sym() drops. A cell on the boundary
// misses the forces of the boundary (loads and supports act at its nucleus): its stress
// is that of its facets alone.
//
// Strain. The springs see the jump of the cells' rigid motions at p_f,
// Delta_f = u_b(p_f) - u_a(p_f); for nuclei that follow an affine motion u = H x with
// the rotation of H's skew part this is eps l_f, l_f = x_b - x_a, whatever p_f. The fit
//   eps_c = sym(S N^-1),  S = sum_f A_f Delta_f (x) n_f,  N = sum_f A_f |l_f| n_f (x) n_f,
// n_f = l_f / |l_f|, is then exact (S = eps N), also for a cell on the boundary; where
// the facets' directions do not span the space (a cell with one neighbour), N^-1 is
// N's pseudo-inverse. Broken facets count: their opening is the crack's strain.
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/lac/la_parallel_vector.h>

#include "rbsn/model.h"
#include "rbsn/rigid_motion.h"

#include <array>
#include <cmath>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::cell_tensors(std::vector<dealii::SymmetricTensor<2, dim>> &stress,
                             std::vector<dealii::SymmetricTensor<2, dim>> &strain) const
    {
      // The sums of every local cell, a facet adding to both of its cells: r (x) F
      // (dim^2 values), S (dim^2) and N (its dim (dim + 1) / 2 independent values), in
      // DoF-shaped vectors so that compress(add) brings a ghost cell's sums to its owner.
      constexpr unsigned int n_tensor = dim * dim, n_sym = dim * (dim + 1) / 2;
      constexpr unsigned int n_sums   = 2 * n_tensor + n_sym;
      constexpr unsigned int n_slots  = (n_sums + n_dofs - 1) / n_dofs;
      std::array<Vector, n_slots> sums;
      for (Vector &s : sums)
        s.reinit(partitioner);
      const auto add = [&](const unsigned int c, const unsigned int k, const double value) {
        sums[k / n_dofs].local_element(n_dofs * c + k % n_dofs) += value;
      };

      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          const Facet<dim>   &f  = network.facets[e];
          const Springs<dim> &sp = springs[e];
          const auto          ld = facet_local_dofs(e);
          std::array<double, n_dofs> Ua, Ub;
          for (unsigned int k = 0; k < n_dofs; ++k)
            {
              Ua[k] = u.local_element(ld[k]);
              Ub[k] = u.local_element(ld[n_dofs + k]);
            }
          const dealii::Tensor<1, dim> l     = local_nuclei[f.b] - local_nuclei[f.a];
          const double                 h     = l.norm();
          const dealii::Tensor<1, dim> n     = l / h;
          const dealii::Tensor<1, dim> jump  = rigid_motion<dim>(Ub, f.midpoint - local_nuclei[f.b]) -
                                               rigid_motion<dim>(Ua, f.midpoint - local_nuclei[f.a]);
          // The force on cell a: minus the translational part of B^T f (the internal
          // force of its DoFs); cell b takes the opposite one.
          dealii::Tensor<1, dim> force_a;
          if (!sp.broken)
            for (unsigned int d = 0; d < dim; ++d)
              for (unsigned int i = 0; i < n_dofs; ++i)
                force_a[d] -= sp.B[i][d] * sp.force[i];
          for (const unsigned int c : {f.a, f.b})
            {
              const dealii::Tensor<1, dim> r    = f.midpoint - local_nuclei[c];
              const dealii::Tensor<1, dim> on_c = c == f.a ? force_a : -force_a;
              for (unsigned int i = 0; i < dim; ++i)
                for (unsigned int j = 0; j < dim; ++j)
                  {
                    add(c, dim * i + j, r[i] * on_c[j]);
                    add(c, n_tensor + dim * i + j, sp.area * jump[i] * n[j]);
                  }
              for (unsigned int k = 0; k < n_sym; ++k)
                {
                  const auto ij = dealii::SymmetricTensor<2, dim>::unrolled_to_component_indices(k);
                  add(c, 2 * n_tensor + k, sp.area * h * n[ij[0]] * n[ij[1]]);
                }
            }
        }
      for (Vector &s : sums)
        s.compress(dealii::VectorOperation::add);

      const auto &bodies = scene().body_descriptions();
      stress.assign(n_owned_cells, dealii::SymmetricTensor<2, dim>());
      strain.assign(n_owned_cells, dealii::SymmetricTensor<2, dim>());
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          const auto value = [&](const unsigned int k) {
            return sums[k / n_dofs].local_element(n_dofs * c + k % n_dofs);
          };
          double volume = cell_measure(c);
          if constexpr (dim == 2)
            volume *= bodies[cell_body[c]].thickness_at(network.cells[c].centroid);
          dealii::Tensor<2, dim>          moment, S;
          dealii::SymmetricTensor<2, dim> N;
          for (unsigned int i = 0; i < dim; ++i)
            for (unsigned int j = 0; j < dim; ++j)
              {
                moment[i][j] = value(dim * i + j);
                S[i][j]      = value(n_tensor + dim * i + j);
              }
          for (unsigned int k = 0; k < n_sym; ++k)
            N[dealii::SymmetricTensor<2, dim>::unrolled_to_component_indices(k)] = value(2 * n_tensor + k);
          stress[c] = dealii::symmetrize(moment) / volume;
          strain[c] = dealii::symmetrize(S * pseudo_inverse(N));
        }
    }



    template <int dim>
    dealii::Tensor<2, dim>
    Model<dim>::pseudo_inverse(const dealii::SymmetricTensor<2, dim> &N)
    {
      // N = sum_k lambda_k v_k v_k^T; eigenvalues below 1e-10 of the largest (directions
      // no facet measures) are left out.
      dealii::Tensor<2, dim> inverse;
      const auto             pairs = dealii::eigenvectors(N);
      const double           largest = std::abs(pairs[0].first);
      for (const auto &[lambda, vector] : pairs)
        if (std::abs(lambda) > 1e-10 * largest)
          inverse += dealii::outer_product(vector, vector) / lambda;
      return inverse;
    }



    template <int dim>
    void
    Model<dim>::additional_values(const double                          *base,
                                  const dealii::SymmetricTensor<2, dim> &stress,
                                  const dealii::SymmetricTensor<2, dim> &strain,
                                  const Material::Interface<dim>        &material,
                                  double                                *out) const
    {
      // base: x, u and v of the point (the first 3 dim columns of point_columns()).
      dealii::Point<dim>     x;
      dealii::Tensor<1, dim> w, velocity;
      for (unsigned int d = 0; d < dim; ++d)
        {
          x[d]        = base[d];
          w[d]        = base[dim + d];
          velocity[d] = base[2 * dim + d];
        }
      // The network is a plane model in 2D: sigma_zz is that of the elastic plane strain
      // state, nu (s_xx + s_yy), and 0 in plane stress.
      double sigma_zz = 0;
      if (dim == 2 && material.elasticity().stress_state == Material::StressState::plane_strain)
        sigma_zz = material.elasticity().poissons_ratio * trace(stress);
      scene().output_control().additional_columns.evaluate(
        PointData::PointView<dim>{x, w, velocity, stress, strain, &material, {}, sigma_zz}, out);
    }



    template <int dim>
    std::vector<const Material::Interface<dim> *>
    Model<dim>::body_materials() const
    {
      std::vector<const Material::Interface<dim> *> materials;
      for (const auto &b : scene().body_descriptions())
        materials.push_back(&scene().material(b.material, "Body " + b.name + "/Material"));
      return materials;
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

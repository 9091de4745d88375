// The facets' springs: their stiffnesses, kinematics (B), laws, and the cells' DoFs and mass.
#include <deal.II/base/mpi.h>

#include "rbsn/model.h"

#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::facet_dofs(const unsigned int e, std::vector<dof_index> &dofs) const
    {
      const auto &f = network.facets[e];
      for (unsigned int k = 0; k < n_dofs; ++k)
        {
          dofs[k]          = n_dofs * cell_block[f.a] + k;
          dofs[n_dofs + k] = n_dofs * cell_block[f.b] + k;
        }
    }



    template <int dim>
    std::array<unsigned int, 2 * Model<dim>::n_dofs>
    Model<dim>::facet_local_dofs(const unsigned int e) const
    {
      const auto                          &f = network.facets[e];
      std::array<unsigned int, 2 * n_dofs> dofs;
      for (unsigned int k = 0; k < n_dofs; ++k)
        {
          dofs[k]          = n_dofs * f.a + k;
          dofs[n_dofs + k] = n_dofs * f.b + k;
        }
      return dofs;
    }



    template <int dim>
    void
    Model<dim>::setup_springs()
    {
      const auto &bodies = scene().body_descriptions();
      springs.assign(network.facets.size(), Springs<dim>());
      std::string out_of_range, where; // the first facet whose springs overflow
      for (unsigned int e = 0; e < network.facets.size() && out_of_range.empty(); ++e)
        {
          const Facet<dim> &f  = network.facets[e];
          Springs<dim>     &sp = springs[e];
          const auto       &ba = bodies[cell_body[f.a]], &bb = bodies[cell_body[f.b]];
          const auto       &ma = scene().material(ba.material, "Body " + ba.name + "/Material");
          const auto       &mb = scene().material(bb.material, "Body " + bb.name + "/Material");
          FacetSprings<dim> facet;
          facet.moment_yield_factor = moment_yield;
          spring_geometry(f, ba, bb, ma, mb, sp, facet);
          facet.k = sp.k;
          // Finite inputs can still overflow here (a thickness of 1e300): the stiffnesses
          // and the forces they lead to (E A bounds the yield forces) must be numbers.
          if (out_of_range.empty())
            for (unsigned int i = 0; i < n_dofs; ++i)
              if (!(sp.k[i] > 0 && std::isfinite(sp.k[i]) &&
                    std::isfinite(sp.area * std::max(ma.elasticity().youngs_modulus, mb.elasticity().youngs_modulus))))
                {
                  std::ostringstream m;
                  m << "the facet between the cells at " << local_nuclei[f.a] << " and " << local_nuclei[f.b]
                    << " gets a spring stiffness of " << sp.k[i] << " (area " << sp.area << ", Young's modulus "
                    << ma.elasticity().youngs_modulus << "): the geometry and the material are out of the range "
                    << "of double precision together";
                  out_of_range = m.str();
                  where        = dim == 2 ? "Body " + ba.name + "/Thickness" : "Material/Young's modulus";
                  break;
                }
          if (!out_of_range.empty())
            continue;

          // The spring law's springs (static: linear springs, the plasticity ignored).
          if (analysis != Analysis::linear_static)
            {
              sp.state.assign(spring_law->n_state_variables(), 0.0);
              sp.hysteretic = spring_law->setup_facet(e, facet, ma, mb, sp.state.data());
              if (!sp.hysteretic)
                sp.state.clear();
            }
          for (unsigned int i = 0; i < n_dofs; ++i)
            sp.tangent[i][i] = sp.k[i]; // the first predictor's
          sp.trial_state = sp.state;
        }
      // Every rank refuses, with the first rank's facet.
      const auto found = dealii::Utilities::MPI::all_gather(scene().mpi_communicator(), std::make_pair(where, out_of_range));
      for (const auto &[place, problem] : found)
        if (!problem.empty())
          throw InputError(place, problem);
    }



    template <int dim>
    void
    Model<dim>::spring_geometry(const Facet<dim>               &f,
                                const BodyDescription<dim>     &ba,
                                const BodyDescription<dim>     &bb,
                                const Material::Interface<dim> &ma,
                                const Material::Interface<dim> &mb,
                                Springs<dim>                   &sp,
                                FacetSprings<dim>              &facet) const
    {
      // B (eq. 3.6, with the corrections in doc/theory.md): the displacement of the
      // facet's point P as a point of cell b minus as a point of cell a, u_P = u_i +
      // theta_i x (P - x_i), in the facet's axes, and the relative rotation
      // theta_b - theta_a in them.
      const dealii::Tensor<1, dim> ra = f.midpoint - local_nuclei[f.a];
      const dealii::Tensor<1, dim> rb = f.midpoint - local_nuclei[f.b];
      if constexpr (dim == 2)
        {
          // The thinner side at the facet's midpoint (two bodies may meet there).
          const double t = std::min(ba.thickness_at(f.midpoint), bb.thickness_at(f.midpoint));
          const double l = f.length;
          // Voronoi scaling (eq. 3.9), the two half-cells in series:
          // k_n = t l / (h_a / E'_a + h_b / E'_b), k_t likewise with G, k_phi = k_n l^2 / 12.
          sp.k[0] = t * l / (f.h_a / ma.elasticity().p_wave_modulus() + f.h_b / mb.elasticity().p_wave_modulus());
          sp.k[1] = shear_ratio > 0 ? shear_ratio * sp.k[0] :
                                      t * l / (f.h_a / ma.elasticity().shear_modulus() +
                                               f.h_b / mb.elasticity().shear_modulus());
          sp.k[2]                  = sp.k[0] * l * l / 12;
          sp.thickness             = t;
          sp.area                  = t * l;
          facet.thickness          = t;
          facet.length             = l;
          facet.area               = t * l;
          facet.second_moments[0]  = t * l * l * l / 12;
          // u_P = u_i - (y_P - y_i) theta_i, v_P = v_i + (x_P - x_i) theta_i.
          const dealii::Tensor<1, 2> n = f.normal, tt({-n[1], n[0]});
          const auto cross = [](const dealii::Tensor<1, 2> &r, const dealii::Tensor<1, 2> &w) {
            return r[0] * w[1] - r[1] * w[0];
          };
          sp.B[0] = {{-n[0], -n[1], -cross(ra, n), n[0], n[1], cross(rb, n)}};
          sp.B[1] = {{-tt[0], -tt[1], -cross(ra, tt), tt[0], tt[1], cross(rb, tt)}};
          sp.B[2] = {{0, 0, -1, 0, 0, 1}};
        }
      else
        {
          // k_n = A / (h_a / E'_a + h_b / E'_b), the shear springs likewise with G, the
          // bending springs k_n I_i / A (E I_i / h of the beam between the nuclei), the
          // torsion spring k_s J / A (G J / h), J = I_1 + I_2 (doc/rbsn3d.md).
          const double A = f.area, I1 = f.second_moment_1, I2 = f.second_moment_2;
          const double kn = A / (f.h_a / ma.elasticity().p_wave_modulus() + f.h_b / mb.elasticity().p_wave_modulus());
          const double ks = shear_ratio > 0 ? shear_ratio * kn :
                                              A / (f.h_a / ma.elasticity().shear_modulus() +
                                                   f.h_b / mb.elasticity().shear_modulus());
          sp.k = {{kn, ks, ks, kn * I1 / A, kn * I2 / A, ks * (I1 + I2) / A}};
          sp.area                 = A;
          facet.area              = A;
          facet.length            = std::sqrt(A);
          facet.second_moments[0] = I1;
          facet.second_moments[1] = I2;
          // Rows of the translations along t: t . (u_b + theta_b x r_b - u_a - theta_a x r_a)
          // = t . u_b + theta_b . (r_b x t) - t . u_a - theta_a . (r_a x t); rotations
          // about t: t . (theta_b - theta_a).
          const std::array<dealii::Tensor<1, 3>, 3> axes{{f.normal, f.axis_1, f.axis_2}};
          for (unsigned int i = 0; i < 3; ++i)
            {
              const dealii::Tensor<1, 3> &t  = axes[i];
              const dealii::Tensor<1, 3>  ca = dealii::cross_product_3d(ra, t), cb = dealii::cross_product_3d(rb, t);
              for (unsigned int d = 0; d < 3; ++d)
                {
                  sp.B[i][d]     = -t[d];
                  sp.B[i][3 + d] = -ca[d];
                  sp.B[i][6 + d] = t[d];
                  sp.B[i][9 + d] = cb[d];
                }
            }
          // The rotations in the order of the springs: about axis_1, axis_2, the normal.
          const std::array<dealii::Tensor<1, 3>, 3> rotation_axes{{f.axis_1, f.axis_2, f.normal}};
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int d = 0; d < 3; ++d)
              {
                sp.B[3 + i][3 + d] = -rotation_axes[i][d];
                sp.B[3 + i][9 + d] = rotation_axes[i][d];
              }
        }
    }



    template <int dim>
    void
    Model<dim>::cell_mass_matrix(const unsigned int c, dealii::FullMatrix<double> &M) const
    {
      // Rigid cell of mass m, centroid at o from the nucleus, inertia J about the nucleus:
      // the kinetic energy 1/2 m |u' + omega x o|^2 + 1/2 omega . J_c omega (eq. 3.12), i.e.
      // M = [m I, -m [o]x; m [o]x, J] with [o]x w = o x w (in 2D omega = theta' e_z).
      const double                  m = cell_mass[c];
      const dealii::Tensor<1, dim> &o = cell_offset[c];
      M.reinit(n_dofs, n_dofs);
      for (unsigned int d = 0; d < dim; ++d)
        M(d, d) = m;
      if constexpr (dim == 2)
        {
          M(0, 2) = M(2, 0) = -m * o[1];
          M(1, 2) = M(2, 1) = m * o[0];
          M(2, 2)           = cell_inertia[c][0][0];
        }
      else
        {
          // -m [o]x = m [[0, o_z, -o_y], [-o_z, 0, o_x], [o_y, -o_x, 0]] (rows u, columns theta).
          const double C[3][3] = {{0, m * o[2], -m * o[1]}, {-m * o[2], 0, m * o[0]}, {m * o[1], -m * o[0], 0}};
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
              {
                M(i, 3 + j) = C[i][j];
                M(3 + j, i) = C[i][j];
                M(3 + i, 3 + j) = cell_inertia[c][i][j];
              }
        }
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

// Absorbing (Lysmer-Kuhlemeyer) boundaries: viscous dashpots on boundary faces that let
// waves leave the mesh.
//
// The dashpots' traction t = -rho c_p (v.n) n - rho c_s (v - (v.n) n) = -A v, with
//   A = rho c_p n (x) n + rho c_s (I - n (x) n),
// c_p^2 = (lambda + 2 mu) / rho (3D, plane strain, axisymmetric), E / (rho (1 - nu^2)) (plane
// stress), c_s^2 = mu / rho, does the virtual work int_Gamma N_i . t dGamma = -(C_b v)_i with
//   C_b,ij = int_Gamma N_i . A N_j dGamma = sum_faces sum_q N_i N_j A_{c_i c_j} w_q
// (w_q = JxW t, t the thickness in 2D, 2 pi r axisymmetric): a symmetric positive
// semi-definite damping matrix that enters the equations of motion beside the Rayleigh C,
//   M a + (C + C_b) v + f_int(u) = f_ext.
// A face takes rho, c_p and c_s of its cell's material (a boundary face has one cell). A plane
// wave at normal incidence carries the traction sigma n = -rho c v (P: v along n, S: across),
// which the dashpot supplies exactly: it leaves without reflection (doc/fem.md).
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include "fem/fem.h"

#include <array>
#include <cmath>

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    void
    Solver<dim>::setup_absorbing()
    {
      using Type              = typename BoundaryDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      absorbers.clear();
      std::vector<const BoundaryDescription<dim> *> conditions;
      for (const auto &d : scene.boundary_descriptions())
        if (d.type == Type::absorbing)
          {
            Absorber a;
            a.faces = d.faces;
            if (!d.physical_group.empty())
              {
                const std::string   where = "Boundary " + d.name + "/Set";
                const PhysicalGroup group = physical_group(d.physical_group, where);
                require(group.faces,
                        where,
                        "an absorbing boundary acts on boundary faces, but the physical group '" +
                          d.physical_group + "' is a group of cells");
                a.group = group.tag;
              }
            absorbers.push_back(a);
            conditions.push_back(&d);
          }
      // Each condition must select a boundary face somewhere.
      for (unsigned int k = 0; k < absorbers.size(); ++k)
        {
          unsigned long n = 0;
          for (const auto &cell : dof_handler.active_cell_iterators())
            if (cell->is_locally_owned())
              for (const unsigned int f : cell->face_indices())
                n += absorbs_face(cell, f, &absorbers[k]);
          require(dealii::Utilities::MPI::sum(n, scene.mpi_communicator()) > 0,
                  conditions[k]->where(),
                  "the absorbing boundary selects no boundary face of the fem mesh (faces are "
                  "those of the mesh's bounding box)");
        }
    }



    template <int dim>
    bool
    Solver<dim>::absorbs_face(const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
                              const unsigned int                                            f,
                              const Absorber                                               *only) const
    {
      // A face in the condition's Gmsh group, or one whose centre lies on a face of the
      // bounding box (then all of it does: the box bounds the mesh).
      const auto face = cell->face(f);
      if (!face->at_boundary())
        return false;
      for (const Absorber &a : absorbers)
        {
          if (only != nullptr && &a != only)
            continue;
          if (a.group >= 0 && face->boundary_id() == static_cast<dealii::types::boundary_id>(a.group))
            return true;
          for (const unsigned int side : a.faces)
            {
              const unsigned int d     = side / 2;
              const double       plane = side % 2 == 0 ? mesh_box.lower_bound(d) : mesh_box.upper_bound(d);
              if (std::abs(face->center()[d] - plane) <= 1e-9 * u_scale)
                return true;
            }
        }
      return false;
    }



    template <int dim>
    bool
    Solver<dim>::absorbing_matrix(const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
                                  dealii::FEFaceValues<dim>                                    &ffv,
                                  dealii::FullMatrix<double>                                   &C) const
    {
      if (absorbers.empty())
        return false;
      const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
      const auto             &e = h.material->elasticity();
      // rho c = sqrt(rho M) with M the P-wave modulus (plane stress: E / (1 - nu^2)) or mu.
      const double rho_cp = std::sqrt(h.material->density() * e.p_wave_modulus());
      const double rho_cs = std::sqrt(h.material->density() * e.shear_modulus());
      const auto  &body   = this->get_scene().body_descriptions()[h.body];
      const unsigned int n = fe->n_dofs_per_cell();
      bool               any = false;
      for (const unsigned int f : cell->face_indices())
        if (absorbs_face(cell, f))
          {
            if (!any)
              C = 0;
            any = true;
            ffv.reinit(cell, f);
            for (unsigned int q = 0; q < ffv.n_quadrature_points; ++q)
              {
                const dealii::Tensor<1, dim> &normal = ffv.normal_vector(q);
                const double w = ffv.JxW(q) * this->get_scene().thickness_at(body, ffv.quadrature_point(q));
                for (unsigned int i = 0; i < n; ++i)
                  {
                    const unsigned int ci = fe->system_to_component_index(i).first;
                    for (unsigned int j = 0; j < n; ++j)
                      {
                        const unsigned int cj = fe->system_to_component_index(j).first;
                        // A_{c_i c_j} = rho c_s delta + (rho c_p - rho c_s) n_ci n_cj
                        const double A = (ci == cj ? rho_cs : 0.0) + (rho_cp - rho_cs) * normal[ci] * normal[cj];
                        C(i, j) += ffv.shape_value(i, q) * ffv.shape_value(j, q) * A * w;
                      }
                  }
              }
          }
      return any;
    }



    template <int dim>
    typename Solver<dim>::Vector
    Solver<dim>::absorbing_force(const Vector &velocity, const bool lumped) const
    {
      // y = C_b v, or with the lumped C_b: y_i = d_i v_i with the HRZ diagonal of one component
      // c, d_i = C_b,ii (sum_{k,l in c} C_b,kl) / (sum_{k in c} C_b,kk): positive for every
      // node, also where a row sum is zero (the vertices of a P2 triangle or quadrilateral face
      // carry no load of a uniform traction); equal to the row sums on Q1 and P1 faces (the
      // coupling n_x n_y of an inclined face drops out).
      using namespace dealii;
      Vector             y(owned_dofs, this->get_scene().mpi_communicator());
      const unsigned int n = fe->n_dofs_per_cell();
      FEFaceValues<dim>  ffv(*mapping,
                            *fe,
                            *face_quadrature,
                            update_values | update_quadrature_points | update_JxW_values | update_normal_vectors);
      FullMatrix<double>                   C(n, n);
      dealii::Vector<double>               ve(n), ye(n);
      std::vector<types::global_dof_index> dofs(n);
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned() && absorbing_matrix(cell, ffv, C))
          {
            cell->get_dof_indices(dofs);
            for (unsigned int i = 0; i < n; ++i)
              ve[i] = velocity(dofs[i]);
            if (lumped)
              {
                std::array<double, dim> total{}, diagonal{};
                for (unsigned int i = 0; i < n; ++i)
                  {
                    const unsigned int c = fe->system_to_component_index(i).first;
                    diagonal[c] += C(i, i);
                    for (unsigned int j = 0; j < n; ++j)
                      if (fe->system_to_component_index(j).first == c)
                        total[c] += C(i, j);
                  }
                for (unsigned int i = 0; i < n; ++i)
                  {
                    const unsigned int c = fe->system_to_component_index(i).first;
                    ye[i] = diagonal[c] > 0 ? C(i, i) * total[c] / diagonal[c] * ve[i] : 0.0;
                  }
              }
            else
              C.vmult(ye, ve);
            y.add(dofs, ye);
          }
      y.compress(VectorOperation::add);
      return y;
    }



    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron

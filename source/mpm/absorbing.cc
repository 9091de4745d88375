// Absorbing (Lysmer-Kuhlemeyer) boundaries on the MPM's background grid (doc/mpm.md, "Absorbing
// boundaries"): viscous dashpots on the grid nodes of faces of the grid.
//
// The traction of the infinite medium behind a face with outward normal n,
//   t = -rho c_p (v.n) n - rho c_s (v - (v.n) n)
// (source/fem/absorbing.cc; c_p^2 = M / rho with M the P-wave modulus of the stress state,
// c_s^2 = mu / rho), acts on node i through its lumped face area A_i = int_face N_i dGamma
// (h per in-plane direction, h / 2 at the face's edges; times the thickness in 2D). A face of the
// grid is normal to an axis d, so the dashpot is diagonal in the components:
//   f_i = -c_i v_i,  c_i,d = rho c_p A_i,  c_i,e = rho c_s A_i (e != d),
// and a node on several absorbing faces (an edge, a corner) has the sum. The momentum balance
// takes it with the trapezoidal rule like the Rayleigh mass term (NodalDamping):
//   m_i (v' - v) / dt = f - c (v + v') / 2  ->  dv = dt (f / m - (c / m) v) / (1 + (c / m) dt / 2),
// unconditionally stable for the dashpot alone; with the stiffness explicit the step is the central
// difference with the damping velocity centred in time, whose critical step does not depend on
// the damping: h / max_p(c_p + |v_p|) stays the bound. The dashpot's force -c v_mid is the
// condition's reaction, and its work -c v_mid^2 dt joins boundary_work.
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include "mpm/mpm.h"

#include <algorithm>
#include <set>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    unsigned int
    Solver<dim>::absorbing_body(const unsigned int b) const
    {
      // The bodies with points (the set-up's fill) in the layer of cells next to the faces.
      const Scene<dim> &scene       = this->get_scene();
      const auto       &description = scene.boundary_descriptions()[b];
      const auto       &bodies      = scene.body_descriptions();
      std::set<std::string> materials;
      unsigned int          found = bodies.size();
      std::string           names;
      const Geometry::FillLattice<dim> lattice{lower, cell_size, n_cells};
      for (unsigned int k = 0; k < bodies.size(); ++k)
        {
          if (bodies[k].rigid)
            continue;
          bool touches = false;
          for (const unsigned int face : description.faces)
            {
              std::array<unsigned int, dim> first{}, last;
              for (unsigned int e = 0; e < dim; ++e)
                last[e] = n_cells[e] - 1;
              first[face / 2] = last[face / 2] = face % 2 == 0 ? 0 : n_cells[face / 2] - 1;
              touches = touches ||
                        !Geometry::fill<dim>(bodies[k].shape, lattice, bodies[k].particles_per_cell, first, last)
                           .empty();
            }
          if (!touches)
            continue;
          materials.insert(bodies[k].material);
          names += (names.empty() ? "" : ", ") + bodies[k].name + " (material '" + bodies[k].material + "')";
          found = k;
        }
      require(found < bodies.size(),
              description.where(),
              "no deformable body has material points in the grid cells next to the absorbing faces: "
              "the dashpots take rho, c_p and c_s from the material behind them (put the body's edge on "
              "the face of the grid)");
      require(materials.size() == 1,
              description.where(),
              "bodies of different materials lie next to the absorbing faces (" + names +
                "): the dashpots need the rho c_p and rho c_s of one material");
      return found;
    }



    template <int dim>
    void
    Solver<dim>::setup_absorbing()
    {
      using Type              = typename BoundaryDescription<dim>::Type;
      const Scene<dim> &scene = this->get_scene();
      const auto       &descriptions = scene.boundary_descriptions();
      const auto       &lattice      = grid->lattice();
      dashpots.clear();
      for (unsigned int b = 0; b < descriptions.size(); ++b)
        {
          if (descriptions[b].type != Type::absorbing)
            continue;
          const std::string type = "Boundary " + descriptions[b].name + "/Type";
          // (A Region, which gives no normal, is refused by the scene for every method.)
          require(!axisymmetric, type, "absorbing boundaries of the mpm method are not implemented for "
                                       "axisymmetric scenes (the ring areas 2 pi r of the faces)");
          require(!contact, type, "absorbing boundaries of the mpm method do not work with MPM/Contact "
                                  "(the dashpots act on the common velocity field)");
          require(!grid_moves, type, "absorbing boundaries of the mpm method need a fixed grid (their "
                                     "dashpots sit on the grid's faces; MPM/Grid/Motion moves them)");
          const auto   &body    = scene.body_descriptions()[absorbing_body(b)];
          const auto   &m       = scene.material(body.material, "Body " + body.name + "/Material");
          const double  rho_cp  = std::sqrt(m.density() * m.elasticity().p_wave_modulus());
          const double  rho_cs  = std::sqrt(m.density() * m.elasticity().shear_modulus());
          const auto   &bc      = boundaries[b];
          for (unsigned int k = 0; k < bc.nodes.size(); ++k)
            {
              // The lumped area of the node on the face normal to d.
              const unsigned int d    = bc.normal_direction[k];
              const auto         i    = grid->lattice_index(bc.nodes[k]);
              double             area = body.thickness_at(grid->node_position(bc.nodes[k]));
              for (unsigned int e = 0; e < dim; ++e)
                if (e != d)
                  {
                    const bool edge = i[e] == 0 || i[e] == static_cast<int>(lattice.n_cells[e]);
                    area *= lattice.h[e] * (edge ? 0.5 : 1.0);
                  }
              Dashpot dashpot;
              dashpot.node     = bc.nodes[k];
              dashpot.boundary = b;
              for (unsigned int e = 0; e < dim; ++e)
                dashpot.c[e] = (e == d ? rho_cp : rho_cs) * area;
              dashpots.push_back(dashpot);
            }
        }
      std::stable_sort(dashpots.begin(), dashpots.end(), [](const Dashpot &a, const Dashpot &b) {
        return a.node < b.node;
      });
      dashpot_first.reset(grid->n_local_nodes(), grid->sparse_box());
      for (std::size_t k = dashpots.size(); k-- > 0;)
        dashpot_first[dashpots[k].node] = k + 1;
    }



    template <int dim>
    void
    Solver<dim>::record_dashpots(const unsigned int first,
                                 const unsigned int d,
                                 const double       v_mid,
                                 const double       dt)
    {
      const unsigned int n = dashpots[first - 1].node;
      for (std::size_t k = first - 1; k < dashpots.size() && dashpots[k].node == n; ++k)
        {
          const double force = -dashpots[k].c[d] * v_mid;
          reactions[dashpots[k].boundary][d] += force;
          boundary_work += force * v_mid * dt;
        }
    }



    template void Solver<2>::setup_absorbing();
    template void Solver<3>::setup_absorbing();
    template unsigned int Solver<2>::absorbing_body(unsigned int) const;
    template unsigned int Solver<3>::absorbing_body(unsigned int) const;
    template void Solver<2>::record_dashpots(unsigned int, unsigned int, double, double);
    template void Solver<3>::record_dashpots(unsigned int, unsigned int, double, double);
  } // namespace MPM
} // namespace hysteron

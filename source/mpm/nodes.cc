// The phases of a step that work on the grid nodes only (no basis): the start of a
// step, momenta to velocities and the momentum balance.
#include "mpm/mpm.h"

#include <cstring>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    void
    Solver<dim>::begin_step(const double t)
    {
      constexpr unsigned int C    = 1 + 2 * dim; // mass, momentum / velocity, force / velocity change
      double *const          node = grid->data().data();

      // Reset the nodes touched in the previous step (and the shared ones).
      for (const unsigned int n : active_nodes)
        std::memset(node + std::size_t(n) * C, 0, C * sizeof(double));
      grid->zero_interface(0, C);
      if (contact)
        {
          const std::size_t L     = std::size_t(contact_block) * n_contact_blocks;
          double *const     layer = grid->layer_data().data();
          for (const unsigned int n : active_nodes)
            std::memset(layer + n * L, 0, L * sizeof(double));
          grid->zero_layer_interface(0, contact_block);
        }
      for (const unsigned int n : rigid_nodes)
        rigid_node_body[n] = 0;
      active_nodes.clear();
      rigid_nodes.clear();
      ++stamp;
      for (auto &r : reactions)
        r = dealii::Tensor<1, dim>();
      failed_point = -1;
      failure.clear();

      for (unsigned int l = 1; l < load_per_point.size(); ++l)
        load_per_point[l] = this->get_scene().load_descriptions()[l - 1].value_at(t);
      // Gravity and the ground's acceleration, g - a_g(t) d (the motion is relative to the
      // ground), at the step's start like the loads: the forces of USL and MUSL are those of
      // the state at t (symplectic Euler), and external_work takes the same force, so the
      // energy balance stays closed. Against a_g(t + dt / 2) this shifts the record by dt / 2,
      // far below its sampling step.
      body_acceleration = this->get_scene().body_acceleration(t);
    }



    template <int dim>
    void
    Solver<dim>::nodal_velocities()
    {
      constexpr unsigned int C    = 1 + 2 * dim;
      double *const          node = grid->data().data();
      const double           tiny = small_mass;
      for (const unsigned int n : active_nodes)
        {
          double *const r     = node + std::size_t(n) * C;
          const double  inv_m = r[0] > tiny ? 1.0 / r[0] : 0.0;
          for (unsigned int d = 0; d < dim; ++d)
            r[1 + d] *= inv_m;
        }
      nodes_hold_momenta = false;
    }



    template <int dim>
    void
    Solver<dim>::update_nodal_velocities(const double dt)
    {
      constexpr unsigned int C    = 1 + 2 * dim;
      double *const          node = grid->data().data();
      const double           tiny = small_mass;
      if (nodal_damping.active() || !dashpots.empty())
        update_damped_nodal_velocities(dt);
      else if (nodes_hold_momenta)
        // Delta v_i = dt f_i / m_i, v_i' = p_i / m_i + Delta v_i; nodes without
        // mass get neither velocity nor force.
        for (const unsigned int n : active_nodes)
          {
            double *const r = node + std::size_t(n) * C;
            if (r[0] > tiny)
              {
                const double inv_m = 1.0 / r[0];
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    r[1 + dim + d] *= dt * inv_m;                 // velocity change
                    r[1 + d] = r[1 + d] * inv_m + r[1 + dim + d]; // new velocity
                  }
              }
            else
              for (unsigned int c = 1; c < C; ++c)
                r[c] = 0.0;
          }
      else
        // The nodes hold v_i already: Delta v_i = dt f_i / m_i, v_i' = v_i + Delta v_i.
        for (const unsigned int n : active_nodes)
          {
            double *const r    = node + std::size_t(n) * C;
            const double  dt_m = r[0] > tiny ? dt / r[0] : 0.0;
            for (unsigned int d = 0; d < dim; ++d)
              {
                r[1 + dim + d] *= dt_m;     // velocity change
                r[1 + d] += r[1 + dim + d]; // new velocity
              }
          }
      nodes_hold_momenta = false;
    }



    template void Solver<2>::begin_step(double);
    template void Solver<3>::begin_step(double);
    template void Solver<2>::nodal_velocities();
    template void Solver<3>::nodal_velocities();
    template void Solver<2>::update_nodal_velocities(double);
    template void Solver<3>::update_nodal_velocities(double);
  } // namespace MPM
} // namespace hysteron

#ifndef hysteron_source_mpm_step_h
#define hysteron_source_mpm_step_h

// The phase kernels of one MPM step, templates of the 1D basis kernel, and the
// StepPhases implementation that the update schemes call. Included only by
// source/mpm/step_*.cc, which instantiate make_step_phases<dim, Basis>.

#include "mpm/mpm.h"
#include "mpm/support.h"

#include <cmath>
#include <cstring>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    template <typename Basis, bool with_forces, bool with_contact>
    void
    Solver<dim>::particles_to_grid()
    {
      using namespace dealii;
      using Support = internal::Support<dim, Basis>;

      const internal::GridGeometry<dim> g(*grid);
      constexpr unsigned int C       = 1 + 2 * dim;
      constexpr unsigned int K       = contact_block;
      double *const          node    = grid->data().data();
      const auto            &cur     = particles.current;
      // Contact: body b's block of node n is layer[n * L + b * K, ...).
      double *const     layer = with_contact ? grid->layer_data().data() : nullptr;
      const std::size_t L     = with_contact ? std::size_t(K) * n_contact_blocks : 0;

      for (const auto &group : particles.groups)
        {
          unsigned int last_cell = numbers::invalid_unsigned_int;
          Support      support;
          for (unsigned int p = group.begin; p < group.end; ++p)
            {
              support.reinit(g.lattice, *grid, cur.x[p], g.inv_h);
              // The nodes of a cell are listed once per step (the first point of the cell).
              if (particles.cell[p] != last_cell)
                {
                  last_cell = particles.cell[p];
                  support.for_each(g.s1, g.s2, [&](const unsigned int n, double, const Tensor<1, dim> &) {
                    if (node_stamp[n] != stamp)
                      {
                        node_stamp[n] = stamp;
                        active_nodes.push_back(n);
                      }
                    if constexpr (!with_contact)
                      if (group.material == nullptr && rigid_node_body[n] == 0)
                        {
                          rigid_node_body[n] = group.rigid_body + 1;
                          rigid_nodes.push_back(n);
                        }
                  });
                }
              const double m = particles.mass[p];
              if (group.material == nullptr)
                {
                  // Contact: a rigid body's mass and mass gradient give its share of the
                  // contact normals (its velocity is prescribed).
                  if constexpr (with_contact)
                    {
                      double *const block = layer + std::size_t(group.rigid_body) * K;
                      const double  ms    = m / particles.thickness[p];
                      support.for_each(g.s1, g.s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &grad) {
                        double *const q = block + n * L;
                        q[0] += N * m;
                        for (unsigned int d = 0; d < dim; ++d)
                          q[1 + 2 * dim + d] += ms * grad[d];
                      });
                    }
                  continue;
                }
              const Tensor<1, dim> mv = m * cur.v[p];
              // Contact: the body's block, and the point's mass per unit thickness (2D) or
              // per radian of ring (axisymmetric) for the mass gradient: the normal is that
              // of the section, whatever the thickness or the radius.
              double *const block =
                with_contact ? layer + std::size_t(particles.body[p]) * K : nullptr;
              const double ms = with_contact ? m / particles.thickness[p] : 0.0;
              if constexpr (with_forces)
                {
                  // f_i += N_ip (m_p b + f_p) - V_p sigma_p grad N_ip with b = g - a_g(t) d
                  // (axisymmetric: and - N_ip V_p sigma_tt / r_p e_r, the hoop term, joins m_p b + f_p)
                  Tensor<1, dim> f_ext =
                    m * body_acceleration + particles.load_factor[p] * load_per_point[particles.load[p]];
                  if (dim == 2 && axisymmetric)
                    f_ext[0] -= hoop_force(group, p, cur);
                  const SymmetricTensor<2, dim> vs = cur.volume[p] * cur.stress[p];
                  support.for_each(g.s1, g.s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &grad) {
                    double *const        r = node + std::size_t(n) * C;
                    const Tensor<1, dim> f = N * f_ext - vs * grad;
                    r[0] += N * m;
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        r[1 + d] += N * mv[d];
                        r[1 + dim + d] += f[d];
                      }
                    if constexpr (with_contact)
                      {
                        double *const q = block + n * L;
                        q[0] += N * m;
                        for (unsigned int d = 0; d < dim; ++d)
                          {
                            q[1 + d] += N * mv[d];
                            q[1 + dim + d] += f[d];
                            q[1 + 2 * dim + d] += ms * grad[d];
                          }
                      }
                  });
                }
              else
                support.for_each(g.s1, g.s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &grad) {
                  double *const r = node + std::size_t(n) * C;
                  r[0] += N * m;
                  for (unsigned int d = 0; d < dim; ++d)
                    r[1 + d] += N * mv[d];
                  if constexpr (with_contact)
                    {
                      double *const q = block + n * L;
                      q[0] += N * m;
                      for (unsigned int d = 0; d < dim; ++d)
                        {
                          q[1 + d] += N * mv[d];
                          q[1 + 2 * dim + d] += ms * grad[d];
                        }
                    }
                  else
                    (void)grad;
                });
            }
        }
      grid->exchange(0, with_forces ? C : 1 + dim);
      nodes_hold_momenta = true;
      if constexpr (with_contact)
        {
          grid->exchange_layer(0, K);
          layer_holds_momenta = true;
          layer_from_points   = true;
        }
    }



    template <int dim>
    template <typename Basis, bool with_contact, bool viscous>
    void
    Solver<dim>::forces_to_grid(const bool updated_stresses)
    {
      using namespace dealii;
      using Support = internal::Support<dim, Basis>;

      const internal::GridGeometry<dim> g(*grid);
      constexpr unsigned int C       = 1 + 2 * dim;
      constexpr unsigned int K       = contact_block;
      double *const          node    = grid->data().data();
      double *const          layer   = with_contact ? grid->layer_data().data() : nullptr;
      const std::size_t      L       = with_contact ? std::size_t(K) * n_contact_blocks : 0;
      const auto            &cur     = particles.current;
      const auto            &state   = updated_stresses ? particles.next : particles.current;

      // Viscous: the strain rates come from the nodal velocities (not momenta).
      Assert(!viscous || !nodes_hold_momenta, dealii::ExcInternalError());
      double viscous_work = 0;
      for (const auto &group : particles.groups)
        if (group.material != nullptr)
          {
            Support support;
            // a1 lambda and a1 mu of the group's elasticity: C0 = lambda I (x) I + 2 mu S.
            const auto  &elasticity = group.material->elasticity();
            const double a1_lambda  = viscous ? stiffness_damping * elasticity.effective_lambda() : 0;
            const double a1_mu      = viscous ? stiffness_damping * elasticity.shear_modulus() : 0;
            for (unsigned int p = group.begin; p < group.end; ++p)
              {
                support.reinit(g.lattice, *grid, cur.x[p], g.inv_h);
                Tensor<1, dim> f_ext =
                  particles.mass[p] * body_acceleration +
                  particles.load_factor[p] * load_per_point[particles.load[p]];
                if (dim == 2 && axisymmetric)
                  f_ext[0] -= hoop_force(group, p, state);
                SymmetricTensor<2, dim> vs = state.volume[p] * state.stress[p];
                if constexpr (viscous)
                  {
                    // sigma_v = a1 C0 : d, d = sym(sum_i v_i (x) grad N_ip); its power V sigma_v : d.
                    const SymmetricTensor<2, dim> d = internal::strain_rate(support, g, node);
                    const SymmetricTensor<2, dim> s_v =
                      a1_lambda * trace(d) * unit_symmetric_tensor<dim>() + 2.0 * a1_mu * d;
                    vs += state.volume[p] * s_v;
                    viscous_work += state.volume[p] * (s_v * d);
                  }
                double *const                 block =
                  with_contact ? layer + std::size_t(particles.body[p]) * K : nullptr;
                support.for_each(g.s1, g.s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &grad) {
                  double *const        r = node + std::size_t(n) * C;
                  const Tensor<1, dim> f = N * f_ext - vs * grad;
                  for (unsigned int d = 0; d < dim; ++d)
                    r[1 + dim + d] += f[d];
                  if constexpr (with_contact)
                    for (unsigned int d = 0; d < dim; ++d)
                      block[n * L + 1 + dim + d] += f[d];
                });
              }
          }
      if constexpr (viscous)
        damping_work += step_dt * viscous_work;
      grid->exchange(1 + dim, dim);
      if constexpr (with_contact)
        grid->exchange_layer(1 + dim, dim);
    }



    template <int dim>
    template <typename Basis, bool with_contact>
    bool
    Solver<dim>::grid_to_particles(const double t, const double dt)
    {
      using namespace dealii;
      using Support = internal::Support<dim, Basis>;

      const internal::GridGeometry<dim> g(*grid);
      // A point reads the nodes of the common field or, with contact, its body's block.
      constexpr unsigned int C       = 1 + 2 * dim;
      constexpr unsigned int K       = contact_block;
      const double *const    node    = with_contact ? grid->layer_data().data() : grid->data().data();
      const std::size_t      stride  = with_contact ? std::size_t(K) * n_contact_blocks : C;
      const auto            &cur     = particles.current;
      auto                  &nxt     = particles.next;

      // Velocities (FLIP/PIC blend) and positions.
      const double alpha = flip_fraction;
      max_speed          = 0;
      kinetic_energy     = 0;
      for (const auto &group : particles.groups)
        {
          if (group.material == nullptr)
            {
              const auto          &rigid = this->get_scene().body_descriptions()[group.rigid_body];
              const Tensor<1, dim> v_mid = rigid.rigid_velocity_at(t + 0.5 * dt);
              const Tensor<1, dim> v_end = rigid.rigid_velocity_at(t + dt);
              for (unsigned int p = group.begin; p < group.end; ++p)
                {
                  nxt.v[p] = v_end;
                  nxt.x[p] = cur.x[p] + dt * v_mid;
                  track_cell(p, nxt.x[p]);
                }
              max_speed = std::max(max_speed, v_end.norm());
              continue;
            }
          double  group_max_speed = 0, group_kinetic = 0;
          Support support;
          for (unsigned int p = group.begin; p < group.end; ++p)
            {
              support.reinit(g.lattice, *grid, cur.x[p], g.inv_h);
              Tensor<1, dim>      v_pic, dv;
              const double *const base = with_contact ? node + std::size_t(particles.body[p]) * K : node;
              support.for_each(g.s1, g.s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &) {
                const double *const r = base + n * stride;
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    v_pic[d] += N * r[1 + d];
                    dv[d] += N * r[1 + dim + d];
                  }
              });
              const Tensor<1, dim> v_new = alpha * (cur.v[p] + dv) + (1.0 - alpha) * v_pic;
              nxt.v[p]                   = v_new;
              nxt.x[p]                   = cur.x[p] + dt * v_pic;
              group_max_speed            = std::max(group_max_speed, v_new.norm_square());
              group_kinetic += particles.mass[p] * v_new.norm_square();
              const Tensor<1, dim> f_ext =
                particles.mass[p] * body_acceleration +
                particles.load_factor[p] * load_per_point[particles.load[p]];
              external_work += 0.5 * dt * (f_ext * (cur.v[p] + v_new));
              track_cell(p, nxt.x[p]);
            }
          max_speed = std::max(max_speed, group.wave_speed + std::sqrt(group_max_speed));
          kinetic_energy += 0.5 * group_kinetic;
        }
      if (!(max_speed < std::numeric_limits<double>::max()))
        for (unsigned int p = 0; p < particles.size() && failed_point < 0; ++p)
          if (!std::isfinite(nxt.v[p].norm_square()))
            {
              failed_point = p;
              failure      = "a non-finite velocity";
            }
      return failed_point < 0;
    }



    template <int dim>
    template <typename Basis, bool with_contact>
    void
    Solver<dim>::remap_momenta()
    {
      using namespace dealii;
      using Support = internal::Support<dim, Basis>;

      const internal::GridGeometry<dim> g(*grid);
      constexpr unsigned int C    = 1 + 2 * dim;
      double *const          node = grid->data().data();
      const auto            &cur  = particles.current;
      const auto            &nxt  = particles.next;

      // p_i = sum_p N_ip m_p v_p' (the masses m_i are those of the step's start).
      constexpr unsigned int K     = contact_block;
      double *const          layer = with_contact ? grid->layer_data().data() : nullptr;
      const std::size_t      L     = with_contact ? std::size_t(K) * n_contact_blocks : 0;
      for (const unsigned int n : active_nodes)
        for (unsigned int d = 0; d < dim; ++d)
          node[std::size_t(n) * C + 1 + d] = 0.0;
      grid->zero_interface(1, dim);
      if constexpr (with_contact)
        {
          for (const unsigned int n : active_nodes)
            for (std::size_t b = 0; b < L; b += K)
              for (unsigned int d = 0; d < dim; ++d)
                layer[n * L + b + 1 + d] = 0.0;
          grid->zero_layer_interface(1, dim);
        }
      for (const auto &group : particles.groups)
        if (group.material != nullptr)
          {
            Support support;
            for (unsigned int p = group.begin; p < group.end; ++p)
              {
                support.reinit(g.lattice, *grid, cur.x[p], g.inv_h);
                const Tensor<1, dim> mv = particles.mass[p] * nxt.v[p];
                double *const        block =
                  with_contact ? layer + std::size_t(particles.body[p]) * K : nullptr;
                support.for_each(g.s1, g.s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &) {
                  double *const r = node + std::size_t(n) * C;
                  for (unsigned int d = 0; d < dim; ++d)
                    r[1 + d] += N * mv[d];
                  if constexpr (with_contact)
                    for (unsigned int d = 0; d < dim; ++d)
                      block[n * L + 1 + d] += N * mv[d];
                });
              }
          }
      grid->exchange(1, dim);
      nodes_hold_momenta = true;
      if constexpr (with_contact)
        {
          grid->exchange_layer(1, dim);
          layer_holds_momenta = true;
        }
    }



    template <int dim>
    template <typename Basis, bool midpoint, bool with_contact>
    bool
    Solver<dim>::update_stresses(const double dt, const bool record_work)
    {
      using namespace dealii;
      using Support = internal::Support<dim, Basis>;

      const internal::GridGeometry<dim> g(*grid);
      // A point reads the nodes of the common field or, with contact, its body's block.
      constexpr unsigned int C      = 1 + 2 * dim;
      constexpr unsigned int K      = contact_block;
      const double *const    node   = with_contact ? grid->layer_data().data() : grid->data().data();
      const std::size_t      stride = with_contact ? std::size_t(K) * n_contact_blocks : C;
      auto               &cur     = particles.current;
      auto               &nxt     = particles.next;
      const Tensor<2, dim> identity = unit_symmetric_tensor<dim>();

      for (const auto &group : particles.groups)
        {
          const unsigned int begin = group.begin, end = group.end;
          if (group.material == nullptr)
            {
              for (unsigned int p = begin; p < end; ++p)
                {
                  nxt.stress[p] = cur.stress[p];
                  nxt.strain[p] = cur.strain[p];
                  nxt.F[p]      = cur.F[p];
                  nxt.volume[p] = cur.volume[p];
                }
              continue;
            }
          // Chunks of points: strain increments of a chunk, then one material
          // call for the chunk (the scratch stays in cache).
          Support support;
          for (unsigned int chunk = begin; chunk < end; chunk += stress_chunk)
            {
              const unsigned int chunk_end = std::min(end, chunk + stress_chunk);
              for (unsigned int p = chunk; p < chunk_end; ++p)
                {
                  support.reinit(g.lattice, *grid, cur.x[p], g.inv_h);
                  Tensor<2, dim>      L; // velocity gradient sum_i v_i (x) grad N_i
                  const double *const base =
                    with_contact ? node + std::size_t(particles.body[p]) * K : node;
                  support.for_each(g.s1, g.s2, [&](const unsigned int n, double, const Tensor<1, dim> &grad) {
                    const double *const r = base + n * stride;
                    if constexpr (midpoint)
                      {
                        // v_i - Delta v_i / 2 = (v_i(t) + v_i(t + dt)) / 2
                        for (unsigned int i = 0; i < dim; ++i)
                          {
                            const double v = r[1 + i] - 0.5 * r[1 + dim + i];
                            for (unsigned int j = 0; j < dim; ++j)
                              L[i][j] += v * grad[j];
                          }
                      }
                    else
                      for (unsigned int i = 0; i < dim; ++i)
                        for (unsigned int j = 0; j < dim; ++j)
                          L[i][j] += r[1 + i] * grad[j];
                  });
                  const SymmetricTensor<2, dim> de = symmetrize(L) * dt;
                  strain_increment[p - chunk]      = de;
                  nxt.strain[p]                    = cur.strain[p] + de;
                  nxt.F[p]                         = (identity + dt * L) * cur.F[p];
                  if (dim == 2 && axisymmetric)
                    {
                      // Hoop strain rate v_r / r (v_r = sum_i N_i v_i,x, a second pass so
                      // that plane and 3D scenes pay nothing); the ring's volume changes with
                      // the in-plane area (det(I + dt L)) and the radius (1 + d eps_tt).
                      double v_r = 0;
                      support.for_each(g.s1, g.s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &) {
                        const double *const r = base + n * stride;
                        v_r += N * (midpoint ? r[1] - 0.5 * r[1 + dim] : r[1]);
                      });
                      const double hoop            = dt * v_r / cur.x[p][0];
                      hoop_increment[p - chunk]    = hoop;
                      nxt.volume[p] = cur.volume[p] * determinant(identity + dt * L) * (1.0 + hoop);
                    }
                  else
                    nxt.volume[p] = determinant(nxt.F[p]) * particles.volume0[p];
                  if (jaumann)
                    {
                      // Jaumann rate: sigma' = C : d + W sigma - sigma W with the spin
                      // W = skew(L); W sigma - sigma W is symmetric for symmetric sigma.
                      const Tensor<2, dim> W = 0.5 * dt * (L - transpose(L));
                      const Tensor<2, dim> s = cur.stress[p];
                      nxt.stress[p]          = symmetrize(W * s - s * W) + cur.stress[p];
                      // The material's tensor state (plastic strain, back stress) turns with
                      // the stress, by the orthogonal (I - W/2)^{-1} (I + W/2) = I + W + O(W^2).
                      state_rotation[p - chunk] = invert(identity - 0.5 * W) * (identity + 0.5 * W);
                    }
                  else
                    nxt.stress[p] = cur.stress[p];
                }
              const unsigned int n_points = chunk_end - chunk;
              const std::size_t  offset   = group.state_offset + std::size_t(chunk - begin) * group.n_state;
              const std::size_t  n_state  = std::size_t(n_points) * group.n_state;
              if (n_state > 0)
                std::memcpy(nxt.material_state.data() + offset,
                            cur.material_state.data() + offset,
                            n_state * sizeof(double));
              if (jaumann && group.n_state > 0)
                for (unsigned int p = chunk; p < chunk_end; ++p)
                  group.material->rotate_state(state_rotation[p - chunk],
                                               ArrayView<double>(nxt.material_state.data() + offset +
                                                                   std::size_t(p - chunk) * group.n_state,
                                                                 group.n_state));
              if (axisymmetric)
                group.material->update_axisymmetric(view(strain_increment.data(), n_points),
                                                    view(hoop_increment.data(), n_points),
                                                    view(nxt.stress.data() + chunk, n_points),
                                                    view(nxt.material_state.data() + offset, n_state),
                                                    ArrayView<SymmetricTensor<4, dim>>(),
                                                    ArrayView<Material::HoopTangent<dim>>());
              else
                group.material->update(view(strain_increment.data(), n_points),
                                       view(nxt.stress.data() + chunk, n_points),
                                       view(nxt.material_state.data() + offset, n_state),
                                       ArrayView<SymmetricTensor<4, dim>>());
              // Stress power, trapezoidal in time: dW = V sigma_mid : d eps (+ V sigma_tt,mid
              // d eps_tt when axisymmetric).
              double work = 0;
              for (unsigned int p = chunk; p < chunk_end; ++p)
                work += 0.25 * (cur.volume[p] + nxt.volume[p]) *
                        ((cur.stress[p] + nxt.stress[p]) * strain_increment[p - chunk]);
              if (axisymmetric)
                for (unsigned int p = chunk; p < chunk_end; ++p)
                  work += 0.25 * (cur.volume[p] + nxt.volume[p]) *
                          (hoop_stress(group, p, cur) + hoop_stress(group, p, nxt)) *
                          hoop_increment[p - chunk];
              if (!std::isfinite(work))
                {
                  for (unsigned int p = chunk; p < chunk_end && failed_point < 0; ++p)
                    if (!std::isfinite(nxt.stress[p].norm()) || !std::isfinite(nxt.volume[p]))
                      {
                        failed_point = p;
                        failure      = "a non-finite stress";
                      }
                  return failed_point < 0;
                }
              if (record_work)
                internal_work += work;
            }
        }
      return true;
    }



    /**
     * The phases of the step with the basis @p Basis, for the update schemes:
     * each virtual function calls the solver's kernel of this basis (the
     * choice between kernels is one branch per phase and step).
     */
    template <int dim, typename Basis, bool with_contact>
    class PhaseKernels : public StepPhases<dim>
    {
    public:
      explicit PhaseKernels(Solver<dim> &solver)
        : solver(solver)
      {}

      void
      particles_to_grid(const bool forces) override
      {
        if (forces && solver.stiffness_damping > 0)
          {
            // The viscous stress needs the nodal velocities of the step's start: the
            // masses and momenta first, then the forces (the nodes hold velocities).
            solver.template particles_to_grid<Basis, false, with_contact>();
            solver.nodal_velocities();
            solver.template forces_to_grid<Basis, with_contact, true>(false);
          }
        else if (forces)
          solver.template particles_to_grid<Basis, true, with_contact>();
        else
          solver.template particles_to_grid<Basis, false, with_contact>();
      }

      void
      forces_to_grid(const typename StepPhases<dim>::Stress stress) override
      {
        const bool updated = stress == StepPhases<dim>::Stress::updated;
        if (solver.stiffness_damping > 0)
          solver.template forces_to_grid<Basis, with_contact, true>(updated);
        else
          solver.template forces_to_grid<Basis, with_contact, false>(updated);
      }

      void
      nodal_velocities() override
      {
        solver.nodal_velocities();
      }

      void
      update_nodal_velocities(const double dt) override
      {
        solver.update_nodal_velocities(dt);
      }

      void
      boundary_conditions(const double t, const double dt, const bool record) override
      {
        solver.apply_boundary_conditions(t, dt, record);
      }

      bool
      grid_to_particles(const double t, const double dt) override
      {
        return solver.template grid_to_particles<Basis, with_contact>(t, dt);
      }

      void
      remap_momenta() override
      {
        solver.template remap_momenta<Basis, with_contact>();
      }

      bool
      update_stresses(const double dt, const typename StepPhases<dim>::Velocity velocity) override
      {
        return velocity == StepPhases<dim>::Velocity::midpoint ?
                 solver.template update_stresses<Basis, true, with_contact>(dt, true) :
                 solver.template update_stresses<Basis, false, with_contact>(dt, true);
      }

      bool
      predict_stresses(const double dt) override
      {
        return solver.template update_stresses<Basis, false, with_contact>(dt, false);
      }

    private:
      Solver<dim> &solver;
    };



    template <int dim, typename Basis, bool with_contact>
    std::unique_ptr<StepPhases<dim>>
    make_step_phases(Solver<dim> &solver)
    {
      return std::make_unique<PhaseKernels<dim, Basis, with_contact>>(solver);
    }
  } // namespace MPM
} // namespace hysteron

#endif

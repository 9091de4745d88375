#ifndef hysteron_source_mpm_step_h
#define hysteron_source_mpm_step_h

// The kernels of one MPM step, templates of the 1D basis kernel. Included only
// by source/mpm/step_*.cc, which instantiate Solver<dim>::step<Basis>.

#include <hysteron/mpm/mpm.h>

#include <cmath>
#include <cstring>

namespace hysteron
{
  namespace MPM
  {
    namespace internal
    {
      /**
       * The tensor-product support of one point: the 1D values and derivatives
       * per direction and the local grid node of the first support node. The
       * node of entry (a, b, c) is base + a + b s1 + c s2.
       */
      template <int dim, typename Basis>
      struct Support
      {
        static constexpr unsigned int n1 = Basis::n_support;
        double                        w[dim][n1];
        double                        g[dim][n1];
        unsigned int                  base;

        DEAL_II_ALWAYS_INLINE inline void
        reinit(const Lattice<dim>        &lattice,
               const BackgroundGrid<dim> &grid,
               const dealii::Point<dim>  &x,
               const double               inv_h)
        {
          base = 0;
          for (unsigned int d = 0; d < dim; ++d)
            {
              int first;
              Basis::evaluate((x[d] - lattice.origin[d]) * inv_h,
                              lattice.n_cells[d],
                              first,
                              w[d],
                              g[d]);
              for (unsigned int k = 0; k < n1; ++k)
                g[d][k] *= inv_h;
              base += (first - grid.box_lower(d)) * grid.stride(d);
            }
        }

        /// Call f(node, N, grad N) for every support node.
        template <typename Function>
        DEAL_II_ALWAYS_INLINE inline void
        for_each(const unsigned int s1, const unsigned int s2, const Function &f) const
        {
          dealii::Tensor<1, dim> grad;
          if constexpr (dim == 2)
            {
              for (unsigned int b = 0; b < n1; ++b)
                for (unsigned int a = 0; a < n1; ++a)
                  {
                    grad[0] = g[0][a] * w[1][b];
                    grad[1] = w[0][a] * g[1][b];
                    f(base + a + b * s1, w[0][a] * w[1][b], grad);
                  }
            }
          else
            {
              (void)s2;
              for (unsigned int c = 0; c < n1; ++c)
                for (unsigned int b = 0; b < n1; ++b)
                  {
                    const double wbc = w[1][b] * w[2][c];
                    for (unsigned int a = 0; a < n1; ++a)
                      {
                        grad[0] = g[0][a] * wbc;
                        grad[1] = w[0][a] * g[1][b] * w[2][c];
                        grad[2] = w[0][a] * w[1][b] * g[2][c];
                        f(base + a + b * s1 + c * s2, w[0][a] * wbc, grad);
                      }
                  }
            }
        }
      };
    } // namespace internal



    template <int dim>
    template <typename Basis>
    void
    Solver<dim>::step(const double t, const double dt)
    {
      using namespace dealii;
      using Support = internal::Support<dim, Basis>;

      const Lattice<dim> &lattice = grid->lattice();
      const double        inv_h   = 1.0 / lattice.h;
      const unsigned int  s1      = grid->stride(1);
      const unsigned int  s2      = dim == 3 ? grid->stride(dim - 1) : 0;
      constexpr unsigned int C    = 1 + 2 * dim; // mass, momentum / velocity, force / velocity change
      double *const       node    = grid->data().data();
      auto               &cur     = particles.current;
      auto               &nxt     = particles.next;
      const Tensor<1, dim> gravity = this->get_scene().gravity();
      const double         tiny    = small_mass;

      // Reset the nodes touched in the previous step (and the shared ones).
      for (const unsigned int n : active_nodes)
        std::memset(node + std::size_t(n) * C, 0, C * sizeof(double));
      grid->zero_interface(0, C);
      for (const unsigned int n : rigid_nodes)
        rigid_node_body[n] = 0;
      active_nodes.clear();
      rigid_nodes.clear();
      ++stamp;
      for (auto &r : reactions)
        r = Tensor<1, dim>();
      failed_point = -1;
      failure.clear();

      for (unsigned int l = 1; l < load_per_point.size(); ++l)
        load_per_point[l] = this->get_scene().load_descriptions()[l - 1].value_at(t);

      // 1. P2G: mass, momentum and (except USF) forces.
      const bool forces_now = scheme != Scheme::usf;
      for (const auto &group : particles.groups)
        {
          unsigned int last_cell = numbers::invalid_unsigned_int;
          Support      support;
          for (unsigned int p = group.begin; p < group.end; ++p)
            {
              support.reinit(lattice, *grid, cur.x[p], inv_h);
              if (particles.cell[p] != last_cell)
                {
                  last_cell = particles.cell[p];
                  support.for_each(s1, s2, [&](const unsigned int n, double, const Tensor<1, dim> &) {
                    if (node_stamp[n] != stamp)
                      {
                        node_stamp[n] = stamp;
                        active_nodes.push_back(n);
                      }
                    if (group.material == nullptr && rigid_node_body[n] == 0)
                      {
                        rigid_node_body[n] = group.rigid_body + 1;
                        rigid_nodes.push_back(n);
                      }
                  });
                }
              if (group.material == nullptr)
                continue;
              const double         m  = particles.mass[p];
              const Tensor<1, dim> mv = m * cur.v[p];
              if (forces_now)
                {
                  const Tensor<1, dim> f_ext =
                    m * gravity + particles.load_factor[p] * load_per_point[particles.load[p]];
                  const SymmetricTensor<2, dim> vs = cur.volume[p] * cur.stress[p];
                  support.for_each(s1, s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &grad) {
                    double *const       r = node + std::size_t(n) * C;
                    const Tensor<1, dim> f = N * f_ext - vs * grad;
                    r[0] += N * m;
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        r[1 + d] += N * mv[d];
                        r[1 + dim + d] += f[d];
                      }
                  });
                }
              else
                support.for_each(s1, s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &) {
                  double *const r = node + std::size_t(n) * C;
                  r[0] += N * m;
                  for (unsigned int d = 0; d < dim; ++d)
                    r[1 + d] += N * mv[d];
                });
            }
        }
      grid->exchange(0, forces_now ? C : 1 + dim);

      // 2. Nodal velocities and their change over the step.
      if (scheme == Scheme::usf)
        {
          for (const unsigned int n : active_nodes)
            {
              double *const r = node + std::size_t(n) * C;
              const double  inv_m = r[0] > tiny ? 1.0 / r[0] : 0.0;
              for (unsigned int d = 0; d < dim; ++d)
                r[1 + d] *= inv_m;
            }
          apply_boundary_conditions(t, dt, false);
          update_stresses<Basis>(dt);
          if (failed_point >= 0)
            return;
          // Forces from the updated stresses.
          for (const auto &group : particles.groups)
            if (group.material != nullptr)
              {
                Support support;
                for (unsigned int p = group.begin; p < group.end; ++p)
                  {
                    support.reinit(lattice, *grid, cur.x[p], inv_h);
                    const Tensor<1, dim> f_ext =
                      particles.mass[p] * gravity +
                      particles.load_factor[p] * load_per_point[particles.load[p]];
                    const SymmetricTensor<2, dim> vs = nxt.volume[p] * nxt.stress[p];
                    support.for_each(s1, s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &grad) {
                      double *const        r = node + std::size_t(n) * C;
                      const Tensor<1, dim> f = N * f_ext - vs * grad;
                      for (unsigned int d = 0; d < dim; ++d)
                        r[1 + dim + d] += f[d];
                    });
                  }
              }
          grid->exchange(1 + dim, dim);
          for (const unsigned int n : active_nodes)
            {
              double *const r = node + std::size_t(n) * C;
              const double  dt_m = r[0] > tiny ? dt / r[0] : 0.0;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  r[1 + dim + d] *= dt_m;       // velocity change
                  r[1 + d] += r[1 + dim + d];   // new velocity
                }
            }
        }
      else
        for (const unsigned int n : active_nodes)
          {
            double *const r = node + std::size_t(n) * C;
            if (r[0] > tiny)
              {
                const double inv_m = 1.0 / r[0];
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    r[1 + dim + d] *= dt * inv_m;                    // velocity change
                    r[1 + d] = r[1 + d] * inv_m + r[1 + dim + d];    // new velocity
                  }
              }
            else
              for (unsigned int c = 1; c < C; ++c)
                r[c] = 0.0;
          }
      apply_boundary_conditions(t + dt, dt, true);

      // 3. G2P: velocities (FLIP/PIC blend) and positions.
      const double alpha = flip_fraction;
      max_speed          = 0;
      kinetic_energy     = 0;
      for (const auto &group : particles.groups)
        {
          if (group.material == nullptr)
            {
              const Tensor<1, dim> v_mid =
                evaluate_in_time<dim>(*this->get_scene().body_descriptions()[group.rigid_body].rigid_velocity,
                                      t + 0.5 * dt);
              const Tensor<1, dim> v_end =
                evaluate_in_time<dim>(*this->get_scene().body_descriptions()[group.rigid_body].rigid_velocity,
                                      t + dt);
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
              support.reinit(lattice, *grid, cur.x[p], inv_h);
              Tensor<1, dim> v_pic, dv;
              support.for_each(s1, s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &) {
                const double *const r = node + std::size_t(n) * C;
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
                particles.mass[p] * gravity +
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
      if (failed_point >= 0)
        return;

      // 4. MUSL: nodal velocities from the updated point momenta.
      if (scheme == Scheme::musl)
        {
          for (const unsigned int n : active_nodes)
            for (unsigned int d = 0; d < dim; ++d)
              node[std::size_t(n) * C + 1 + d] = 0.0;
          grid->zero_interface(1, dim);
          for (const auto &group : particles.groups)
            if (group.material != nullptr)
              {
                Support support;
                for (unsigned int p = group.begin; p < group.end; ++p)
                  {
                    support.reinit(lattice, *grid, cur.x[p], inv_h);
                    const Tensor<1, dim> mv = particles.mass[p] * nxt.v[p];
                    support.for_each(s1, s2, [&](const unsigned int n, const double N, const Tensor<1, dim> &) {
                      double *const r = node + std::size_t(n) * C;
                      for (unsigned int d = 0; d < dim; ++d)
                        r[1 + d] += N * mv[d];
                    });
                  }
              }
          grid->exchange(1, dim);
          for (const unsigned int n : active_nodes)
            {
              double *const r     = node + std::size_t(n) * C;
              const double  inv_m = r[0] > tiny ? 1.0 / r[0] : 0.0;
              for (unsigned int d = 0; d < dim; ++d)
                r[1 + d] *= inv_m;
            }
          apply_boundary_conditions(t + dt, dt, false);
        }

      // 5. Strains and stresses (USF did this before the forces).
      if (scheme != Scheme::usf)
        update_stresses<Basis>(dt);
    }



    template <int dim>
    template <typename Basis>
    void
    Solver<dim>::update_stresses(const double dt)
    {
      using namespace dealii;
      using Support = internal::Support<dim, Basis>;

      const Lattice<dim> &lattice = grid->lattice();
      const double        inv_h   = 1.0 / lattice.h;
      const unsigned int  s1      = grid->stride(1);
      const unsigned int  s2      = dim == 3 ? grid->stride(dim - 1) : 0;
      constexpr unsigned int C    = 1 + 2 * dim;
      const double *const node    = grid->data().data();
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
                  support.reinit(lattice, *grid, cur.x[p], inv_h);
                  Tensor<2, dim> L; // velocity gradient sum_i v_i (x) grad N_i
                  support.for_each(s1, s2, [&](const unsigned int n, double, const Tensor<1, dim> &grad) {
                    const double *const r = node + std::size_t(n) * C;
                    for (unsigned int i = 0; i < dim; ++i)
                      for (unsigned int j = 0; j < dim; ++j)
                        L[i][j] += r[1 + i] * grad[j];
                  });
                  const SymmetricTensor<2, dim> de = symmetrize(L) * dt;
                  strain_increment[p - chunk]      = de;
                  nxt.strain[p]                    = cur.strain[p] + de;
                  nxt.F[p]                         = (identity + dt * L) * cur.F[p];
                  nxt.volume[p]                    = determinant(nxt.F[p]) * particles.volume0[p];
                  if (jaumann)
                    {
                      // Jaumann rate: sigma' = C : d + W sigma - sigma W with the spin
                      // W = skew(L); W sigma - sigma W is symmetric for symmetric sigma.
                      const Tensor<2, dim> W = 0.5 * dt * (L - transpose(L));
                      const Tensor<2, dim> s = cur.stress[p];
                      nxt.stress[p]          = symmetrize(W * s - s * W) + cur.stress[p];
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
              group.material->update(view(strain_increment.data(), n_points),
                                     view(nxt.stress.data() + chunk, n_points),
                                     view(nxt.material_state.data() + offset, n_state),
                                     ArrayView<SymmetricTensor<4, dim>>());
              // Stress power, trapezoidal in time: dW = V sigma_mid : d eps.
              double work = 0;
              for (unsigned int p = chunk; p < chunk_end; ++p)
                work += 0.25 * (cur.volume[p] + nxt.volume[p]) *
                        ((cur.stress[p] + nxt.stress[p]) * strain_increment[p - chunk]);
              if (!std::isfinite(work))
                {
                  for (unsigned int p = chunk; p < chunk_end && failed_point < 0; ++p)
                    if (!std::isfinite(nxt.stress[p].norm()) || !std::isfinite(nxt.volume[p]))
                      {
                        failed_point = p;
                        failure      = "a non-finite stress";
                      }
                  return;
                }
              internal_work += work;
            }
        }
    }
  } // namespace MPM
} // namespace hysteron

#endif

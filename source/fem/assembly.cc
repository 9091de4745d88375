#include <deal.II/base/exceptions.h>
#include <deal.II/base/multithread_info.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/work_stream.h>
#include <deal.II/grid/filtered_iterator.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <hysteron/fem/fem.h>

#include <chrono>
#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      /**
       * B-bar (mean dilatation): B_i <- B_i + (b_i - tr B_i) I / dim at every point, with
       * b_i = sum_q tr B_i(x_q) w_q / sum_q w_q the mean of div N_i over the cell. The
       * dilatation tr eps of every strain is then its mean over the cell (one volumetric
       * constraint per cell instead of one per point, so Q1 does not lock in isochoric
       * flow), and B_i : sigma, B_i : C : B_j are the consistent forces and tangent. In 2D
       * the trace is the in-plane one (plane strain: eps_zz = 0).
       */
      template <int dim>
      void
      mean_dilatation(std::vector<std::vector<dealii::SymmetricTensor<2, dim>>> &B,
                      const std::vector<double>                               &weights)
      {
        const unsigned int n_q = weights.size(), n = B[0].size();
        double             volume = 0;
        for (unsigned int q = 0; q < n_q; ++q)
          volume += weights[q];
        const dealii::SymmetricTensor<2, dim> I = dealii::unit_symmetric_tensor<dim>();
        for (unsigned int i = 0; i < n; ++i)
          {
            double mean = 0;
            for (unsigned int q = 0; q < n_q; ++q)
              mean += dealii::trace(B[q][i]) * weights[q];
            mean /= volume;
            for (unsigned int q = 0; q < n_q; ++q)
              B[q][i] += (mean - dealii::trace(B[q][i])) / dim * I;
          }
      }

      /// sym(e_c (x) g): the symmetric gradient of a shape function that moves component c
      /// with the scalar gradient g.
      template <int dim>
      dealii::SymmetricTensor<2, dim>
      component_gradient(const unsigned int c, const dealii::Tensor<1, dim> &g)
      {
        dealii::SymmetricTensor<2, dim> B;
        for (unsigned int b = 0; b < dim; ++b)
          B[c][b] = b == c ? g[b] : 0.5 * g[b];
        return B;
      }

      /**
       * Half of the Hughes-Winget rotation (I - W/2)^{-1} (I + W/2) of the spin W: that
       * rotation turns about the axial vector w of W by 2 atan(|w|/2), so its half turns by
       * a = atan(|w|/2), by Rodrigues' formula R = I + (sin a / |w|) W + (2 sin^2(a/2) / |w|^2) W^2
       * (in 2D W^2 = -|w|^2 I and R is the plane rotation by a). |W|_F = sqrt(2) |w|.
       */
      template <int dim>
      dealii::Tensor<2, dim>
      half_rotation(const dealii::Tensor<2, dim> &W)
      {
        const double w  = W.norm() / std::sqrt(2.0);
        const double a  = std::atan(0.5 * w);
        const double s1 = w > 0 ? std::sin(a) / w : 0.5;
        const double s2 = w > 0 ? 2.0 * dealii::Utilities::fixed_power<2>(std::sin(0.5 * a) / w) : 0.125;
        return dealii::Tensor<2, dim>(dealii::unit_symmetric_tensor<dim>()) + s1 * W + s2 * (W * W);
      }
    } // namespace



    /*
     * The discrete equations. With N_i the vector shape functions, B_i their
     * symmetric gradients, w_q = JxW_q t (t: the thickness in 2D) and the
     * stresses sigma_q of the material update from the converged state,
     *   f_int,i = sum_q B_i(x_q) : sigma_q w_q,
     *   K_ij    = sum_q B_i : C_q : B_j w_q        (C_q: the material's tangent),
     *   M_ij    = sum_q rho N_i . N_j w_q,   K0_ij = sum_q B_i : D : B_j w_q (elastic),
     *   f_ext,i = sum_q N_i . (rho g + F_l(t) / V_l) w_q + sum_faces N_i . t_l(t) w_f,
     * for body loads F_l (a total force spread over the volume V_l of the
     * material in the load's region) and tractions t_l on the boundary faces in
     * the region.
     *
     * Axisymmetric (x = r, w_q = JxW_q 2 pi r_q): the hoop strain eps_tt = u_r / r is a
     * fourth strain component with the "B" of shape function i equal to
     * n_i = N_i delta(c_i, x) / r, so that
     *   f_int,i += sum_q n_i sigma_tt w_q,
     *   K_ij    += sum_q (B_i : S n_j + n_i H : B_j + n_i C_tt n_j) w_q,
     * with S = d sigma / d eps_tt, H = d sigma_tt / d eps and C_tt = d sigma_tt / d eps_tt
     * (Material::HoopTangent; S = H = lambda I and C_tt = lambda + 2 mu for Hooke's law).
     * The Gauss points lie inside the cells, so r_q > 0 also next to the axis.
     *
     * Quasi-static: r = f_int(u) - f_ext(t1), tangent K.
     * HHT-alpha (Newmark for alpha = 0), beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha:
     *   a1 = (u1 - u0 - dt v0) / (beta dt^2) - (1 - 2 beta) / (2 beta) a0,
     *   v1 = v0 + dt ((1 - gamma) a0 + gamma a1),
     *   r  = M a1 + (1 + alpha)(C v1 + f_int(u1) - f_ext(t1)) - alpha (C v0 + f_int(u0) - f_ext(t0)),
     *   dr/du1 = M / (beta dt^2) + (1 + alpha) gamma / (beta dt) C + (1 + alpha) K,
     * with Rayleigh damping C = a0 M + a1 K0. Everything is formed cell by cell,
     * so that AffineConstraints condenses the prescribed DoFs (and, in the
     * predictor, moves the prescribed increments to the right-hand side).
     *
     * Updated Lagrangian (`Kinematics = updated Lagrangian`): x = X + u. With
     * F = I + grad_X u in the converged (F_n), trial (F_1) and midpoint (F_m = (F_n + F_1)/2)
     * configurations, a gradient in configuration k is grad_k N = F_k^{-T} grad_X N and a
     * volume w det F_k. The increment's velocity gradient at the midpoint,
     * L = grad_X du F_m^{-1}, gives the strain increment d eps = sym L and the spin
     * W = skew L. The Jaumann rate sigma' = C : d + W sigma - sigma W is C : d in a frame
     * that turns with the spin: over the step sigma_1 = Q sigma_n Q^T + Q_h (C : d eps) Q_h^T
     * to second order, with Q the step's rotation and Q_h its half. Hence the stress (and
     * the material's tensor state) is turned by half the step's rotation, updated, and
     * turned by the other half,
     *   sigma_1 = R_h update(R_h sigma_n R_h^T, d eps) R_h^T,   R_h^2 = (I - W/2)^{-1} (I + W/2),
     * which is exact for rigid rotations: u_1 - u_n = (Q - I) x_n gives L = 2 (Q - I)(Q + I)^{-1},
     * a skew tensor, so d eps = 0, and the Cayley transform of W/2 is Q itself. Equilibrium holds in the trial configuration,
     *   f_int,i = sum_q B_i^1 : sigma_1 w_q det F_1,
     * and the tangent is the material one plus the initial-stress (geometric) stiffness,
     *   K_ij = sum_q (B_i^1 : C : B_j^m + delta(c_i, c_j) grad_1 N_i . sigma_1 grad_1 N_j) w_q det F_1,
     * with B_j^m = sym((I - L/2) e_{c_j} (x) grad_m N_j) the derivative of d eps (with B-bar
     * the mean-dilatation B of the midpoint), and C the material's tangent turned by R_h in its
     * stress indices; the derivatives of R_h and of the volume, of order sigma / E, are
     * left out. The
     * mass, loads (dead loads) and thickness stay those of the reference configuration.
     */
    template <int dim>
    bool
    Solver<dim>::assemble(const Vector  &u_iterate,
                          const double   t1,
                          const double   dt,
                          const Assemble what,
                          const bool     update_material)
    {
      using namespace dealii;
      const Scene<dim> &scene   = this->get_scene();
      TimerOutput::Scope timing(scene.timer(), "FEM assembly");
      const bool        matrix  = what == Assemble::residual_and_matrix;
      // dt = 0: the forces of the state u_iterate only (the initial state).
      const bool        dynamic = analysis == Analysis::implicit_dynamics && dt > 0;
      const bool        system  = analysis != Analysis::explicit_dynamics;
      const double      alpha = dynamics.hht_alpha, beta = dynamics.beta(), gamma = dynamics.gamma();
      const double      t0 = t1 - dt;

      if (matrix)
        system_matrix = 0;
      if (system)
        system_rhs = 0;
      f_int   = 0;
      f_ext   = 0;
      inertia = 0;

      const unsigned int n   = fe->n_dofs_per_cell();
      const unsigned int n_q = quadrature->size();
      const FEValuesExtractors::Vector displacement(0);
      std::vector<unsigned int>        comp(n);
      for (unsigned int i = 0; i < n; ++i)
        comp[i] = fe->system_to_component_index(i).first;

      // Loads at t1 (and t0 for HHT): body force densities and tractions.
      const auto &loads = scene.load_descriptions();
      std::vector<Tensor<1, dim>> load1(load_sets.size()), load0(load_sets.size());
      for (unsigned int l = 0; l < load_sets.size(); ++l)
        {
          load1[l] = loads[load_sets[l].load].value_at(t1) * load_sets[l].scale;
          if (dynamic)
            load0[l] = loads[load_sets[l].load].value_at(t0) * load_sets[l].scale;
        }
      const Tensor<1, dim> &g = scene.gravity();
      const unsigned int    n_loads = load_sets.size();

      // 2D: the thickness at a point of the body of the cell (weights hold it already).
      const auto thickness = [&](const CellHistory<dim> &h, const Point<dim> &x) {
        return scene.thickness_at(scene.body_descriptions()[h.body], x);
      };
      const bool axisymmetric = scene.axisymmetric();
      // f += sum_q N_i (rho g + volume loads) w_q + tractions on the boundary faces
      // whose centre lies in the load's region (load values already scaled).
      const auto external = [&](const auto                        &cell,
                                const CellHistory<dim>            &h,
                                const std::vector<Tensor<1, dim>> &value,
                                dealii::Vector<double>            &f,
                                const FEValues<dim>               &fv,
                                FEFaceValues<dim>                 &ffv) {
        f                                 = 0;
        const std::size_t first = cell->active_cell_index() * n_loads;
        for (unsigned int q = 0; q < n_q; ++q)
          {
            Tensor<1, dim> b = h.material->density() * g;
            for (unsigned int l = 0; l < n_loads; ++l)
              if (cell_in_load[first + l] && load_sets[l].kind == LoadSet::Kind::volume &&
                  in_region(l, h.point[q]))
                b += value[l];
            for (unsigned int i = 0; i < n; ++i)
              f[i] += fv.shape_value(i, q) * b[comp[i]] * h.weight[q];
          }
        for (unsigned int l = 0; l < n_loads; ++l)
          if (cell_in_load[first + l] && load_sets[l].kind == LoadSet::Kind::traction)
            for (const unsigned int face : cell->face_indices())
              if (loads_face(l, cell, face))
                {
                  ffv.reinit(cell, face);
                  for (unsigned int q = 0; q < ffv.n_quadrature_points; ++q)
                    for (unsigned int i = 0; i < n; ++i)
                      f[i] += ffv.shape_value(i, q) * value[l][comp[i]] * ffv.JxW(q) * thickness(h, ffv.quadrature_point(q));
                }
      };

      // Cell by cell, in parallel threads (`FEM/Threads`): the worker forms a cell's
      // matrix and vectors (and updates its material points, which only it touches); the
      // copier adds them to the global system in the order of the cells, so that the
      // sums, and the first failure reported, do not depend on the number of threads.
      struct Scratch
      {
        Scratch(const Mapping<dim> &mapping, const FiniteElement<dim> &fe, const Quadrature<dim> &quadrature,
                const Quadrature<dim - 1> &face_quadrature)
          : fv(mapping, fe, quadrature, update_values | update_gradients)
          , ffv(mapping, fe, face_quadrature, update_values | update_quadrature_points | update_JxW_values)
          , M(fe.n_dofs_per_cell(), fe.n_dofs_per_cell())
          , K0(M)
          , B(quadrature.size(), std::vector<SymmetricTensor<2, dim>>(fe.n_dofs_per_cell()))
          , G(fe.n_dofs_per_cell())
          , C(dim * dim * dim * dim)
          , H(fe.n_dofs_per_cell() * dim * dim)
          , Bf(B)
          , B0(B)
          , Gs(quadrature.size(), std::vector<Tensor<1, dim>>(fe.n_dofs_per_cell()))
          , Gf(Gs)
          , G0(Gs)
          , w0(quadrature.size())
          , wm(w0)
          , w1(w0)
          , R(quadrature.size())
          , P(quadrature.size())
          , sG(fe.n_dofs_per_cell())
        {
          for (auto *x : {&fx0, &fi0, &du, &u0, &v0, &a0, &a1, &v1, &Cv0, &Cv1, &tmp})
            x->reinit(fe.n_dofs_per_cell());
        }
        Scratch(const Scratch &other)
          : Scratch(other.fv.get_mapping(), other.fv.get_fe(), other.fv.get_quadrature(), other.ffv.get_quadrature())
        {}
        FEValues<dim>                                   fv;
        FEFaceValues<dim>                               ffv;
        FullMatrix<double>                              M, K0;
        dealii::Vector<double>                          fx0, fi0, du, u0, v0, a0, a1, v1, Cv0, Cv1, tmp;
        std::vector<std::vector<SymmetricTensor<2, dim>>> B;
        std::vector<Tensor<1, dim>>                     G; // the shape gradients at one point
        std::vector<double>                             C, H;
        // Updated Lagrangian: B of the forces (trial configuration, with B-bar) and of
        // f_int(u_n); the shape gradients in the midpoint, trial and converged configurations;
        // the volumes w det F there; the rotations; sigma grad N_j at one point.
        std::vector<std::vector<SymmetricTensor<2, dim>>> Bf, B0;
        std::vector<std::vector<Tensor<1, dim>>>          Gs, Gf, G0;
        std::vector<double>                               w0, wm, w1;
        std::vector<Tensor<2, dim>>                       R, P; ///< P = I - L/2
        std::vector<Tensor<1, dim>>                       sG;
      };
      struct Copy
      {
        explicit Copy(const unsigned int n)
          : A(n, n)
          , r(n)
          , fi(n)
          , fx(n)
          , Mv(n)
          , dofs(n)
        {}
        FullMatrix<double>                   A;
        dealii::Vector<double>               r, fi, fx, Mv; ///< Mv: the inertia forces (dynamics)
        std::vector<types::global_dof_index> dofs;
        bool                                 active = false, failed = false;
        std::string                          message;
        double                               material_seconds = 0;
      };
      using CellIterator = typename DoFHandler<dim>::active_cell_iterator;
      const auto worker = [&](const CellIterator &cell, Scratch &scratch, Copy &out) {
        out.active = out.failed = false;
        auto &fv = scratch.fv;
        auto &ffv = scratch.ffv;
        auto &M = scratch.M, &K0 = scratch.K0;
        auto &fx0 = scratch.fx0, &fi0 = scratch.fi0, &du = scratch.du, &v0 = scratch.v0, &a0 = scratch.a0,
             &a1 = scratch.a1, &v1 = scratch.v1, &Cv0 = scratch.Cv0, &Cv1 = scratch.Cv1, &tmp = scratch.tmp;
        auto &B = scratch.B;
        auto &G = scratch.G;
        auto &C = scratch.C, &H = scratch.H;
        auto &A = out.A;
        auto &r = out.r, &fi = out.fi, &fx = out.fx, &Mv = out.Mv;
        // Axisymmetric: add n_i sigma_tt w to @p f and (if @p K) the hoop terms of the
        // tangent (see the top of this file) at point q, n_i = N_i delta(c_i, x) / r_q.
        const auto add_hoop_terms = [&](const SymmetricTensor<2, dim> &S,
                                        const SymmetricTensor<2, dim> &H_t,
                                        const double                   C_tt,
                                        const double                   sigma_tt,
                                        const unsigned int             q,
                                        const double                   r_q,
                                        const double                   w,
                                        FullMatrix<double>            *K,
                                        dealii::Vector<double>        &f) {
          const double inv_r = 1.0 / r_q;
          for (unsigned int i = 0; i < n; ++i)
            {
              // nr: n_i; bs: B_i : S; hb: H : B_i.
              const double nr = comp[i] == 0 ? fv.shape_value(i, q) * inv_r : 0.0;
              double       bs = 0, hb = 0;
              const auto   g  = fv.shape_grad(i, q);
              for (unsigned int b = 0; b < dim; ++b)
                {
                  bs += S[comp[i]][b] * g[b];
                  hb += H_t[comp[i]][b] * g[b];
                }
              f[i] += nr * sigma_tt * w;
              if (K)
                {
                  // (n_i, B_i : S, H : B_i) in the scratch H (its matrix use at q is done)
                  H[3 * i]     = nr;
                  H[3 * i + 1] = bs;
                  H[3 * i + 2] = hb;
                }
            }
          if (K)
            for (unsigned int i = 0; i < n; ++i)
              for (unsigned int j = 0; j < n; ++j)
                (*K)(i, j) += (H[3 * i + 1] * H[3 * j] + H[3 * i] * H[3 * j + 2] +
                               H[3 * i] * C_tt * H[3 * j]) * w;
        };
        auto &dofs = out.dofs;
        Mv = 0;
        fv.reinit(cell);
        cell->get_dof_indices(dofs);
        out.active = true;
        CellHistory<dim> &h   = *cell_history[cell->active_cell_index()];
        const double      rho = h.material->density();
        for (unsigned int i = 0; i < n; ++i)
          du[i] = u_iterate(dofs[i]) - u_ghost(dofs[i]);
        if (finite_strain)
          {
            // The kinematics of the increment (see the top of this file).
            auto &u0 = scratch.u0;
            for (unsigned int i = 0; i < n; ++i)
              u0[i] = u_ghost(dofs[i]);
            const Tensor<2, dim> I = unit_symmetric_tensor<dim>();
            for (unsigned int q = 0; q < n_q; ++q)
              {
                Tensor<2, dim> grad_u0, grad_du;
                for (unsigned int i = 0; i < n; ++i)
                  {
                    const Tensor<1, dim> &g = fv.shape_grad(i, q);
                    grad_u0[comp[i]] += u0[i] * g;
                    grad_du[comp[i]] += du[i] * g;
                  }
                const Tensor<2, dim> F0 = I + grad_u0, F1 = F0 + grad_du, Fm = F0 + 0.5 * grad_du;
                const double         J0 = determinant(F0), J1 = determinant(F1), Jm = determinant(Fm);
                if (!(J1 > 0 && Jm > 0))
                  {
                    out.failed = true;
                    std::ostringstream m;
                    m << "the element at " << cell->center() << " (body '" << scene.body_descriptions()[h.body].name
                      << "') turns inside out in the step to t = " << t1 << " s (det F = " << J1
                      << " at a quadrature point): the increment is too large for the mesh";
                    out.message = m.str();
                    return;
                  }
                // The converged configuration only serves f_int(u_n) of HHT-alpha.
                const Tensor<2, dim> inv0T = dynamic ? transpose(invert(F0)) : Tensor<2, dim>(),
                                     inv1T = transpose(invert(F1)), invmT = transpose(invert(Fm));
                for (unsigned int i = 0; i < n; ++i)
                  {
                    const Tensor<1, dim> &g = fv.shape_grad(i, q);
                    scratch.Gs[q][i] = invmT * g;
                    scratch.Gf[q][i] = inv1T * g;
                    if (dynamic)
                      scratch.G0[q][i] = inv0T * g;
                    B[q][i]          = component_gradient(comp[i], scratch.Gs[q][i]);
                    if (b_bar)
                      scratch.Bf[q][i] = component_gradient(comp[i], scratch.Gf[q][i]);
                    if (b_bar && dynamic)
                      scratch.B0[q][i] = component_gradient(comp[i], scratch.G0[q][i]);
                  }
                scratch.w0[q]        = h.weight[q] * J0;
                scratch.wm[q]        = h.weight[q] * Jm;
                scratch.w1[q]        = h.weight[q] * J1;
                h.trial_volume[q]    = scratch.w1[q];
                const Tensor<2, dim> L = grad_du * transpose(invmT);
                const Tensor<2, dim> W = 0.5 * (L - transpose(L));
                scratch.R[q]           = half_rotation(W);
                scratch.P[q]           = I - 0.5 * L;
              }
            if (b_bar)
              {
                mean_dilatation(B, scratch.wm);
                mean_dilatation(scratch.Bf, scratch.w1);
                if (dynamic)
                  mean_dilatation(scratch.B0, scratch.w0);
              }
          }
        else
          {
            for (unsigned int q = 0; q < n_q; ++q)
              for (unsigned int i = 0; i < n; ++i)
                B[q][i] = fv[displacement].symmetric_gradient(i, q);
            if (b_bar)
              mean_dilatation(B, h.weight);
          }
        for (unsigned int q = 0; q < n_q; ++q)
          {
            SymmetricTensor<2, dim> e;
            for (unsigned int i = 0; i < n; ++i)
              if (du[i] != 0)
                e += du[i] * B[q][i];
            h.increment[q] = e;
            if (axisymmetric)
              {
                double u_r = 0;
                for (unsigned int i = 0; i < n; ++i)
                  if (comp[i] == 0 && du[i] != 0)
                    u_r += du[i] * fv.shape_value(i, q);
                h.hoop_increment[q] = u_r / h.point[q][0];
              }
          }

        // The material: from the converged state to the trial state.
        h.trial_stress = h.stress;
        h.trial_state  = h.state;
        if (finite_strain)
          for (unsigned int q = 0; q < n_q; ++q)
            {
              // The first half of the Jaumann rotation of the stress and of the material's
              // tensor state.
              const Tensor<2, dim> &R = scratch.R[q];
              h.trial_stress[q]       = symmetrize(R * Tensor<2, dim>(h.stress[q]) * transpose(R));
              h.material->rotate_state(R, ArrayView<double>(h.trial_state.data() + q * h.n_state, h.n_state));
            }
        const auto material_start = std::chrono::steady_clock::now();
        if (update_material)
          try
            {
              if (axisymmetric)
                h.material->update_axisymmetric(
                  make_array_view(std::as_const(h.increment)),
                  make_array_view(std::as_const(h.hoop_increment)),
                  make_array_view(h.trial_stress),
                  make_array_view(h.trial_state),
                  matrix ? make_array_view(h.tangent) : ArrayView<SymmetricTensor<4, dim>>(),
                  matrix ? make_array_view(h.hoop_tangent) : ArrayView<Material::HoopTangent<dim>>());
              else
                h.material->update(make_array_view(std::as_const(h.increment)),
                                   make_array_view(h.trial_stress),
                                   make_array_view(h.trial_state),
                                   matrix ? make_array_view(h.tangent) :
                                            ArrayView<SymmetricTensor<4, dim>>());
            }
          catch (const RuntimeError &e)
            {
              out.failed = true;
              std::ostringstream m;
              m << e.what() << " (in the cell at " << cell->center() << ", body '"
                << scene.body_descriptions()[h.body].name << "', step to t = " << t1 << " s)";
              out.message = m.str();
            }
        out.material_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - material_start).count();
        if (out.failed)
          return;
        if (finite_strain)
          for (unsigned int q = 0; q < n_q; ++q)
            {
              // The second half of the rotation (the tangent is turned where it is used).
              const Tensor<2, dim> &R = scratch.R[q];
              h.trial_stress[q]       = symmetrize(R * Tensor<2, dim>(h.trial_stress[q]) * transpose(R));
              h.material->rotate_state(R, ArrayView<double>(h.trial_state.data() + q * h.n_state, h.n_state));
            }

        // Shape function i moves component c_i only, with the gradient g_i of its scalar
        // shape function: B_i = sym(e_{c_i} (x) g_i), so (with the minor symmetries of
        // sigma and C) B_i : sigma = sigma_{c_i b} g_i[b] and
        //   B_i : C : B_j = g_i[b] C_{c_i b c_j d} g_j[d],
        // dim^2 products per pair instead of a contraction of two symmetric tensors.
        fi = 0;
        if (matrix)
          A = 0;
        for (unsigned int q = 0; q < n_q; ++q)
          {
            const double w = finite_strain ? scratch.w1[q] : h.weight[q];
            const SymmetricTensor<2, dim> &s = h.trial_stress[q];
            if (finite_strain && matrix)
              {
                // The initial-stress stiffness delta(c_i, c_j) grad N_i . sigma grad N_j w.
                const auto &Gf = scratch.Gf[q];
                for (unsigned int j = 0; j < n; ++j)
                  scratch.sG[j] = s * Gf[j];
                for (unsigned int i = 0; i < n; ++i)
                  for (unsigned int j = 0; j < n; ++j)
                    if (comp[i] == comp[j])
                      A(i, j) += (Gf[i] * scratch.sG[j]) * w;
              }
            if (b_bar)
              {
                // The B-bar matrices are not those of one component: contract in full.
                const auto &Bf = finite_strain ? scratch.Bf[q] : B[q];
                for (unsigned int i = 0; i < n; ++i)
                  fi[i] += (Bf[i] * s) * w;
                if (matrix)
                  for (unsigned int j = 0; j < n; ++j)
                    {
                      SymmetricTensor<2, dim> CB = h.tangent[q] * B[q][j];
                      if (finite_strain)
                        CB = symmetrize(scratch.R[q] * Tensor<2, dim>(CB) * transpose(scratch.R[q]));
                      for (unsigned int i = 0; i < n; ++i)
                        A(i, j) += (Bf[i] * CB) * w;
                    }
                continue;
              }
            // The forces' gradients G (trial configuration) and the strains' (midpoint).
            for (unsigned int i = 0; i < n; ++i)
              G[i] = finite_strain ? scratch.Gf[q][i] : fv.shape_grad(i, q);
            const std::vector<Tensor<1, dim>> &Gj = finite_strain ? scratch.Gs[q] : G;
            for (unsigned int i = 0; i < n; ++i)
              {
                double v = 0;
                for (unsigned int b = 0; b < dim; ++b)
                  v += s[comp[i]][b] * G[i][b];
                fi[i] += v * w;
              }
            if (matrix)
              {
                // C as a plain array, then H_j[c][b] = w C_{c b c_j d} g_j[d].
                const SymmetricTensor<4, dim> &T = h.tangent[q];
                for (unsigned int a = 0; a < dim; ++a)
                  for (unsigned int b = 0; b < dim; ++b)
                    for (unsigned int c = 0; c < dim; ++c)
                      for (unsigned int d = 0; d < dim; ++d)
                        C[((a * dim + b) * dim + c) * dim + d] = T[a][b][c][d];
                if (finite_strain)
                  {
                    // sigma_1 = R_h S R_h^T: the tangent turned in its stress indices,
                    // C'_{abkd} = R_ai R_bj C_ijkd (H holds the copy; its use at q comes later).
                    const Tensor<2, dim> &R = scratch.R[q];
                    std::copy(C.begin(), C.end(), H.begin());
                    for (unsigned int a = 0; a < dim; ++a)
                      for (unsigned int b = 0; b < dim; ++b)
                        for (unsigned int kd = 0; kd < dim * dim; ++kd)
                          {
                            double v = 0;
                            for (unsigned int i = 0; i < dim; ++i)
                              for (unsigned int j = 0; j < dim; ++j)
                                v += R[a][i] * R[b][j] * H[(i * dim + j) * dim * dim + kd];
                            C[(a * dim + b) * dim * dim + kd] = v;
                          }
                  }
                if (finite_strain)
                  {
                    // d(d eps) / du_j = sym((I - L/2) e_{c_j} (x) grad_m N_j) (F_m moves with u_1):
                    // H_j[c][b] = w C_{c b k d} P_{k c_j} g_j[d] with P = I - L/2.
                    const Tensor<2, dim> &P = scratch.P[q];
                    for (unsigned int j = 0; j < n; ++j)
                      for (unsigned int c = 0; c < dim; ++c)
                        for (unsigned int b = 0; b < dim; ++b)
                          {
                            double v = 0;
                            for (unsigned int k = 0; k < dim; ++k)
                              {
                                const double *row = &C[((c * dim + b) * dim + k) * dim];
                                double        r   = 0;
                                for (unsigned int d = 0; d < dim; ++d)
                                  r += row[d] * Gj[j][d];
                                v += P[k][comp[j]] * r;
                              }
                            H[(j * dim + c) * dim + b] = w * v;
                          }
                  }
                else
                  for (unsigned int j = 0; j < n; ++j)
                    for (unsigned int c = 0; c < dim; ++c)
                      for (unsigned int b = 0; b < dim; ++b)
                        {
                          const double *row = &C[((c * dim + b) * dim + comp[j]) * dim];
                          double        v   = 0;
                          for (unsigned int d = 0; d < dim; ++d)
                            v += row[d] * Gj[j][d];
                          H[(j * dim + c) * dim + b] = w * v;
                        }
                for (unsigned int i = 0; i < n; ++i)
                  for (unsigned int j = 0; j < n; ++j)
                    {
                      const double *hj = &H[(j * dim + comp[i]) * dim];
                      double        v  = 0;
                      for (unsigned int b = 0; b < dim; ++b)
                        v += G[i][b] * hj[b];
                      A(i, j) += v;
                    }
              }
            if (axisymmetric)
              add_hoop_terms(h.hoop_tangent[q].stress_by_hoop,
                             h.hoop_tangent[q].hoop_by_strain,
                             h.hoop_tangent[q].hoop_by_hoop,
                             h.out_of_plane_stress(q, true),
                             q,
                             h.point[q][0],
                             w,
                             matrix ? &A : nullptr,
                             fi);
          }
        external(cell, h, load1, fx, fv, ffv);

        if (dynamic)
          {
            // Mass, elastic stiffness (damping) and the Newmark kinematics of the cell.
            M  = 0;
            K0 = 0;
            const SymmetricTensor<4, dim> D = h.material->elasticity().template stiffness<dim>();
            const auto                   &el = h.material->elasticity();
            const SymmetricTensor<2, dim> lambda_I = el.lame_lambda() * unit_symmetric_tensor<dim>();
            fi0 = 0;
            for (unsigned int q = 0; q < n_q; ++q)
              {
                // The mass of the reference configuration; damping's K0 in the step's
                // (midpoint) configuration and f_int(u_n) in the converged one.
                const double w = h.weight[q];
                for (unsigned int i = 0; i < n; ++i)
                  for (unsigned int j = 0; j < n; ++j)
                    if (comp[i] == comp[j])
                      M(i, j) += rho * fv.shape_value(i, q) * fv.shape_value(j, q) * w;
                const double wK = finite_strain ? scratch.wm[q] : w;
                if (dynamics.rayleigh_stiffness > 0)
                  for (unsigned int j = 0; j < n; ++j)
                    {
                      const SymmetricTensor<2, dim> DB = D * B[q][j];
                      for (unsigned int i = 0; i < n; ++i)
                        K0(i, j) += (B[q][i] * DB) * wK;
                    }
                if (finite_strain)
                  for (unsigned int i = 0; i < n; ++i)
                    fi0[i] += (b_bar ? scratch.B0[q][i] * h.stress[q] :
                                       component_gradient(comp[i], scratch.G0[q][i]) * h.stress[q]) *
                              scratch.w0[q];
                else
                  for (unsigned int i = 0; i < n; ++i)
                    fi0[i] += (B[q][i] * h.stress[q]) * w;
                // Axisymmetric: the hoop terms of f_int(u0) and of the elastic K0.
                if (axisymmetric)
                  add_hoop_terms(lambda_I,
                                 lambda_I,
                                 el.lame_lambda() + 2.0 * el.shear_modulus(),
                                 h.out_of_plane_stress(q, false),
                                 q,
                                 h.point[q][0],
                                 w,
                                 dynamics.rayleigh_stiffness > 0 ? &K0 : nullptr,
                                 fi0);
              }
            external(cell, h, load0, fx0, fv, ffv);
            for (unsigned int i = 0; i < n; ++i)
              {
                v0[i] = v_ghost(dofs[i]);
                a0[i] = a_ghost(dofs[i]);
                a1[i] = (du[i] - dt * v0[i]) / (beta * dt * dt) - (1 - 2 * beta) / (2 * beta) * a0[i];
                v1[i] = v0[i] + dt * ((1 - gamma) * a0[i] + gamma * a1[i]);
              }
            // C v = a0 M v + a1 K0 v.
            M.vmult(Mv, a1);
            M.vmult(Cv0, v0);
            M.vmult(Cv1, v1);
            Cv0 *= dynamics.rayleigh_mass;
            Cv1 *= dynamics.rayleigh_mass;
            if (dynamics.rayleigh_stiffness > 0)
              {
                K0.vmult(tmp, v0);
                Cv0.add(dynamics.rayleigh_stiffness, tmp);
                K0.vmult(tmp, v1);
                Cv1.add(dynamics.rayleigh_stiffness, tmp);
              }
            for (unsigned int i = 0; i < n; ++i)
              r[i] = Mv[i] + (1 + alpha) * (Cv1[i] + fi[i] - fx[i]) -
                     alpha * (Cv0[i] + fi0[i] - fx0[i]);
            if (matrix)
              {
                const double c_M = 1 / (beta * dt * dt) + (1 + alpha) * gamma / (beta * dt) * dynamics.rayleigh_mass;
                const double c_K0 = (1 + alpha) * gamma / (beta * dt) * dynamics.rayleigh_stiffness;
                for (unsigned int i = 0; i < n; ++i)
                  for (unsigned int j = 0; j < n; ++j)
                    A(i, j) = (1 + alpha) * A(i, j) + c_M * M(i, j) + c_K0 * K0(i, j);
              }
            for (unsigned int i = 0; i < n; ++i)
              Mv[i] += Cv1[i];
          }
        else
          for (unsigned int i = 0; i < n; ++i)
            r[i] = fi[i] - fx[i];
        r *= -1.0;
      };
      bool        failed = false;
      std::string message;
      const auto  copier = [&](const Copy &c) {
        if (!c.active)
          return;
        material_seconds += c.material_seconds;
        if (c.failed)
          {
            if (!failed)
              message = c.message;
            failed = true;
          }
        if (failed)
          return;
        if (system)
          {
            if (matrix)
              constraints.distribute_local_to_global(c.A, c.r, c.dofs, system_matrix, system_rhs, true);
            else
              constraints.distribute_local_to_global(c.r, c.dofs, system_rhs);
          }
        f_int.add(c.dofs, c.fi);
        f_ext.add(c.dofs, c.fx);
        if (dynamic)
          inertia.add(c.dofs, c.Mv);
      };
      // Threads for this loop only (deal.II's other operations keep one). With more than one,
      // FEValues computes every cell's geometry afresh instead of reusing that of a translated
      // neighbour, so the results differ from one thread's at round-off; they are the same
      // for any number of threads above one.
      using Filtered = FilteredIterator<CellIterator>;
      // MPI_InitFinalize gives every method one thread; the guard raises the limit here only.
      struct ThreadLimit
      {
        explicit ThreadLimit(const unsigned int n)
          : raised(n > 1)
        {
          if (raised)
            MultithreadInfo::set_thread_limit(n);
        }
        ~ThreadLimit()
        {
          if (raised)
            MultithreadInfo::set_thread_limit(1);
        }
        const bool raised;
      } limit(threads);
      WorkStream::run(Filtered(IteratorFilters::LocallyOwnedCell(), dof_handler.begin_active()),
                      Filtered(IteratorFilters::LocallyOwnedCell(), dof_handler.end()),
                      worker,
                      copier,
                      Scratch(*mapping, *fe, *quadrature, *face_quadrature),
                      Copy(n));

      // Forces shared by nodes (a load region without quadrature points).
      for (unsigned int l = 0; l < n_loads; ++l)
        if (load_sets[l].kind == LoadSet::Kind::nodal)
          for (unsigned int k = 0; k < load_sets[l].nodal_dofs.size(); ++k)
            {
              const auto         dof = load_sets[l].nodal_dofs[k];
              const unsigned int c   = load_sets[l].nodal_components[k];
              f_ext(dof) += load1[l][c];
              if (system && !constraints.is_constrained(dof))
                system_rhs(dof) += dynamic ? (1 + alpha) * load1[l][c] - alpha * load0[l][c] : load1[l][c];
            }

      if (matrix)
        system_matrix.compress(VectorOperation::add);
      if (system)
        system_rhs.compress(VectorOperation::add);
      f_int.compress(VectorOperation::add);
      f_ext.compress(VectorOperation::add);
      inertia.compress(VectorOperation::add);

      // A failure on any rank is a failure everywhere (with the first message).
      MPI_Comm comm = scene.mpi_communicator();
      if (dealii::Utilities::MPI::logical_or(failed, comm))
        {
          const unsigned int rank  = dealii::Utilities::MPI::this_mpi_process(comm);
          const unsigned int first = dealii::Utilities::MPI::min(failed ? rank : dealii::numbers::invalid_unsigned_int, comm);
          material_failure         = dealii::Utilities::MPI::broadcast(comm, message, first);
          return false;
        }
      last_force_level = std::max({f_int.l2_norm(), f_ext.l2_norm(), inertia.l2_norm()});
      return std::isfinite(last_force_level) && (!system || std::isfinite(system_rhs.l2_norm()));
    }



    template <int dim>
    void
    Solver<dim>::commit(const double t1, const double dt)
    {
      (void)t1;
      using namespace dealii;
      double     work         = 0;
      const bool axisymmetric = this->get_scene().axisymmetric();
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            for (unsigned int q = 0; q < h.stress.size(); ++q)
              {
                // Trapezoidal internal work 1/2 (sigma_n + sigma_n+1) : d eps (+ the hoop part),
                // over the volume of the step's midpoint.
                work += 0.5 * ((h.stress[q] + h.trial_stress[q]) * h.increment[q]) *
                        (finite_strain ? 0.5 * (h.volume[q] + h.trial_volume[q]) : h.weight[q]);
                if (axisymmetric)
                  work += 0.5 * (h.out_of_plane_stress(q, false) + h.out_of_plane_stress(q, true)) *
                          h.hoop_increment[q] * h.weight[q];
                h.strain[q] += h.increment[q];
              }
            h.stress.swap(h.trial_stress);
            h.state.swap(h.trial_state);
            if (finite_strain)
              h.volume = h.trial_volume;
          }
      internal_work += work; // this rank's part (summed when a table row is written)

      Vector increment = u_trial;
      increment -= u;
      if (analysis == Analysis::implicit_dynamics)
        {
          dynamics.update(increment, dt, v, a);
          v_ghost = v;
          a_ghost = a;
        }
      else if (analysis == Analysis::quasi_static && dt > 0)
        {
          // The rate of the load path (t is the load parameter): what the probes
          // report as velocity, comparable with a slow dynamic run. No kinetic energy.
          v = increment;
          v *= 1 / dt;
          v_ghost = v;
        }

      // External and boundary work (trapezoidal, this rank's DoFs), the reactions of the new state.
      for (const auto i : owned_dofs)
        external_work += 0.5 * (f_ext_old(i) + f_ext(i)) * increment(i);
      Vector r = f_int;
      r += inertia;
      r -= f_ext;
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        if (owned_dofs.is_element(constrained_list[k]))
          boundary_work += 0.5 * (reaction_old(constrained_list[k]) + r(constrained_list[k])) *
                           increment(constrained_list[k]);
      reaction_old = r;
      f_int_old    = f_int;
      f_ext_old    = f_ext;
      force_scale  = std::max(force_scale, last_force_level);
      u            = u_trial;
      u_ghost      = u;
    }



    template <int dim>
    void
    Solver<dim>::elastic_stiffness_product(const Vector &x, Vector &y) const
    {
      // y = K0 x = sum_q B_i : D : eps(x) w_q, matrix-free (explicit damping, power iteration).
      using namespace dealii;
      const unsigned int n   = fe->n_dofs_per_cell();
      const unsigned int n_q = quadrature->size();
      FEValues<dim>      fv(*mapping, *fe, *quadrature, update_gradients);
      const FEValuesExtractors::Vector displacement(0);
      std::vector<types::global_dof_index> dofs(n);
      dealii::Vector<double>               xe(n), ye(n);
      std::vector<std::vector<SymmetricTensor<2, dim>>> B(n_q, std::vector<SymmetricTensor<2, dim>>(n));
      y = 0;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            fv.reinit(cell);
            cell->get_dof_indices(dofs);
            const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            const SymmetricTensor<4, dim> D = h.material->elasticity().template stiffness<dim>();
            for (unsigned int i = 0; i < n; ++i)
              xe[i] = x(dofs[i]);
            for (unsigned int q = 0; q < n_q; ++q)
              for (unsigned int i = 0; i < n; ++i)
                B[q][i] = fv[displacement].symmetric_gradient(i, q);
            if (b_bar)
              mean_dilatation(B, h.weight);
            ye = 0;
            for (unsigned int q = 0; q < n_q; ++q)
              {
                SymmetricTensor<2, dim> e;
                for (unsigned int i = 0; i < n; ++i)
                  e += xe[i] * B[q][i];
                const SymmetricTensor<2, dim> s = D * e;
                for (unsigned int i = 0; i < n; ++i)
                  ye[i] += (B[q][i] * s) * h.weight[q];
              }
            y.add(dofs, ye);
          }
      y.compress(VectorOperation::add);
    }



    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron

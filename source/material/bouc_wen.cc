#include <hysteron/material/bouc_wen.h>

#include "material/bouc_wen_fused_forward_euler.h"
#include "material/bouc_wen_kernels.h"
#include "material/bouc_wen_point.h"

#include <cmath>
#include <sstream>
#include <type_traits>

namespace hysteron
{
  namespace Material
  {
    namespace
    {
      using namespace BoucWenKernels;

      template <StressState S>
      using StressStateTag = std::integral_constant<StressState, S>;

      /**
       * Call fn(stress state tag, kinematic tag, degradation tag) for the
       * configuration of a material: the one runtime branch per batch, after
       * which everything is a compile-time constant.
       */
      template <int dim, typename Function>
      void
      dispatch(const StressState state, const bool kinematic, const bool degrading, Function &&fn)
      {
        const auto with_state = [&](auto s) {
          if (kinematic)
            {
              if (degrading)
                fn(s, std::true_type(), std::true_type());
              else
                fn(s, std::true_type(), std::false_type());
            }
          else
            {
              if (degrading)
                fn(s, std::false_type(), std::true_type());
              else
                fn(s, std::false_type(), std::false_type());
            }
        };
        if constexpr (dim == 3)
          with_state(StressStateTag<StressState::three_dimensional>());
        else if (state == StressState::plane_stress)
          with_state(StressStateTag<StressState::plane_stress>());
        else
          with_state(StressStateTag<StressState::plane_strain>());
      }

      template <int dim>
      bool
      want_hoop_tangent(const dealii::ArrayView<dealii::SymmetricTensor<4, dim>> &tangents,
                        const dealii::ArrayView<HoopTangent<dim>>                &hoop_tangents)
      {
        Assert(hoop_tangents.size() == 0 || hoop_tangents.size() == tangents.size(),
               dealii::ExcDimensionMismatch(hoop_tangents.size(), tangents.size()));
        (void)tangents;
        return hoop_tangents.size() > 0;
      }

      /// One batch; @p hoop: null, or the hoop strain increments (axisymmetric), whose
      /// tangent terms go to @p hoop_tangents if that is not empty.
      template <int dim, typename L, BoucWenIntegrator integrator>
      void
      run_batch(const Constants                                                &c,
                const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
                const double                                                   *hoop,
                const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
                const dealii::ArrayView<double>                                &states,
                const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
                const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents)
      {
        const bool want_hoop = want_hoop_tangent(tangents, hoop_tangents);
        using P                             = Point<dim, L>;
        constexpr unsigned int size         = L::Slots::size;
        const bool             want_tangent = tangents.size() > 0;
        AssertDimension(states.size(), strain_increments.size() * size);
        AssertDimension(stresses.size(), strain_increments.size());
        Assert(!want_tangent || tangents.size() == strain_increments.size(),
               dealii::ExcDimensionMismatch(tangents.size(), strain_increments.size()));

        if constexpr (integrator == BoucWenIntegrator::forward_euler && !L::is_degrading)
          {
            using FE                  = FusedForwardEuler<dim, L>;
            const unsigned int n_half = c.n_integer % 2 == 0 ? c.n_integer / 2 : 0;
            double            *st     = states.data();
            std::size_t        p      = 0;
            if (!want_tangent)
              for (; p + 4 <= strain_increments.size(); p += 4, st += 4 * size)
                FE::template update_points<4>(c,
                                              n_half,
                                              &strain_increments[p],
                                              hoop ? hoop + p : nullptr,
                                              &stresses[p],
                                              st,
                                              size);
            for (; p < strain_increments.size(); ++p, st += size)
              FE::update(c,
                         n_half,
                         strain_increments[p],
                         hoop ? hoop[p] : 0.0,
                         stresses[p],
                         st,
                         want_tangent ? &tangents[p] : nullptr,
                         want_hoop ? &hoop_tangents[p] : nullptr);
            return;
          }

        std::size_t p = 0;
        if constexpr (integrator == BoucWenIntegrator::adaptive)
          if (!want_tangent)
            {
              // Interleaved first attempts (Law::adaptive_points()); no tangent, so
              // only the end state's H1 and H2 are needed.
              constexpr unsigned int n_points = 8;
              typename L::VecN       y[n_points];
              typename L::VecK       deps[n_points];
              typename L::Rates      r[n_points];
              for (; p + n_points <= strain_increments.size(); p += n_points)
                {
                  double *st = states.data() + p * size;
                  for (unsigned int k = 0; k < n_points; ++k)
                    {
                      P::load(stresses[p + k], st + k * size, y[k]);
                      P::strain(strain_increments[p + k], hoop ? hoop[p + k] : 0.0, deps[k]);
                    }
                  L::template adaptive_points<n_points>(c, y, deps, r);
                  for (unsigned int k = 0; k < n_points; ++k)
                    P::store(c, y[k], r[k].H1, r[k].H2, stresses[p + k], st + k * size);
                }
            }

        typename L::VecN y;
        typename L::VecK deps;
        typename L::MatK T;
        for (; p < strain_increments.size(); ++p)
          {
            double *st = states.data() + p * size;
            P::load(stresses[p], st, y);
            P::strain(strain_increments[p], hoop ? hoop[p] : 0.0, deps);
            double H1 = 0, H2 = 0;
            if constexpr (integrator == BoucWenIntegrator::forward_euler)
              {
                typename L::Rates r;
                L::forward_euler(c, y, deps, r);
                H1 = L::H1_at(c, y.data());
                H2 = r.H2;
                if (want_tangent)
                  L::continuum_tangent(c, r, T);
              }
            else if constexpr (integrator == BoucWenIntegrator::adaptive)
              {
                typename L::Rates r;
                L::adaptive(c, y, deps, r, want_tangent);
                H1 = r.H1;
                H2 = r.H2;
                if (want_tangent)
                  L::continuum_tangent(c, r, T);
              }
            else
              L::backward_euler(c, y, deps, H1, H2, want_tangent ? &T : nullptr);
            P::store(c, y, H1, H2, stresses[p], st);
            if (want_tangent)
              P::tangent(T, tangents[p], want_hoop ? &hoop_tangents[p] : nullptr);
          }
      }
    } // namespace

    template <int dim>
    void
    BoucWen<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      BoucWenParameters::declare_parameters(prm);
    }

    template <int dim>
    void
    BoucWen<dim>::parse_parameters(const Section &section)
    {
      for (const auto &w : parameters.parse_parameters(section))
        this->add_warning(w);
      {
        Section bouc_wen(section, "Bouc-Wen");
        family.parse_parameters(bouc_wen, parameters);
      }

      const Elasticity &el = this->elasticity();
      stress_state         = dim == 3 ? StressState::three_dimensional : el.stress_state;

      Constants &c   = constants;
      c.E            = el.youngs_modulus;
      c.nu           = el.poissons_ratio;
      c.two_mu       = 2.0 * el.shear_modulus();
      c.lambda_eff   = el.effective_lambda();
      c.sigma_y0     = parameters.yield_stress;
      c.eps_y        = c.sigma_y0 / c.E;
      // (An implausible yield strain sigma_y / E is refused or warned about by the
      // parameters, for every user of the law.)
      const double a = parameters.post_yield_ratio;
      const double m = parameters.isotropic_fraction;
      c.H            = a * c.E / (1.0 - a);
      c.kin          = (1.0 - m) * 2.0 / 3.0 * c.H;
      c.kin_q        = (1.0 - m) * c.H;
      c.iso          = m * c.H;
      c.n            = parameters.smoothness;
      c.n_integer =
        (c.n == std::floor(c.n) && c.n >= 1 && c.n <= 1024) ? static_cast<unsigned int>(c.n) : 0;
      c.n_half       = c.n_integer % 2 == 0 ? c.n_integer / 2 : 0;
      c.radial_g     = 2.25 / (c.H + 1.5 * c.two_mu);
      c.H_3mu        = c.H + 1.5 * c.two_mu;
      c.beta         = parameters.beta;
      c.gamma        = parameters.gamma;
      c.c_eta        = parameters.stiffness_degradation_c_eta;
      c.m_u          = parameters.stiffness_degradation_m_u;
      c.inv_m_u1     = 1.0 / (c.m_u + 1.0);
      c.c_nu_scaled  = parameters.strength_deterioration_c_nu / (c.sigma_y0 * c.eps_y);
      c.tol          = parameters.tolerance;
      c.inv_tol      = 1.0 / c.tol;
      c.inv_sigma_y0 = 1.0 / c.sigma_y0;
      c.inv_eps_y    = 1.0 / c.eps_y;
      c.inv_energy   = 1.0 / (c.sigma_y0 * c.eps_y);

      kinematic = m < 1.0;
      degrading = parameters.degradation();

      dispatch<dim>(stress_state, kinematic, degrading, [&](auto s, auto k, auto d) {
        using L     = Law<decltype(s)::value, decltype(k)::value, decltype(d)::value>;
        using Slots = typename L::Slots;
        const std::array<const char *, 6> components =
          dim == 3 ? std::array<const char *, 6>{{"xx", "yy", "zz", "xy", "yz", "xz"}} :
                     std::array<const char *, 6>{{"xx", "yy", "zz", "xy", "", ""}};
        names.assign(Slots::size, "");
        names[Slots::H1]     = "H1";
        names[Slots::H2]     = "H2";
        names[Slots::eps_ps] = "eps_ps";
        for (unsigned int f = 0; f < L::F; ++f)
          {
            names[Slots::epsp + f] = std::string("epsp_") + components[f];
            if (L::is_kinematic)
              names[Slots::alpha + f] = std::string("alpha_") + components[f];
          }
        slot_epsp_zz = Slots::epsp + 2;
        slot_epsp    = Slots::epsp;
        if (L::is_kinematic)
          slot_alpha = Slots::alpha;
        if (decltype(s)::value == StressState::plane_strain) // and axisymmetric
          {
            names[Slots::sigma_zz] = "sigma_zz";
            slot_sigma_zz          = Slots::sigma_zz;
          }
        if (L::is_degrading)
          {
            names[Slots::e_h]  = "e_h";
            names[Slots::eta]  = "eta";
            names[Slots::nu_s] = "nu_s";
            slot_eta           = Slots::eta;
            slot_nu_s          = Slots::nu_s;
          }
        if (L::track_eps_zz)
          {
            names[Slots::eps_zz] = "epsilon_zz";
            slot_eps_zz          = Slots::eps_zz;
          }
      });
    }

    template <int dim>
    void
    BoucWen<dim>::rotate_state(const dealii::Tensor<2, dim> &R, const dealii::ArrayView<double> &state) const
    {
      // The in-plane (2D) or full (3D) tensor of the slots xx, yy, zz, xy(, yz, xz): turned
      // as R T R^T; zz of a 2D model is normal to the plane of the rotation.
      constexpr unsigned int n_pairs     = dim == 3 ? 6 : 4;
      constexpr unsigned int pairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
      for (const unsigned int first : {slot_epsp, slot_alpha})
        if (first != static_cast<unsigned int>(-1))
          {
            dealii::SymmetricTensor<2, dim> t;
            for (unsigned int f = 0; f < n_pairs; ++f)
              if (pairs[f][0] < dim && pairs[f][1] < dim)
                t[pairs[f][0]][pairs[f][1]] = state[first + f];
            const dealii::Tensor<2, dim> turned = R * dealii::Tensor<2, dim>(t) * dealii::transpose(R);
            for (unsigned int f = 0; f < n_pairs; ++f)
              if (pairs[f][0] < dim && pairs[f][1] < dim)
                state[first + f] = 0.5 * (turned[pairs[f][0]][pairs[f][1]] + turned[pairs[f][1]][pairs[f][0]]);
          }
    }



    template <int dim>
    void
    BoucWen<dim>::initialize_state(const dealii::ArrayView<double> &state) const
    {
      AssertDimension(state.size(), names.size());
      std::fill(state.begin(), state.end(), 0.0);
      if (degrading)
        {
          state[slot_eta]  = 1.0;
          state[slot_nu_s] = 1.0;
        }
    }

    template <int dim>
    void
    BoucWen<dim>::update(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double>                                &states,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents) const
    {
      update_batch(strain_increments, nullptr, stresses, states, tangents, {});
    }

    template <int dim>
    void
    BoucWen<dim>::update_axisymmetric(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const dealii::ArrayView<const double>                          &hoop_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double>                                &states,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
      const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents) const
    {
      // The plane-strain kernels with eps_zz' = the hoop strain rate: the same 3D law on
      // the components xx, yy, zz, xy, with sigma_zz (= sigma_tt) in the state.
      Assert(dim == 2 && stress_state == StressState::axisymmetric, dealii::ExcInternalError());
      AssertDimension(hoop_increments.size(), strain_increments.size());
      update_batch(
        strain_increments, hoop_increments.data(), stresses, states, tangents, hoop_tangents);
    }

    template <int dim>
    void
    BoucWen<dim>::update_batch(
      const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
      const double                                                   *hoop_increments,
      const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
      const dealii::ArrayView<double>                                &states,
      const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
      const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents) const
    {
      dispatch<dim>(stress_state, kinematic, degrading, [&](auto s, auto k, auto d) {
        using L = Law<decltype(s)::value, decltype(k)::value, decltype(d)::value>;
        const auto run = [&](auto integrator) {
          run_batch<dim, L, decltype(integrator)::value>(constants,
                                                        strain_increments,
                                                        hoop_increments,
                                                        stresses,
                                                        states,
                                                        tangents,
                                                        hoop_tangents);
        };
        switch (parameters.integrator)
          {
            case BoucWenIntegrator::forward_euler:
              run(std::integral_constant<BoucWenIntegrator, BoucWenIntegrator::forward_euler>());
              break;
            case BoucWenIntegrator::adaptive:
              run(std::integral_constant<BoucWenIntegrator, BoucWenIntegrator::adaptive>());
              break;
            case BoucWenIntegrator::backward_euler:
              run(std::integral_constant<BoucWenIntegrator, BoucWenIntegrator::backward_euler>());
              break;
          }
      });
    }

    template <int dim>
    void
    BoucWen<dim>::out_of_plane(const dealii::SymmetricTensor<2, dim> &strain,
                               const dealii::SymmetricTensor<2, dim> &stress,
                               const dealii::ArrayView<const double> &state,
                               double                                &eps_zz,
                               double                                &sigma_zz) const
    {
      if (dim == 2 && (stress_state == StressState::plane_strain ||
                       stress_state == StressState::axisymmetric))
        {
          eps_zz   = 0;
          sigma_zz = state[slot_sigma_zz];
        }
      else if (dim == 2 && degrading)
        {
          sigma_zz = 0;
          eps_zz   = state[slot_eps_zz];
        }
      else
        {
          // The elastic part (sigma_zz = 0) plus the plastic part of eps_zz (zero in 3D).
          Interface<dim>::out_of_plane(strain, stress, state, eps_zz, sigma_zz);
          if (dim == 2)
            eps_zz += state[slot_epsp_zz];
        }
    }

    template class BoucWen<2>;
    template class BoucWen<3>;
  } // namespace Material
} // namespace hysteron

HYSTERON_REGISTER_MATERIAL(
  hysteron::Material::BoucWen,
  "bouc-wen",
  "triaxial smooth Bouc-Wen law: von Mises yield with mixed isotropic/kinematic "
  "hardening (m), smooth switches H1 = |q/sigma_y|^n and H2 = beta + gamma sgn(n:D:deps), "
  "optional stiffness degradation and strength deterioration (eq. 2.46); plane stress, "
  "plane strain or 3D; forward Euler, adaptive Runge-Kutta or backward Euler with a "
  "consistent tangent (subsection Bouc-Wen).")

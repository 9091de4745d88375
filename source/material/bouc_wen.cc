#include <hysteron/material/bouc_wen.h>

#include <cmath>
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

      /// Conversions between the interface (SymmetricTensor, tensor components
      /// in the state) and the Mandel vectors of the kernels.
      template <int dim, typename LawType>
      struct Point
      {
        using L     = LawType;
        using G     = typename L::G;
        using Slots = typename L::Slots;
        static_assert(G::dim == dim, "stress state and dimension do not match");

        static void
        load(const dealii::SymmetricTensor<2, dim> &stress, const double *st, typename L::VecN &y)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int f = G::full[a];
              if (dim == 2 && f == 2)
                y[a] = st[Slots::sigma_zz]; // plane strain
              else
                {
                  const auto ij = tensor_index<dim>(f);
                  y[a]          = stress[ij[0]][ij[1]] * mandel_weight(f);
                }
            }
          for (unsigned int f = 0; f < L::F; ++f)
            y[L::i_epsp + f] = st[Slots::epsp + f] * mandel_weight(f);
          y[L::i_eps_ps] = st[Slots::eps_ps];
          if constexpr (L::is_degrading)
            y[L::i_e_h] = st[Slots::e_h];
          if constexpr (L::track_eps_zz)
            y[L::i_eps_zz] = st[Slots::eps_zz];
        }

        static void
        strain(const dealii::SymmetricTensor<2, dim> &e, typename L::VecK &d)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int f = G::full[a];
              if (dim == 2 && f == 2)
                d[a] = 0; // plane strain: eps_zz' = 0
              else
                {
                  const auto ij = tensor_index<dim>(f);
                  d[a]          = e[ij[0]][ij[1]] * mandel_weight(f);
                }
            }
        }

        static void
        store(const Constants                 &c,
              const typename L::VecN          &y,
              const double                     H1,
              const double                     H2,
              dealii::SymmetricTensor<2, dim> &stress,
              double                          *st)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int f = G::full[a];
              if (dim == 2 && f == 2)
                st[Slots::sigma_zz] = y[a];
              else
                {
                  const auto ij        = tensor_index<dim>(f);
                  stress[ij[0]][ij[1]] = y[a] / mandel_weight(f);
                }
            }
          st[Slots::H1]     = H1;
          st[Slots::H2]     = H2;
          st[Slots::eps_ps] = y[L::i_eps_ps];
          for (unsigned int f = 0; f < L::F; ++f)
            {
              const double e      = y[L::i_epsp + f] / mandel_weight(f);
              st[Slots::epsp + f] = e;
              if constexpr (L::is_kinematic)
                st[Slots::alpha + f] = c.kin * e; // alpha = (1 - m) C_p eps_p
            }
          if constexpr (L::is_degrading)
            {
              st[Slots::e_h]  = y[L::i_e_h];
              st[Slots::eta]  = L::eta_of(c, y[L::i_eps_ps]);
              st[Slots::nu_s] = 1.0 + c.c_nu_scaled * y[L::i_e_h];
            }
          if constexpr (L::track_eps_zz)
            st[Slots::eps_zz] = y[L::i_eps_zz];
        }

        static void
        tangent(const typename L::MatK &T, dealii::SymmetricTensor<4, dim> &out)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int fa = G::full[a];
              if (dim == 2 && fa == 2)
                continue; // plane strain: sigma_zz is not an interface component
              const auto ij = tensor_index<dim>(fa);
              for (unsigned int b = 0; b < L::K; ++b)
                {
                  const unsigned int fb = G::full[b];
                  if (dim == 2 && fb == 2)
                    continue;
                  const auto kl = tensor_index<dim>(fb);
                  out[ij[0]][ij[1]][kl[0]][kl[1]] =
                    T[a][b] / (mandel_weight(fa) * mandel_weight(fb));
                }
            }
        }
      };

      template <int dim, typename L, BoucWenIntegrator integrator>
      void
      run_batch(const Constants                                                &c,
                const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
                const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
                const dealii::ArrayView<double>                                &states,
                const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents)
      {
        using P                             = Point<dim, L>;
        constexpr unsigned int size         = L::Slots::size;
        const bool             want_tangent = tangents.size() > 0;
        AssertDimension(states.size(), strain_increments.size() * size);
        AssertDimension(stresses.size(), strain_increments.size());
        Assert(!want_tangent || tangents.size() == strain_increments.size(),
               dealii::ExcDimensionMismatch(tangents.size(), strain_increments.size()));

        typename L::VecN y;
        typename L::VecK deps;
        typename L::MatK T;
        for (std::size_t p = 0; p < strain_increments.size(); ++p)
          {
            double *st = states.data() + p * size;
            P::load(stresses[p], st, y);
            P::strain(strain_increments[p], deps);
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
                L::adaptive(c, y, deps, r);
                H1 = r.H1;
                H2 = r.H2;
                if (want_tangent)
                  L::continuum_tangent(c, r, T);
              }
            else
              L::backward_euler(c, y, deps, H1, H2, want_tangent ? &T : nullptr);
            P::store(c, y, H1, H2, stresses[p], st);
            if (want_tangent)
              P::tangent(T, tangents[p]);
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

      const Elasticity &el = this->elasticity();
      stress_state         = dim == 3 ? StressState::three_dimensional : el.stress_state;

      Constants &c   = constants;
      c.E            = el.youngs_modulus;
      c.nu           = el.poissons_ratio;
      c.two_mu       = 2.0 * el.shear_modulus();
      c.lambda_eff   = el.effective_lambda();
      c.sigma_y0     = parameters.yield_stress;
      c.eps_y        = c.sigma_y0 / c.E;
      const double a = parameters.post_yield_ratio;
      const double m = parameters.isotropic_fraction;
      c.H            = a * c.E / (1.0 - a);
      c.kin          = (1.0 - m) * 2.0 / 3.0 * c.H;
      c.kin_q        = (1.0 - m) * c.H;
      c.iso          = m * c.H;
      c.n            = parameters.smoothness;
      c.n_integer =
        (c.n == std::floor(c.n) && c.n >= 1 && c.n <= 1024) ? static_cast<unsigned int>(c.n) : 0;
      c.beta         = parameters.beta;
      c.gamma        = parameters.gamma;
      c.c_eta        = parameters.stiffness_degradation_c_eta;
      c.m_u          = parameters.stiffness_degradation_m_u;
      c.inv_m_u1     = 1.0 / (c.m_u + 1.0);
      c.c_nu_scaled  = parameters.strength_deterioration_c_nu / (c.sigma_y0 * c.eps_y);
      c.tol          = parameters.tolerance;
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
        if (decltype(s)::value == StressState::plane_strain)
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
      dispatch<dim>(stress_state, kinematic, degrading, [&](auto s, auto k, auto d) {
        using L = Law<decltype(s)::value, decltype(k)::value, decltype(d)::value>;
        switch (parameters.integrator)
          {
            case BoucWenIntegrator::forward_euler:
              run_batch<dim, L, BoucWenIntegrator::forward_euler>(constants,
                                                                  strain_increments,
                                                                  stresses,
                                                                  states,
                                                                  tangents);
              break;
            case BoucWenIntegrator::adaptive:
              run_batch<dim, L, BoucWenIntegrator::adaptive>(constants,
                                                             strain_increments,
                                                             stresses,
                                                             states,
                                                             tangents);
              break;
            case BoucWenIntegrator::backward_euler:
              run_batch<dim, L, BoucWenIntegrator::backward_euler>(constants,
                                                                   strain_increments,
                                                                   stresses,
                                                                   states,
                                                                   tangents);
              break;
          }
      });
    }

    template <int dim>
    void
    BoucWen<dim>::out_of_plane(const dealii::SymmetricTensor<2, dim> &,
                               const dealii::SymmetricTensor<2, dim> &stress,
                               const dealii::ArrayView<const double> &state,
                               double                                &eps_zz,
                               double                                &sigma_zz) const
    {
      eps_zz   = 0;
      sigma_zz = 0;
      if (dim != 2)
        return;
      if (stress_state == StressState::plane_strain)
        sigma_zz = state[slot_sigma_zz];
      else if (degrading)
        eps_zz = state[slot_eps_zz];
      else // elastic part of sigma_zz = 0 plus the plastic part
        eps_zz = -constants.nu / constants.E * (stress[0][0] + stress[1][1]) + state[slot_epsp_zz];
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

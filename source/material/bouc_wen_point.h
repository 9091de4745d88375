#ifndef hysteron_source_material_bouc_wen_point_h
#define hysteron_source_material_bouc_wen_point_h

// One point of the triaxial Bouc-Wen law at the interface: its stress, state, strain
// increment and tangent between SymmetricTensor (tensor shear components) and the Mandel
// vectors of the kernels (bouc_wen_kernels.h).

#include <deal.II/base/symmetric_tensor.h>

#include <hysteron/material/bouc_wen.h>

#include "material/bouc_wen_kernels.h"

namespace hysteron
{
  namespace Material
  {
    namespace BoucWenKernels
    {
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

        /// The Mandel strain increment; in 2D @p hoop is eps_zz' (0 in plane strain, the
        /// hoop strain increment when axisymmetric).
        static void
        strain(const dealii::SymmetricTensor<2, dim> &e, const double hoop, typename L::VecK &d)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int f = G::full[a];
              if (dim == 2 && f == 2)
                d[a] = hoop;
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

        /// The interface tangent from the Mandel one: T_ab / (w_a w_b). The zz row and
        /// column (plane strain and axisymmetric: K = F, a = 2) go to @p hoop if given.
        static void
        tangent(const typename L::MatK            &T,
                dealii::SymmetricTensor<4, dim>   &out,
                HoopTangent<dim>                  *hoop)
        {
          for (unsigned int a = 0; a < L::K; ++a)
            {
              const unsigned int fa = G::full[a];
              if (dim == 2 && fa == 2)
                continue; // sigma_zz is not an in-plane component
              const auto ij = tensor_index<dim>(fa);
              for (unsigned int b = 0; b < L::K; ++b)
                {
                  const unsigned int fb = G::full[b];
                  if (dim == 2 && fb == 2)
                    {
                      if (hoop)
                        {
                          hoop->stress_by_hoop[ij[0]][ij[1]] = T[a][b] / mandel_weight(fa);
                          hoop->hoop_by_strain[ij[0]][ij[1]] = T[b][a] / mandel_weight(fa);
                        }
                      continue;
                    }
                  const auto kl = tensor_index<dim>(fb);
                  out[ij[0]][ij[1]][kl[0]][kl[1]] =
                    T[a][b] / (mandel_weight(fa) * mandel_weight(fb));
                }
            }
          if (hoop && dim == 2 && L::K == 4)
            hoop->hoop_by_hoop = T[2][2];
        }
      };
    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#endif

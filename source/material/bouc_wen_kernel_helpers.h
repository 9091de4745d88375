#ifndef hysteron_source_material_bouc_wen_kernel_helpers_h
#define hysteron_source_material_bouc_wen_kernel_helpers_h

// The small pieces the Bouc-Wen point kernels (bouc_wen_kernels.h) are built from: the
// Mandel geometry of each stress state, a fixed-size LU solver and the powers |t|^n.

#include <hysteron/base/exceptions.h>
#include <hysteron/material/bouc_wen_constants.h>
#include <hysteron/material/elasticity.h>
#include <hysteron/material/integer_power.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace hysteron
{
  namespace Material
  {
    namespace BoucWenKernels
    {
      constexpr double sqrt2 = 1.41421356237309504880;


      template <StressState S>
      struct Geometry;

      template <>
      struct Geometry<StressState::three_dimensional>
      {
        static constexpr int          dim      = 3;
        static constexpr unsigned int F        = 6;
        static constexpr unsigned int K        = 6;
        static constexpr unsigned int n_normal = 3; ///< normal components of the K vector
        static constexpr std::array<unsigned int, K> full = {{0, 1, 2, 3, 4, 5}};
      };

      template <>
      struct Geometry<StressState::plane_strain>
      {
        static constexpr int                         dim      = 2;
        static constexpr unsigned int                F        = 4;
        static constexpr unsigned int                K        = 4;
        static constexpr unsigned int                n_normal = 3;
        static constexpr std::array<unsigned int, K> full     = {{0, 1, 2, 3}};
      };

      template <>
      struct Geometry<StressState::plane_stress>
      {
        static constexpr int                         dim      = 2;
        static constexpr unsigned int                F        = 4;
        static constexpr unsigned int                K        = 3;
        static constexpr unsigned int                n_normal = 2;
        static constexpr std::array<unsigned int, K> full     = {{0, 1, 3}};
      };

      /// Tensor indices of the full component f (2D: f = 2 is zz, f = 3 is xy).
      template <int dim>
      constexpr std::array<unsigned int, 2>
      tensor_index(const unsigned int f)
      {
        if (dim == 3)
          {
            constexpr unsigned int i[6] = {0, 1, 2, 0, 1, 0}, j[6] = {0, 1, 2, 1, 2, 2};
            return {{i[f], j[f]}};
          }
        constexpr unsigned int i[4] = {0, 1, 2, 0}, j[4] = {0, 1, 2, 1};
        return {{i[f], j[f]}};
      }

      /// Mandel weight of the full component f: 1 (normal) or sqrt(2) (shear).
      constexpr double
      mandel_weight(const unsigned int f)
      {
        return f < 3 ? 1.0 : sqrt2;
      }

      /// LU factorization with partial pivoting (LAPACK style: P A = L U, whole rows
      /// swapped) of the row-major M x M matrix A, in place; false if singular.
      template <unsigned int M>
      bool
      lu_factorize(std::array<double, M * M> &A, std::array<unsigned int, M> &pivot)
      {
        for (unsigned int k = 0; k < M; ++k)
          {
            unsigned int p = k;
            for (unsigned int r = k + 1; r < M; ++r)
              if (std::abs(A[r * M + k]) > std::abs(A[p * M + k]))
                p = r;
            pivot[k] = p;
            if (!(std::abs(A[p * M + k]) > 0) || !std::isfinite(A[p * M + k]))
              return false;
            if (p != k)
              for (unsigned int c = 0; c < M; ++c)
                std::swap(A[k * M + c], A[p * M + c]);
            const double inv = 1.0 / A[k * M + k];
            for (unsigned int r = k + 1; r < M; ++r)
              {
                const double f = (A[r * M + k] *= inv);
                for (unsigned int c = k + 1; c < M; ++c)
                  A[r * M + c] -= f * A[k * M + c];
              }
          }
        return true;
      }

      /// Solve A x = b in place with the factors of lu_factorize().
      template <unsigned int M>
      void
      lu_solve(const std::array<double, M * M>   &LU,
               const std::array<unsigned int, M> &pivot,
               double                            *b)
      {
        // The factorization swapped whole rows (L included): permute b first.
        for (unsigned int k = 0; k < M; ++k)
          std::swap(b[k], b[pivot[k]]);
        for (unsigned int k = 0; k < M; ++k)
          for (unsigned int r = k + 1; r < M; ++r)
            b[r] -= LU[r * M + k] * b[k];
        for (int k = M - 1; k >= 0; --k)
          {
            double s = b[k];
            for (unsigned int c = k + 1; c < M; ++c)
              s -= LU[k * M + c] * b[c];
            b[k] = s / LU[k * M + k];
          }
      }

      /// max(a, b) that propagates a NaN in b (std::max would drop it).
      inline double
      max_nan(const double a, const double b)
      {
        return (b > a || b != b) ? b : a;
      }

      /// x^n, by repeated squaring when n is a small integer (std::pow is several
      /// times slower, and H1 is evaluated at every stage).
      inline double
      power(const Constants &c, const double x)
      {
        return c.n_integer == 0 ? std::pow(x, c.n) : integer_power(x, c.n_integer);
      }

      /// t^m and t^(m - 1) for an integer m >= 1 (the H1 = t^(n/2) of stage_rates() and
      /// H1 / q^2 = t^(n/2 - 1) / sigma_y^2), sharing the squarings for m = 2, 4, 8, 16.
      inline double
      power_pair(const double t, const unsigned int m, double &t_m1)
      {
        switch (m)
          {
            case 1:
              t_m1 = 1;
              return t;
            case 2:
              t_m1 = t;
              return t * t;
            case 4:
              {
                const double t2 = t * t;
                t_m1            = t2 * t;
                return t2 * t2;
              }
            case 8:
              {
                const double t2 = t * t, t4 = t2 * t2;
                t_m1 = t4 * (t2 * t);
                return t4 * t4;
              }
            case 16:
              {
                const double t2 = t * t, t4 = t2 * t2, t8 = t4 * t4;
                t_m1 = t8 * (t4 * (t2 * t));
                return t8 * t8;
              }
            default:
              t_m1 = integer_power(t, m - 1);
              return t_m1 * t;
          }
      }

      inline double
      sign(const double x)
      {
        return (x > 0) ? 1.0 : ((x < 0) ? -1.0 : 0.0);
      }

      /**
       * The law for one configuration. Explicit integrators work on the vector
       * y = (sigma [K], eps_p [F], eps_ps, e_h (degradation), eps_zz (plane
       * stress with degradation)); backward Euler on its own unknowns.
       */
    } // namespace BoucWenKernels
  }   // namespace Material
} // namespace hysteron

#endif

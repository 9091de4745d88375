#ifndef hysteron_source_rbsn_spread_h
#define hysteron_source_rbsn_spread_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include "rbsn/tessellation.h"

#include <algorithm>
#include <cmath>
#include <vector>

/**
 * @file
 * Points at equal steps of the normalised arc length along a polyline: the boundary
 * points between two corners, in 2D (boundary_2d.cc) and on the sharp edges in 3D
 * (sharp_edges_3d.cc).
 */
namespace hysteron
{
  namespace RBSN
  {
    /**
     * Points along a polyline between two corners at equal steps of the normalised
     * arc length tau(s) = int_0^s ds / d (s / d_m for a constant d): the interior
     * points j = 1 .. pieces - 1 of pieces = ceil(tau_total), and the first point too
     * if @p with_start.
     */
    template <int dim>
    void
    spread(const std::vector<dealii::Point<dim>> &path,
           const Spacing<dim>                    &spacing,
           const bool                             with_start,
           std::vector<dealii::Point<dim>>       &points)
    {
      double length = 0;
      for (unsigned int k = 0; k + 1 < path.size(); ++k)
        length += path[k].distance(path[k + 1]);
      // tau tabulated at arc lengths s (midpoint rule, steps of at most d / 4).
      std::vector<double> s_table{0.0}, tau_table{0.0};
      if (spacing.is_constant())
        {
          s_table.push_back(length);
          tau_table.push_back(length / spacing.min);
        }
      else
        for (unsigned int k = 0; k + 1 < path.size(); ++k)
          {
            const double                 seg = path[k].distance(path[k + 1]);
            const dealii::Tensor<1, dim> r   = path[k + 1] - path[k];
            const double                 s0  = s_table.back();
            for (double t = 0; t < seg;)
              {
                const double step = std::min(seg - t, 0.25 * spacing(path[k] + (t / seg) * r));
                const double tau  = step / spacing(path[k] + ((t + 0.5 * step) / seg) * r);
                t                 = step < seg - t ? t + step : seg;
                s_table.push_back(s0 + t);
                tau_table.push_back(tau_table.back() + tau);
              }
          }
      const double       total  = tau_table.back();
      const unsigned int pieces = std::max(1u, static_cast<unsigned int>(std::ceil(total - 1e-9)));
      double             walked = 0;
      unsigned int       k = 0, m = 0;
      for (unsigned int j = with_start ? 0 : 1; j < pieces; ++j)
        {
          double target = j * length / pieces;
          if (!spacing.is_constant())
            {
              const double tau = j * total / pieces;
              while (m + 2 < tau_table.size() && tau_table[m + 1] < tau)
                ++m;
              const double dt = tau_table[m + 1] - tau_table[m];
              target = s_table[m] + (dt > 0 ? (tau - tau_table[m]) / dt : 0.0) * (s_table[m + 1] - s_table[m]);
            }
          while (k + 2 < path.size() && walked + path[k].distance(path[k + 1]) < target)
            walked += path[k].distance(path[k + 1]), ++k;
          const double seg = path[k].distance(path[k + 1]);
          const double f   = seg > 0 ? (target - walked) / seg : 0.0;
          points.push_back(path[k] + f * (path[k + 1] - path[k]));
        }
    }
  } // namespace RBSN
} // namespace hysteron

#endif

// The minimum distance of the nuclei, d(x): its evaluation and its sampling over the bodies.
#include <hysteron/base/exceptions.h>
#include "rbsn/tessellation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    Spacing<dim>::Spacing(const double d_m)
      : min(d_m)
      , max(d_m)
    {}



    template <int dim>
    Spacing<dim>::Spacing(std::function<double(const dealii::Point<dim> &)> function,
                          const std::string                                &expression,
                          const std::string                                &where)
      : function(std::move(function))
      , expression(expression)
      , where(where)
    {}



    template <int dim>
    double
    Spacing<dim>::operator()(const dealii::Point<dim> &p) const
    {
      if (!function)
        return min;
      const double d = function(p);
      if (!(d > 0) || !std::isfinite(d))
        {
          std::ostringstream s;
          s.precision(6);
          s << "the expression '" << expression << "' evaluates to " << d << " at x = " << p[0]
            << ", y = " << p[1];
          if (dim == 3)
            s << ", z = " << p[dim - 1];
          s << ": the minimum distance must be > 0 in the bodies";
          throw InputError(where, s.str());
        }
      return d;
    }



    template <int dim>
    void
    Spacing<dim>::sample(const std::vector<const Geometry::Region<dim> *> &bodies)
    {
      dealii::Point<dim> lo, hi;
      for (unsigned int k = 0; k < dim; ++k)
        {
          lo[k] = std::numeric_limits<double>::max();
          hi[k] = -lo[k];
        }
      for (const auto *b : bodies)
        {
          const auto box = b->bounding_box().get_boundary_points();
          for (unsigned int k = 0; k < dim; ++k)
            {
              lo[k] = std::min(lo[k], box.first[k]);
              hi[k] = std::max(hi[k], box.second[k]);
            }
        }
      double box_measure = 1;
      for (unsigned int k = 0; k < dim; ++k)
        box_measure *= hi[k] - lo[k];
      if (!(box_measure > 0 && std::isfinite(box_measure)))
        return; // unbounded or degenerate: poisson_disk_points() says so
      // Square (cubic) cells, about 2^16 (2^18) of them.
      const double h = dim == 2 ? std::sqrt(box_measure / 65536.0) : std::cbrt(box_measure / 262144.0);
      std::array<unsigned int, dim> n;
      dealii::Tensor<1, dim>        step;
      std::size_t                   total = 1;
      double                        cell  = 1;
      for (unsigned int k = 0; k < dim; ++k)
        {
          n[k]    = std::max(1, static_cast<int>(std::ceil((hi[k] - lo[k]) / h)));
          step[k] = (hi[k] - lo[k]) / n[k];
          total *= n[k];
          cell *= step[k];
        }
      std::vector<double> value(total, 0.0); // 0: outside
      sample_lo = lo;
      sample_step = step;
      sample_n    = n;
      measure     = 0;
      sample_weight.assign(total, 0.0);
      double              integral = 0, smallest = std::numeric_limits<double>::max(), largest = 0;
      const auto index = [&](const std::array<unsigned int, dim> &i) {
        std::size_t k = 0;
        for (int d = dim - 1; d >= 0; --d)
          k = k * n[d] + i[d];
        return k;
      };
      // The samples in the order x fastest (as the 2D loops over j, then i).
      for (std::size_t k = 0; k < total; ++k)
        {
          std::array<unsigned int, dim> i;
          std::size_t                   r = k;
          for (unsigned int d = 0; d < dim; ++d)
            {
              i[d] = r % n[d];
              r /= n[d];
            }
          dealii::Point<dim> x;
          for (unsigned int d = 0; d < dim; ++d)
            x[d] = lo[d] + (i[d] + 0.5) * step[d];
          if (std::none_of(bodies.begin(), bodies.end(), [&](const auto *b) { return b->contains(x); }))
            continue;
          const double d = (*this)(x);
          value[k]       = d;
          integral += cell / (dim == 2 ? d * d : d * d * d);
          smallest = std::min(smallest, d);
          largest  = std::max(largest, d);
          measure += cell;
          sample_weight[k] = density * cell / (dim == 2 ? d * d : d * d * d);
        }
      predicted_points = density * integral;
      if (function && largest > 0)
        {
          min = smallest;
          max = largest;
          // |grad d| from the differences of neighbouring samples in the bodies.
          gradient = 0;
          for (std::size_t k = 0; k < total; ++k)
            if (const double d = value[k]; d > 0)
              {
                std::array<unsigned int, dim> i;
                std::size_t                   r = k;
                for (unsigned int q = 0; q < dim; ++q)
                  {
                    i[q] = r % n[q];
                    r /= n[q];
                  }
                for (unsigned int q = 0; q < dim; ++q)
                  if (i[q] + 1 < n[q])
                    {
                      auto next = i;
                      ++next[q];
                      if (const double e = value[index(next)]; e > 0)
                        gradient = std::max(gradient, std::abs(e - d) / step[q]);
                    }
              }
        }
    }



    template <int dim>
    std::vector<double>
    Spacing<dim>::predicted_in_blocks(const dealii::Point<dim>      &origin,
                                      const double                   size,
                                      const std::array<int, dim>    &n) const
    {
      std::size_t n_blocks = 1;
      for (unsigned int d = 0; d < dim; ++d)
        n_blocks *= n[d];
      std::vector<double> result(n_blocks, 0.0);
      for (std::size_t k = 0; k < sample_weight.size(); ++k)
        if (sample_weight[k] > 0)
          {
            std::size_t r = k, block = 0, stride = 1;
            for (unsigned int d = 0; d < dim; ++d)
              {
                const double x = sample_lo[d] + (r % sample_n[d] + 0.5) * sample_step[d];
                r /= sample_n[d];
                const int i = std::clamp(static_cast<int>(std::floor((x - origin[d]) / size)), 0, n[d] - 1);
                block += stride * i;
                stride *= n[d];
              }
            result[block] += sample_weight[k];
          }
      return result;
    }



    template class Spacing<2>;
    template class Spacing<3>;
  } // namespace RBSN
} // namespace hysteron

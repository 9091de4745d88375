#include <deal.II/base/exceptions.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/rbsn/tessellation.h>

#include "rbsn/cgal.h"
#include "rbsn/sampling.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <random>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      using Point   = dealii::Point<2>;
      using Segment = std::array<Point, 2>;
      using Sampling::text;
      using Sampling::uniform;

      double
      cross(const dealii::Tensor<1, 2> &a, const dealii::Tensor<1, 2> &b)
      {
        return a[0] * b[1] - a[1] * b[0];
      }

      /**
       * The parameters s, t in (0, 1) of the proper intersection of the segments
       * a + s (b - a) and c + t (d - c), or false (parallel, or outside).
       */
      bool
      intersect(const Point &a, const Point &b, const Point &c, const Point &d, double &s, double &t)
      {
        const dealii::Tensor<1, 2> r = b - a, q = d - c;
        const double               den = cross(r, q);
        if (std::abs(den) <= 1e-14 * r.norm() * q.norm())
          return false;
        s = cross(c - a, q) / den;
        t = cross(c - a, r) / den;
        return s > 1e-12 && s < 1 - 1e-12 && t > -1e-12 && t < 1 + 1e-12;
      }

      /**
       * The boundary of the union of @p bodies as segments with the domain on
       * their left: every primitive's polygonized boundary, split where it
       * crosses another, keeping the pieces with the domain on exactly one side.
       */
      std::vector<Segment>
      oriented_boundary(const std::vector<Geometry::Region<2>> &bodies, const double boundary_h, const double scale)
      {
        std::vector<Segment> raw;
        for (const auto &b : bodies)
          for (const auto &s : b.boundary_segments(boundary_h))
            if (s[0].distance(s[1]) > 1e-12 * scale)
              raw.push_back(s);
        const auto inside = [&](const Point &p) {
          for (const auto &b : bodies)
            if (b.contains(p))
              return true;
          return false;
        };
        std::vector<Segment> result;
        const double         eps = 1e-8 * scale;
        for (unsigned int i = 0; i < raw.size(); ++i)
          {
            std::vector<double> cuts{0.0, 1.0};
            for (unsigned int j = 0; j < raw.size(); ++j)
              {
                double s, t;
                if (j != i && intersect(raw[i][0], raw[i][1], raw[j][0], raw[j][1], s, t))
                  cuts.push_back(s);
              }
            std::sort(cuts.begin(), cuts.end());
            const dealii::Tensor<1, 2> r = raw[i][1] - raw[i][0];
            const dealii::Tensor<1, 2> n({-r[1] / r.norm(), r[0] / r.norm()}); // left normal
            for (unsigned int k = 0; k + 1 < cuts.size(); ++k)
              {
                if (cuts[k + 1] - cuts[k] < 1e-12)
                  continue;
                const Point p = raw[i][0] + cuts[k] * r, q = raw[i][0] + cuts[k + 1] * r;
                const Point m = 0.5 * (p + q);
                const bool  left = inside(m + eps * n), right = inside(m - eps * n);
                if (left && !right)
                  result.push_back(Segment{{p, q}});
                else if (right && !left)
                  result.push_back(Segment{{q, p}});
              }
          }
        // A boundary shared by two primitives (both boundaries through it) appears twice.
        std::vector<Segment> unique;
        for (const auto &s : result)
          {
            bool seen = false;
            for (const auto &u : unique)
              seen = seen || (u[0].distance(s[0]) < 1e-10 * scale && u[1].distance(s[1]) < 1e-10 * scale);
            if (!seen)
              unique.push_back(s);
          }
        return unique;
      }

      /// The exact integrals of a region over oriented boundary pieces (Green's theorem).
      struct Moments
      {
        double area = 0, sx = 0, sy = 0, polar = 0; ///< int 1, x, y, x^2 + y^2

        void
        add(const Point &p, const Point &q)
        {
          const double c = p[0] * q[1] - q[0] * p[1];
          area += 0.5 * c;
          sx += c * (p[0] + q[0]) / 6;
          sy += c * (p[1] + q[1]) / 6;
          polar += c * (p[0] * p[0] + p[0] * q[0] + q[0] * q[0] + p[1] * p[1] + p[1] * q[1] + q[1] * q[1]) / 12;
        }
      };

      /// Join boundary pieces into closed loops by matching end points.
      std::vector<std::vector<Point>>
      chain(std::vector<Segment> pieces, const double tolerance)
      {
        std::vector<std::vector<Point>> loops;
        while (!pieces.empty())
          {
            std::vector<Point> loop{pieces.back()[0], pieces.back()[1]};
            pieces.pop_back();
            while (!pieces.empty() && loop.back().distance(loop.front()) > tolerance)
              {
                unsigned int best = 0;
                double       d    = std::numeric_limits<double>::max();
                for (unsigned int k = 0; k < pieces.size(); ++k)
                  if (pieces[k][0].distance(loop.back()) < d)
                    {
                      d    = pieces[k][0].distance(loop.back());
                      best = k;
                    }
                if (d > tolerance)
                  break;
                loop.push_back(pieces[best][1]);
                pieces.erase(pieces.begin() + best);
              }
            if (loop.back().distance(loop.front()) <= tolerance)
              loop.pop_back();
            if (loop.size() >= 3)
              loops.push_back(loop);
          }
        return loops;
      }
    } // namespace



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



    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const double                         d_m,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where)
    {
      require(d_m > 0 && std::isfinite(d_m), where, "the minimum distance must be > 0");
      return poisson_disk_points(domain, Spacing<2>(d_m), fixed, seed, where);
    }



    namespace
    {
      /**
       * The background grid of the Poisson-disk sampling in 2D: square cells of side
       * d_min / sqrt(2) (each holds at most one random point; larger cells if that grid
       * would exceed 4e7 cells: still exact, only slower) over the box [lo, hi] of the
       * sampling and a margin around it, the points of each cell listed from head[cell]
       * through next[]. A trial p is refused by q if |p - q| < min(d(p), d(q)). With
       * |grad d| <= L, d(p) >= d(q) - L |p - q|, so every p with |p - q| < d(q) / (1 + L)
       * is refused: the cells inside that disk of q are covered.
       */
      class Grid2
      {
      public:
        Grid2(const Point &box_lo, const Point &box_hi, const double margin, const Spacing<2> &d)
          : d(d)
          , margin(margin)
          , shrink(1 / (1 + d.gradient))
        {
          const dealii::Tensor<1, 2> m({margin, margin});
          lo              = box_lo - m;
          hi              = box_hi + m;
          const double wx = hi[0] - lo[0], wy = hi[1] - lo[1];
          cell            = std::max(d.min / std::sqrt(2.0), std::sqrt(wx * wy / 4e7));
          nx              = std::max(1, static_cast<int>(std::ceil(wx / cell)));
          ny              = std::max(1, static_cast<int>(std::ceil(wy / cell)));
          head.assign(static_cast<std::size_t>(nx) * ny, -1);
          covered.assign(head.size(), false);
        }

        int
        column(const double x) const
        {
          return std::clamp(static_cast<int>(std::floor((x - lo[0]) / cell)), 0, nx - 1);
        }

        int
        row(const double y) const
        {
          return std::clamp(static_cast<int>(std::floor((y - lo[1]) / cell)), 0, ny - 1);
        }

        bool
        in_grid(const Point &p) const
        {
          return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1];
        }

        /// Add p with d(p) = @p dp and cover the cells of its disk of radius dp / (1 + L).
        void
        add(const Point &p, const double dp)
        {
          const int         i = column(p[0]), j = row(p[1]);
          const std::size_t c = static_cast<std::size_t>(j) * nx + i;
          next.push_back(head[c]);
          head[c] = static_cast<int>(points.size());
          points.push_back(p);
          radius.push_back(dp);
          const double R     = dp * shrink;
          const int    reach = static_cast<int>(std::ceil(R / cell));
          for (int b = std::max(0, j - reach); b <= std::min(ny - 1, j + reach); ++b)
            for (int a = std::max(0, i - reach); a <= std::min(nx - 1, i + reach); ++a)
              {
                // The corner of the cell farthest from p.
                const double x0 = lo[0] + a * cell, y0 = lo[1] + b * cell;
                const double fx = std::max(std::abs(x0 - p[0]), std::abs(x0 + cell - p[0]));
                const double fy = std::max(std::abs(y0 - p[1]), std::abs(y0 + cell - p[1]));
                if (fx * fx + fy * fy < R * R)
                  covered[static_cast<std::size_t>(b) * nx + a] = true;
              }
        }

        /**
         * Whether p (in the domain, @p inside) keeps its distance from every point, and
         * d(p) in @p dp. Fixed points beyond the grid (far) are checked one by one where
         * d(p) exceeds the margin, or with @p refuse_wide such a trial is refused (the
         * points beyond the margin are not known).
         */
        template <typename Inside>
        bool
        free(const Point &p, double &dp, const Inside &inside, const bool refuse_wide) const
        {
          if (!in_grid(p) || covered[static_cast<std::size_t>(row(p[1])) * nx + column(p[0])] || !inside(p))
            return false;
          dp              = d(p);
          const int i     = column(p[0]), j = row(p[1]);
          const int reach = static_cast<int>(std::ceil(dp / cell));
          for (int b = std::max(0, j - reach); b <= std::min(ny - 1, j + reach); ++b)
            for (int a = std::max(0, i - reach); a <= std::min(nx - 1, i + reach); ++a)
              for (int k = head[static_cast<std::size_t>(b) * nx + a]; k >= 0; k = next[k])
                if (points[k].distance(p) < std::min(dp, radius[k]))
                  return false;
          if (dp > margin)
            {
              if (refuse_wide)
                return false;
              for (const auto &q : far)
                if (q.distance(p) < dp) // d(q) is not needed: the stricter test
                  return false;
            }
          return true;
        }

        /// Whether every trial in the square [x0, x0 + size] x [y0, y0 + size] is refused
        /// because one point's disk of radius d(q) / (1 + L) holds its four corners.
        bool
        square_covered(const double x0, const double y0, const double size) const
        {
          const int square_reach = static_cast<int>(std::ceil(d.max * shrink / cell));
          const int i = column(x0 + 0.5 * size), j = row(y0 + 0.5 * size);
          for (int b = std::max(0, j - square_reach - 1); b <= std::min(ny - 1, j + square_reach + 1); ++b)
            for (int a = std::max(0, i - square_reach - 1); a <= std::min(nx - 1, i + square_reach + 1); ++a)
              for (int k = head[static_cast<std::size_t>(b) * nx + a]; k >= 0; k = next[k])
                {
                  const double fx = std::max(std::abs(x0 - points[k][0]), std::abs(x0 + size - points[k][0]));
                  const double fy = std::max(std::abs(y0 - points[k][1]), std::abs(y0 + size - points[k][1]));
                  const double R  = radius[k] * shrink;
                  if (fx * fx + fy * fy < R * R)
                    return true;
                }
          return false;
        }

        const Spacing<2>   &d;
        const double        margin, shrink;
        Point               lo, hi;
        double              cell = 0;
        int                 nx = 1, ny = 1;
        std::vector<int>    head, next;
        std::vector<bool>   covered; ///< every trial in the cell is refused (see add())
        std::vector<Point>  points;
        std::vector<double> radius; ///< d at each point
        std::vector<Point>  far;    ///< fixed points beyond the grid
      };



      /**
       * The random points of the 2D Poisson-disk sampling (poisson_disk_points()), in
       * the domain's box, or with @p clip in the part of it in one block of a tiled
       * network (the trials outside the block refused, the darts thrown into it only).
       */
      std::vector<Point>
      sample_2d(const Geometry::Region<2> &domain,
                const Spacing<2>          &d,
                const std::vector<Point>  &fixed,
                const std::uint64_t        seed,
                const std::string         &where,
                const Sampling::Clip<2>   *clip)
      {
        require(d.min > 0 && d.max >= d.min, where, "the minimum distance must be > 0");
        const auto domain_box = domain.bounding_box().get_boundary_points();
        require(std::isfinite(domain_box.second[0] - domain_box.first[0]) &&
                  std::isfinite(domain_box.second[1] - domain_box.first[1]),
                where,
                "the domain is unbounded");
        // The box of the sampling: the domain's, or its part in the block. The grid
        // covers it and a margin of 2 d_max, at most the box's size (the points there
        // may exclude trials in the domain); a block's margin is the tiling's.
        Point box_lo = domain_box.first, box_hi = domain_box.second;
        if (clip)
          {
            const auto block = clip->box();
            for (unsigned int k = 0; k < 2; ++k)
              {
                box_lo[k] = std::max(box_lo[k], block.first[k]);
                box_hi[k] = std::min(box_hi[k], block.second[k]);
                if (box_lo[k] > box_hi[k])
                  return {};
              }
          }
        const double margin =
          clip ? clip->margin : std::min(2 * d.max, std::max(box_hi[0] - box_lo[0], box_hi[1] - box_lo[1]));
        Grid2 grid(box_lo, box_hi, margin, d);
        // Whether the square [x0, x0 + size]^2 meets the box (where darts go).
        const auto meets = [&](const double x0, const double y0, const double size) {
          return std::max(x0, box_lo[0]) <= std::min(x0 + size, box_hi[0]) &&
                 std::max(y0, box_lo[1]) <= std::min(y0 + size, box_hi[1]);
        };
        const auto inside = [&](const Point &p) { return (!clip || clip->contains(p)) && domain.contains(p); };

        // The fixed points: in the grid (and the front) if within the margin.
        std::vector<unsigned int> active;
        std::vector<Point>        result;
        for (const auto &p : fixed)
          if (grid.in_grid(p))
            {
              active.push_back(grid.points.size());
              grid.add(p, d(p));
            }
          else
            grid.far.push_back(p);

        // Bridson: grow from active points by trial points in the annulus [d, 2 d]
        // around them until the front dies out.
        std::mt19937_64 rng(seed);
        const auto      try_add = [&](const Point &p) {
          double dp;
          if (!grid.free(p, dp, inside, clip != nullptr))
            return false;
          active.push_back(grid.points.size());
          grid.add(p, dp);
          result.push_back(p);
          return true;
        };
        const auto annulus = [&](const Point &c, const double dc) {
          const double r = dc * (1 + uniform(rng)), phi = 2 * M_PI * uniform(rng);
          return Point(c[0] + r * std::cos(phi), c[1] + r * std::sin(phi));
        };
        const auto grow = [&]() { Sampling::grow_front(active, grid.points, grid.radius, rng, annulus, try_add); };
        grow();
        // Up to @p trials random points in a square (its part in the box); the first
        // one that is free is added and the front grows from it.
        const auto darts = [&](const double x0, const double y0, const double size, const unsigned int trials) {
          const double ax = std::max(x0, box_lo[0]), bx = std::min(x0 + size, box_hi[0]);
          const double ay = std::max(y0, box_lo[1]), by = std::min(y0 + size, box_hi[1]);
          if (ax > bx || ay > by)
            return;
          const auto draw = [&]() {
            const double u = uniform(rng), v = uniform(rng);
            return Point(ax + u * (bx - ax), ay + v * (by - ay));
          };
          Sampling::throw_darts(trials, draw, try_add, grow);
        };
        // The gaps the front left (other components, the first seed, corners): 30
        // trials in every grid cell that no exclusion disk covers, in a fixed order,
        // and the front again from each point found. Points only cover more, so one
        // pass visits each cell once.
        std::vector<std::array<double, 3>> squares; // x0, y0, size: the gaps left
        for (int j = 0; j < grid.ny; ++j)
          for (int i = 0; i < grid.nx; ++i)
            {
              const double x0 = grid.lo[0] + i * grid.cell, y0 = grid.lo[1] + j * grid.cell;
              if (grid.covered[static_cast<std::size_t>(j) * grid.nx + i] || (clip && !meets(x0, y0, grid.cell)))
                continue;
              darts(x0, y0, grid.cell, 30);
              if (!grid.covered[static_cast<std::size_t>(j) * grid.nx + i])
                squares.push_back({{x0, y0, grid.cell}});
            }
        // The remaining gaps are slivers between exclusion disks: quarter every square
        // that is not covered (nor outside the domain at its corners and centre) and
        // throw 10 darts into each quarter, for 2 levels, down to cells / 4 (as in
        // the maximal Poisson-disk sampling of Ebeida et al., 2012). Two levels give
        // the density of the former sweeps of 20 darts per cell (0.68 A / d^2 and the
        // boundary rows; doc/rbsn.md); more levels approach the jamming limit, 3 %
        // denser.
        for (unsigned int level = 0; level < 2 && !squares.empty(); ++level)
          {
            std::vector<std::array<double, 3>> quarters;
            for (const auto &q : squares)
              for (unsigned int c = 0; c < 4; ++c)
                {
                  const double h = 0.5 * q[2], x0 = q[0] + (c % 2) * h, y0 = q[1] + (c / 2) * h;
                  const bool   in = domain.contains(Point(x0 + 0.5 * h, y0 + 0.5 * h)) ||
                                  domain.contains(Point(x0, y0)) || domain.contains(Point(x0 + h, y0)) ||
                                  domain.contains(Point(x0, y0 + h)) || domain.contains(Point(x0 + h, y0 + h));
                  if (in && (!clip || meets(x0, y0, h)) && !grid.square_covered(x0, y0, h))
                    quarters.push_back({{x0, y0, h}});
                }
            squares.clear();
            for (const auto &q : quarters)
              if (!grid.square_covered(q[0], q[1], q[2]))
                {
                  darts(q[0], q[1], q[2], 10);
                  if (!grid.square_covered(q[0], q[1], q[2]))
                    squares.push_back(q);
                }
          }
        return result;
      }
    } // namespace



    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const Spacing<2>                    &d,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where)
    {
      std::vector<Point> result = sample_2d(domain, d, fixed, seed, where, nullptr);
      result.insert(result.begin(), fixed.begin(), fixed.end());
      return result;
    }



    namespace Sampling
    {
      struct BodySampler2::Data
      {
        const Geometry::Region<2> &body;
        const Spacing<2>          &d;
        std::string                where;
      };



      BodySampler2::BodySampler2(const Geometry::Region<2> &body,
                                 const Spacing<2>          &d,
                                 const std::vector<Point> & /*fixed: the 2D sampler has no forbidden disks*/,
                                 const double /*boundary_h: the region is sampled as it is*/,
                                 const std::string &where)
        : data(new Data{body, d, where})
      {}



      BodySampler2::~BodySampler2() = default;



      std::vector<Point>
      BodySampler2::operator()(const std::vector<Point> &known, const std::uint64_t seed, const Clip<2> &clip) const
      {
        return sample_2d(data->body, data->d, known, seed, data->where, &clip);
      }
    } // namespace Sampling



    std::vector<dealii::Point<2>>
    boundary_points(const Geometry::Region<2> &domain, const Spacing<2> &spacing, const double boundary_h)
    {
      const auto   box   = domain.bounding_box().get_boundary_points();
      const double scale = box.first.distance(box.second);
      // The boundary of the polygonized domain (the one the cells are clipped to): a
      // chord of a curved boundary lies inside the exact curve, on neither side of it.
      const auto loops = chain(oriented_boundary({domain.polygonized(boundary_h)}, boundary_h, scale), 1e-9 * scale);
      std::vector<Point> points;
      for (const auto &loop : loops)
        {
          // Corners (a turn of more than 20 degrees) are kept; between corners the
          // points are spread evenly in tau(s) = int_0^s ds / d, the arc length in
          // units of the local d (s / d_m for a constant d).
          const unsigned int        n = loop.size();
          std::vector<unsigned int> corners;
          for (unsigned int k = 0; k < n; ++k)
            {
              const dealii::Tensor<1, 2> u = loop[k] - loop[(k + n - 1) % n], w = loop[(k + 1) % n] - loop[k];
              const double angle = std::atan2(std::abs(cross(u, w)), u * w);
              if (angle > 20.0 * M_PI / 180.0)
                corners.push_back(k);
            }
          if (corners.empty())
            corners.push_back(0);
          for (unsigned int c = 0; c < corners.size(); ++c)
            {
              const unsigned int first = corners[c], last = corners[(c + 1) % corners.size()];
              std::vector<Point> path{loop[first]};
              for (unsigned int k = (first + 1) % n; k != last; k = (k + 1) % n)
                path.push_back(loop[k]);
              path.push_back(loop[last]);
              if (corners.size() == 1)
                path.back() = loop[first]; // a closed curve without corners
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
                    const double               seg = path[k].distance(path[k + 1]);
                    const dealii::Tensor<1, 2> r   = path[k + 1] - path[k];
                    const double               s0  = s_table.back();
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
              // Points at tau = j total / pieces, j = 0 .. pieces - 1 (the next run adds its corner),
              // so that neighbours are at most the local d apart.
              double       walked = 0;
              unsigned int k      = 0, m = 0;
              for (unsigned int j = 0; j < pieces; ++j)
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
                  while (k + 1 < path.size() - 1 && walked + path[k].distance(path[k + 1]) < target)
                    walked += path[k].distance(path[k + 1]), ++k;
                  const double seg = path[k].distance(path[k + 1]);
                  const double f   = seg > 0 ? (target - walked) / seg : 0.0;
                  points.push_back(path[k] + f * (path[k + 1] - path[k]));
                }
            }
        }
      return points;
    }



    Tessellation<2>
    voronoi(const std::vector<dealii::Point<2>>            &nuclei,
            const std::vector<const Geometry::Region<2> *> &bodies,
            const double                                    boundary_h,
            const std::string                              &where,
            const std::vector<bool>                        &wanted)
    {
      using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
      using Vb     = CGAL::Triangulation_vertex_base_with_info_2<unsigned int, Kernel>;
      using Tds    = CGAL::Triangulation_data_structure_2<Vb>;
      using DT     = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

      require(nuclei.size() >= 2, where, "a network needs at least two cells");
      std::vector<Geometry::Region<2>> domain;
      dealii::Point<2>                 lo(std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
      dealii::Point<2>                 hi = -lo;
      for (const auto *b : bodies)
        {
          domain.push_back(b->polygonized(boundary_h));
          const auto box = b->bounding_box().get_boundary_points();
          for (unsigned int d = 0; d < 2; ++d)
            {
              lo[d] = std::min(lo[d], box.first[d]);
              hi[d] = std::max(hi[d], box.second[d]);
            }
        }
      const double scale = lo.distance(hi);
      const auto   in_domain = [&](const Point &p, const double tolerance) {
        for (const auto &b : domain)
          if (b.contains(p, tolerance))
            return true;
        return false;
      };
      for (const auto &p : nuclei)
        require(in_domain(p, 1e-9 * scale), where, "the point " + text(p) + " lies outside the bodies");
      const std::vector<Segment> boundary = oriented_boundary(domain, boundary_h, scale);
      // The boundary segments in buckets of about two cells' size over the box, so
      // that a cell meets only the segments near it.
      const double bucket = std::max(2 * std::sqrt((hi[0] - lo[0]) * (hi[1] - lo[1]) / nuclei.size()), 1e-3 * scale);
      const int    bx     = std::max(1, static_cast<int>(std::ceil((hi[0] - lo[0]) / bucket))),
                by     = std::max(1, static_cast<int>(std::ceil((hi[1] - lo[1]) / bucket)));
      const auto bucket_range = [&](const Point &a, const Point &b) {
        const auto at = [&](const double x, const double origin, const int n) {
          return std::clamp(static_cast<int>(std::floor((x - origin) / bucket)), 0, n - 1);
        };
        return std::array<int, 4>{{at(a[0], lo[0], bx), at(b[0], lo[0], bx), at(a[1], lo[1], by), at(b[1], lo[1], by)}};
      };
      std::vector<std::vector<unsigned int>> buckets(static_cast<std::size_t>(bx) * by);
      for (unsigned int k = 0; k < boundary.size(); ++k)
        {
          const Point a(std::min(boundary[k][0][0], boundary[k][1][0]), std::min(boundary[k][0][1], boundary[k][1][1]));
          const Point b(std::max(boundary[k][0][0], boundary[k][1][0]), std::max(boundary[k][0][1], boundary[k][1][1]));
          const auto  r = bucket_range(a, b);
          for (int y = r[2]; y <= r[3]; ++y)
            for (int x = r[0]; x <= r[1]; ++x)
              buckets[static_cast<std::size_t>(y) * bx + x].push_back(k);
        }
      std::vector<unsigned int> seen(boundary.size(), 0);

      // The Delaunay triangulation gives every cell's Voronoi neighbours.
      DT dt;
      {
        std::vector<std::pair<Kernel::Point_2, unsigned int>> input;
        for (unsigned int i = 0; i < nuclei.size(); ++i)
          input.emplace_back(Kernel::Point_2(nuclei[i][0], nuclei[i][1]), i);
        dt.insert(input.begin(), input.end());
      }
      require(dt.number_of_vertices() == nuclei.size(), where, "two points coincide");
      std::vector<std::vector<unsigned int>> neighbours(nuclei.size());
      if (dt.dimension() < 2)
        {
          // Collinear nuclei (e.g. a single element of two cells): the Voronoi
          // neighbours are the next points along the line.
          std::vector<unsigned int> order(nuclei.size());
          for (unsigned int i = 0; i < order.size(); ++i)
            order[i] = i;
          const dealii::Tensor<1, 2> direction = nuclei[1] - nuclei[0];
          std::sort(order.begin(), order.end(), [&](const unsigned int a, const unsigned int b) {
            return nuclei[a] * direction < nuclei[b] * direction;
          });
          for (unsigned int k = 0; k + 1 < order.size(); ++k)
            {
              neighbours[order[k]].push_back(order[k + 1]);
              neighbours[order[k + 1]].push_back(order[k]);
            }
        }
      else
      for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v)
        {
          auto c = dt.incident_vertices(v), done = c;
          if (c != nullptr)
            do
              if (!dt.is_infinite(c))
                neighbours[v->info()].push_back(c->info());
            while (++c != done);
          std::sort(neighbours[v->info()].begin(), neighbours[v->info()].end());
        }

      Tessellation<2> result;
      result.cells.resize(nuclei.size());
      std::map<std::pair<unsigned int, unsigned int>, std::vector<Segment>> facet_pieces;
      const double eps = 1e-9 * scale;
      for (unsigned int i = 0; i < nuclei.size(); ++i)
        {
          if (!wanted.empty() && !wanted[i])
            continue;
          // The convex Voronoi cell: the box around the domain clipped by the
          // bisector of every neighbour (each edge tagged with its neighbour).
          const double       margin = 0.5 * scale;
          std::vector<Point> poly{Point(lo[0] - margin, lo[1] - margin), Point(hi[0] + margin, lo[1] - margin),
                                  Point(hi[0] + margin, hi[1] + margin), Point(lo[0] - margin, hi[1] + margin)};
          std::vector<int>   tag(4, -1); // tag[k]: the edge poly[k] -> poly[k + 1]
          for (const unsigned int j : neighbours[i])
            {
              const dealii::Tensor<1, 2> n = nuclei[j] - nuclei[i];
              const Point                m = 0.5 * (nuclei[i] + nuclei[j]);
              const auto                 f = [&](const Point &p) { return (p - m) * n; }; // <= 0 inside
              std::vector<Point>         out;
              std::vector<int>           out_tag;
              for (unsigned int k = 0; k < poly.size(); ++k)
                {
                  const Point &p = poly[k], &q = poly[(k + 1) % poly.size()];
                  const double fp = f(p), fq = f(q);
                  if (fp <= 0)
                    {
                      out.push_back(p);
                      out_tag.push_back(tag[k]);
                    }
                  if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0))
                    {
                      out.push_back(p + fp / (fp - fq) * (q - p));
                      out_tag.push_back(fp < 0 ? static_cast<int>(j) : tag[k]);
                    }
                  else if (fp == 0 && fq > 0)
                    out_tag.back() = j; // p on the bisector: the edge from p runs along it
                }
              poly.swap(out);
              tag.swap(out_tag);
            }
          // Drop repeated vertices (a bisector through a vertex, as for cocircular
          // nuclei): a zero-length edge has no direction, and the inside tests below
          // need one for every edge. The edge that follows keeps its tag.
          {
            std::vector<Point> kept;
            std::vector<int>   kept_tag;
            for (unsigned int k = 0; k < poly.size(); ++k)
              if (poly[k].distance(poly[(k + 1) % poly.size()]) >= 1e-14 * scale)
                {
                  kept.push_back(poly[k]);
                  kept_tag.push_back(tag[k]);
                }
            poly.swap(kept);
            tag.swap(kept_tag);
          }

          // The boundary segments whose buckets meet the cell's box (in their
          // order). A cell that meets none lies in the domain: its nucleus does.
          std::vector<Segment> near;
          {
            Point a = poly[0], b = poly[0];
            for (const auto &p : poly)
              for (unsigned int d = 0; d < 2; ++d)
                {
                  a[d] = std::min(a[d], p[d] - 2 * eps);
                  b[d] = std::max(b[d], p[d] + 2 * eps);
                }
            const auto                r = bucket_range(a, b);
            std::vector<unsigned int> found;
            for (int y = r[2]; y <= r[3]; ++y)
              for (int x = r[0]; x <= r[1]; ++x)
                for (const unsigned int k : buckets[static_cast<std::size_t>(y) * bx + x])
                  if (seen[k] != i + 1)
                    {
                      seen[k] = i + 1;
                      found.push_back(k);
                    }
            std::sort(found.begin(), found.end());
            for (const unsigned int k : found)
              near.push_back(boundary[k]);
          }

          // The boundary of cell and domain: the cell's edges inside the domain,
          // and the domain's boundary inside the cell.
          std::vector<Segment> pieces;
          Moments              moments;
          const unsigned int   m = poly.size();
          for (unsigned int k = 0; k < m; ++k)
            {
              const Point &p = poly[k], &q = poly[(k + 1) % m];
              std::vector<double> cuts{0.0, 1.0};
              for (const auto &s : near)
                {
                  double a, b;
                  if (intersect(p, q, s[0], s[1], a, b))
                    cuts.push_back(a);
                }
              std::sort(cuts.begin(), cuts.end());
              const dealii::Tensor<1, 2> r = q - p;
              const dealii::Tensor<1, 2> left({-r[1] / r.norm(), r[0] / r.norm()});
              for (unsigned int c = 0; c + 1 < cuts.size(); ++c)
                {
                  if (cuts[c + 1] - cuts[c] < 1e-12)
                    continue;
                  const Point a = p + cuts[c] * r, b = p + cuts[c + 1] * r;
                  if (!near.empty() && !in_domain(0.5 * (a + b) + eps * left, 0.0))
                    continue;
                  pieces.push_back(Segment{{a, b}});
                  moments.add(a, b);
                  if (tag[k] >= 0 && static_cast<unsigned int>(tag[k]) > i)
                    facet_pieces[{i, static_cast<unsigned int>(tag[k])}].push_back(Segment{{a, b}});
                }
            }
          for (const auto &s : near)
            {
              // Cyrus-Beck: the part of s inside the convex cell.
              double t0 = 0, t1 = 1;
              const dealii::Tensor<1, 2> r = s[1] - s[0];
              for (unsigned int k = 0; k < m && t0 < t1; ++k)
                {
                  const Point               &p = poly[k], &q = poly[(k + 1) % m];
                  const dealii::Tensor<1, 2> e = q - p;
                  // inside: cross(e, x - p) >= 0 (counter-clockwise cell)
                  const double g0 = cross(e, s[0] - p), dg = cross(e, r);
                  if (std::abs(dg) < 1e-300)
                    {
                      if (g0 < 0)
                        t1 = -1;
                      continue;
                    }
                  const double t = -g0 / dg;
                  if (dg > 0)
                    t0 = std::max(t0, t);
                  else
                    t1 = std::min(t1, t);
                }
              if (t1 - t0 < 1e-12)
                continue;
              const Point a = s[0] + t0 * r, b = s[0] + t1 * r, mid = 0.5 * (a + b);
              // Strictly inside the cell (a piece on the cell's edge came from the edge).
              bool strict = true;
              for (unsigned int k = 0; k < m && strict; ++k)
                {
                  const dealii::Tensor<1, 2> e = poly[(k + 1) % m] - poly[k];
                  strict = cross(e, mid - poly[k]) > eps * e.norm();
                }
              if (!strict)
                continue;
              pieces.push_back(Segment{{a, b}});
              moments.add(a, b);
              result.cells[i].boundary.push_back(Segment{{a, b}});
            }

          Cell<2> &cell = result.cells[i];
          cell.nucleus = nuclei[i];
          for (const auto &piece : pieces)
            for (const auto &p : piece)
              cell.reach = std::max(cell.reach, p.distance(nuclei[i]));
          cell.area    = moments.area;
          require(cell.area > 0, where, "the cell of the point " + text(nuclei[i]) + " has no area in the bodies");
          cell.centroid     = Point(moments.sx / moments.area, moments.sy / moments.area);
          cell.polar_moment = moments.polar - moments.area * cell.centroid.square();
          cell.outline      = chain(pieces, 1e-8 * scale);
        }

      // Facets: the Voronoi edges in the domain (pieces across a hole joined).
      for (const auto &[cells, pieces] : facet_pieces)
        {
          Facet<2> f;
          f.a = cells.first;
          f.b = cells.second;
          dealii::Tensor<1, 2> weighted;
          double               longest = 0;
          for (const auto &s : pieces)
            {
              const double l = s[0].distance(s[1]);
              f.length += l;
              weighted += l * (0.5 * (s[0] + s[1]));
              if (l > longest)
                {
                  longest = l;
                  f.p3    = s[0];
                  f.p4    = s[1];
                }
            }
          if (f.length < 1e-12 * scale)
            continue;
          f.midpoint = Point(weighted[0] / f.length, weighted[1] / f.length);
          const dealii::Tensor<1, 2> d = nuclei[f.b] - nuclei[f.a];
          f.distance                   = d.norm();
          f.normal                     = d / f.distance;
          f.h_a                        = (f.midpoint - nuclei[f.a]) * f.normal;
          f.h_b                        = (nuclei[f.b] - f.midpoint) * f.normal;
          result.facets.push_back(f);
        }
      return result;
    }



    StageReport::StageReport(const dealii::ConditionalOStream &console, const bool enabled)
      : console(console)
      , on(enabled)
    {}



    void
    StageReport::operator()(const std::string &what)
    {
      if (on)
        {
          std::ostringstream line;
          line << "rbsn: " << what << " in " << std::fixed << std::setprecision(1) << clock.wall_time() << " s";
          console << line.str() << std::endl;
        }
      clock.restart();
    }



    std::string
    StageReport::count(const std::size_t n)
    {
      std::string digits = std::to_string(n), grouped;
      for (std::size_t k = 0; k < digits.size(); ++k)
        {
          if (k > 0 && (digits.size() - k) % 3 == 0)
            grouped += ',';
          grouped += digits[k];
        }
      return grouped;
    }
  } // namespace RBSN
} // namespace hysteron

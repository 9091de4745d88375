#include <deal.II/base/exceptions.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/rbsn/tessellation.h>

// CGAL's headers are not warning-clean under -Wall -Wextra.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
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

      double
      cross(const dealii::Tensor<1, 2> &a, const dealii::Tensor<1, 2> &b)
      {
        return a[0] * b[1] - a[1] * b[0];
      }

      /// A uniform double in [0, 1) from the top 53 bits (the same on every platform).
      double
      uniform(std::mt19937_64 &rng)
      {
        return (rng() >> 11) * (1.0 / 9007199254740992.0);
      }

      std::string
      text(const Point &p)
      {
        std::ostringstream s;
        s.precision(10);
        s << "(" << p[0] << ", " << p[1] << ")";
        return s.str();
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



    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const double                         d_m,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where)
    {
      require(d_m > 0 && std::isfinite(d_m), where, "the minimum distance must be > 0");
      const auto   box = domain.bounding_box();
      const Point  lo  = box.get_boundary_points().first, hi = box.get_boundary_points().second;
      const double wx = hi[0] - lo[0], wy = hi[1] - lo[1];
      require(std::isfinite(wx) && std::isfinite(wy), where, "the domain is unbounded");
      require(0.7 * wx * wy / (d_m * d_m) <= 5e6,
              where,
              "about " + std::to_string(static_cast<long>(0.7 * wx * wy / (d_m * d_m))) +
                " points at this minimum distance (at most 5e6)");

      // Background grid of cells d_m / sqrt(2): at most one random point per cell.
      const double cell = d_m / std::sqrt(2.0);
      const int    nx = std::max(1, static_cast<int>(std::ceil(wx / cell))),
                ny = std::max(1, static_cast<int>(std::ceil(wy / cell)));
      std::vector<std::vector<unsigned int>> grid(static_cast<std::size_t>(nx) * ny);
      const auto                             index = [&](const Point &p) {
        const int i = std::clamp(static_cast<int>((p[0] - lo[0]) / cell), 0, nx - 1);
        const int j = std::clamp(static_cast<int>((p[1] - lo[1]) / cell), 0, ny - 1);
        return std::make_pair(i, j);
      };
      std::vector<Point> points;
      const auto         add = [&](const Point &p) {
        const auto [i, j] = index(p);
        grid[static_cast<std::size_t>(j) * nx + i].push_back(points.size());
        points.push_back(p);
      };
      const auto free = [&](const Point &p) {
        if (!domain.contains(p))
          return false;
        const auto [i, j] = index(p);
        for (int b = std::max(0, j - 2); b <= std::min(ny - 1, j + 2); ++b)
          for (int a = std::max(0, i - 2); a <= std::min(nx - 1, i + 2); ++a)
            for (const unsigned int k : grid[static_cast<std::size_t>(b) * nx + a])
              if (points[k].distance(p) < d_m)
                return false;
        return true;
      };
      for (const auto &p : fixed)
        add(p);

      // Bridson: grow from active points by trial points in the annulus [d_m, 2 d_m];
      // when the front dies out, look for a free spot anywhere (other components,
      // the first seed), and stop when a sweep of random trials finds none.
      std::mt19937_64           rng(seed);
      std::vector<unsigned int> active;
      for (unsigned int k = 0; k < points.size(); ++k)
        active.push_back(k);
      const unsigned int sweep = std::max<unsigned int>(1000, 20 * nx * ny);
      while (true)
        {
          while (!active.empty())
            {
              const unsigned int pick = static_cast<unsigned int>(uniform(rng) * active.size());
              const Point        c    = points[active[pick]];
              bool               grew = false;
              for (unsigned int attempt = 0; attempt < 30; ++attempt)
                {
                  const double r = d_m * (1 + uniform(rng)), phi = 2 * M_PI * uniform(rng);
                  const Point  p(c[0] + r * std::cos(phi), c[1] + r * std::sin(phi));
                  if (free(p))
                    {
                      active.push_back(points.size());
                      add(p);
                      grew = true;
                      break;
                    }
                }
              if (!grew)
                {
                  active[pick] = active.back();
                  active.pop_back();
                }
            }
          bool found = false;
          for (unsigned int attempt = 0; attempt < sweep && !found; ++attempt)
            {
              const Point p(lo[0] + wx * uniform(rng), lo[1] + wy * uniform(rng));
              if (free(p))
                {
                  active.push_back(points.size());
                  add(p);
                  found = true;
                }
            }
          if (!found)
            break;
        }
      return points;
    }



    std::vector<dealii::Point<2>>
    boundary_points(const Geometry::Region<2> &domain, const double spacing, const double boundary_h)
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
          // points are spread evenly by arc length.
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
              const unsigned int pieces = std::max(1u, static_cast<unsigned int>(std::ceil(length / spacing - 1e-9)));
              // Points at arc lengths j * length / pieces, j = 0 .. pieces - 1 (the next run adds its corner).
              double       walked = 0;
              unsigned int k      = 0;
              for (unsigned int j = 0; j < pieces; ++j)
                {
                  const double target = j * length / pieces;
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



    Tessellation
    voronoi(const std::vector<dealii::Point<2>>           &nuclei,
            const std::vector<const Geometry::Region<2> *> &bodies,
            const double                                    boundary_h,
            const std::string                              &where)
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

      Tessellation result;
      result.cells.resize(nuclei.size());
      std::map<std::pair<unsigned int, unsigned int>, std::vector<Segment>> facet_pieces;
      const double eps = 1e-9 * scale;
      for (unsigned int i = 0; i < nuclei.size(); ++i)
        {
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

          // The boundary of cell and domain: the cell's edges inside the domain,
          // and the domain's boundary inside the cell.
          std::vector<Segment> pieces;
          Moments              moments;
          const unsigned int   m = poly.size();
          for (unsigned int k = 0; k < m; ++k)
            {
              const Point &p = poly[k], &q = poly[(k + 1) % m];
              std::vector<double> cuts{0.0, 1.0};
              for (const auto &s : boundary)
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
                  if (!in_domain(0.5 * (a + b) + eps * left, 0.0))
                    continue;
                  pieces.push_back(Segment{{a, b}});
                  moments.add(a, b);
                  if (tag[k] >= 0 && static_cast<unsigned int>(tag[k]) > i)
                    facet_pieces[{i, static_cast<unsigned int>(tag[k])}].push_back(Segment{{a, b}});
                }
            }
          for (const auto &s : boundary)
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

          Cell &cell = result.cells[i];
          cell.nucleus = nuclei[i];
          cell.area    = moments.area;
          require(cell.area > 0, where, "the cell of the point " + text(nuclei[i]) + " has no area in the bodies");
          cell.centroid     = Point(moments.sx / moments.area, moments.sy / moments.area);
          cell.polar_moment = moments.polar - moments.area * cell.centroid.square();
          cell.outline      = chain(pieces, 1e-8 * scale);
        }

      // Facets: the Voronoi edges in the domain (pieces across a hole joined).
      for (const auto &[cells, pieces] : facet_pieces)
        {
          Facet  f;
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
  } // namespace RBSN
} // namespace hysteron

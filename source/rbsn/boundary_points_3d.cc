// The 3D boundary points: those of the sharp edges, then Poisson-disk points on the boundary's planar faces.
#include <hysteron/base/exceptions.h>
#include "rbsn/tessellation.h"

#include "rbsn/poisson_grid_3d.h"
#include "rbsn/polyhedron.h"
#include "rbsn/sampling.h"
#include "rbsn/sharp_edges_3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>

namespace hysteron
{
  namespace RBSN
  {
    namespace Sampling
    {
      namespace
      {
        using Point2 = std::array<double, 2>;

        /// The faces of the domain's boundary grouped by their plane (and side).
        struct FaceGroup
        {
          unsigned int              plane = 0;
          bool                      flipped = false;
          std::vector<unsigned int> polygons;
        };

        std::vector<FaceGroup>
        face_groups(const std::vector<Polyhedral::BoundaryPolygon> &polygons)
        {
          std::vector<FaceGroup>                        groups;
          std::map<std::pair<unsigned int, bool>, unsigned int> number;
          for (unsigned int k = 0; k < polygons.size(); ++k)
            {
              const auto key = std::make_pair(polygons[k].plane, polygons[k].flipped);
              auto       g   = number.find(key);
              if (g == number.end())
                {
                  g = number.emplace(key, groups.size()).first;
                  groups.push_back(FaceGroup{key.first, key.second, {}});
                }
              groups[g->second].polygons.push_back(k);
            }
          return groups;
        }



        /// A convex 2D polygon clipped to the square [x0, x0 + size] x [y0, y0 + size].
        std::vector<Point2>
        clip_to_square(std::vector<Point2> poly, const double x0, const double y0, const double size)
        {
          for (unsigned int side = 0; side < 4 && poly.size() >= 3; ++side)
            {
              // inside: sign * (x_axis - bound) <= 0
              const unsigned int axis  = side % 2;
              const double       sign  = side < 2 ? -1 : 1;
              const double       bound = side < 2 ? (axis == 0 ? x0 : y0) : (axis == 0 ? x0 + size : y0 + size);
              std::vector<Point2> out;
              for (unsigned int k = 0; k < poly.size(); ++k)
                {
                  const Point2 &a = poly[k], &b = poly[(k + 1) % poly.size()];
                  const double  fa = sign * (a[axis] - bound), fb = sign * (b[axis] - bound);
                  if (fa <= 0)
                    out.push_back(a);
                  if ((fa < 0 && fb > 0) || (fa > 0 && fb < 0))
                    {
                      const Point2 &i = fa < 0 ? a : b, &o = fa < 0 ? b : a;
                      const double  fi = fa < 0 ? fa : fb, fo = fa < 0 ? fb : fa;
                      const double  t  = fi / (fi - fo);
                      out.push_back({{i[0] + t * (o[0] - i[0]), i[1] + t * (o[1] - i[1])}});
                    }
                }
              poly.swap(out);
            }
          if (poly.size() < 3)
            poly.clear();
          return poly;
        }



        /**
         * Poisson-disk points on one planar face of the boundary (the polygons of one
         * plane and side), keeping the distance rule from all the points of @p grid:
         * Bridson's front in the plane from the points already on the face, then darts
         * into the squares of a grid in the plane that no exclusion ball covers (their
         * part on the face), then into their quarters, for 2 levels.
         */
        class FaceSampler
        {
        public:
          FaceSampler(const std::vector<Polyhedral::BoundaryPolygon> &polygons,
                      const FaceGroup                                &group,
                      Grid3                                          &grid,
                      std::mt19937_64                                &rng,
                      std::vector<Point>                             &points)
            : grid(grid)
            , rng(rng)
            , points(points)
          {
            const auto &first = polygons[group.polygons[0]].polygon;
            n                 = first.normal;
            e1                = Polyhedral::perpendicular(n);
            e2                = cross_product_3d(n, e1);
            o                 = first.vertices[0];
            for (const unsigned int k : group.polygons)
              {
                faces.emplace_back();
                for (const auto &v : polygons[k].polygon.vertices)
                  {
                    faces.back().push_back(to_plane(v));
                    box3.add(v);
                    for (unsigned int a = 0; a < 2; ++a)
                      {
                        lo[a] = std::min(lo[a], faces.back().back()[a]);
                        hi[a] = std::max(hi[a], faces.back().back()[a]);
                      }
                  }
              }
          }

          /// The points, in squares of side @p cell; points within @p match of the face are on it.
          void
          run(const double cell, const double match)
          {
            start_front(match);
            grow();
            refine(sweep(cell));
          }

        private:
          Grid3                           &grid;
          std::mt19937_64                 &rng;
          std::vector<Point>              &points;
          Vector                           n, e1, e2; ///< the face's normal and a basis of its plane
          Point                            o;         ///< the origin in the plane
          std::vector<std::vector<Point2>> faces;     ///< the polygons in the plane
          Box                              box3;
          Point2                           lo{{1e300, 1e300}}, hi{{-1e300, -1e300}};
          std::vector<unsigned int>        active; ///< the front

          Point2
          to_plane(const Point &x) const
          {
            return Point2{{(x - o) * e1, (x - o) * e2}};
          }

          Point
          to_space(const Point2 &q) const
          {
            return o + q[0] * e1 + q[1] * e2;
          }

          bool
          on_face(const Point2 &q, const double tolerance) const
          {
            for (const auto &f : faces)
              {
                bool in = true;
                for (unsigned int k = 0; k < f.size() && in; ++k)
                  {
                    const Point2 &a = f[k], &b = f[(k + 1) % f.size()];
                    const double  ex = b[0] - a[0], ey = b[1] - a[1];
                    in = ex * (q[1] - a[1]) - ey * (q[0] - a[0]) >= -tolerance * std::sqrt(ex * ex + ey * ey);
                  }
                if (in)
                  return true;
              }
            return false;
          }

          /// The front starts from the points already on the face (its edges' points).
          void
          start_front(const double match)
          {
            std::vector<unsigned int> found;
            grid.near(box3, found);
            for (const unsigned int k : found)
              if (std::abs(n * (grid.points[k] - o)) <= match && on_face(to_plane(grid.points[k]), match))
                active.push_back(k);
          }

          /// A point q of the plane, if free (the darts are drawn on the face).
          bool
          try_add(const Point2 &q)
          {
            const auto  anywhere = [](const Point &) { return true; };
            double      dp;
            const Point p = to_space(q);
            if (!grid.free(p, dp, anywhere))
              return false;
            active.push_back(grid.points.size());
            grid.add(p, dp);
            points.push_back(p);
            return true;
          }

          /// Bridson's front: its trials are drawn in the annulus about c in the plane,
          /// and must lie on the face.
          void
          grow()
          {
            const auto annulus = [&](const Point &c3, const double dc) {
              const Point2 c = to_plane(c3);
              const double r = dc * (1 + uniform(rng)), phi = 2 * M_PI * uniform(rng);
              return Point2{{c[0] + r * std::cos(phi), c[1] + r * std::sin(phi)}};
            };
            const auto try_add_on_face = [&](const Point2 &q) { return on_face(q, 0) && try_add(q); };
            Sampling::grow_front(active, grid.points, grid.radius, rng, annulus, try_add_on_face);
          }

          /// Up to @p trials darts uniformly over the part of the face in a square (its fan
          /// triangles); false if the face misses the square.
          bool
          darts(const double x0, const double y0, const double size, const unsigned int trials)
          {
            std::vector<std::array<Point2, 3>> triangles;
            std::vector<double>                cumulative;
            double                             total = 0;
            for (const auto &f : faces)
              {
                const auto part = clip_to_square(f, x0, y0, size);
                for (unsigned int k = 1; k + 1 < part.size(); ++k)
                  {
                    const double area = 0.5 * ((part[k][0] - part[0][0]) * (part[k + 1][1] - part[0][1]) -
                                               (part[k][1] - part[0][1]) * (part[k + 1][0] - part[0][0]));
                    if (area <= 0)
                      continue;
                    triangles.push_back({{part[0], part[k], part[k + 1]}});
                    total += area;
                    cumulative.push_back(total);
                  }
              }
            if (triangles.empty())
              return false;
            // A triangle by area, then a uniform point in it (folded barycentrics).
            const auto draw = [&]() {
              const double pick = uniform(rng) * total;
              const auto   t    = std::min<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                                                       cumulative.begin(),
                                                     triangles.size() - 1);
              double u = uniform(rng), v = uniform(rng);
              if (u + v > 1)
                {
                  u = 1 - u;
                  v = 1 - v;
                }
              const auto &T = triangles[t];
              return Point2{{T[0][0] + u * (T[1][0] - T[0][0]) + v * (T[2][0] - T[0][0]),
                             T[0][1] + u * (T[1][1] - T[0][1]) + v * (T[2][1] - T[0][1])}};
            };
            Sampling::throw_darts(
              trials, draw, [&](const Point2 &q) { return try_add(q); }, [&]() { grow(); });
            return true;
          }

          bool
          square_covered(const double x0, const double y0, const double size) const
          {
            const Point corners[4] = {to_space({{x0, y0}}),
                                      to_space({{x0 + size, y0}}),
                                      to_space({{x0, y0 + size}}),
                                      to_space({{x0 + size, y0 + size}})};
            return grid.covers(corners, 4);
          }

          /// 30 darts into every square of side @p cell that no ball covers: the squares left.
          std::vector<std::array<double, 3>>
          sweep(const double cell)
          {
            const int nx = std::max(1, static_cast<int>(std::ceil((hi[0] - lo[0]) / cell)));
            const int ny = std::max(1, static_cast<int>(std::ceil((hi[1] - lo[1]) / cell)));
            std::vector<std::array<double, 3>> squares;
            for (int j = 0; j < ny; ++j)
              for (int i = 0; i < nx; ++i)
                {
                  const double x0 = lo[0] + i * cell, y0 = lo[1] + j * cell;
                  if (!square_covered(x0, y0, cell) && darts(x0, y0, cell, 30) && !square_covered(x0, y0, cell))
                    squares.push_back({{x0, y0, cell}});
                }
            return squares;
          }

          /// 10 darts into each quarter of the @p squares left, for 2 levels.
          void
          refine(std::vector<std::array<double, 3>> squares)
          {
            for (unsigned int level = 0; level < 2 && !squares.empty(); ++level)
              {
                std::vector<std::array<double, 3>> quarters;
                for (const auto &q : squares)
                  for (unsigned int c = 0; c < 4; ++c)
                    {
                      const double h = 0.5 * q[2];
                      quarters.push_back({{q[0] + (c % 2) * h, q[1] + (c / 2) * h, h}});
                    }
                squares.clear();
                for (const auto &q : quarters)
                  if (!square_covered(q[0], q[1], q[2]) && darts(q[0], q[1], q[2], 10) &&
                      !square_covered(q[0], q[1], q[2]))
                    squares.push_back(q);
              }
          }
        };
      } // namespace
    } // namespace Sampling



    std::vector<dealii::Point<3>>
    boundary_points(const Geometry::Region<3> &region,
                    const Spacing<3>          &spacing,
                    const double               boundary_h,
                    const std::uint64_t        seed)
    {
      const std::string where = "the shape '" + region.expression() + "'";
      require(spacing.min > 0 && spacing.max >= spacing.min, where, "the minimum distance must be > 0");
      const Polyhedral::Domain domain({&region}, boundary_h, where);
      const auto               polygons = domain.boundary();
      const double             match    = 1e-9 * domain.scale;

      // The corners and the points along the sharp edges.
      std::vector<dealii::Point<3>> points = Polyhedral::sharp_edge_points(polygons, match, spacing);

      // Poisson-disk points on every planar face (the polygons of one plane),
      // keeping the distance rule from all points so far.
      Sampling::Grid3 grid(domain.box, spacing);
      for (const auto &p : points)
        grid.add(p, spacing(p));
      std::mt19937_64 rng(seed);
      for (const auto &group : Sampling::face_groups(polygons))
        Sampling::FaceSampler(polygons, group, grid, rng, points).run(spacing.min / std::sqrt(2.0), match);
      return points;
    }
  } // namespace RBSN
} // namespace hysteron

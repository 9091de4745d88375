// The 3D Poisson-disk sampling: the forbidden balls of the boundary points, Bridson's front and the darts into its gaps.
#include <hysteron/base/exceptions.h>
#include "rbsn/tessellation.h"

#include "rbsn/poisson_grid_3d.h"
#include "rbsn/polyhedron.h"
#include "rbsn/sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace Sampling
    {
      namespace
      {
        /**
         * Forbidden balls that keep random nuclei from owning any of the boundary where
         * the fixed points cover it. A point p owns the boundary point x if it is closer
         * to x than every fixed point, |p - x| < rho(x) = min_q |x - q|. On a boundary
         * polygon F, the part R_q of F nearest to the fixed point q (F clipped by the
         * bisector planes of q and the other fixed points: a convex polygon) has
         * |p - x|^2 - |q - x|^2 affine in x, so p is closer than q to a point of R_q iff
         * it is to a vertex v of R_q. The union of the balls B(x, rho(x)) over the
         * boundary is therefore the union of the balls B(v, |v - q|) over the vertices of
         * these restricted Voronoi regions: the circumcentres of the fixed points in a
         * face, and where the regions meet the polygons' edges and corners. This holds
         * for any polyhedral boundary: the faces of a box, and the narrow sides of a prism
         * or the small triangles of a geodesic sphere, which hold too few fixed points of
         * their own for a Delaunay triangulation in their plane. Balls of radius below
         * 1.25 d(v) are returned (a saturated surface; sparse user points are left alone).
         */
        std::vector<std::pair<Point, double>>
        boundary_balls(const Polyhedral::Domain                       &domain,
                       const std::vector<Polyhedral::BoundaryPolygon> &polygons,
                       const std::vector<Point>                       &fixed,
                       const Spacing<3>                               &d)
        {
          std::vector<std::pair<Point, double>> balls;
          if (fixed.empty())
            return balls;
          // Only vertices within reach = 1.25 d_max of their q give balls, and a fixed
          // point q' cuts such a vertex off R_q only if |q' - q| < 2 reach.
          const double reach = 1.25 * d.max;
          using Key          = std::array<long long, 3>;
          const auto key     = [&](const Point &p) {
            return Key{{static_cast<long long>(std::floor(p[0] / reach)), static_cast<long long>(std::floor(p[1] / reach)),
                        static_cast<long long>(std::floor(p[2] / reach))}};
          };
          std::map<Key, std::vector<unsigned int>> grid;
          for (unsigned int i = 0; i < fixed.size(); ++i)
            grid[key(fixed[i])].push_back(i);
          const auto within = [&](const Point &lo, const Point &hi, std::vector<unsigned int> &result) {
            result.clear();
            const Key a = key(lo), b = key(hi);
            for (long long z = a[2]; z <= b[2]; ++z)
              for (long long y = a[1]; y <= b[1]; ++y)
                for (long long x = a[0]; x <= b[0]; ++x)
                  if (const auto g = grid.find(Key{{x, y, z}}); g != grid.end())
                    result.insert(result.end(), g->second.begin(), g->second.end());
          };
          // The fixed points within 2 reach of each q, nearest first (computed when needed).
          std::vector<std::vector<unsigned int>> neighbours(fixed.size());
          std::vector<bool>                      listed(fixed.size(), false);
          std::vector<unsigned int>              found;
          const auto                             neighbours_of = [&](const unsigned int q) -> const std::vector<unsigned int> & {
            if (!listed[q])
              {
                const Vector r({2 * reach, 2 * reach, 2 * reach});
                within(fixed[q] - r, fixed[q] + r, found);
                auto &list = neighbours[q];
                for (const unsigned int k : found)
                  if (k != q && fixed[k].distance(fixed[q]) < 2 * reach && fixed[k].distance(fixed[q]) > domain.tolerance)
                    list.push_back(k);
                std::sort(list.begin(), list.end(), [&](const unsigned int a, const unsigned int b) {
                  const double da = fixed[a].distance_square(fixed[q]), db = fixed[b].distance_square(fixed[q]);
                  return da < db || (da == db && a < b);
                });
                listed[q] = true;
              }
            return neighbours[q];
          };
          Polyhedral::Clipper       clipper(domain.tolerance);
          Polyhedral::ConvexPolygon region, clipped;
          std::vector<unsigned int> candidates;
          for (const auto &b : polygons)
            {
              // The fixed points within reach of the polygon's box.
              const Box    box = b.polygon.bounding_box();
              const Vector r({reach, reach, reach});
              within(box.lo - r, box.hi + r, candidates);
              std::sort(candidates.begin(), candidates.end());
              for (const unsigned int q : candidates)
                {
                  double gap = 0; // the distance of q from the box
                  for (unsigned int k = 0; k < 3; ++k)
                    gap += std::pow(std::max({box.lo[k] - fixed[q][k], fixed[q][k] - box.hi[k], 0.0}), 2);
                  if (gap >= reach * reach)
                    continue;
                  region      = b.polygon;
                  bool  empty = false;
                  const auto farthest = [&]() {
                    double rho = 0;
                    for (const auto &v : region.vertices)
                      rho = std::max(rho, v.distance(fixed[q]));
                    return rho;
                  };
                  double rho_max = farthest();
                  for (const unsigned int k : neighbours_of(q))
                    {
                      const Vector e = fixed[k] - fixed[q];
                      const double h = e.norm();
                      if (h > 2 * rho_max)
                        break; // its bisector misses the region (and so do the farther ones')
                      const Polyhedral::Plane bisector{e / h, (e / h) * (0.5 * (fixed[q] + fixed[k]))};
                      const auto              cut = clipper.clip(region, bisector, 0, clipped);
                      if (cut == Polyhedral::Cut::outside)
                        {
                          empty = true;
                          break;
                        }
                      if (cut == Polyhedral::Cut::cut)
                        {
                          region.vertices.swap(clipped.vertices);
                          rho_max = farthest();
                        }
                    }
                  if (empty)
                    continue;
                  for (const auto &v : region.vertices)
                    {
                      const double rho = v.distance(fixed[q]);
                      if (rho > domain.tolerance && rho < 1.25 * d(v))
                        balls.emplace_back(v, rho);
                    }
                }
            }
          return balls;
        }



        /// The part of @p box in the block of @p clip; false if there is none.
        bool
        restrict_to_block(const Sampling::Clip<3> &clip, Box &box)
        {
          const auto block = clip.box();
          for (unsigned int k = 0; k < 3; ++k)
            {
              box.lo[k] = std::max(box.lo[k], block.first[k]);
              box.hi[k] = std::min(box.hi[k], block.second[k]);
              if (box.lo[k] > box.hi[k])
                return false;
            }
          return true;
        }



        /**
         * The random points of the 3D Poisson-disk sampling (poisson_disk_points()) in
         * @p domain, the @p fixed points in the grid and the front, the @p balls
         * forbidden; with @p clip in the part of the domain in one block of a tiled
         * network (the trials outside the block refused, the darts thrown into it only).
         */
        std::vector<Point>
        sample_3d(const Polyhedral::Domain                    &domain,
                  const Spacing<3>                            &d,
                  const std::vector<Point>                    &fixed,
                  const std::vector<std::pair<Point, double>> &balls,
                  const std::uint64_t                          seed,
                  const Sampling::Clip<3>                     *clip)
        {
          Box box = domain.box;
          if (clip && !restrict_to_block(*clip, box))
            return {};
          Grid3 grid(box, d, clip ? clip->margin : -1);
          for (const auto &p : fixed)
            grid.add(p, d(p));
          // The fixed points on the boundary own it: no random point may come closer to
          // a piece of it than they are.
          grid.forbid(balls);
          const auto in_domain = [&](const Point &p) { return (!clip || clip->contains(p)) && domain.contains(p); };
          // Whether the cube [corner, corner + size] meets the box (where darts go).
          const auto meets = [&](const Point &corner, const double size) {
            for (unsigned int k = 0; k < 3; ++k)
              if (std::max(corner[k], box.lo[k]) > std::min(corner[k] + size, box.hi[k]))
                return false;
            return true;
          };

          // Bridson: grow from active points by trials in the shell [d, 2 d] around them
          // (uniform directions) until the front dies out.
          std::vector<unsigned int> active;
          for (unsigned int k = 0; k < grid.points.size(); ++k)
            active.push_back(k);
          std::vector<Point> result;
          std::mt19937_64    rng(seed);
          const auto         try_add = [&](const Point &p) {
            double dp;
            if (!grid.free(p, dp, in_domain))
              return false;
            active.push_back(grid.points.size());
            grid.add(p, dp);
            result.push_back(p);
            return true;
          };
          // Uniform directions: z = cos(theta) uniform in [-1, 1], phi in [0, 2 pi).
          const auto shell = [&](const Point &c, const double dc) {
            const double r = dc * (1 + uniform(rng)), z = 2 * uniform(rng) - 1, phi = 2 * M_PI * uniform(rng);
            const double s = std::sqrt(std::max(0.0, 1 - z * z));
            return Point(c[0] + r * s * std::cos(phi), c[1] + r * s * std::sin(phi), c[2] + r * z);
          };
          const auto grow = [&]() { Sampling::grow_front(active, grid.points, grid.radius, rng, shell, try_add); };
          grow();
          // Up to @p trials random points in a cube (its part in the box); the first that
          // is free is added and the front grows from it.
          const auto darts = [&](const Point &corner, const double size, const unsigned int trials) {
            Point a, b;
            for (unsigned int k = 0; k < 3; ++k)
              {
                a[k] = std::max(corner[k], box.lo[k]);
                b[k] = std::min(corner[k] + size, box.hi[k]);
                if (a[k] > b[k])
                  return;
              }
            const auto draw = [&]() {
              const double u = uniform(rng), v = uniform(rng), w = uniform(rng);
              return Point(a[0] + u * (b[0] - a[0]), a[1] + v * (b[1] - a[1]), a[2] + w * (b[2] - a[2]));
            };
            Sampling::throw_darts(trials, draw, try_add, grow);
          };
          const auto cube_covered = [&](const Point &corner, const double size) {
            Point corners[8];
            for (unsigned int c = 0; c < 8; ++c)
              corners[c] = corner + Vector({(c & 1) * size, ((c >> 1) & 1) * size, ((c >> 2) & 1) * size});
            return grid.covers(corners, 8);
          };
          // The gaps the front left: 30 trials in every cube that no exclusion ball
          // covers, in a fixed order, and the front again from each point found.
          std::vector<std::pair<Point, double>> cubes; // corner, size: the gaps left
          for (int k = 0; k < grid.n[2]; ++k)
            for (int j = 0; j < grid.n[1]; ++j)
              for (int i = 0; i < grid.n[0]; ++i)
                if (!grid.covered[grid.index(i, j, k)])
                  {
                    const Point corner = grid.lo + grid.cell * Vector({1.0 * i, 1.0 * j, 1.0 * k});
                    if (clip && !meets(corner, grid.cell))
                      continue;
                    darts(corner, grid.cell, 30);
                    if (!grid.covered[grid.index(i, j, k)])
                      cubes.emplace_back(corner, grid.cell);
                  }
          // The slivers between exclusion balls: split every cube that is not covered (nor
          // outside the domain at its corners and centre) into 8 and throw 10 darts into
          // each, for 2 levels (as the 2D sampling does with quarters).
          for (unsigned int level = 0; level < 2 && !cubes.empty(); ++level)
            {
              std::vector<std::pair<Point, double>> octants;
              for (const auto &q : cubes)
                for (unsigned int c = 0; c < 8; ++c)
                  {
                    const double h = 0.5 * q.second;
                    const Point  x0 = q.first + Vector({(c & 1) * h, ((c >> 1) & 1) * h, ((c >> 2) & 1) * h});
                    bool         inside = domain.contains(x0 + Vector({0.5 * h, 0.5 * h, 0.5 * h}));
                    for (unsigned int e = 0; e < 8 && !inside; ++e)
                      inside = domain.contains(x0 + Vector({(e & 1) * h, ((e >> 1) & 1) * h, ((e >> 2) & 1) * h}));
                    if (inside && (!clip || meets(x0, h)) && !cube_covered(x0, h))
                      octants.emplace_back(x0, h);
                  }
              cubes.clear();
              for (const auto &q : octants)
                if (!cube_covered(q.first, q.second))
                  {
                    darts(q.first, q.second, 10);
                    if (!cube_covered(q.first, q.second))
                      cubes.push_back(q);
                  }
            }
          return result;
        }
      } // namespace



      struct BodySampler3::Data
      {
        const Spacing<3>                      &d;
        Polyhedral::Domain                     domain;
        std::vector<std::pair<Point, double>> balls; ///< of the network's fixed points
      };



      BodySampler3::BodySampler3(const Geometry::Region<3> &body,
                                 const Spacing<3>          &d,
                                 const std::vector<Point>  &fixed,
                                 const double               boundary_h,
                                 const std::string         &where)
        : data(new Data{d, Polyhedral::Domain({&body}, boundary_h > 0 ? boundary_h : 0.25 * d.min, where), {}})
      {
        data->balls = boundary_balls(data->domain, data->domain.boundary(), fixed, d);
      }



      BodySampler3::~BodySampler3() = default;



      std::vector<Point>
      BodySampler3::operator()(const std::vector<Point> &known, const std::uint64_t seed, const Clip<3> &clip) const
      {
        // The forbidden balls that reach the block's grid (the block and its margin).
        const auto             block = clip.box();
        std::vector<std::pair<Point, double>> near;
        for (const auto &b : data->balls)
          {
            bool meets = true;
            for (unsigned int k = 0; k < 3 && meets; ++k)
              meets = b.first[k] >= block.first[k] - clip.margin - b.second &&
                      b.first[k] <= block.second[k] + clip.margin + b.second;
            if (meets)
              near.push_back(b);
          }
        return sample_3d(data->domain, data->d, known, near, seed, &clip);
      }
    } // namespace Sampling



    std::vector<dealii::Point<3>>
    poisson_disk_points(const Geometry::Region<3>           &region,
                        const Spacing<3>                    &d,
                        const std::vector<dealii::Point<3>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where,
                        const double                         boundary_h)
    {
      require(d.min > 0 && d.max >= d.min && std::isfinite(d.max), where, "the minimum distance must be > 0");
      const Polyhedral::Domain domain({&region}, boundary_h > 0 ? boundary_h : 0.25 * d.min, where);
      const auto boundary = domain.boundary();
      {
        // The saturated set's size: density V / d^3 for a constant d (V of the
        // polyhedral domain), else the sampled prediction.
        const double volume    = Polyhedral::Domain::volume(boundary);
        const double predicted = d.is_constant() ? Spacing<3>::density * volume / (d.min * d.min * d.min) :
                                                   d.predicted_points;
        std::ostringstream s;
        s << "about " << static_cast<long>(predicted) << " points predicted at this minimum distance ("
          << Spacing<3>::density << " int 1/d^3 dV over the body; at most 5e6)";
        require(predicted <= 5e6, where, s.str());
      }
      std::vector<dealii::Point<3>> result =
        Sampling::sample_3d(domain, d, fixed, Sampling::boundary_balls(domain, boundary, fixed, d), seed, nullptr);
      result.insert(result.begin(), fixed.begin(), fixed.end());
      return result;
    }
  } // namespace RBSN
} // namespace hysteron

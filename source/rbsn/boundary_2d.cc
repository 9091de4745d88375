// The 2D boundary: the oriented boundary of a union of regions, its loops, and the points along it.
#include "rbsn/tessellation.h"

#include "rbsn/boundary_2d.h"
#include "rbsn/spread.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hysteron
{
  namespace RBSN
  {
    namespace Planar
    {
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
    } // namespace Planar



    namespace
    {
      using Planar::chain;
      using Planar::cross;
      using Planar::oriented_boundary;
      using Planar::Point;
    } // namespace



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
              // Points at tau = j total / pieces, j = 0 .. pieces - 1 (the next run adds
              // its corner), so that neighbours are at most the local d apart.
              spread(path, spacing, true, points);
            }
        }
      return points;
    }
  } // namespace RBSN
} // namespace hysteron

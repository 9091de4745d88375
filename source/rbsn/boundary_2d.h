#ifndef hysteron_source_rbsn_boundary_2d_h
#define hysteron_source_rbsn_boundary_2d_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <hysteron/geometry/region.h>

#include <array>
#include <cmath>
#include <vector>

/**
 * @file
 * The 2D boundary geometry that the tessellation and the boundary points share:
 * the crossing of two segments, the oriented boundary of a union of regions, and
 * its closed loops.
 */
namespace hysteron
{
  namespace RBSN
  {
    namespace Planar
    {
      using Point   = dealii::Point<2>;
      using Segment = std::array<Point, 2>;

      /// The z component of a x b.
      inline double
      cross(const dealii::Tensor<1, 2> &a, const dealii::Tensor<1, 2> &b)
      {
        return a[0] * b[1] - a[1] * b[0];
      }

      /**
       * The parameters s, t in (0, 1) of the proper intersection of the segments
       * a + s (b - a) and c + t (d - c), or false (parallel, or outside).
       */
      inline bool
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
      oriented_boundary(const std::vector<Geometry::Region<2>> &bodies, const double boundary_h, const double scale);

      /// Join boundary pieces into closed loops by matching end points.
      std::vector<std::vector<Point>>
      chain(std::vector<Segment> pieces, const double tolerance);
    } // namespace Planar
  }   // namespace RBSN
} // namespace hysteron

#endif

// 2D regions as straight-sided polygons: disks as regular polygons, regions with their
// disks so replaced, and the boundaries of the primitives as segments (what the
// unstructured mesher takes as constraints).
#include <deal.II/base/exceptions.h>

#include <hysteron/geometry/region.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hysteron
{
  namespace Geometry
  {
    template <int dim>
    std::vector<dealii::Point<2>>
    Region<dim>::polygon_vertices(const Primitive &polygon) const
    {
      AssertThrow(polygon.kind == Kind::polygon &&
                    polygon.first_vertex + polygon.n_vertices <= vertices.size(),
                  dealii::ExcMessage("polygon_vertices: not a polygon of this region"));
      return std::vector<dealii::Point<2>>(vertices.begin() + polygon.first_vertex,
                                           vertices.begin() + polygon.first_vertex +
                                             polygon.n_vertices);
    }



    template <int dim>
    unsigned int
    Region<dim>::n_disk_sides(const double radius, const double h)
    {
      AssertThrow(h > 0 && std::isfinite(h) && radius > 0 && std::isfinite(radius),
                  dealii::ExcMessage("n_disk_sides: need r > 0 and h > 0"));
      const double n = std::max(16.0, std::ceil(2 * M_PI * radius / h));
      AssertThrow(n < 1e9, dealii::ExcMessage("n_disk_sides: 2 pi r / h is too large"));
      const unsigned int m = static_cast<unsigned int>(n);
      return (m + 3) / 4 * 4;
    }



    template <int dim>
    std::vector<dealii::Point<2>>
    Region<dim>::disk_polygon(const dealii::Point<2> &centre, const double radius, const double h)
    {
      const unsigned int            n       = n_disk_sides(radius, h);
      const unsigned int            quarter = n / 4;
      std::vector<dealii::Point<2>> v(n);
      for (unsigned int m = 0; m < quarter; ++m)
        {
          // (c, s) for the angle 2 pi m / n in [0, pi/2); the other quadrants are
          // exact rotations by 90 degrees.
          const double angle = 2 * M_PI * m / n;
          const double c = (m == 0 ? 1.0 : std::cos(angle)), s = (m == 0 ? 0.0 : std::sin(angle));
          const double x[4] = {c, -s, -c, s};
          const double y[4] = {s, c, -s, -c};
          for (unsigned int q = 0; q < 4; ++q)
            v[q * quarter + m] =
              dealii::Point<2>(centre[0] + radius * x[q], centre[1] + radius * y[q]);
        }
      return v;
    }



    template <int dim>
    Region<2>
    Region<dim>::polygonized(const double h) const
    {
      if constexpr (dim == 2)
        {
          Region<2> result = *this;
          for (auto &q : result.primitives)
            if (q.kind == Kind::disk)
              {
                const auto v =
                  disk_polygon(dealii::Point<2>(q.p[0], q.p[1]), q.p[2], h);
                q.kind         = Kind::polygon;
                q.first_vertex = result.vertices.size();
                q.n_vertices   = v.size();
                result.vertices.insert(result.vertices.end(), v.begin(), v.end());
              }
          return result;
        }
      else
        {
          (void)h;
          AssertThrow(false, dealii::ExcNotImplemented());
          return Region<2>();
        }
    }



    template <int dim>
    std::vector<std::array<dealii::Point<2>, 2>>
    Region<dim>::boundary_segments(const double h) const
    {
      std::vector<std::array<dealii::Point<2>, 2>> segments;
      AssertThrow(dim == 2, dealii::ExcNotImplemented());
      const auto add_loop = [&segments](const std::vector<dealii::Point<2>> &v) {
        for (unsigned int i = 0; i < v.size(); ++i)
          segments.push_back({{v[i], v[(i + 1) % v.size()]}});
      };
      for (const auto &q : primitives)
        switch (q.kind)
          {
            case Kind::rectangle:
              add_loop({dealii::Point<2>(q.p[0], q.p[1]),
                        dealii::Point<2>(q.p[2], q.p[1]),
                        dealii::Point<2>(q.p[2], q.p[3]),
                        dealii::Point<2>(q.p[0], q.p[3])});
              break;
            case Kind::disk:
              add_loop(disk_polygon(dealii::Point<2>(q.p[0], q.p[1]), q.p[2], h));
              break;
            case Kind::polygon:
              add_loop(polygon_vertices(q));
              break;
            default: // all: no boundary; 3D kinds cannot occur in 2D
              break;
          }
      return segments;
    }



    template class Region<2>;
    template class Region<3>;
  } // namespace Geometry
} // namespace hysteron

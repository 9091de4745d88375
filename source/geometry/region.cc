// Regions as sets of points: the membership test (the postfix program over the primitives,
// each one's closed set inflated or deflated by a tolerance), the bounding box, the volume,
// and read access.
#include <deal.II/base/exceptions.h>

#include <hysteron/geometry/region.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace hysteron
{
  namespace Geometry
  {
    namespace
    {
      constexpr double infinity = std::numeric_limits<double>::infinity();

      /// Squared distance of p to the segment ab.
      double
      distance_squared(const dealii::Point<2> &a, const dealii::Point<2> &b, const double px,
                       const double py)
      {
        const double ex = b[0] - a[0], ey = b[1] - a[1];
        double       t  = ((px - a[0]) * ex + (py - a[1]) * ey) / (ex * ex + ey * ey);
        t               = std::min(1.0, std::max(0.0, t));
        const double dx = px - (a[0] + t * ex), dy = py - (a[1] + t * ey);
        return dx * dx + dy * dy;
      }

      /// The exact area or volume of primitive @p q (@p vertices: the polygons' vertices).
      template <int dim>
      double
      primitive_volume(const typename Region<dim>::Primitive &q,
                       const std::vector<dealii::Point<2>>   &vertices)
      {
        using Kind = typename Region<dim>::Kind;
        switch (q.kind)
          {
            case Kind::rectangle:
            case Kind::box:
              {
                double v = 1;
                for (unsigned int d = 0; d < dim; ++d)
                  v *= q.p[dim + d] - q.p[d];
                return v;
              }
            case Kind::disk:
              return M_PI * q.p[2] * q.p[2];
            case Kind::sphere:
              return 4. / 3. * M_PI * q.p[3] * q.p[3] * q.p[3];
            case Kind::cylinder:
              return M_PI * q.p[6] * q.p[6] * q.p[7];
            case Kind::polygon:
              {
                // The shoelace formula.
                const dealii::Point<2> *v          = vertices.data() + q.first_vertex;
                double                  twice_area = 0;
                for (unsigned int i = 0, j = q.n_vertices - 1; i < q.n_vertices; j = i++)
                  twice_area += v[j][0] * v[i][1] - v[i][0] * v[j][1];
                return 0.5 * std::abs(twice_area);
              }
            case Kind::all:
              return infinity;
          }
        return 0;
      }

      /// The midpoint rule on n^dim cells over the box of @p region: the cells whose
      /// centre is in the region times the cell's volume.
      template <int dim>
      double
      midpoint_volume(const Region<dim> &region, const unsigned int n)
      {
        const auto box         = region.bounding_box();
        double     cell_volume = 1;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double side = box.get_boundary_points().second[d] - box.get_boundary_points().first[d];
            if (!std::isfinite(side))
              return infinity;
            cell_volume *= side / n;
          }
        const dealii::Point<dim> lo = box.get_boundary_points().first;
        const dealii::Point<dim> hi = box.get_boundary_points().second;
        std::size_t              count = 0;
        std::array<unsigned int, dim> i{};
        const std::size_t n_cells = static_cast<std::size_t>(std::pow(n, dim));
        for (std::size_t c = 0; c < n_cells; ++c)
          {
            std::size_t r = c;
            dealii::Point<dim> p;
            for (unsigned int d = 0; d < dim; ++d)
              {
                i[d] = r % n;
                r /= n;
                p[d] = lo[d] + (i[d] + 0.5) * (hi[d] - lo[d]) / n;
              }
            if (region.contains(p))
              ++count;
          }
        return count * cell_volume;
      }
    } // namespace



    template <int dim>
    Region<dim>::Region() = default;



    template <int dim>
    inline bool
    Region<dim>::primitive_contains(const Primitive          &q,
                                    const dealii::Point<dim> &x,
                                    const double              tolerance) const
    {
      const double t = q.sign * tolerance;
      switch (q.kind)
        {
          case Kind::rectangle:
          case Kind::box:
            for (unsigned int d = 0; d < dim; ++d)
              if (x[d] < q.p[d] - t || x[d] > q.p[dim + d] + t)
                return false;
            return true;
          case Kind::disk:
          case Kind::sphere:
            {
              const double r = q.p[dim] + t;
              if (r < 0)
                return false;
              double d2 = 0;
              for (unsigned int d = 0; d < dim; ++d)
                d2 += (x[d] - q.p[d]) * (x[d] - q.p[d]);
              return d2 <= r * r;
            }
          case Kind::cylinder:
            {
              const double r = q.p[6] + t;
              if (r < 0)
                return false;
              double s = 0, d2 = 0;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  const double y = x[d] - q.p[d];
                  s += y * q.p[3 + d];
                  d2 += y * y;
                }
              // s = |axis| * (axial coordinate of x)
              const double length = q.p[7];
              if (s < -t * length || s > (length + t) * length)
                return false;
              const double axial = s / length;
              return d2 - axial * axial <= r * r;
            }
          case Kind::polygon:
            {
              const dealii::Point<2> *v      = vertices.data() + q.first_vertex;
              const unsigned int      n      = q.n_vertices;
              const double            px     = x[0];
              const double            py     = x[1];
              bool                    inside = false;
              for (unsigned int i = 0, j = n - 1; i < n; j = i++)
                if ((v[i][1] > py) != (v[j][1] > py) &&
                    px < v[j][0] + (py - v[j][1]) * (v[i][0] - v[j][0]) / (v[i][1] - v[j][1]))
                  inside = !inside;
              if (inside && t == 0)
                return true;
              if (!inside && t < 0)
                return false;
              double d2 = infinity;
              for (unsigned int i = 0, j = n - 1; i < n; j = i++)
                d2 = std::min(d2, distance_squared(v[j], v[i], px, py));
              if (inside) // inflated (t > 0): inside; deflated (t < 0): at least -t from the boundary
                return t > 0 || d2 >= t * t;
              return d2 <= t * t; // t >= 0: on the boundary or within t of it
            }
          case Kind::all:
            return true;
        }
      return false;
    }



    template <int dim>
    bool
    Region<dim>::contains(const dealii::Point<dim> &p, const double tolerance) const
    {
      if (program.size() == 1)
        return primitive_contains(primitives[program[0].index], p, tolerance);

      bool         stack[max_stack_depth];
      unsigned int top = 0;
      for (const auto &instruction : program)
        switch (instruction.op)
          {
            case Op::push:
              stack[top++] = primitive_contains(primitives[instruction.index], p, tolerance);
              break;
            case Op::unite:
              --top;
              stack[top - 1] = stack[top - 1] || stack[top];
              break;
            case Op::subtract:
              --top;
              stack[top - 1] = stack[top - 1] && !stack[top];
              break;
          }
      return top == 1 && stack[0];
    }



    template <int dim>
    dealii::BoundingBox<dim>
    Region<dim>::bounding_box() const
    {
      return box;
    }



    template <int dim>
    double
    Region<dim>::volume_estimate() const
    {
      if (program.empty())
        return 0;
      if (program.size() == 1)
        return primitive_volume<dim>(primitives[program[0].index], vertices);
      return midpoint_volume(*this, dim == 2 ? 512 : 96);
    }



    template <int dim>
    const std::string &
    Region<dim>::expression() const
    {
      return expression_string;
    }



    template <int dim>
    bool
    Region<dim>::is_empty() const
    {
      return program.empty();
    }



    template <int dim>
    const std::vector<typename Region<dim>::Primitive> &
    Region<dim>::get_primitives() const
    {
      return primitives;
    }



    template <int dim>
    const std::vector<typename Region<dim>::Instruction> &
    Region<dim>::get_program() const
    {
      return program;
    }



    template class Region<2>;
    template class Region<3>;
  } // namespace Geometry
} // namespace hysteron

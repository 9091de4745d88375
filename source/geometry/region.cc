#include <deal.II/base/exceptions.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/region.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace Geometry
  {
    namespace
    {
      constexpr double infinity = std::numeric_limits<double>::infinity();

      /// Description of a primitive: its name, its dimension and its arguments.
      struct ShapeInfo
      {
        const char *name;
        int         dim;
        const char *arguments;
        unsigned    n_numbers; // 0 for polygon (variable) and all
      };

      const ShapeInfo shapes[] = {{"rectangle", 2, "x0, y0, x1, y1", 4},
                                  {"disk", 2, "cx, cy, r", 3},
                                  {"polygon", 2, "x1, y1, x2, y2, x3, y3, ...", 0},
                                  {"box", 3, "x0, y0, z0, x1, y1, z1", 6},
                                  {"sphere", 3, "cx, cy, cz, r", 4},
                                  {"cylinder", 3, "x0, y0, z0, x1, y1, z1, r", 7},
                                  {"all", 0, "", 0}};

      std::string
      known_shapes(const int dim)
      {
        std::string list;
        for (const auto &s : shapes)
          if (s.dim == dim || s.dim == 0)
            list += (list.empty() ? "" : ", ") + std::string(s.name);
        return "(known in " + std::to_string(dim) + "D: " + list + ")";
      }

      std::string
      to_string(const double x)
      {
        std::ostringstream s;
        s.precision(16);
        s << x;
        return s.str();
      }

      /// Sign of the cross product (b - a) x (c - a).
      double
      orientation(const dealii::Point<2> &a, const dealii::Point<2> &b, const dealii::Point<2> &c)
      {
        const double v = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        return (v > 0) - (v < 0);
      }

      /// Whether c, collinear with a and b, lies on the closed segment ab.
      bool
      on_segment(const dealii::Point<2> &a, const dealii::Point<2> &b, const dealii::Point<2> &c)
      {
        return std::min(a[0], b[0]) <= c[0] && c[0] <= std::max(a[0], b[0]) &&
               std::min(a[1], b[1]) <= c[1] && c[1] <= std::max(a[1], b[1]);
      }

      /// Whether the closed segments ab and cd have a point in common.
      bool
      segments_intersect(const dealii::Point<2> &a,
                         const dealii::Point<2> &b,
                         const dealii::Point<2> &c,
                         const dealii::Point<2> &d)
      {
        const double o1 = orientation(a, b, c), o2 = orientation(a, b, d),
                     o3 = orientation(c, d, a), o4 = orientation(c, d, b);
        if (o1 * o2 < 0 && o3 * o4 < 0)
          return true;
        return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
               (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
      }

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
    } // namespace



    /**
     * Recursive descent parser; emits primitives and the postfix program.
     */
    template <int dim>
    struct Region<dim>::Parser
    {
      const std::string &s;
      const std::string &where;
      Region<dim>       &region;
      std::size_t        pos         = 0;
      unsigned int       stack_depth = 0;
      unsigned int       paren_depth = 0;

      [[noreturn]] void
      fail(const std::string &problem) const
      {
        throw InputError(where, problem);
      }

      /// "position N" (1-based) of the character at @p p.
      static std::string
      at(const std::size_t p)
      {
        return "position " + std::to_string(p + 1);
      }

      void
      skip_space()
      {
        while (pos < s.size() && std::isspace(static_cast<unsigned char>(s[pos])))
          ++pos;
      }

      static bool
      is_identifier_char(const char c)
      {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
      }

      /// The token at @p p, quoted, for error messages.
      std::string
      token_at(const std::size_t p) const
      {
        if (p >= s.size())
          return "the end of the expression";
        std::size_t e = p + 1;
        if (is_identifier_char(s[p]) || s[p] == '.')
          while (e < s.size() && (is_identifier_char(s[e]) || s[e] == '.'))
            ++e;
        return "'" + s.substr(p, e - p) + "'";
      }

      void
      emit(const Op op, const unsigned int index = 0)
      {
        if (op == Op::push)
          {
            if (++stack_depth > max_stack_depth)
              fail("the expression is nested too deeply (more than " +
                   std::to_string(max_stack_depth) + " pending terms)");
          }
        else
          --stack_depth;
        region.program.push_back({op, index});
      }

      void
      parse_expression(const double sign)
      {
        parse_term(sign);
        while (true)
          {
            skip_space();
            if (pos < s.size() && (s[pos] == '+' || s[pos] == '-'))
              {
                const bool is_union = (s[pos] == '+');
                ++pos;
                parse_term(is_union ? sign : -sign);
                emit(is_union ? Op::unite : Op::subtract);
              }
            else
              return;
          }
      }

      void
      parse_term(const double sign)
      {
        skip_space();
        if (pos < s.size() && s[pos] == '(')
          {
            const std::size_t open = pos;
            if (++paren_depth > max_stack_depth)
              fail("parentheses nested deeper than " + std::to_string(max_stack_depth) +
                   " levels at " + at(open));
            ++pos;
            parse_expression(sign);
            skip_space();
            if (pos >= s.size())
              fail("unbalanced parentheses: '(' at " + at(open) + " is never closed");
            if (s[pos] != ')')
              fail("expected '+', '-' or ')' at " + at(pos) + ", found " + token_at(pos));
            ++pos;
            --paren_depth;
            return;
          }
        if (pos < s.size() && std::isalpha(static_cast<unsigned char>(s[pos])))
          {
            parse_primitive(sign);
            return;
          }
        fail("expected a shape or '(' at " + at(pos) + ", found " + token_at(pos));
      }

      double
      parse_number()
      {
        skip_space();
        if (pos >= s.size())
          fail("expected a number at " + at(pos) + ", found the end of the expression");
        const char *begin = s.c_str() + pos;
        char       *end   = nullptr;
        const double x    = std::strtod(begin, &end);
        if (end == begin)
          fail("expected a number at " + at(pos) + ", found " + token_at(pos));
        const std::size_t length = end - begin;
        if (!std::isfinite(x))
          fail("non-finite number '" + s.substr(pos, length) + "' at " + at(pos));
        pos += length;
        return x;
      }

      void
      parse_primitive(const double sign)
      {
        const std::size_t start = pos;
        while (pos < s.size() && is_identifier_char(s[pos]))
          ++pos;
        std::string name = s.substr(start, pos - start);
        for (auto &c : name)
          c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));

        const ShapeInfo *info = nullptr;
        for (const auto &shape : shapes)
          if (name == shape.name)
            info = &shape;
        if (info == nullptr)
          fail("unknown shape '" + s.substr(start, pos - start) + "' at " + at(start) + " " +
               known_shapes(dim));
        if (info->dim != 0 && info->dim != dim)
          fail(std::to_string(info->dim) + "D shape '" + name + "' in a " + std::to_string(dim) +
               "D scene at " + at(start) + " " + known_shapes(dim));

        // The list of numbers; optional for 'all'.
        std::vector<double> x;
        skip_space();
        if (pos < s.size() && s[pos] == '(')
          {
            const std::size_t open = pos;
            ++pos;
            skip_space();
            if (pos < s.size() && s[pos] == ')')
              ++pos;
            else
              while (true)
                {
                  x.push_back(parse_number());
                  skip_space();
                  if (pos >= s.size())
                    fail("unbalanced parentheses: '(' at " + at(open) + " is never closed");
                  if (s[pos] == ',')
                    ++pos;
                  else if (s[pos] == ')')
                    {
                      ++pos;
                      break;
                    }
                  else
                    fail("expected ',' or ')' at " + at(pos) + ", found " + token_at(pos));
                }
          }
        else if (info->dim != 0)
          fail("expected '(' after '" + name + "' at " + at(pos) + ", found " + token_at(pos));

        const std::string here = " (" + name + " at " + at(start) + ")";
        const auto        need = [&](const unsigned int n) {
          if (x.size() != n)
            fail(name + " needs " + std::to_string(n) + " numbers (" + info->arguments +
                 "), got " + std::to_string(x.size()) + here);
        };
        const auto positive_radius = [&](const double r) {
          if (!(r > 0))
            fail(name + ": radius must be > 0, got " + to_string(r) + here);
        };

        Primitive primitive{};
        primitive.sign = sign;
        if (name == "all")
          {
            need(0);
            primitive.kind = Kind::all;
          }
        else if (name == "rectangle" || name == "box")
          {
            need(2 * dim);
            primitive.kind = (dim == 2 ? Kind::rectangle : Kind::box);
            for (unsigned int d = 0; d < dim; ++d)
              {
                if (x[d] == x[dim + d])
                  fail(name + ": the corners must differ in every coordinate, but both have " +
                       "coordinate " + std::to_string(d) + " = " + to_string(x[d]) + here);
                primitive.p[d]       = std::min(x[d], x[dim + d]);
                primitive.p[dim + d] = std::max(x[d], x[dim + d]);
              }
          }
        else if (name == "disk" || name == "sphere")
          {
            need(dim + 1);
            positive_radius(x[dim]);
            primitive.kind = (dim == 2 ? Kind::disk : Kind::sphere);
            std::copy(x.begin(), x.end(), primitive.p.begin());
          }
        else if (name == "cylinder")
          {
            need(7);
            positive_radius(x[6]);
            primitive.kind = Kind::cylinder;
            double length2 = 0;
            for (unsigned int d = 0; d < 3; ++d)
              {
                primitive.p[d]     = x[d];
                primitive.p[3 + d] = x[3 + d] - x[d];
                length2 += primitive.p[3 + d] * primitive.p[3 + d];
              }
            if (!(length2 > 0))
              fail(name + ": the axis end points must differ" + here);
            primitive.p[6] = x[6];
            primitive.p[7] = std::sqrt(length2);
          }
        else // polygon
          {
            if (x.size() < 6 || x.size() % 2 != 0)
              fail(name + " needs an even number of at least 6 numbers (" + info->arguments +
                   "), got " + std::to_string(x.size()) + here);
            primitive.kind         = Kind::polygon;
            primitive.first_vertex = region.vertices.size();
            primitive.n_vertices   = x.size() / 2;
            const unsigned int n   = primitive.n_vertices;
            std::vector<dealii::Point<2>> v(n);
            for (unsigned int i = 0; i < n; ++i)
              v[i] = dealii::Point<2>(x[2 * i], x[2 * i + 1]);
            double twice_area = 0;
            for (unsigned int i = 0; i < n; ++i)
              {
                const auto &a = v[i], &b = v[(i + 1) % n], &c = v[(i + 2) % n];
                twice_area += a[0] * b[1] - b[0] * a[1];
                if (a == b)
                  fail(name + ": vertices " + std::to_string(i + 1) + " and " +
                       std::to_string((i + 1) % n + 1) + " coincide" + here);
                // Adjacent edges may only share their common vertex.
                if (orientation(a, b, c) == 0 &&
                    (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]) < 0)
                  fail(name + ": edges " + std::to_string(i + 1) + " and " +
                       std::to_string((i + 1) % n + 1) +
                       " overlap (not a simple polygon)" + here);
              }
            for (unsigned int i = 0; i < n; ++i)
              for (unsigned int j = i + 2; j < n; ++j)
                if (!(i == 0 && j == n - 1) &&
                    segments_intersect(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]))
                  fail(name + ": edges " + std::to_string(i + 1) + " and " +
                       std::to_string(j + 1) + " intersect (not a simple polygon)" + here);
            if (!(std::abs(twice_area) > 0))
              fail(name + ": the polygon has zero area" + here);
            region.vertices.insert(region.vertices.end(), v.begin(), v.end());
          }
        region.primitives.push_back(primitive);
        emit(Op::push, region.primitives.size() - 1);
      }
    };



    template <int dim>
    Region<dim>::Region() = default;



    template <int dim>
    Region<dim>
    Region<dim>::parse(const std::string &expression, const std::string &where)
    {
      Region<dim> region;
      Parser      parser{expression, where, region};
      parser.skip_space();
      if (parser.pos == expression.size())
        throw InputError(where, "the expression is empty (expected e.g. " +
                                  std::string(dim == 2 ? "'rectangle(0, 0, 1, 1)')" :
                                                         "'box(0, 0, 0, 1, 1, 1)')"));
      parser.parse_expression(1.0);
      parser.skip_space();
      if (parser.pos < expression.size())
        {
          if (expression[parser.pos] == ')')
            parser.fail("unbalanced parentheses: ')' at " + Parser::at(parser.pos) +
                        " has no matching '('");
          parser.fail("unexpected " + parser.token_at(parser.pos) + " at " +
                      Parser::at(parser.pos) +
                      " after the end of the expression (expected '+' or '-')");
        }
      region.expression_string = expression;

      // The bounding box: union of the boxes of the added terms.
      std::vector<std::pair<dealii::Point<dim>, dealii::Point<dim>>> stack;
      for (const auto &instruction : region.program)
        {
          if (instruction.op == Op::push)
            {
              const Primitive   &q = region.primitives[instruction.index];
              dealii::Point<dim> lo, hi;
              switch (q.kind)
                {
                  case Kind::rectangle:
                  case Kind::box:
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        lo[d] = q.p[d];
                        hi[d] = q.p[dim + d];
                      }
                    break;
                  case Kind::disk:
                  case Kind::sphere:
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        lo[d] = q.p[d] - q.p[dim];
                        hi[d] = q.p[d] + q.p[dim];
                      }
                    break;
                  case Kind::cylinder:
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        const double c = q.p[3 + d] / q.p[7];
                        const double e = q.p[6] * std::sqrt(std::max(0.0, 1 - c * c));
                        lo[d] = std::min(q.p[d], q.p[d] + q.p[3 + d]) - e;
                        hi[d] = std::max(q.p[d], q.p[d] + q.p[3 + d]) + e;
                      }
                    break;
                  case Kind::polygon: // only in 2D
                    for (unsigned int d = 0; d < dim && d < 2; ++d)
                      {
                        lo[d] = infinity;
                        hi[d] = -infinity;
                        for (unsigned int i = 0; i < q.n_vertices; ++i)
                          {
                            lo[d] = std::min(lo[d], region.vertices[q.first_vertex + i][d]);
                            hi[d] = std::max(hi[d], region.vertices[q.first_vertex + i][d]);
                          }
                      }
                    break;
                  case Kind::all:
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        lo[d] = -infinity;
                        hi[d] = infinity;
                      }
                    break;
                }
              stack.emplace_back(lo, hi);
            }
          else
            {
              const auto b = stack.back();
              stack.pop_back();
              if (instruction.op == Op::unite)
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    stack.back().first[d]  = std::min(stack.back().first[d], b.first[d]);
                    stack.back().second[d] = std::max(stack.back().second[d], b.second[d]);
                  }
            }
        }
      Assert(stack.size() == 1, dealii::ExcInternalError());
      region.box = dealii::BoundingBox<dim>(stack.back());
      return region;
    }



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
        {
          const Primitive &q = primitives[program[0].index];
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
                  const dealii::Point<2> *v          = vertices.data() + q.first_vertex;
                  double                  twice_area = 0;
                  for (unsigned int i = 0, j = q.n_vertices - 1; i < q.n_vertices; j = i++)
                    twice_area += v[j][0] * v[i][1] - v[i][0] * v[j][1];
                  return 0.5 * std::abs(twice_area);
                }
              case Kind::all:
                return infinity;
            }
        }

      const unsigned int n          = (dim == 2 ? 512 : 96);
      double             cell_volume = 1;
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
          if (contains(p))
            ++count;
        }
      return count * cell_volume;
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



    template <int dim>
    double
    fill_particle_volume(const FillLattice<dim> &lattice, const unsigned int k)
    {
      AssertThrow(k >= 1, dealii::ExcMessage("fill: k must be >= 1"));
      return std::pow(lattice.h / k, dim);
    }



    template <int dim>
    std::vector<dealii::Point<dim>>
    fill(const Region<dim>                                                    &region,
         const FillLattice<dim>                                               &lattice,
         const unsigned int                                                    k,
         const std::array<unsigned int, dim>                                  &range_first,
         const std::array<unsigned int, dim>                                  &range_last,
         const std::function<bool(const std::array<unsigned int, dim> &cell)> &keep_cell)
    {
      AssertThrow(lattice.h > 0 && std::isfinite(lattice.h),
                  dealii::ExcMessage("fill: the lattice spacing h must be > 0"));
      AssertThrow(k >= 1, dealii::ExcMessage("fill: k must be >= 1"));
      std::vector<dealii::Point<dim>> points;
      if (region.is_empty())
        return points;

      const double h         = lattice.h;
      const double tolerance = 1e-12 * h;
      const double margin    = 1e-9 * h; // visiting one cell too many is harmless

      // The range of cells [first, last] whose box intersects the bounding box.
      const auto                    corners = region.bounding_box().get_boundary_points();
      std::array<unsigned int, dim> first, last;
      for (unsigned int d = 0; d < dim; ++d)
        {
          if (lattice.n_cells[d] == 0)
            return points;
          const double n  = lattice.n_cells[d];
          const double lo = (corners.first[d] - margin - lattice.origin[d]) / h - 1;
          const double hi = (corners.second[d] + margin - lattice.origin[d]) / h;
          const double f  = std::max<double>(range_first[d], std::ceil(std::min(lo, n)));
          const double l  = std::min<double>(std::min<double>(n - 1, range_last[d]),
                                             std::floor(std::max(hi, -1.0)));
          if (l < f)
            return points;
          first[d] = static_cast<unsigned int>(f);
          last[d]  = static_cast<unsigned int>(l);
        }

      const double                  sub_h = h / k;
      std::array<unsigned int, dim> cell  = first;
      std::array<unsigned int, dim> sub{};
      while (true)
        {
          if (!keep_cell || keep_cell(cell))
            {
              sub.fill(0);
              while (true)
                {
                  dealii::Point<dim> p;
                  for (unsigned int d = 0; d < dim; ++d)
                    p[d] = lattice.origin[d] + cell[d] * h + (sub[d] + 0.5) * sub_h;
                  if (region.contains(p, tolerance))
                    points.push_back(p);
                  unsigned int d = 0;
                  for (; d < dim; ++d)
                    if (++sub[d] < k)
                      break;
                    else
                      sub[d] = 0;
                  if (d == dim)
                    break;
                }
            }
          unsigned int d = 0;
          for (; d < dim; ++d)
            if (++cell[d] <= last[d])
              break;
            else
              cell[d] = first[d];
          if (d == dim)
            break;
        }
      return points;
    }



    template <int dim>
    std::vector<dealii::Point<dim>>
    fill(const Region<dim> &region, const FillLattice<dim> &lattice, const unsigned int k)
    {
      std::array<unsigned int, dim> first{}, last;
      for (unsigned int d = 0; d < dim; ++d)
        last[d] = lattice.n_cells[d] > 0 ? lattice.n_cells[d] - 1 : 0;
      return fill<dim>(region, lattice, k, first, last);
    }



    template class Region<2>;
    template class Region<3>;
    template struct FillLattice<2>;
    template struct FillLattice<3>;
    template std::vector<dealii::Point<2>>
    fill(const Region<2> &, const FillLattice<2> &, unsigned int);
    template std::vector<dealii::Point<3>>
    fill(const Region<3> &, const FillLattice<3> &, unsigned int);
    template std::vector<dealii::Point<2>>
    fill<2>(const Region<2> &,
              const FillLattice<2> &,
              unsigned int,
              const std::array<unsigned int, 2> &,
              const std::array<unsigned int, 2> &,
              const std::function<bool(const std::array<unsigned int, 2> &)> &);
    template std::vector<dealii::Point<3>>
    fill<3>(const Region<3> &,
              const FillLattice<3> &,
              unsigned int,
              const std::array<unsigned int, 3> &,
              const std::array<unsigned int, 3> &,
              const std::function<bool(const std::array<unsigned int, 3> &)> &);
    template double
    fill_particle_volume(const FillLattice<2> &, unsigned int);
    template double
    fill_particle_volume(const FillLattice<3> &, unsigned int);
  } // namespace Geometry
} // namespace hysteron

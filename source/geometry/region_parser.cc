// The parser of region expressions: shapes and their numbers checked with messages that
// name the offending token and its position, the postfix program, and its bounding box.
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

      /// A shape as read: where it starts, its name (lower case), description and numbers,
      /// and " (name at position N)" for the messages of its checks.
      struct Shape
      {
        std::size_t         start = 0;
        std::string         name;
        const ShapeInfo    *info = nullptr;
        std::vector<double> x;
        std::string         here;
      };

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

      /// A shape with its numbers: its primitive, added (@p sign = +1) or subtracted (-1).
      void
      parse_primitive(const double sign)
      {
        Shape shape = parse_shape_name();
        shape.x     = parse_numbers(shape);
        shape.here  = " (" + shape.name + " at " + at(shape.start) + ")";

        Primitive primitive{};
        primitive.sign = sign;
        if (shape.name == "all")
          {
            need(shape, 0);
            primitive.kind = Kind::all;
          }
        else if (shape.name == "rectangle" || shape.name == "box")
          make_box(shape, primitive);
        else if (shape.name == "disk" || shape.name == "sphere")
          make_ball(shape, primitive);
        else if (shape.name == "cylinder")
          make_cylinder(shape, primitive);
        else
          make_polygon(shape, primitive);
        region.primitives.push_back(primitive);
        emit(Op::push, region.primitives.size() - 1);
      }

      /// The shape named at the current position: a known one of this dimension, its name
      /// in lower case.
      Shape
      parse_shape_name()
      {
        Shape shape;
        shape.start = pos;
        while (pos < s.size() && is_identifier_char(s[pos]))
          ++pos;
        const std::string as_given = s.substr(shape.start, pos - shape.start);
        shape.name                 = as_given;
        for (auto &c : shape.name)
          c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));

        for (const auto &known : shapes)
          if (shape.name == known.name)
            shape.info = &known;
        if (shape.info == nullptr)
          fail("unknown shape '" + as_given + "' at " + at(shape.start) + " " + known_shapes(dim));
        if (shape.info->dim != 0 && shape.info->dim != dim)
          fail(std::to_string(shape.info->dim) + "D shape '" + shape.name + "' in a " +
               std::to_string(dim) + "D scene at " + at(shape.start) + " " + known_shapes(dim));
        return shape;
      }

      /// The list of numbers in parentheses after the shape's name; optional for 'all'.
      std::vector<double>
      parse_numbers(const Shape &shape)
      {
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
        else if (shape.info->dim != 0)
          fail("expected '(' after '" + shape.name + "' at " + at(pos) + ", found " +
               token_at(pos));
        return x;
      }

      /// The shape must have exactly @p n numbers.
      void
      need(const Shape &shape, const unsigned int n) const
      {
        if (shape.x.size() != n)
          fail(shape.name + " needs " + std::to_string(n) + " numbers (" + shape.info->arguments +
               "), got " + std::to_string(shape.x.size()) + shape.here);
      }

      void
      require_positive_radius(const Shape &shape, const double r) const
      {
        if (!(r > 0))
          fail(shape.name + ": radius must be > 0, got " + to_string(r) + shape.here);
      }

      /// rectangle/box: the lower corner, then the upper one (the corners in any order).
      void
      make_box(const Shape &shape, Primitive &primitive) const
      {
        const auto &x = shape.x;
        need(shape, 2 * dim);
        primitive.kind = (dim == 2 ? Kind::rectangle : Kind::box);
        for (unsigned int d = 0; d < dim; ++d)
          {
            if (x[d] == x[dim + d])
              fail(shape.name + ": the corners must differ in every coordinate, but both have " +
                   "coordinate " + std::to_string(d) + " = " + to_string(x[d]) + shape.here);
            primitive.p[d]       = std::min(x[d], x[dim + d]);
            primitive.p[dim + d] = std::max(x[d], x[dim + d]);
          }
      }

      /// disk/sphere: the centre, then the radius.
      void
      make_ball(const Shape &shape, Primitive &primitive) const
      {
        need(shape, dim + 1);
        require_positive_radius(shape, shape.x[dim]);
        primitive.kind = (dim == 2 ? Kind::disk : Kind::sphere);
        std::copy(shape.x.begin(), shape.x.end(), primitive.p.begin());
      }

      /// cylinder: p0, the axis p1 - p0, r and |p1 - p0|.
      void
      make_cylinder(const Shape &shape, Primitive &primitive) const
      {
        const auto &x = shape.x;
        need(shape, 7);
        require_positive_radius(shape, x[6]);
        primitive.kind = Kind::cylinder;
        double length2 = 0;
        for (unsigned int d = 0; d < 3; ++d)
          {
            primitive.p[d]     = x[d];
            primitive.p[3 + d] = x[3 + d] - x[d];
            length2 += primitive.p[3 + d] * primitive.p[3 + d];
          }
        if (!(length2 > 0))
          fail(shape.name + ": the axis end points must differ" + shape.here);
        primitive.p[6] = x[6];
        primitive.p[7] = std::sqrt(length2);
      }

      /// polygon: a simple polygon of nonzero area; its vertices go to the region's list.
      void
      make_polygon(const Shape &shape, Primitive &primitive)
      {
        const auto &x = shape.x;
        if (x.size() < 6 || x.size() % 2 != 0)
          fail(shape.name + " needs an even number of at least 6 numbers (" +
               shape.info->arguments + "), got " + std::to_string(x.size()) + shape.here);
        primitive.kind         = Kind::polygon;
        primitive.first_vertex = region.vertices.size();
        primitive.n_vertices   = x.size() / 2;
        const unsigned int n   = primitive.n_vertices;
        std::vector<dealii::Point<2>> v(n);
        for (unsigned int i = 0; i < n; ++i)
          v[i] = dealii::Point<2>(x[2 * i], x[2 * i + 1]);
        const double twice_area = check_adjacent_edges(shape, v);
        check_edge_crossings(shape, v);
        if (!(std::abs(twice_area) > 0))
          fail(shape.name + ": the polygon has zero area" + shape.here);
        region.vertices.insert(region.vertices.end(), v.begin(), v.end());
      }

      /// Consecutive vertices must differ and adjacent edges share only their common
      /// vertex. Returns twice the signed area (shoelace formula).
      double
      check_adjacent_edges(const Shape &shape, const std::vector<dealii::Point<2>> &v) const
      {
        const unsigned int n          = v.size();
        double             twice_area = 0;
        for (unsigned int i = 0; i < n; ++i)
          {
            const auto &a = v[i], &b = v[(i + 1) % n], &c = v[(i + 2) % n];
            twice_area += a[0] * b[1] - b[0] * a[1];
            if (a == b)
              fail(shape.name + ": vertices " + std::to_string(i + 1) + " and " +
                   std::to_string((i + 1) % n + 1) + " coincide" + shape.here);
            // Adjacent edges may only share their common vertex.
            if (orientation(a, b, c) == 0 &&
                (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]) < 0)
              fail(shape.name + ": edges " + std::to_string(i + 1) + " and " +
                   std::to_string((i + 1) % n + 1) + " overlap (not a simple polygon)" +
                   shape.here);
          }
        return twice_area;
      }

      /// Edges that are not adjacent must not meet.
      void
      check_edge_crossings(const Shape &shape, const std::vector<dealii::Point<2>> &v) const
      {
        const unsigned int n = v.size();
        for (unsigned int i = 0; i < n; ++i)
          for (unsigned int j = i + 2; j < n; ++j)
            if (!(i == 0 && j == n - 1) &&
                segments_intersect(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]))
              fail(shape.name + ": edges " + std::to_string(i + 1) + " and " +
                   std::to_string(j + 1) + " intersect (not a simple polygon)" + shape.here);
      }

      /// The box [lo, hi] of primitive @p q (infinite for `all`).
      std::pair<dealii::Point<dim>, dealii::Point<dim>>
      primitive_box(const Primitive &q) const
      {
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
              // The end disks reach r sqrt(1 - c^2) beyond the axis along a direction
              // whose cosine with the axis is c.
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
        return {lo, hi};
      }

      /// The program run on boxes: a union is the box of both boxes, a difference keeps
      /// the first box.
      dealii::BoundingBox<dim>
      program_box() const
      {
        std::vector<std::pair<dealii::Point<dim>, dealii::Point<dim>>> stack;
        for (const auto &instruction : region.program)
          {
            if (instruction.op == Op::push)
              {
                stack.push_back(primitive_box(region.primitives[instruction.index]));
                continue;
              }
            const auto b = stack.back();
            stack.pop_back();
            if (instruction.op == Op::unite)
              for (unsigned int d = 0; d < dim; ++d)
                {
                  stack.back().first[d]  = std::min(stack.back().first[d], b.first[d]);
                  stack.back().second[d] = std::max(stack.back().second[d], b.second[d]);
                }
          }
        Assert(stack.size() == 1, dealii::ExcInternalError());
        return dealii::BoundingBox<dim>(stack.back());
      }
    };



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
      region.box               = parser.program_box();
      return region;
    }



    template class Region<2>;
    template class Region<3>;
  } // namespace Geometry
} // namespace hysteron

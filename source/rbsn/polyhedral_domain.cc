// The polyhedral domain: its CSG program, point location, intersection and boundary.
#include <hysteron/base/exceptions.h>

#include "rbsn/polyhedron.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace hysteron
{
  namespace RBSN
  {
    namespace Polyhedral
    {
      namespace
      {
        /**
         * Whether the convex planar polygon @p face (on @p plane) meets the box @p b grown
         * by @p tolerance: no separating axis among the box's axes (the boxes already
         * overlap), the polygon's normal, and the cross products of its edges with the
         * box's axes.
         */
        bool
        meets(const std::vector<Point> &face, const Plane &plane, const Box &b, const double tolerance)
        {
          const Point  centre = Point(0.5 * (b.lo + b.hi));
          const Vector half   = 0.5 * (b.hi - b.lo);
          const auto   radius = [&](const Vector &axis) {
            return std::abs(axis[0]) * half[0] + std::abs(axis[1]) * half[1] + std::abs(axis[2]) * half[2];
          };
          if (std::abs(plane(centre)) > radius(plane.normal) + tolerance)
            return false;
          for (unsigned int e = 0; e < face.size(); ++e)
            {
              const Vector edge = face[(e + 1) % face.size()] - face[e];
              for (unsigned int k = 0; k < 3; ++k)
                {
                  Vector a;
                  a[k]               = 1;
                  const Vector axis  = cross_product_3d(edge, a);
                  const double norm  = axis.norm();
                  if (norm <= 1e-12 * edge.norm())
                    continue;
                  double lo = std::numeric_limits<double>::max(), hi = -lo;
                  for (const auto &v : face)
                    {
                      lo = std::min(lo, axis * (v - centre));
                      hi = std::max(hi, axis * (v - centre));
                    }
                  const double r = radius(axis);
                  if (lo > r + tolerance * norm || hi < -r - tolerance * norm)
                    return false;
                }
            }
          return true;
        }
      } // namespace



      Domain::Domain(const std::vector<const Geometry::Region<3> *> &bodies, const double h, const std::string &where)
      {
        require(!bodies.empty(), where, "there are no bodies");
        require(h > 0 && std::isfinite(h), where, "the resolution of curved boundaries must be > 0");
        using Op = Geometry::Region<3>::Op;
        for (const auto *body : bodies)
          {
            require(!body->is_empty(), where, "a body has no shape");
            const unsigned int offset = primitive.size();
            for (const auto &p : body->get_primitives())
              {
                require(p.kind != Geometry::Region<3>::Kind::all,
                        where,
                        "the shape '" + body->expression() +
                          "' contains 'all', which is unbounded: the RBSN needs bounded bodies");
                add_primitive(p, h);
              }
            std::vector<int> stack;
            for (const auto &instruction : body->get_program())
              {
                program.push_back(instruction);
                if (instruction.op == Op::push)
                  program.back().index += offset;
                Node node;
                node.op = instruction.op;
                if (instruction.op == Op::push)
                  {
                    node.primitive = offset + instruction.index;
                    node.box       = primitive[node.primitive].box;
                  }
                else
                  {
                    node.right = stack.back();
                    stack.pop_back();
                    node.left = stack.back();
                    stack.pop_back();
                    node.box = nodes[node.left].box;
                    if (node.op == Op::unite)
                      node.box.add(nodes[node.right].box);
                  }
                stack.push_back(nodes.size());
                nodes.push_back(node);
              }
            Assert(stack.size() == 1, dealii::ExcInternalError());
            if (root < 0)
              root = stack[0];
            else
              {
                program.push_back({Op::unite, 0});
                Node node;
                node.op    = Op::unite;
                node.left  = root;
                node.right = stack[0];
                node.box   = nodes[root].box;
                node.box.add(nodes[stack[0]].box);
                root = nodes.size();
                nodes.push_back(node);
              }
          }
        box   = nodes[root].box;
        scale = box.lo.distance(box.hi);
        double extent = 0;
        for (unsigned int d = 0; d < 3; ++d)
          extent = std::max({extent, std::abs(box.lo[d]), std::abs(box.hi[d])});
        require(std::isfinite(scale) && scale > 0, where, "the bodies are unbounded or empty");
        tolerance = 1e-13 * (scale + extent);

        // Planes that coincide (within the tolerance), found among the planes of
        // equal rounded normal and offset: the faces on them share that plane.
        coplanar.assign(planes.size(), {});
        std::map<std::array<long long, 4>, std::vector<unsigned int>> groups;
        for (unsigned int p = 0; p < planes.size(); ++p)
          {
            // Orient every plane alike (first clearly nonzero component positive).
            Vector       n = planes[p].normal;
            double       c = planes[p].offset;
            unsigned int k = 0;
            while (k < 2 && std::abs(n[k]) < 1e-6)
              ++k;
            if (n[k] < 0)
              {
                n = -n;
                c = -c;
              }
            const std::array<long long, 4> key{{std::llround(n[0] * 1e9),
                                                std::llround(n[1] * 1e9),
                                                std::llround(n[2] * 1e9),
                                                std::llround(c / (scale + extent) * 1e9)}};
            groups[key].push_back(p);
          }
        for (const auto &group : groups)
          for (const unsigned int p : group.second)
            for (const unsigned int q : group.second)
              if (p != q && plane_primitive[p] != plane_primitive[q])
                {
                  const double same = planes[p].normal * planes[q].normal;
                  const double gap =
                    same > 0 ? planes[p].offset - planes[q].offset : planes[p].offset + planes[q].offset;
                  if (std::abs(std::abs(same) - 1) < 1e-12 && std::abs(gap) < 1e3 * tolerance)
                    coplanar[p].emplace_back(q, same > 0);
                }
      }



      bool
      Domain::primitive_contains(const Primitive &q, const Point &p, const double t) const
      {
        const Plane *plane = planes.data() + q.first_plane;
        // Outside its box (grown by more than any grown corner moves): outside.
        const double margin = 10 * std::abs(t) + tolerance;
        for (unsigned int d = 0; d < 3; ++d)
          if (p[d] < q.box.lo[d] - margin || p[d] > q.box.hi[d] + margin)
            return false;
        switch (q.shape)
          {
            case Primitive::Shape::box:
              for (unsigned int f = 0; f < 6; ++f)
                if (plane[f](p) > t)
                  return false;
              return true;
            case Primitive::Shape::prism:
              {
                // The axial planes, then the side whose angular range holds p (it
                // maximises n . p - c) and its two neighbours (rounding).
                const Vector y     = p - q.centre;
                const double axial = y * q.axis;
                if (std::abs(axial) > 0.5 * q.length + t)
                  return false;
                const unsigned int n = q.sides;
                double             angle = std::atan2(y * q.w, y * q.u);
                if (angle < 0)
                  angle += 2 * M_PI;
                const int k = static_cast<int>(std::floor(angle / (2 * M_PI / n)));
                for (int s = k - 1; s <= k + 1; ++s)
                  if (plane[(s + 2 * n) % n](p) > t)
                    return false;
                return true;
              }
            case Primitive::Shape::polyhedron:
              {
                const Vector y   = p - q.centre;
                const double rho = y.norm();
                if (rho <= q.inradius + t)
                  return true;
                if (rho > q.outradius + 2 * std::abs(t) + tolerance) // the vertices lie on the sphere
                  return false;
                Box direction;
                direction.add(Point(y / rho));
                std::vector<unsigned int> faces;
                q.normal_tree.query(direction, 0.5 * q.cone, faces);
                for (const unsigned int f : faces)
                  if (plane[f](p) > t)
                    return false;
                return true;
              }
          }
        return false;
      }



      bool
      Domain::contains(const Point &p, const double tolerance) const
      {
        const double margin = 10 * std::abs(tolerance) + this->tolerance;
        for (unsigned int d = 0; d < 3; ++d)
          if (p[d] < box.lo[d] - margin || p[d] > box.hi[d] + margin)
            return false;
        // The postfix program (the bodies' programs joined by unions).
        bool         stack[Geometry::Region<3>::max_stack_depth + 2];
        unsigned int top = 0;
        for (const auto &instruction : program)
          switch (instruction.op)
            {
              case Geometry::Region<3>::Op::push:
                {
                  const Primitive &q = primitive[instruction.index];
                  stack[top++]       = primitive_contains(q, p, q.sign * tolerance);
                  break;
                }
              case Geometry::Region<3>::Op::unite:
                --top;
                stack[top - 1] = stack[top - 1] || stack[top];
                break;
              case Geometry::Region<3>::Op::subtract:
                --top;
                stack[top - 1] = stack[top - 1] && !stack[top];
                break;
            }
        return stack[0];
      }



      Domain::Side
      Domain::side(const unsigned int plane, const Vector &direction) const
      {
        Side s;
        const auto add = [&](const unsigned int p) {
          // Beyond a face (the plane's normal along the direction) its primitive is not;
          // behind it the primitive continues across the plane, which is dropped.
          if (planes[p].normal * direction > 0)
            s.changes.emplace_back(plane_primitive[p], -1);
          else
            s.changes.emplace_back(plane_primitive[p], static_cast<int>(p));
        };
        add(plane);
        for (const auto &c : coplanar[plane])
          add(c.first);
        return s;
      }



      void
      Domain::near_planes(const Primitive &q, const Box &b, std::vector<unsigned int> &result) const
      {
        // The faces that meet the box (their boxes first). Only those bound P inside it.
        result.clear();
        if (q.face_tree.empty())
          {
            for (unsigned int f = 0; f < q.faces.size(); ++f)
              if (q.face_boxes[f].overlaps(b, tolerance))
                result.push_back(f);
          }
        else
          q.face_tree.query(b, tolerance, result);
        unsigned int kept = 0;
        for (const unsigned int f : result)
          if (meets(q.faces[f], planes[q.first_plane + f], b, 2 * tolerance))
            result[kept++] = q.first_plane + f;
        result.resize(kept);
      }



      template <class Shape>
      void
      Domain::inside(const int k, const Shape &X, const Side *side, std::vector<Shape> &out, Clipper &clipper) const
      {
        const Node &node = nodes[k];
        const Box   b    = X.bounding_box();
        if (!b.overlaps(node.box, tolerance))
          return;
        switch (node.op)
          {
            case Geometry::Region<3>::Op::push:
              {
                // X n P = X n (the half-spaces of the faces of P that meet X's box B):
                // within B, P is bounded by those faces alone. Without such a face, X
                // lies inside P or outside.
                const int dropped = Side::change(side, node.primitive);
                if (dropped == -1)
                  return;
                const Primitive          &q = primitive[node.primitive];
                std::vector<unsigned int> near;
                near_planes(q, b, near);
                if (near.empty())
                  {
                    if (primitive_contains(q, X.vertex_mean(), 0))
                      out.push_back(X);
                    return;
                  }
                Shape current = X, next;
                for (const unsigned int p : near)
                  if (static_cast<int>(p) != dropped)
                    switch (clipper.clip(current, planes[p], plane_tag(p, false), next))
                      {
                        case Cut::outside:
                          return;
                        case Cut::cut:
                          std::swap(current, next);
                          break;
                        case Cut::inside:
                          break;
                      }
                out.push_back(std::move(current));
                return;
              }
            case Geometry::Region<3>::Op::unite:
              {
                // X n (A u B) = (X n A) + ((X \ A) n B)
                inside(node.left, X, side, out, clipper);
                std::vector<Shape> rest;
                outside(node.left, X, side, rest, clipper);
                for (const auto &Y : rest)
                  inside(node.right, Y, side, out, clipper);
                return;
              }
            case Geometry::Region<3>::Op::subtract:
              {
                // X n (A \ B) = (X n A) \ B
                std::vector<Shape> in;
                inside(node.left, X, side, in, clipper);
                for (const auto &Y : in)
                  outside(node.right, Y, side, out, clipper);
                return;
              }
          }
      }



      template <class Shape>
      void
      Domain::outside(const int k, const Shape &X, const Side *side, std::vector<Shape> &out, Clipper &clipper) const
      {
        const Node &node = nodes[k];
        const Box   b    = X.bounding_box();
        if (!b.overlaps(node.box, tolerance))
          {
            out.push_back(X);
            return;
          }
        switch (node.op)
          {
            case Geometry::Region<3>::Op::push:
              {
                // X \ P = U_j X n h_1 n ... n h_(j-1) n not h_j over the near faces.
                const int dropped = Side::change(side, node.primitive);
                if (dropped == -1)
                  {
                    out.push_back(X);
                    return;
                  }
                const Primitive          &q = primitive[node.primitive];
                std::vector<unsigned int> near;
                near_planes(q, b, near);
                if (near.empty())
                  {
                    if (!primitive_contains(q, X.vertex_mean(), 0))
                      out.push_back(X);
                    return;
                  }
                Shape rest = X, piece;
                for (const unsigned int p : near)
                  if (static_cast<int>(p) != dropped)
                    {
                      switch (clipper.clip(rest, planes[p].flipped(), plane_tag(p, true), piece))
                        {
                          case Cut::outside: // rest lies in h_p
                            continue;
                          case Cut::inside: // rest lies beyond h_p: outside P
                            out.push_back(std::move(rest));
                            return;
                          case Cut::cut:
                            out.push_back(std::move(piece));
                            break;
                        }
                      Shape next;
                      if (clipper.clip(rest, planes[p], plane_tag(p, false), next) == Cut::cut)
                        rest = std::move(next);
                    }
                return; // what is left lies in P
              }
            case Geometry::Region<3>::Op::unite:
              {
                // X \ (A u B) = (X \ A) \ B
                std::vector<Shape> rest;
                outside(node.left, X, side, rest, clipper);
                for (const auto &Y : rest)
                  outside(node.right, Y, side, out, clipper);
                return;
              }
            case Geometry::Region<3>::Op::subtract:
              {
                // X \ (A \ B) = (X \ A) + ((X n A) n B)
                outside(node.left, X, side, out, clipper);
                std::vector<Shape> in;
                inside(node.left, X, side, in, clipper);
                for (const auto &Y : in)
                  inside(node.right, Y, side, out, clipper);
                return;
              }
          }
      }



      void
      Domain::intersect(const ConvexPolyhedron &X, std::vector<ConvexPolyhedron> &pieces, Clipper &clipper) const
      {
        inside(root, X, nullptr, pieces, clipper);
      }



      void
      Domain::boundary_part(const ConvexPolygon        &G,
                            const unsigned int          plane,
                            std::vector<ConvexPolygon> &result,
                            Clipper                    &clipper) const
      {
        const Side beyond = side(plane, G.normal);
        outside(root, G, &beyond, result, clipper);
      }



      std::vector<BoundaryPolygon>
      Domain::boundary() const
      {
        Clipper                      clipper(tolerance);
        std::vector<BoundaryPolygon> result;
        std::vector<ConvexPolygon>   behind_pieces, parts, rest, pieces;
        for (unsigned int qi = 0; qi < primitive.size(); ++qi)
          for (unsigned int f = 0; f < primitive[qi].faces.size(); ++f)
            {
              const unsigned int p = primitive[qi].first_plane + f;
              const Vector       n = planes[p].normal;
              const ConvexPolygon F{primitive[qi].faces[f], n};
              const Side          behind = side(p, -n), beyond = side(p, n);
              for (const bool flipped : {false, true})
                {
                  // The domain on one side of F and not on the other: the outward normal
                  // points to the side without it.
                  behind_pieces.clear();
                  parts.clear();
                  inside(root, F, flipped ? &beyond : &behind, behind_pieces, clipper);
                  for (const auto &Y : behind_pieces)
                    outside(root, Y, flipped ? &behind : &beyond, parts, clipper);
                  // A face of an earlier primitive on the same plane has these parts already.
                  for (const auto &c : coplanar[p])
                    if (c.first < p && !parts.empty())
                      {
                        const Primitive    &o    = primitive[plane_primitive[c.first]];
                        const auto         &loop = o.faces[c.first - o.first_plane];
                        const Vector        m    = planes[c.first].normal;
                        rest.clear();
                        for (auto &Y : parts)
                          {
                            // Y minus the convex face: Y n e_1 n ... n e_(j-1) n not e_j over
                            // its edges' outward half-planes e_j.
                            ConvexPolygon current = Y, piece, next;
                            bool          left    = true;
                            for (unsigned int e = 0; e < loop.size() && left; ++e)
                              {
                                const Point &a = loop[e], &b = loop[(e + 1) % loop.size()];
                                const Vector out = unit(cross_product_3d(b - a, m));
                                const Plane  edge{out, out * a};
                                const Cut    cut = clipper.clip(current, edge.flipped(), 0, piece);
                                if (cut == Cut::outside)
                                  continue;
                                if (cut == Cut::inside)
                                  {
                                    rest.push_back(current);
                                    left = false;
                                    break;
                                  }
                                rest.push_back(piece);
                                if (clipper.clip(current, edge, 0, next) == Cut::cut)
                                  current = next;
                              }
                          }
                        parts.swap(rest);
                      }
                  for (auto &Y : parts)
                    {
                      BoundaryPolygon b;
                      b.polygon = std::move(Y);
                      b.plane   = p;
                      b.flipped = flipped;
                      if (flipped)
                        {
                          std::reverse(b.polygon.vertices.begin(), b.polygon.vertices.end());
                          b.polygon.normal = -n;
                        }
                      result.push_back(std::move(b));
                    }
                }
            }
        return result;
      }



      double
      Domain::volume() const
      {
        return volume(boundary());
      }



      double
      Domain::volume(const std::vector<BoundaryPolygon> &boundary)
      {
        // The divergence theorem with div x = 3: V = 1/3 sum over the boundary of
        // x . n A (x any point of a planar polygon: x . n is constant on it).
        double v = 0;
        for (const auto &b : boundary)
          v += b.polygon.vertices[0] * area_vector(b.polygon.vertices.data(), b.polygon.vertices.size()) / 3;
        return v;
      }
    } // namespace Polyhedral
  }   // namespace RBSN
} // namespace hysteron

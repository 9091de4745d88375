#include <hysteron/base/exceptions.h>

#include "rbsn/polyhedron.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace hysteron
{
  namespace RBSN
  {
    namespace Polyhedral
    {
      namespace
      {
        Vector
        unit(const Vector &v)
        {
          return v / v.norm();
        }

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



      void
      ConvexPolyhedron::make_box(const Point &lo, const Point &hi, const int tag)
      {
        clear();
        // Vertex v has the coordinate d from hi if bit d of v is set.
        for (unsigned int v = 0; v < 8; ++v)
          vertices.emplace_back((v & 1) ? hi[0] : lo[0], (v & 2) ? hi[1] : lo[1], (v & 4) ? hi[2] : lo[2]);
        // -x, +x, -y, +y, -z, +z, each counter-clockwise seen from outside.
        static const unsigned int loops[6][4] = {
          {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
        for (const auto &loop : loops)
          {
            face_vertices.insert(face_vertices.end(), loop, loop + 4);
            face_start.push_back(face_vertices.size());
            tags.push_back(tag);
          }
      }



      std::vector<Point>
      ConvexPolyhedron::face(const unsigned int f) const
      {
        std::vector<Point> loop;
        for (unsigned int k = face_start[f]; k < face_start[f + 1]; ++k)
          loop.push_back(vertices[face_vertices[k]]);
        return loop;
      }



      Vector
      perpendicular(const Vector &n)
      {
        // The coordinate axis least aligned with n, made orthogonal to it.
        unsigned int k = 0;
        for (unsigned int d = 1; d < 3; ++d)
          if (std::abs(n[d]) < std::abs(n[k]))
            k = d;
        Vector e;
        e[k] = 1;
        return unit(e - (e * n) * n);
      }



      Vector
      area_vector(const Point *loop, const unsigned int n)
      {
        Vector a;
        for (unsigned int k = 1; k + 1 < n; ++k)
          a += cross_product_3d(loop[k] - loop[0], loop[k + 1] - loop[0]);
        return 0.5 * a;
      }



      Cut
      Clipper::classify(const std::vector<Point> &vertices, const Plane &plane)
      {
        value.resize(vertices.size());
        double lo = std::numeric_limits<double>::max(), hi = -lo;
        for (unsigned int v = 0; v < vertices.size(); ++v)
          {
            value[v] = plane(vertices[v]);
            lo       = std::min(lo, value[v]);
            hi       = std::max(hi, value[v]);
          }
        if (hi <= tolerance)
          return Cut::inside;
        if (lo >= -tolerance)
          return Cut::outside;
        return Cut::cut;
      }



      Cut
      Clipper::clip(const ConvexPolyhedron &in, const Plane &plane, const int tag, ConvexPolyhedron &out)
      {
        const unsigned int nv = in.vertices.size();
        if (const Cut c = classify(in.vertices, plane); c != Cut::cut)
          return c;

        // The vertices kept (in the half-space or on the plane), then one new vertex on
        // every edge from strictly inside to strictly outside, shared by its two faces.
        out.clear();
        index.assign(nv, -1);
        for (unsigned int v = 0; v < nv; ++v)
          if (value[v] <= tolerance)
            {
              index[v] = out.vertices.size();
              out.vertices.push_back(in.vertices[v]);
            }
        const unsigned int n_kept = out.vertices.size();
        cuts.clear();
        const auto cut_vertex = [&](const unsigned int a, const unsigned int b) {
          const auto key = std::make_pair(std::min(a, b), std::max(a, b));
          for (const auto &c : cuts)
            if (c.first == key)
              return c.second;
          // From the inside vertex i to the outside vertex o: value 0 at t = f_i / (f_i - f_o).
          const unsigned int i = value[a] < 0 ? a : b, o = value[a] < 0 ? b : a;
          const double       t = value[i] / (value[i] - value[o]);
          const unsigned int k = out.vertices.size();
          out.vertices.push_back(in.vertices[i] + t * (in.vertices[o] - in.vertices[i]));
          cuts.emplace_back(key, k);
          return k;
        };
        for (unsigned int f = 0; f < in.n_faces(); ++f)
          {
            const unsigned int begin = out.face_vertices.size();
            const unsigned int first = in.face_start[f], m = in.face_start[f + 1] - first;
            bool               strict = false; // a vertex strictly inside
            for (unsigned int k = 0; k < m; ++k)
              {
                const unsigned int a = in.face_vertices[first + k], b = in.face_vertices[first + (k + 1) % m];
                if (value[a] <= tolerance)
                  {
                    out.face_vertices.push_back(index[a]);
                    strict = strict || value[a] < -tolerance;
                  }
                if ((value[a] < -tolerance && value[b] > tolerance) || (value[a] > tolerance && value[b] < -tolerance))
                  out.face_vertices.push_back(cut_vertex(a, b));
              }
            // A face without a vertex strictly inside lies on the plane (or is a sliver of
            // it): the new face replaces it.
            if (!strict || out.face_vertices.size() - begin < 3)
              out.face_vertices.resize(begin);
            else
              {
                out.face_start.push_back(out.face_vertices.size());
                out.tags.push_back(in.tags[f]);
              }
          }

        // The vertices on the plane: merge those closer than the tolerance (the first
        // one stays), then drop repeated vertices from the loops.
        const unsigned int nout = out.vertices.size();
        cap.clear();
        for (unsigned int v = 0; v < nv; ++v)
          if (index[v] >= 0 && value[v] >= -tolerance)
            cap.push_back(index[v]);
        for (unsigned int k = n_kept; k < nout; ++k)
          cap.push_back(k);
        merged.resize(nout);
        std::iota(merged.begin(), merged.end(), 0u);
        bool any_merged = false;
        for (unsigned int a = 0; a < cap.size(); ++a)
          if (merged[cap[a]] == cap[a])
            for (unsigned int b = a + 1; b < cap.size(); ++b)
              if (merged[cap[b]] == cap[b] &&
                  out.vertices[cap[a]].distance_square(out.vertices[cap[b]]) <= tolerance * tolerance)
                {
                  merged[cap[b]] = cap[a];
                  any_merged     = true;
                }
        if (any_merged)
          {
            std::vector<unsigned int> start{0}, loops;
            std::vector<int>          kept_tags;
            for (unsigned int f = 0; f < out.n_faces(); ++f)
              {
                const unsigned int begin = loops.size();
                const unsigned int first = out.face_start[f], m = out.face_start[f + 1] - first;
                for (unsigned int k = 0; k < m; ++k)
                  {
                    const unsigned int v = merged[out.face_vertices[first + k]];
                    if (loops.size() == begin || loops.back() != v)
                      loops.push_back(v);
                  }
                while (loops.size() - begin > 1 && loops.back() == loops[begin])
                  loops.pop_back();
                if (loops.size() - begin < 3)
                  loops.resize(begin);
                else
                  {
                    start.push_back(loops.size());
                    kept_tags.push_back(out.tags[f]);
                  }
              }
            out.face_start.swap(start);
            out.face_vertices.swap(loops);
            out.tags.swap(kept_tags);
          }

        // The new face: the (merged) vertices on the plane that the faces use, sorted by
        // their angle about the plane's normal (counter-clockwise seen from outside).
        used.assign(nout, false);
        for (const unsigned int v : out.face_vertices)
          used[v] = true;
        order.clear();
        for (const unsigned int v : cap)
          if (used[v] && merged[v] == v)
            order.push_back(v);
        if (order.size() >= 3)
          {
            Vector centre;
            for (const unsigned int v : order)
              centre += out.vertices[v];
            centre /= static_cast<double>(order.size());
            const Vector e1 = perpendicular(plane.normal), e2 = cross_product_3d(plane.normal, e1);
            angle.resize(nout);
            for (const unsigned int v : order)
              {
                const Vector r = out.vertices[v] - Point(centre);
                angle[v]       = std::atan2(r * e2, r * e1);
              }
            std::sort(order.begin(), order.end(), [&](const unsigned int a, const unsigned int b) {
              return angle[a] < angle[b] || (angle[a] == angle[b] && a < b);
            });
            out.face_vertices.insert(out.face_vertices.end(), order.begin(), order.end());
            out.face_start.push_back(out.face_vertices.size());
            out.tags.push_back(tag);
          }
        if (out.n_faces() < 4)
          {
            out.clear();
            return Cut::outside; // nothing of volume is left
          }

        // Drop the vertices no face uses (merged ones, those of dropped faces).
        used.assign(nout, false);
        for (const unsigned int v : out.face_vertices)
          used[v] = true;
        if (std::find(used.begin(), used.end(), false) != used.end())
          {
            std::vector<unsigned int> number(nout, 0);
            unsigned int              count = 0;
            for (unsigned int v = 0; v < nout; ++v)
              if (used[v])
                {
                  number[v]             = count;
                  out.vertices[count++] = out.vertices[v];
                }
            out.vertices.resize(count);
            for (auto &v : out.face_vertices)
              v = number[v];
          }
        return Cut::cut;
      }



      Cut
      Clipper::clip(const ConvexPolygon &in, const Plane &plane, const int, ConvexPolygon &out)
      {
        const unsigned int n = in.vertices.size();
        if (const Cut c = classify(in.vertices, plane); c != Cut::cut)
          return c;
        // Sutherland-Hodgman for one plane; the new point computed from the inside end.
        out.vertices.clear();
        out.normal = in.normal;
        const auto push = [&](const Point &p) {
          if (out.vertices.empty() || out.vertices.back().distance_square(p) > tolerance * tolerance)
            out.vertices.push_back(p);
        };
        for (unsigned int k = 0; k < n; ++k)
          {
            const unsigned int a = k, b = (k + 1) % n;
            if (value[a] <= tolerance)
              push(in.vertices[a]);
            if ((value[a] < -tolerance && value[b] > tolerance) || (value[a] > tolerance && value[b] < -tolerance))
              {
                const unsigned int i = value[a] < 0 ? a : b, o = value[a] < 0 ? b : a;
                const double       t = value[i] / (value[i] - value[o]);
                push(in.vertices[i] + t * (in.vertices[o] - in.vertices[i]));
              }
          }
        while (out.vertices.size() > 1 &&
               out.vertices.back().distance_square(out.vertices.front()) <= tolerance * tolerance)
          out.vertices.pop_back();
        if (out.vertices.size() < 3)
          {
            out.vertices.clear();
            return Cut::outside;
          }
        return Cut::cut;
      }



      void
      Moments::add_volume(const ConvexPolyhedron &p, const Point &r)
      {
        // Each face's fan triangles (v0, vk, vk+1) with r form tetrahedra of signed
        // volume V = a . (b x c) / 6 (a, b, c the vertices relative to r), whose
        // integrals are V (a + b + c) / 4 and V / 20 (a a^T + b b^T + c c^T + s s^T),
        // s = a + b + c (the moments of a simplex with a vertex at the origin).
        for (unsigned int f = 0; f < p.n_faces(); ++f)
          {
            const unsigned int begin = p.face_start[f], m = p.face_start[f + 1] - begin;
            const Vector       a     = p.vertices[p.face_vertices[begin]] - r;
            for (unsigned int k = 1; k + 1 < m; ++k)
              {
                const Vector b = p.vertices[p.face_vertices[begin + k]] - r;
                const Vector c = p.vertices[p.face_vertices[begin + k + 1]] - r;
                const double V = a * cross_product_3d(b, c) / 6;
                const Vector s = a + b + c;
                measure += V;
                first += (V / 4) * s;
                for (unsigned int i = 0; i < 3; ++i)
                  for (unsigned int j = i; j < 3; ++j)
                    second[i][j] += V / 20 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]);
              }
          }
      }



      void
      Moments::add_area(const Point *loop, const unsigned int n, const Vector &normal, const Point &r)
      {
        // Fan triangles of area A: int (x - r) = A s / 3, int (x - r)(x - r)^T =
        // A / 12 (a a^T + b b^T + c c^T + s s^T), s = a + b + c.
        const Vector a = loop[0] - r;
        for (unsigned int k = 1; k + 1 < n; ++k)
          {
            const Vector b = loop[k] - r, c = loop[k + 1] - r;
            const double A = 0.5 * (cross_product_3d(b - a, c - a) * normal);
            const Vector s = a + b + c;
            measure += A;
            first += (A / 3) * s;
            for (unsigned int i = 0; i < 3; ++i)
              for (unsigned int j = i; j < 3; ++j)
                second[i][j] += A / 12 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]);
          }
      }



      void
      BoxTree::build(std::vector<Box> b)
      {
        boxes = std::move(b);
        order.resize(boxes.size());
        std::iota(order.begin(), order.end(), 0u);
        nodes.clear();
        if (!boxes.empty())
          make(0, boxes.size());
      }



      int
      BoxTree::make(const unsigned int first, const unsigned int count)
      {
        const int self = nodes.size();
        nodes.emplace_back();
        Box box, centres;
        for (unsigned int k = first; k < first + count; ++k)
          {
            box.add(boxes[order[k]]);
            centres.add(Point(0.5 * (boxes[order[k]].lo + boxes[order[k]].hi)));
          }
        nodes[self].box = box;
        if (count <= 4)
          {
            nodes[self].first = first;
            nodes[self].count = count;
            return self;
          }
        unsigned int axis = 0;
        for (unsigned int d = 1; d < 3; ++d)
          if (centres.hi[d] - centres.lo[d] > centres.hi[axis] - centres.lo[axis])
            axis = d;
        const unsigned int half = count / 2;
        std::nth_element(order.begin() + first,
                         order.begin() + first + half,
                         order.begin() + first + count,
                         [&](const unsigned int a, const unsigned int b) {
                           const double ca = boxes[a].lo[axis] + boxes[a].hi[axis],
                                        cb = boxes[b].lo[axis] + boxes[b].hi[axis];
                           return ca < cb || (ca == cb && a < b);
                         });
        const int left     = make(first, half);
        const int right    = make(first + half, count - half);
        nodes[self].left  = left;
        nodes[self].right = right;
        return self;
      }



      void
      BoxTree::query(const Box &q, const double tolerance, std::vector<unsigned int> &result) const
      {
        if (nodes.empty())
          return;
        const std::size_t begin = result.size();
        int               stack[128];
        unsigned int      top = 0;
        stack[top++]          = 0;
        while (top > 0)
          {
            const Node &node = nodes[stack[--top]];
            if (!node.box.overlaps(q, tolerance))
              continue;
            if (node.left < 0)
              {
                for (unsigned int k = node.first; k < node.first + node.count; ++k)
                  if (boxes[order[k]].overlaps(q, tolerance))
                    result.push_back(order[k]);
              }
            else
              {
                stack[top++] = node.left;
                stack[top++] = node.right;
              }
          }
        std::sort(result.begin() + begin, result.end());
      }



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



      void
      Domain::add_primitive(const Geometry::Region<3>::Primitive &p, const double h)
      {
        using Kind = Geometry::Region<3>::Kind;
        Primitive q;
        q.sign        = p.sign;
        q.first_plane = planes.size();
        std::vector<Point> vertices;
        std::vector<Plane> face_planes;
        if (p.kind == Kind::box)
          {
            q.shape = Primitive::Shape::box;
            ConvexPolyhedron b;
            b.make_box(Point(p.p[0], p.p[1], p.p[2]), Point(p.p[3], p.p[4], p.p[5]), 0);
            vertices = b.vertices;
            for (unsigned int f = 0; f < 6; ++f)
              {
                q.faces.push_back(b.face(f));
                const unsigned int d = f / 2;
                Plane              plane;
                plane.normal[d] = f % 2 == 0 ? -1 : 1;
                plane.offset    = f % 2 == 0 ? -p.p[d] : p.p[3 + d];
                face_planes.push_back(plane);
              }
            q.centre = Point(0.5 * (b.vertices[0] + b.vertices[7]));
          }
        else if (p.kind == Kind::cylinder)
          {
            // The inscribed prism: the regular n-gon of Region<2>::disk_polygon() in the
            // frame (u, w) normal to the axis t (u x w = t), its quadrants exact rotations.
            q.shape = Primitive::Shape::prism;
            const Point  p0(p.p[0], p.p[1], p.p[2]);
            const Vector a({p.p[3], p.p[4], p.p[5]});
            const double r = p.p[6];
            q.length       = a.norm();
            q.axis         = a / q.length;
            unsigned int m = 0;
            for (unsigned int d = 1; d < 3; ++d)
              if (std::abs(q.axis[d]) > std::abs(q.axis[m]))
                m = d;
            Vector e;
            e[(m + 1) % 3] = 1;
            q.u            = unit(e - (e * q.axis) * q.axis);
            q.w            = cross_product_3d(q.axis, q.u);
            const unsigned int n = Geometry::Region<3>::n_disk_sides(r, h), quarter = n / 4;
            q.sides              = n;
            std::vector<Vector> ring(n), normal(n);
            for (unsigned int k = 0; k < quarter; ++k)
              {
                const double phi = 2 * M_PI * k / n, mid = 2 * M_PI * (k + 0.5) / n;
                const double c = k == 0 ? 1.0 : std::cos(phi), s = k == 0 ? 0.0 : std::sin(phi);
                const double cm = std::cos(mid), sm = std::sin(mid);
                const double x[4] = {c, -s, -c, s}, y[4] = {s, c, -s, -c};
                const double xm[4] = {cm, -sm, -cm, sm}, ym[4] = {sm, cm, -sm, -cm};
                for (unsigned int r4 = 0; r4 < 4; ++r4)
                  {
                    ring[r4 * quarter + k]   = r * (x[r4] * q.u + y[r4] * q.w);
                    normal[r4 * quarter + k] = xm[r4] * q.u + ym[r4] * q.w;
                  }
              }
            const Point p1 = p0 + a;
            for (unsigned int k = 0; k < n; ++k)
              vertices.push_back(p0 + ring[k]);
            for (unsigned int k = 0; k < n; ++k)
              vertices.push_back(p1 + ring[k]);
            const double inset = r * std::cos(M_PI / n);
            for (unsigned int k = 0; k < n; ++k)
              {
                const unsigned int k1 = (k + 1) % n;
                q.faces.push_back({vertices[k], vertices[k1], vertices[n + k1], vertices[n + k]});
                face_planes.push_back(Plane{normal[k], normal[k] * p0 + inset});
              }
            std::vector<Point> bottom(vertices.rbegin() + n, vertices.rend());
            q.faces.push_back(bottom);
            face_planes.push_back(Plane{-q.axis, -(q.axis * p0)});
            q.faces.emplace_back(vertices.begin() + n, vertices.end());
            face_planes.push_back(Plane{q.axis, q.axis * p1});
            q.centre = p0 + 0.5 * a;
          }
        else
          {
            Assert(p.kind == Kind::sphere, dealii::ExcInternalError());
            // A geodesic polyhedron: the icosahedron's faces split into k^2 triangles
            // whose vertices are projected onto the sphere (a convex polyhedron
            // inscribed in it). Its longest edge is about 1.32 r / k: k grows until
            // every edge is at most h.
            q.shape = Primitive::Shape::polyhedron;
            const Point  c(p.p[0], p.p[1], p.p[2]);
            const double r   = p.p[3];
            const double phi = 0.5 * (1 + std::sqrt(5.0));
            const Vector ico[12] = {Vector({-1, phi, 0}), Vector({1, phi, 0}),  Vector({-1, -phi, 0}),
                                    Vector({1, -phi, 0}), Vector({0, -1, phi}), Vector({0, 1, phi}),
                                    Vector({0, -1, -phi}), Vector({0, 1, -phi}), Vector({phi, 0, -1}),
                                    Vector({phi, 0, 1}),  Vector({-phi, 0, -1}), Vector({-phi, 0, 1})};
            static const unsigned int tri[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
            for (unsigned int k = std::max(1, static_cast<int>(std::ceil(1.3 * r / h)));; ++k)
              {
                AssertThrow(k < 5000, dealii::ExcMessage("sphere: the resolution h is too fine for its radius"));
                vertices.clear();
                q.faces.clear();
                // Shared vertices: the icosahedron's, then k - 1 on each of its edges
                // (from the lower to the higher index), then those inside each face.
                std::map<std::pair<unsigned int, unsigned int>, unsigned int> edge_first;
                const auto project = [&](const Vector &x) { return c + r * unit(x); };
                for (const auto &v : ico)
                  vertices.push_back(project(v));
                for (const auto &t : tri)
                  for (unsigned int e = 0; e < 3; ++e)
                    {
                      const unsigned int a = std::min(t[e], t[(e + 1) % 3]), b = std::max(t[e], t[(e + 1) % 3]);
                      if (edge_first.count({a, b}) == 0)
                        {
                          edge_first[{a, b}] = vertices.size();
                          for (unsigned int i = 1; i < k; ++i)
                            vertices.push_back(project(ico[a] + (static_cast<double>(i) / k) * (ico[b] - ico[a])));
                        }
                    }
                for (const auto &t : tri)
                  {
                    const Vector &A = ico[t[0]], &B = ico[t[1]], &C = ico[t[2]];
                    const unsigned int interior = vertices.size();
                    // row[i]: the first interior point of row i (j = 1 .. k - 1 - i)
                    std::vector<unsigned int> row(k + 1, interior);
                    for (unsigned int i = 2; i < k; ++i)
                      row[i] = row[i - 1] + (k - i);
                    for (unsigned int i = 1; i < k; ++i)
                      for (unsigned int j = 1; i + j < k; ++j)
                        vertices.push_back(
                          project(A + (static_cast<double>(i) / k) * (B - A) + (static_cast<double>(j) / k) * (C - A)));
                    // The vertex at A + i/k (B - A) + j/k (C - A).
                    const auto along = [&](const unsigned int a, const unsigned int b, const unsigned int s) {
                      if (s == 0)
                        return a;
                      if (s == k)
                        return b;
                      return a < b ? edge_first[{a, b}] + s - 1 : edge_first[{b, a}] + k - s - 1;
                    };
                    const auto at = [&](const unsigned int i, const unsigned int j) -> unsigned int {
                      if (j == 0)
                        return along(t[0], t[1], i);
                      if (i == 0)
                        return along(t[0], t[2], j);
                      if (i + j == k)
                        return along(t[1], t[2], j);
                      return row[i] + j - 1;
                    };
                    const auto triangle = [&](const unsigned int a, const unsigned int b, const unsigned int d) {
                      const Vector n = cross_product_3d(vertices[b] - vertices[a], vertices[d] - vertices[a]);
                      if (n * (vertices[a] - c) >= 0)
                        q.faces.push_back({vertices[a], vertices[b], vertices[d]});
                      else
                        q.faces.push_back({vertices[a], vertices[d], vertices[b]});
                    };
                    for (unsigned int i = 0; i < k; ++i)
                      for (unsigned int j = 0; i + j < k; ++j)
                        {
                          triangle(at(i, j), at(i + 1, j), at(i, j + 1));
                          if (i + j + 1 < k)
                            triangle(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                        }
                  }
                double longest = 0;
                for (const auto &f : q.faces)
                  for (unsigned int e = 0; e < 3; ++e)
                    longest = std::max(longest, f[e].distance(f[(e + 1) % 3]));
                if (longest <= h)
                  break;
              }
            face_planes.clear();
            for (const auto &f : q.faces)
              {
                const Vector n = unit(cross_product_3d(f[1] - f[0], f[2] - f[0]));
                face_planes.push_back(Plane{n, n * Point((f[0] + f[1] + f[2]) / 3.0)});
              }
            q.centre = c;
          }

        for (const auto &v : vertices)
          q.box.add(v);
        q.inradius  = std::numeric_limits<double>::max();
        q.outradius = 0;
        for (const auto &plane : face_planes)
          q.inradius = std::min(q.inradius, -plane(q.centre));
        for (const auto &v : vertices)
          q.outradius = std::max(q.outradius, v.distance(q.centre));
        for (const auto &f : q.faces)
          {
            Box b;
            for (const auto &v : f)
              b.add(v);
            q.face_boxes.push_back(b);
          }
        if (q.faces.size() > 8)
          q.face_tree.build(q.face_boxes);
        if (q.shape == Primitive::Shape::polyhedron)
          {
            // The face that maximises n_k . p - c_k lies in the direction of p: with
            // rho = |p - centre| > inradius / 2 its normal is within gamma of that
            // direction, cos gamma = cos beta - (R - r_in) / (r_in / 2), beta the largest
            // angle between a face's normal and its vertices seen from the centre.
            double           beta = 0;
            std::vector<Box> normals;
            for (unsigned int f = 0; f < q.faces.size(); ++f)
              {
                for (const auto &v : q.faces[f])
                  beta = std::max(
                    beta, std::acos(std::clamp(face_planes[f].normal * unit(v - q.centre), -1.0, 1.0)));
                Box b;
                b.add(Point(face_planes[f].normal));
                normals.push_back(b);
              }
            const double cos_gamma = std::cos(beta) - (q.outradius - q.inradius) / (0.5 * q.inradius);
            const double gamma     = std::acos(std::clamp(cos_gamma, -1.0, 1.0));
            q.cone                 = 1.01 * 2 * std::sin(0.5 * gamma) + 1e-9;
            q.normal_tree.build(normals);
          }
        for (unsigned int f = 0; f < face_planes.size(); ++f)
          plane_primitive.push_back(primitive.size());
        planes.insert(planes.end(), face_planes.begin(), face_planes.end());
        primitive.push_back(std::move(q));
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

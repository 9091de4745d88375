// Convex polyhedra and polygons: boxes, faces, normals, exact integrals and the box tree.
#include "rbsn/polyhedron.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace hysteron
{
  namespace RBSN
  {
    namespace Polyhedral
    {
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
    } // namespace Polyhedral
  }   // namespace RBSN
} // namespace hysteron

// The domain's primitives as convex polyhedra: boxes, prisms and geodesic spheres.
#include "rbsn/polyhedron.h"

#include <algorithm>
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
        using Primitive = Domain::Primitive;
        using Input     = Geometry::Region<3>::Primitive;



        /// The box [p_0..2, p_3..5]: its 6 faces on the planes x_d = lo_d, hi_d (returned).
        std::vector<Plane>
        make_box(const Input &p, Primitive &q, std::vector<Point> &vertices)
        {
          std::vector<Plane> face_planes;
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
          return face_planes;
        }



        /// The cylinder (p_0..2, axis p_3..5, radius p_6) as its inscribed prism; its face planes.
        std::vector<Plane>
        make_prism(const Input &p, const double h, Primitive &q, std::vector<Point> &vertices)
        {
          std::vector<Plane> face_planes;
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
          return face_planes;
        }



        /**
         * The geodesic polyhedron of level @p k inscribed in the sphere (@p c, @p r): the
         * icosahedron's faces split into k^2 triangles whose vertices are projected onto
         * the sphere, each face counter-clockwise seen from outside.
         */
        void
        geodesic_faces(const Point                     &c,
                       const double                     r,
                       const unsigned int               k,
                       std::vector<Point>              &vertices,
                       std::vector<std::vector<Point>> &faces)
        {
          const double phi = 0.5 * (1 + std::sqrt(5.0));
          const Vector ico[12] = {Vector({-1, phi, 0}), Vector({1, phi, 0}),  Vector({-1, -phi, 0}),
                                  Vector({1, -phi, 0}), Vector({0, -1, phi}), Vector({0, 1, phi}),
                                  Vector({0, -1, -phi}), Vector({0, 1, -phi}), Vector({phi, 0, -1}),
                                  Vector({phi, 0, 1}),  Vector({-phi, 0, -1}), Vector({-phi, 0, 1})};
          static const unsigned int tri[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                  {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                  {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                  {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
          vertices.clear();
          faces.clear();
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
                  faces.push_back({vertices[a], vertices[b], vertices[d]});
                else
                  faces.push_back({vertices[a], vertices[d], vertices[b]});
              };
              for (unsigned int i = 0; i < k; ++i)
                for (unsigned int j = 0; i + j < k; ++j)
                  {
                    triangle(at(i, j), at(i + 1, j), at(i, j + 1));
                    if (i + j + 1 < k)
                      triangle(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                  }
            }
        }



        /**
         * The sphere (centre p_0..2, radius p_3) as a geodesic polyhedron; its face planes.
         * Its longest edge is about 1.32 r / k: the level k grows until every edge is at
         * most h.
         */
        std::vector<Plane>
        make_geodesic(const Input &p, const double h, Primitive &q, std::vector<Point> &vertices)
        {
          q.shape = Primitive::Shape::polyhedron;
          const Point  c(p.p[0], p.p[1], p.p[2]);
          const double r = p.p[3];
          for (unsigned int k = std::max(1, static_cast<int>(std::ceil(1.3 * r / h)));; ++k)
            {
              AssertThrow(k < 5000, dealii::ExcMessage("sphere: the resolution h is too fine for its radius"));
              geodesic_faces(c, r, k, vertices, q.faces);
              double longest = 0;
              for (const auto &f : q.faces)
                for (unsigned int e = 0; e < 3; ++e)
                  longest = std::max(longest, f[e].distance(f[(e + 1) % 3]));
              if (longest <= h)
                break;
            }
          std::vector<Plane> face_planes;
          for (const auto &f : q.faces)
            {
              const Vector n = unit(cross_product_3d(f[1] - f[0], f[2] - f[0]));
              face_planes.push_back(Plane{n, n * Point((f[0] + f[1] + f[2]) / 3.0)});
            }
          q.centre = c;
          return face_planes;
        }



        /// The primitive's box, in- and outradius about its centre, and its faces' boxes.
        void
        bound(Primitive &q, const std::vector<Point> &vertices, const std::vector<Plane> &face_planes)
        {
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
        }



        /// The tree of a geodesic polyhedron's face normals and its cone (for contains()).
        void
        make_normal_tree(Primitive &q, const std::vector<Plane> &face_planes)
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
      } // namespace



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
          face_planes = make_box(p, q, vertices);
        else if (p.kind == Kind::cylinder)
          face_planes = make_prism(p, h, q, vertices);
        else
          {
            Assert(p.kind == Kind::sphere, dealii::ExcInternalError());
            face_planes = make_geodesic(p, h, q, vertices);
          }
        bound(q, vertices, face_planes);
        if (q.shape == Primitive::Shape::polyhedron)
          make_normal_tree(q, face_planes);
        for (unsigned int f = 0; f < face_planes.size(); ++f)
          plane_primitive.push_back(primitive.size());
        planes.insert(planes.end(), face_planes.begin(), face_planes.end());
        primitive.push_back(std::move(q));
      }
    } // namespace Polyhedral
  }   // namespace RBSN
} // namespace hysteron

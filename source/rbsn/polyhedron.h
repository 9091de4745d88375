#ifndef hysteron_source_rbsn_polyhedron_h
#define hysteron_source_rbsn_polyhedron_h

#include <deal.II/base/point.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <hysteron/geometry/region.h>

#include <string>
#include <utility>
#include <vector>

/**
 * @file
 * The geometric kernel of the 3D RBSN (doc/rbsn/geometry_3d.md): convex
 * polyhedra and polygons clipped by planes, their exact integrals, and the
 * polyhedral domain, a union/difference program over convex polyhedra that
 * stand for the boxes, cylinders (prisms) and spheres (geodesic polyhedra) of
 * a Geometry::Region<3>. A convex set X meets the domain in a union of
 * disjoint convex pieces, found by clipping X with the primitives' planes:
 *
 *   X n P            = X n h_1 n ... n h_m                   (P = n_k h_k)
 *   X \ P            = U_j X n h_1 n ... n h_(j-1) n not h_j  (disjoint)
 *   X n (A u B)      = (X n A) + ((X \ A) n B)
 *   X n (A \ B)      = (X n A) \ B
 *   X \ (A u B)      = (X \ A) \ B
 *   X \ (A \ B)      = (X \ A) + ((X n A) n B).
 *
 * The shapes, their integrals and the box tree are in polyhedron.cc, the clipping
 * in clipper.cc, the domain in polyhedral_domain.cc and its primitives in
 * polyhedral_primitives.cc.
 */
namespace hysteron
{
  namespace RBSN
  {
    namespace Polyhedral
    {
      using Point  = dealii::Point<3>;
      using Vector = dealii::Tensor<1, 3>;

      /// The closed half-space {x : normal . x <= offset}, |normal| = 1.
      struct Plane
      {
        Vector normal;
        double offset = 0;

        double
        operator()(const Point &x) const
        {
          return normal * x - offset;
        }

        Plane
        flipped() const
        {
          return Plane{-normal, -offset};
        }
      };

      /// An axis-aligned box; empty() until a point is added.
      struct Box
      {
        Point lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};

        void
        add(const Point &p)
        {
          for (unsigned int d = 0; d < 3; ++d)
            {
              lo[d] = std::min(lo[d], p[d]);
              hi[d] = std::max(hi[d], p[d]);
            }
        }

        void
        add(const Box &b)
        {
          add(b.lo);
          add(b.hi);
        }

        /// Whether the boxes, each grown by @p tolerance, meet.
        bool
        overlaps(const Box &b, const double tolerance) const
        {
          for (unsigned int d = 0; d < 3; ++d)
            if (lo[d] > b.hi[d] + 2 * tolerance || b.lo[d] > hi[d] + 2 * tolerance)
              return false;
          return true;
        }
      };

      /// The bounding box of a set of points.
      inline Box
      bounding_box(const std::vector<Point> &points)
      {
        Box b;
        for (const auto &p : points)
          b.add(p);
        return b;
      }

      /// The mean of a non-empty set of points (inside their convex hull).
      inline Point
      mean(const std::vector<Point> &points)
      {
        Vector s;
        for (const auto &p : points)
          s += p;
        return Point(s / static_cast<double>(points.size()));
      }

      /// The unit vector along @p v != 0.
      inline Vector
      unit(const Vector &v)
      {
        return v / v.norm();
      }

      /**
       * Face tags: a Voronoi neighbour j >= 0, the starting box (-1), or plane p of
       * the domain, as given (its half-space) or flipped (the complement's).
       */
      constexpr int box_tag = -1;

      inline int
      plane_tag(const unsigned int plane, const bool flipped)
      {
        return -2 - static_cast<int>(2 * plane + (flipped ? 1 : 0));
      }

      inline bool
      is_plane_tag(const int tag)
      {
        return tag <= -2;
      }

      inline unsigned int
      tag_plane(const int tag)
      {
        return static_cast<unsigned int>(-2 - tag) / 2;
      }

      inline bool
      tag_flipped(const int tag)
      {
        return (static_cast<unsigned int>(-2 - tag) % 2) == 1;
      }

      /**
       * A convex polyhedron: its vertices and its faces, each a loop of vertex
       * indices counter-clockwise seen from outside, with a tag.
       */
      struct ConvexPolyhedron
      {
        std::vector<Point>        vertices;
        std::vector<unsigned int> face_start{0}; ///< face f: face_vertices[face_start[f], face_start[f + 1])
        std::vector<unsigned int> face_vertices;
        std::vector<int>          tags;

        unsigned int
        n_faces() const
        {
          return tags.size();
        }

        bool
        empty() const
        {
          return tags.empty();
        }

        void
        clear()
        {
          vertices.clear();
          face_start.assign(1, 0);
          face_vertices.clear();
          tags.clear();
        }

        /// The box [lo, hi] with every face tagged @p tag.
        void
        make_box(const Point &lo, const Point &hi, const int tag);

        Box
        bounding_box() const
        {
          return Polyhedral::bounding_box(vertices);
        }

        /// The mean of the vertices (a point inside).
        Point
        vertex_mean() const
        {
          return mean(vertices);
        }

        /// Face @p f as a loop of points.
        std::vector<Point>
        face(const unsigned int f) const;
      };

      /// A convex polygon in space: its vertices counter-clockwise about @p normal.
      struct ConvexPolygon
      {
        std::vector<Point> vertices;
        Vector             normal;

        bool
        empty() const
        {
          return vertices.size() < 3;
        }

        Box
        bounding_box() const
        {
          return Polyhedral::bounding_box(vertices);
        }

        Point
        vertex_mean() const
        {
          return mean(vertices);
        }
      };

      /// Where a convex set lies with respect to a plane.
      enum class Cut
      {
        inside,  ///< in the half-space (within the tolerance): unchanged
        cut,     ///< the plane cuts it: the clipped set is returned
        outside  ///< outside (within the tolerance): nothing is left
      };

      /**
       * Clips convex polyhedra and polygons by planes. Vertices within @p tolerance
       * of the plane count as on it (never cut), new vertices closer than that to
       * each other are merged. Keeps its scratch storage between calls.
       */
      class Clipper
      {
      public:
        explicit Clipper(const double tolerance = 0)
          : tolerance(tolerance)
        {}

        /// out = in n plane (the new face tagged @p tag), unless inside or outside.
        Cut
        clip(const ConvexPolyhedron &in, const Plane &plane, const int tag, ConvexPolyhedron &out);

        /// out = in n plane, unless inside or outside.
        Cut
        clip(const ConvexPolygon &in, const Plane &plane, const int tag, ConvexPolygon &out);

        double tolerance;

      private:
        /// value = the plane's signed distance at each vertex; inside or outside when no
        /// vertex lies beyond the tolerance on the other side, cut otherwise.
        Cut
        classify(const std::vector<Point> &vertices, const Plane &plane);

        /// The steps of clip() for a polyhedron: the vertices kept and the faces cut at
        /// the plane (returns the number of vertices kept), ...
        unsigned int
        cut_faces(const ConvexPolyhedron &in, ConvexPolyhedron &out);

        /// ... the new vertex on the edge (a, b) (the same for both of its faces), ...
        unsigned int
        cut_vertex(const ConvexPolyhedron &in, const unsigned int a, const unsigned int b, ConvexPolyhedron &out);

        /// ... the vertices on the plane (cap) merged where closer than the tolerance, ...
        void
        merge_cap_vertices(const unsigned int n_in, const unsigned int n_kept, ConvexPolyhedron &out);

        /// ... the new face on the plane, tagged @p tag, ...
        void
        add_cap_face(const Plane &plane, const int tag, ConvexPolyhedron &out);

        /// ... and the vertices that no face uses dropped.
        void
        drop_unused_vertices(ConvexPolyhedron &out);

        std::vector<double>                                   value;
        std::vector<int>                                      index;
        std::vector<std::pair<std::pair<unsigned int, unsigned int>, unsigned int>> cuts;
        std::vector<unsigned int>                             cap;
        std::vector<double>                                   angle;
        std::vector<unsigned int>                             order;
        std::vector<unsigned int>                             merged;
        std::vector<bool>                                     used;
      };

      /**
       * Integrals int 1, int (x - r), int (x - r) (x - r)^T over a volume or an area
       * (about the reference point r chosen by the caller).
       */
      struct Moments
      {
        double                        measure = 0;
        Vector                        first;
        dealii::SymmetricTensor<2, 3> second;

        /// Add a convex polyhedron (tetrahedra from r to the fan triangles of its faces).
        void
        add_volume(const ConvexPolyhedron &p, const Point &r);

        /// Add a planar polygon (fan triangles), its area counted along @p normal.
        void
        add_area(const Point *loop, const unsigned int n, const Vector &normal, const Point &r);
      };

      /// The vector area of a planar loop (Newell): area times the normal of its ccw side.
      Vector
      area_vector(const Point *loop, const unsigned int n);

      /// A unit vector perpendicular to the unit vector @p n (deterministic).
      Vector
      perpendicular(const Vector &n);

      /**
       * Bounding-volume hierarchy over boxes: which boxes meet a query box. Leaves of
       * at most 4 boxes, split at the median of the longest axis.
       */
      class BoxTree
      {
      public:
        void
        build(std::vector<Box> boxes);

        /// Append the indices of the boxes that meet @p query (grown by @p tolerance), ascending.
        void
        query(const Box &query, const double tolerance, std::vector<unsigned int> &result) const;

        bool
        empty() const
        {
          return boxes.empty();
        }

      private:
        struct Node
        {
          Box          box;
          unsigned int first = 0, count = 0; ///< a leaf's range of order[]
          int          left = -1, right = -1;
        };
        std::vector<Box>          boxes;
        std::vector<unsigned int> order;
        std::vector<Node>         nodes;

        int
        make(const unsigned int first, const unsigned int count);
      };

      /// A piece of the domain's boundary: a convex polygon (ccw about the outward normal).
      struct BoundaryPolygon
      {
        ConvexPolygon polygon; ///< normal: the outward normal of the domain
        unsigned int  plane = 0;  ///< the plane it lies on (normal = +- that plane's normal)
        bool          flipped = false; ///< whether the normal is minus the plane's normal
      };

      /**
       * The domain of the RBSN in 3D: the union of the bodies, each a union/difference
       * program over convex polyhedra that replace its primitives (a box as it is, a
       * cylinder by the inscribed prism of Region<2>::n_disk_sides() sides, a sphere by
       * an inscribed geodesic polyhedron with edges of at most h).
       */
      class Domain
      {
      public:
        /// Throws InputError(@p where) for `all` (unbounded) and empty bodies.
        Domain(const std::vector<const Geometry::Region<3> *> &bodies, const double h, const std::string &where);

        /**
         * Whether p lies in the polyhedral domain, every added polyhedron grown and
         * every subtracted one shrunk by @p tolerance (in the distance of p from each
         * face plane), as Region::contains().
         */
        bool
        contains(const Point &p, const double tolerance = 0) const;

        /**
         * The disjoint convex pieces of X n domain (appended to @p pieces); their new
         * faces are tagged plane_tag(). @p clipper's tolerance must be set.
         */
        void
        intersect(const ConvexPolyhedron &X, std::vector<ConvexPolyhedron> &pieces, Clipper &clipper) const;

        /**
         * The parts of the face @p G of a piece (on plane @p plane, its outward normal
         * the plane's or the flipped one) that lie on the domain's boundary: where the
         * domain does not continue beyond G. Appended to @p result.
         */
        void
        boundary_part(const ConvexPolygon        &G,
                      const unsigned int          plane,
                      std::vector<ConvexPolygon> &result,
                      Clipper                    &clipper) const;

        /// The boundary of the domain as convex polygons with outward normals (each area once).
        std::vector<BoundaryPolygon>
        boundary() const;

        /// The volume of the polyhedral domain (by the divergence theorem over its boundary).
        double
        volume() const;

        /// The volume enclosed by @p boundary (from boundary()).
        static double
        volume(const std::vector<BoundaryPolygon> &boundary);

        const Plane &
        plane(const unsigned int p) const
        {
          return planes[p];
        }

        unsigned int
        n_planes() const
        {
          return planes.size();
        }

        /// The box around the domain, its diagonal, and the length tolerance used.
        Box    box;
        double scale = 0, tolerance = 0;

        /// The convex polyhedra of the primitives (their faces lie on their planes).
        struct Primitive
        {
          enum class Shape
          {
            box,
            prism,
            polyhedron
          } shape = Shape::box;
          double                          sign = 1; ///< +1 added, -1 subtracted (tolerance)
          unsigned int                    first_plane = 0; ///< face k lies on plane first_plane + k
          std::vector<std::vector<Point>> faces;           ///< ccw seen from outside
          std::vector<Box>                face_boxes;
          BoxTree                         face_tree;       ///< over face_boxes (many faces only)
          Box                             box;
          Point                           centre;          ///< an interior point
          double                          inradius = 0;    ///< min over the planes of offset - normal . centre
          double                          outradius = 0;   ///< max distance of a vertex from the centre
          // prism: the axis frame, the number of sides and the length
          Vector       axis, u, w;
          double       length = 0;
          unsigned int sides  = 0;
          // geodesic polyhedron: the face normals as points, for the faces facing a direction
          BoxTree normal_tree;
          double  cone = 0; ///< the chord between a direction and the normals of the faces that matter
        };

        const std::vector<Primitive> &
        primitives() const
        {
          return primitive;
        }

      private:
        std::vector<Primitive>                              primitive;
        std::vector<Plane>                                  planes;
        std::vector<unsigned int>                           plane_primitive; ///< the primitive of each plane
        std::vector<std::vector<std::pair<unsigned int, bool>>> coplanar; ///< other planes on it, same orientation?

        /// The CSG program as a tree: a leaf (a primitive) or an operation on two nodes.
        struct Node
        {
          Geometry::Region<3>::Op op        = Geometry::Region<3>::Op::push;
          unsigned int            primitive = 0;
          int                     left = -1, right = -1;
          Box                     box;
        };
        std::vector<Node> nodes;
        int               root = -1;
        /// The same as a postfix program (for contains()).
        std::vector<Geometry::Region<3>::Instruction> program;

        /// The program evaluated on one side of a plane: primitives with a face on it are
        /// empty (the side beyond their face) or lose that plane (the side behind it).
        struct Side
        {
          std::vector<std::pair<unsigned int, int>> changes; ///< primitive, dropped plane or -1 (empty)

          /// What the side does to a primitive: drops plane p (p >= 0), empties it
          /// (-1), or nothing (-2).
          static int
          change(const Side *side, const unsigned int primitive)
          {
            int result = -2;
            if (side != nullptr)
              for (const auto &c : side->changes)
                if (c.first == primitive)
                  {
                    if (c.second < 0)
                      return -1;
                    result = c.second;
                  }
            return result;
          }
        };

        Side
        side(const unsigned int plane, const Vector &direction) const;

        bool
        primitive_contains(const Primitive &q, const Point &p, const double tolerance) const;

        /// The planes (ids) of the faces of q near @p box; false if none.
        void
        near_planes(const Primitive &q, const Box &box, std::vector<unsigned int> &result) const;

        template <class Shape>
        void
        inside(const int node, const Shape &X, const Side *side, std::vector<Shape> &out, Clipper &clipper) const;

        template <class Shape>
        void
        outside(const int node, const Shape &X, const Side *side, std::vector<Shape> &out, Clipper &clipper) const;

        void
        add_primitive(const Geometry::Region<3>::Primitive &p, const double h);
      };
    } // namespace Polyhedral
  }   // namespace RBSN
} // namespace hysteron

#endif

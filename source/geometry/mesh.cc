// Coarse meshes for the FEM from the bodies' region expressions: a tensor-product
// mesh (2D and 3D) and a CGAL-based unstructured quadrilateral mesh (2D). CGAL is
// used in this translation unit only.
#include <deal.II/base/array_view.h>
#include <deal.II/base/geometry_info.h>

#include <deal.II/grid/grid_tools.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/geometry/mesh.h>

#include "geometry/mesh_common.h"

// CGAL's headers are not clean under -Wall -Wextra -pedantic. Without NDEBUG, CGAL
// would also print a warning for every crossing constraint, suggesting
// Constrained_triangulation_plus_2 to avoid cascaded intersections; intersections
// of constraints that cross already split constraints then carry a round-off
// drift of about 1e-16, which is harmless here.
#define CGAL_NO_CDT_2_WARNING
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-variable"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#pragma GCC diagnostic ignored "-Wdeprecated-copy"
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>

namespace hysteron
{
  namespace Geometry
  {
    using namespace internal;



    namespace
    {
      // The CGAL types of the unstructured mesher: exact predicates, rounded exact
      // intersections of crossing constraints; each vertex carries an index.
      using Kernel     = CGAL::Exact_predicates_inexact_constructions_kernel;
      using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<
        unsigned int,
        Kernel,
        CGAL::Delaunay_mesh_vertex_base_2<Kernel>>;
      using FaceBase      = CGAL::Delaunay_mesh_face_base_2<Kernel>;
      using DataStructure = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
      using Triangulation = CGAL::
        Constrained_Delaunay_triangulation_2<Kernel, DataStructure, CGAL::Exact_intersections_tag>;
      using Criteria      = CGAL::Delaunay_mesh_size_criteria_2<Triangulation>;
      using Mesher        = CGAL::Delaunay_mesher_2<Triangulation, Criteria>;
      using CgalPoint     = Triangulation::Point;
      using VertexHandle  = Triangulation::Vertex_handle;

      /// The shape bound of the refinement: sin^2 of the smallest angle.
      constexpr double shape_bound = 0.125;

      /// Quads per area / h^2 measured for plates with holes (15.0, for the size check).
      constexpr double cells_per_area_over_h2 = 15.5;

      /**
       * Clip the segment [a, b] to the box [lo, hi] (Liang-Barsky). Returns false
       * if less than a segment remains. Parts inside the box stay bit for bit.
       */
      bool
      clip(dealii::Point<2>       &a,
           dealii::Point<2>       &b,
           const dealii::Point<2> &lo,
           const dealii::Point<2> &hi)
      {
        double                 t0 = 0, t1 = 1;
        const dealii::Point<2> a0 = a;
        const double           dx[2] = {b[0] - a[0], b[1] - a[1]};
        for (unsigned int d = 0; d < 2; ++d)
          {
            if (dx[d] == 0)
              {
                if (a[d] < lo[d] || a[d] > hi[d])
                  return false;
                continue;
              }
            double ta = (lo[d] - a0[d]) / dx[d], tb = (hi[d] - a0[d]) / dx[d];
            if (ta > tb)
              std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
          }
        if (!(t0 < t1))
          return false;
        const auto at = [&](const double t) {
          dealii::Point<2> p(a0[0] + t * dx[0], a0[1] + t * dx[1]);
          for (unsigned int d = 0; d < 2; ++d)
            p[d] = std::min(hi[d], std::max(lo[d], p[d]));
          return p;
        };
        const dealii::Point<2> b0 = b;
        a                         = (t0 == 0 ? a0 : at(t0));
        b                         = (t1 == 1 ? b0 : at(t1));
        return !(a == b);
      }

      /// The index of (x, y) in [0, 2^order)^2 along a Hilbert curve.
      std::uint64_t
      hilbert_index(const unsigned int order, std::uint32_t x, std::uint32_t y)
      {
        const std::uint32_t n = 1u << order;
        std::uint64_t       d = 0;
        for (std::uint32_t s = n / 2; s > 0; s /= 2)
          {
            const std::uint32_t rx = (x & s) > 0 ? 1 : 0;
            const std::uint32_t ry = (y & s) > 0 ? 1 : 0;
            d += static_cast<std::uint64_t>(s) * s * ((3 * rx) ^ ry);
            if (ry == 0) // rotate the quadrant
              {
                if (rx == 1)
                  {
                    x = n - 1 - x;
                    y = n - 1 - y;
                  }
                std::swap(x, y);
              }
          }
        return d;
      }

      /// A kept triangle: counter-clockwise, its lexicographically smallest vertex first.
      struct KeptTriangle
      {
        std::uint64_t               key;
        std::array<VertexHandle, 3> v;
        std::array<CgalPoint, 3>    p;
        unsigned int                body;
      };

      /**
       * Check the size before any work: disks' sides and the estimated cell count (from the
       * exact area of single-primitive bodies, else the bounding box). Returns the estimate.
       */
      double
      checked_cell_estimate(const std::vector<const Region<2> *> &bodies,
                            const double                           h,
                            const double                           boundary_h,
                            const std::string                     &where)
      {
        double area_estimate = 0;
        for (unsigned int i = 0; i < bodies.size(); ++i)
          {
            for (const auto &q : bodies[i]->get_primitives())
              if (q.kind == Region<2>::Kind::disk)
                require(2 * M_PI * q.p[2] / boundary_h <= 1e6, where,
                        body_name(bodies, i) + ": a disk of radius " + to_string(q.p[2]) +
                          " needs more than 1e6 sides at h = " + to_string(boundary_h));
            const auto box = bodies[i]->bounding_box().get_boundary_points();
            area_estimate += (bodies[i]->get_program().size() == 1 ?
                                bodies[i]->volume_estimate() :
                                (box.second[0] - box.first[0]) * (box.second[1] - box.first[1]));
          }
        const double estimated_cells = cells_per_area_over_h2 * area_estimate / (h * h);
        require(estimated_cells <= max_cells, where,
                "the mesh at h = " + to_string(h) + " would have about " +
                  to_string(estimated_cells) + " cells, more than the limit of " +
                  to_string(max_cells));
        return estimated_cells;
      }

      /// The constraints: all primitives' boundaries, clipped to the box [lo, hi].
      void
      insert_constraints(Triangulation                        &cdt,
                         const std::vector<const Region<2> *> &bodies,
                         const double                          boundary_h,
                         const dealii::Point<2>               &lo,
                         const dealii::Point<2>               &hi)
      {
        VertexHandle hint;
        for (const auto *body : bodies)
          for (auto segment : body->boundary_segments(boundary_h))
            {
              if (!clip(segment[0], segment[1], lo, hi))
                continue;
              const VertexHandle a = (hint == VertexHandle() ?
                                        cdt.insert(CgalPoint(segment[0][0], segment[0][1])) :
                                        cdt.insert(CgalPoint(segment[0][0], segment[0][1]),
                                                   hint->face()));
              const VertexHandle b =
                cdt.insert(CgalPoint(segment[1][0], segment[1][1]), a->face());
              if (a != b)
                cdt.insert_constraint(a, b);
              hint = b;
            }
      }

      dealii::Point<2>
      centroid(const Triangulation::Face_handle &f)
      {
        const CgalPoint &a = f->vertex(0)->point(), &b = f->vertex(1)->point(),
                        &c = f->vertex(2)->point();
        return dealii::Point<2>((a.x() + b.x() + c.x()) / 3, (a.y() + b.y() + c.y()) / 3);
      }

      /// The domain: triangles (each on one side of every constraint) whose centroid is in
      /// a body; the tolerance only errs on the side of refining.
      void
      mark_domain(Triangulation &cdt, const std::vector<Region<2>> &bodies, const double tolerance)
      {
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
          {
            const dealii::Point<2> c      = centroid(f);
            bool                   inside = false;
            for (const auto &body : bodies)
              inside = inside || body.contains(c, tolerance);
            f->set_in_domain(inside);
          }
      }

      /**
       * Refine point by point (the same sequence as Mesher::refine_mesh()), with a cap on
       * the vertices: features much smaller than h, e.g. two bodies that overlap in a
       * sliver 1e-9 wide along a side, would otherwise need millions of tiny triangles.
       * (Delaunay refinement is graded: a small isolated feature costs only a few vertices
       * per halving of the size.)
       */
      void
      refine(Triangulation &cdt, const double h, const double estimated_cells, const std::string &where)
      {
        Mesher mesher(cdt, Criteria(shape_bound, h));
        mesher.init(/*domain_specified = */ true);
        const std::size_t max_vertices = static_cast<std::size_t>(
          std::min(max_cells / 4, std::max(1e5, 2 * estimated_cells)));
        while (mesher.step_by_step_refine_mesh())
          if (cdt.number_of_vertices() > max_vertices)
            throw InputError(where,
                             "the refinement at h = " + to_string(h) + " exceeded " +
                               std::to_string(max_vertices) +
                               " vertices: the bodies have features much smaller than h "
                               "(nearly coincident boundaries, thin slivers between "
                               "overlapping bodies); align their coordinates or use a "
                               "smaller h");
      }

      /**
       * The refined domain triangles whose centroid lies in a body (the first one that
       * holds it), ordered along a Hilbert curve through their centroids (on a 2^20 grid
       * over the box [lo, hi]), equal keys by their vertices.
       */
      std::vector<KeptTriangle>
      kept_triangles(const Triangulation          &cdt,
                     const std::vector<Region<2>> &bodies,
                     const dealii::Point<2>       &lo,
                     const dealii::Point<2>       &hi)
      {
        std::vector<const Region<2> *> classifiers;
        for (const auto &body : bodies)
          classifiers.push_back(&body);
        const unsigned int order = 20;
        const double       scale[2] = {(1u << order) / std::max(hi[0] - lo[0], 1e-300),
                                       (1u << order) / std::max(hi[1] - lo[1], 1e-300)};
        std::vector<KeptTriangle> kept;
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
          {
            if (!f->is_in_domain())
              continue;
            const dealii::Point<2> c    = centroid(f);
            const int              body = first_body<2>(classifiers, c);
            if (body < 0)
              continue;
            KeptTriangle t;
            unsigned int first = 0;
            for (unsigned int k = 1; k < 3; ++k)
              if (f->vertex(k)->point() < f->vertex(first)->point())
                first = k;
            for (unsigned int k = 0; k < 3; ++k)
              {
                t.v[k] = f->vertex((first + k) % 3);
                t.p[k] = t.v[k]->point();
              }
            std::uint32_t xy[2];
            for (unsigned int d = 0; d < 2; ++d)
              xy[d] = static_cast<std::uint32_t>(std::min(
                (1u << order) - 1.0, std::max(0.0, std::floor((c[d] - lo[d]) * scale[d]))));
            t.key  = hilbert_index(order, xy[0], xy[1]);
            t.body = static_cast<unsigned int>(body);
            kept.push_back(t);
          }
        std::sort(kept.begin(), kept.end(), [](const KeptTriangle &s, const KeptTriangle &t) {
          if (s.key != t.key)
            return s.key < t.key;
          return std::lexicographical_compare(s.p.begin(), s.p.end(), t.p.begin(), t.p.end());
        });
        return kept;
      }

      /**
       * Three quadrilaterals per triangle (vertex, two edge midpoints, centroid; midpoints
       * of shared edges shared), vertices numbered in order of first use.
       *
       * The lines are consistently oriented by construction, so there is no need for
       * GridTools::consistently_order_cells() (a third of the run time): every line of the
       * quads runs from a triangle vertex to an edge midpoint or from an edge midpoint to a
       * centroid, and in each quad (v0, v1, v2, v3) = (vertex, midpoint, midpoint,
       * centroid) deal.II's lines 0->2, 1->3, 0->1, 2->3 all point that way, whichever of
       * the two quads sharing a line is asked. Counter-clockwise triangles give
       * counter-clockwise (positive) quads.
       */
      CoarseMesh<2>
      split_into_quadrilaterals(Triangulation &cdt, const std::vector<KeptTriangle> &kept)
      {
        CoarseMesh<2>          mesh;
        constexpr unsigned int invalid = std::numeric_limits<unsigned int>::max();
        for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
          v->info() = invalid;
        const auto index_of = [&mesh](const VertexHandle &v) {
          if (v->info() == invalid)
            {
              v->info() = mesh.vertices.size();
              mesh.vertices.emplace_back(v->point().x(), v->point().y());
            }
          return v->info();
        };
        std::map<std::pair<unsigned int, unsigned int>, unsigned int> midpoints;
        const auto midpoint_of = [&](const unsigned int i, const unsigned int j) {
          const auto key = std::make_pair(std::min(i, j), std::max(i, j));
          const auto it  = midpoints.find(key);
          if (it != midpoints.end())
            return it->second;
          const unsigned int m = mesh.vertices.size();
          mesh.vertices.push_back(0.5 * (mesh.vertices[key.first] + mesh.vertices[key.second]));
          midpoints.emplace(key, m);
          return m;
        };
        mesh.cells.reserve(3 * kept.size());
        for (const auto &t : kept)
          {
            const unsigned int a = index_of(t.v[0]), b = index_of(t.v[1]), c = index_of(t.v[2]);
            const unsigned int ab = midpoint_of(a, b), bc = midpoint_of(b, c),
                               ca = midpoint_of(c, a);
            const unsigned int g  = mesh.vertices.size();
            mesh.vertices.push_back(
              dealii::Point<2>((t.p[0].x() + t.p[1].x() + t.p[2].x()) / 3,
                               (t.p[0].y() + t.p[1].y() + t.p[2].y()) / 3));
            // Counter-clockwise cycles (a, ab, g, ca), (b, bc, g, ab), (c, ca, g, bc)
            // in deal.II's lexicographic order (0, 1, 3, 2 around the cell).
            for (const std::array<unsigned int, 4> &q : {std::array<unsigned int, 4>{{a, ab, ca, g}},
                                                         std::array<unsigned int, 4>{{b, bc, ab, g}},
                                                         std::array<unsigned int, 4>{{c, ca, bc, g}}})
              {
                dealii::CellData<2> cell;
                std::copy(q.begin(), q.end(), cell.vertices.begin());
                cell.material_id = static_cast<dealii::types::material_id>(t.body);
                mesh.cells.push_back(cell);
              }
          }
#ifdef DEBUG
        for (const auto &cell : mesh.cells)
          {
            const auto &p0 = mesh.vertices[cell.vertices[0]], &p1 = mesh.vertices[cell.vertices[1]],
                       &p2 = mesh.vertices[cell.vertices[2]];
            Assert((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]) > 0,
                   dealii::ExcInternalError());
          }
#endif
        return mesh;
      }
    } // namespace



    CoarseMesh<2>
    unstructured_mesh(const std::vector<const Region<2> *> &bodies,
                      const double                           h,
                      const std::string                     &where,
                      const double                           boundary_h_in)
    {
      const double boundary_h      = boundary_h_in > 0 ? boundary_h_in : h;
      const auto [lo, hi]          = checked_bounding_box(bodies, h, where);
      const double estimated_cells = checked_cell_estimate(bodies, h, boundary_h, where);

      // The bodies with their disks as the polygons of the constraints: the classification
      // of the triangles then agrees with the mesh boundary.
      std::vector<Region<2>> polygonized;
      polygonized.reserve(bodies.size());
      for (const auto *body : bodies)
        polygonized.push_back(body->polygonized(boundary_h));

      Triangulation cdt;
      insert_constraints(cdt, bodies, boundary_h, lo, hi);
      require(cdt.dimension() == 2, where, "the bodies' boundaries enclose no area");
      mark_domain(cdt, polygonized, 1e-6 * h);
      refine(cdt, h, estimated_cells, where);
      CoarseMesh<2> mesh = split_into_quadrilaterals(cdt, kept_triangles(cdt, polygonized, lo, hi));
      check_cell_counts(bodies, mesh, h, where);
      return mesh;
    }
  } // namespace Geometry
} // namespace hysteron

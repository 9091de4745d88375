// The 3D Voronoi tessellation: the Voronoi cells of the nuclei clipped to the polyhedral domain, and their facets.
#include <hysteron/base/exceptions.h>
#include "rbsn/tessellation.h"

#include "rbsn/cgal.h"
#include "rbsn/polyhedron.h"
#include "rbsn/sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      using Polyhedral::ConvexPolygon;
      using Polyhedral::ConvexPolyhedron;
      using Polyhedral::Cut;
      using Polyhedral::Plane;
      using Polyhedral::Point;
      using Polyhedral::Vector;
      using Sampling::text;

      /**
       * The Voronoi neighbours of every nucleus: the edges of the Delaunay triangulation
       * (in any dimension: for coplanar or collinear nuclei CGAL keeps a 2D or 1D
       * triangulation, whose edges are the neighbours in the plane or along the line).
       * Throws InputError(@p where) if two nuclei coincide.
       */
      std::vector<std::vector<unsigned int>>
      delaunay_neighbours(const std::vector<Point> &nuclei, const std::string &where)
      {
        using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
        using Vb     = CGAL::Triangulation_vertex_base_with_info_3<unsigned int, Kernel>;
        using Tds    = CGAL::Triangulation_data_structure_3<Vb>;
        using DT     = CGAL::Delaunay_triangulation_3<Kernel, Tds>;
        const unsigned int                     n = nuclei.size();
        std::vector<std::vector<unsigned int>> neighbours(n);
        DT                                     dt;
        std::vector<std::pair<Kernel::Point_3, unsigned int>> input;
        input.reserve(n);
        for (unsigned int i = 0; i < n; ++i)
          input.emplace_back(Kernel::Point_3(nuclei[i][0], nuclei[i][1], nuclei[i][2]), i);
        dt.insert(input.begin(), input.end());
        if (dt.number_of_vertices() != n)
          {
            std::vector<unsigned int> order(n);
            std::iota(order.begin(), order.end(), 0u);
            const auto less = [&](const unsigned int a, const unsigned int b) {
              return std::lexicographical_compare(nuclei[a].begin_raw(),
                                                  nuclei[a].end_raw(),
                                                  nuclei[b].begin_raw(),
                                                  nuclei[b].end_raw());
            };
            std::sort(order.begin(), order.end(), less);
            for (unsigned int k = 0; k + 1 < n; ++k)
              require(nuclei[order[k]] != nuclei[order[k + 1]],
                      where,
                      "two points coincide at " + text(nuclei[order[k]]));
          }
        for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e)
          {
            const unsigned int a = e->first->vertex(e->second)->info(), b = e->first->vertex(e->third)->info();
            neighbours[a].push_back(b);
            neighbours[b].push_back(a);
          }
        for (auto &list : neighbours)
          std::sort(list.begin(), list.end());
        return neighbours;
      }



      /**
       * The Voronoi cell of nucleus @p i in @p X: the box @p start clipped by the bisector
       * of every neighbour, the nearest first (the cell shrinks fastest); each face tagged
       * with its neighbour. Empty if nuclei lie closer than the tolerance.
       */
      void
      voronoi_cell(const std::vector<Point>        &nuclei,
                   const unsigned int               i,
                   const std::vector<unsigned int> &neighbours,
                   const ConvexPolyhedron          &start,
                   Polyhedral::Clipper             &clipper,
                   ConvexPolyhedron                &X)
      {
        const Point                                 &x = nuclei[i];
        std::vector<std::pair<double, unsigned int>> order;
        for (const unsigned int j : neighbours)
          order.emplace_back(x.distance_square(nuclei[j]), j);
        std::sort(order.begin(), order.end());
        X = start;
        ConvexPolyhedron next;
        for (const auto &o : order)
          {
            const unsigned int j = o.second;
            const Vector       d = nuclei[j] - x;
            const Plane        bisector{d / d.norm(), (d / d.norm()) * Point(0.5 * (x + nuclei[j]))};
            const Cut cut = clipper.clip(X, bisector, static_cast<int>(j), next);
            if (cut == Cut::cut)
              std::swap(X, next);
            else if (cut == Cut::outside) // nuclei closer than the tolerance: no cell
              {
                X.clear();
                return;
              }
          }
      }



      /// The cell's volume, centroid and second moment: exact integrals over its @p pieces.
      void
      integrate_cell(const std::vector<ConvexPolyhedron> &pieces, const double scale, const std::string &where, Cell<3> &cell)
      {
        const Point       &x = cell.nucleus;
        Polyhedral::Moments moments;
        for (const auto &piece : pieces)
          moments.add_volume(piece, x);
        require(moments.measure > 1e-15 * scale * scale * scale,
                where,
                "the cell of the point " + text(x) + " has no volume in the bodies");
        cell.volume   = moments.measure;
        cell.centroid = x + moments.first / moments.measure;
        cell.second_moment = moments.second;
        for (unsigned int a = 0; a < 3; ++a)
          for (unsigned int b = a; b < 3; ++b)
            cell.second_moment[a][b] -= moments.first[a] * moments.first[b] / moments.measure;
      }



      /**
       * The faces of the cell's @p pieces (Cell::pieces) and its reach; the parts of its
       * faces on the domain's planes beyond which the domain does not continue
       * (Cell::boundary; the rest is a cut between two pieces of this cell); and the
       * faces on the bisector of a neighbour b > i in @p facet_faces (neighbour, piece,
       * face).
       */
      void
      cell_faces(const std::vector<ConvexPolyhedron>      &pieces,
                 const unsigned int                        i,
                 const Polyhedral::Domain                 &domain,
                 Polyhedral::Clipper                      &clipper,
                 Cell<3>                                  &cell,
                 std::vector<std::array<unsigned int, 3>> &facet_faces)
      {
        std::vector<ConvexPolygon> parts;
        facet_faces.clear();
        cell.pieces.resize(pieces.size());
        for (unsigned int p = 0; p < pieces.size(); ++p)
          {
            const auto &piece = pieces[p];
            for (const auto &v : piece.vertices)
              cell.reach = std::max(cell.reach, v.distance(cell.nucleus));
            cell.pieces[p].resize(piece.n_faces());
            for (unsigned int f = 0; f < piece.n_faces(); ++f)
              {
                auto &face = cell.pieces[p][f];
                for (unsigned int k = piece.face_start[f]; k < piece.face_start[f + 1]; ++k)
                  face.push_back(piece.vertices[piece.face_vertices[k]]);
                const int tag = piece.tags[f];
                if (tag > static_cast<int>(i))
                  facet_faces.push_back({{static_cast<unsigned int>(tag), p, f}});
                else if (Polyhedral::is_plane_tag(tag))
                  {
                    const unsigned int plane = Polyhedral::tag_plane(tag);
                    const Vector       n     = domain.plane(plane).normal;
                    ConvexPolygon      G{face, Polyhedral::tag_flipped(tag) ? -n : n};
                    parts.clear();
                    domain.boundary_part(G, plane, parts, clipper);
                    for (auto &part : parts)
                      cell.boundary.push_back(std::move(part.vertices));
                  }
              }
          }
      }



      /**
       * The principal axes and second moments of a facet's area from its moments about
       * a reference point. The second moment about the centroid, in a basis (e1, e2) of
       * the plane: M = [[a, c], [c, b]]; its eigenvector of the larger eigenvalue at the
       * angle theta = atan2(2 c, a - b) / 2 from e1. axis_1 is the other one (I_1 =
       * int (xi . axis_2)^2 dA is the larger moment) and axis_2 = normal x axis_1.
       */
      void
      principal_axes(const Polyhedral::Moments &area, Facet<3> &facet)
      {
        dealii::SymmetricTensor<2, 3> J = area.second;
        for (unsigned int p = 0; p < 3; ++p)
          for (unsigned int q = p; q < 3; ++q)
            J[p][q] -= area.first[p] * area.first[q] / area.measure;
        const Vector e1 = Polyhedral::perpendicular(facet.normal), e2 = cross_product_3d(facet.normal, e1);
        const double a = e1 * (J * e1), bb = e2 * (J * e2), c = e1 * (J * e2);
        const double mean = 0.5 * (a + bb), radius = std::sqrt(0.25 * (a - bb) * (a - bb) + c * c);
        if (radius <= 1e-9 * std::abs(mean))
          {
            facet.axis_1 = e1; // isotropic: the deterministic basis of the plane
            facet.axis_2 = e2;
          }
        else
          {
            const double theta = 0.5 * std::atan2(2 * c, a - bb);
            facet.axis_1       = -std::sin(theta) * e1 + std::cos(theta) * e2;
            facet.axis_2       = cross_product_3d(facet.normal, facet.axis_1);
          }
        facet.second_moment_1 = mean + radius;
        facet.second_moment_2 = mean - radius;
      }



      /// The facets of cell @p i with its neighbours b > i: the faces tagged b of all pieces.
      void
      add_facets(const std::vector<Point>                 &nuclei,
                 const unsigned int                        i,
                 const Cell<3>                            &cell,
                 std::vector<std::array<unsigned int, 3>> &facet_faces,
                 const double                              scale,
                 Tessellation<3>                          &result)
      {
        const Point &x = nuclei[i];
        std::sort(facet_faces.begin(), facet_faces.end());
        for (unsigned int s = 0; s < facet_faces.size();)
          {
            const unsigned int b = facet_faces[s][0];
            Facet<3>           facet;
            facet.a                = i;
            facet.b                = b;
            const Vector d         = nuclei[b] - x;
            facet.distance         = d.norm();
            facet.normal           = d / facet.distance;
            const Point reference  = Point(0.5 * (x + nuclei[b]));
            Polyhedral::Moments area;
            for (; s < facet_faces.size() && facet_faces[s][0] == b; ++s)
              {
                const auto &face = cell.pieces[facet_faces[s][1]][facet_faces[s][2]];
                area.add_area(face.data(), face.size(), facet.normal, reference);
                facet.polygons.push_back(face);
              }
            if (area.measure < 1e-12 * scale * scale)
              continue;
            facet.area     = area.measure;
            facet.midpoint = reference + area.first / area.measure;
            facet.h_a      = (facet.midpoint - x) * facet.normal;
            facet.h_b      = (nuclei[b] - facet.midpoint) * facet.normal;
            principal_axes(area, facet);
            result.facets.push_back(std::move(facet));
          }
      }
    } // namespace



    Tessellation<3>
    voronoi(const std::vector<dealii::Point<3>>            &nuclei,
            const std::vector<const Geometry::Region<3> *> &bodies,
            const double                                    boundary_h,
            const std::string                              &where,
            const std::vector<bool>                        &wanted)
    {
      const unsigned int n = nuclei.size();
      require(n >= 2, where, "a network needs at least two cells");
      require(wanted.empty() || wanted.size() == n, where, "one flag per nucleus is needed");
      const Polyhedral::Domain domain(bodies, boundary_h, where);
      const double             scale = domain.scale;
      for (const auto &p : nuclei)
        require(domain.contains(p, 1e-9 * scale), where, "the point " + text(p) + " lies outside the bodies");
      const std::vector<std::vector<unsigned int>> neighbours = delaunay_neighbours(nuclei, where);

      Tessellation<3> result;
      result.cells.resize(n);
      Polyhedral::Clipper           clipper(domain.tolerance);
      ConvexPolyhedron              start, X;
      std::vector<ConvexPolyhedron> pieces;
      const Vector                  margin({0.5 * scale, 0.5 * scale, 0.5 * scale});
      start.make_box(domain.box.lo - margin, domain.box.hi + margin, Polyhedral::box_tag);
      std::vector<std::array<unsigned int, 3>> facet_faces; // neighbour, piece, face
      for (unsigned int i = 0; i < n; ++i)
        {
          if (!wanted.empty() && !wanted[i])
            continue;
          // The Voronoi cell, its pieces in the domain, their integrals, faces and facets.
          voronoi_cell(nuclei, i, neighbours[i], start, clipper, X);
          pieces.clear();
          if (!X.empty())
            domain.intersect(X, pieces, clipper);
          Cell<3> &cell = result.cells[i];
          cell.nucleus  = nuclei[i];
          integrate_cell(pieces, scale, where, cell);
          cell_faces(pieces, i, domain, clipper, cell, facet_faces);
          add_facets(nuclei, i, cell, facet_faces, scale, result);
        }
      return result;
    }
  } // namespace RBSN
} // namespace hysteron

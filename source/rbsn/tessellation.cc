// The 2D Voronoi tessellation: the Voronoi cells of the nuclei clipped to the bodies, and their facets.
#include <deal.II/base/exceptions.h>

#include <hysteron/base/exceptions.h>
#include "rbsn/tessellation.h"

#include "rbsn/boundary_2d.h"
#include "rbsn/cgal.h"
#include "rbsn/sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      using Planar::chain;
      using Planar::cross;
      using Planar::intersect;
      using Planar::oriented_boundary;
      using Planar::Point;
      using Planar::Segment;
      using Sampling::text;

      /// The exact integrals of a region over oriented boundary pieces (Green's theorem).
      struct Moments
      {
        double area = 0, sx = 0, sy = 0, polar = 0; ///< int 1, x, y, x^2 + y^2

        void
        add(const Point &p, const Point &q)
        {
          const double c = p[0] * q[1] - q[0] * p[1];
          area += 0.5 * c;
          sx += c * (p[0] + q[0]) / 6;
          sy += c * (p[1] + q[1]) / 6;
          polar += c * (p[0] * p[0] + p[0] * q[0] + q[0] * q[0] + p[1] * p[1] + p[1] * q[1] + q[1] * q[1]) / 12;
        }
      };



      /**
       * The domain of a 2D tessellation: the bodies polygonized (segments of
       * boundary_h), their box, and their oriented boundary in buckets of about two
       * cells' size over the box, so that a cell meets only the segments near it.
       */
      class PolygonalDomain
      {
      public:
        PolygonalDomain(const std::vector<const Geometry::Region<2> *> &bodies, const double boundary_h)
          : lo(std::numeric_limits<double>::max(), std::numeric_limits<double>::max())
          , hi(-lo)
          , boundary_h(boundary_h)
        {
          for (const auto *b : bodies)
            {
              domain.push_back(b->polygonized(boundary_h));
              const auto box = b->bounding_box().get_boundary_points();
              for (unsigned int d = 0; d < 2; ++d)
                {
                  lo[d] = std::min(lo[d], box.first[d]);
                  hi[d] = std::max(hi[d], box.second[d]);
                }
            }
          scale = lo.distance(hi);
        }

        bool
        contains(const Point &p, const double tolerance) const
        {
          for (const auto &b : domain)
            if (b.contains(p, tolerance))
              return true;
          return false;
        }

        /// The box around the bodies and its diagonal.
        Point  lo, hi;
        double scale = 0;

        /// The oriented boundary in buckets sized for @p n_cells cells.
        void
        sort_boundary(const std::size_t n_cells)
        {
          boundary = oriented_boundary(domain, boundary_h, scale);
          bucket   = std::max(2 * std::sqrt((hi[0] - lo[0]) * (hi[1] - lo[1]) / n_cells), 1e-3 * scale);
          bx       = std::max(1, static_cast<int>(std::ceil((hi[0] - lo[0]) / bucket)));
          by       = std::max(1, static_cast<int>(std::ceil((hi[1] - lo[1]) / bucket)));
          buckets.assign(static_cast<std::size_t>(bx) * by, {});
          for (unsigned int k = 0; k < boundary.size(); ++k)
            {
              const Point a(std::min(boundary[k][0][0], boundary[k][1][0]), std::min(boundary[k][0][1], boundary[k][1][1]));
              const Point b(std::max(boundary[k][0][0], boundary[k][1][0]), std::max(boundary[k][0][1], boundary[k][1][1]));
              const auto  r = bucket_range(a, b);
              for (int y = r[2]; y <= r[3]; ++y)
                for (int x = r[0]; x <= r[1]; ++x)
                  buckets[static_cast<std::size_t>(y) * bx + x].push_back(k);
            }
          seen.assign(boundary.size(), 0);
        }

        /**
         * The boundary segments whose buckets meet the box of the polygon @p poly grown
         * by 2 @p eps (in their order), for the cell @p i. A cell that meets none lies in
         * the domain: its nucleus does.
         */
        std::vector<Segment>
        near(const std::vector<Point> &poly, const unsigned int i, const double eps)
        {
          Point a = poly[0], b = poly[0];
          for (const auto &p : poly)
            for (unsigned int d = 0; d < 2; ++d)
              {
                a[d] = std::min(a[d], p[d] - 2 * eps);
                b[d] = std::max(b[d], p[d] + 2 * eps);
              }
          const auto                r = bucket_range(a, b);
          std::vector<unsigned int> found;
          for (int y = r[2]; y <= r[3]; ++y)
            for (int x = r[0]; x <= r[1]; ++x)
              for (const unsigned int k : buckets[static_cast<std::size_t>(y) * bx + x])
                if (seen[k] != i + 1)
                  {
                    seen[k] = i + 1;
                    found.push_back(k);
                  }
          std::sort(found.begin(), found.end());
          std::vector<Segment> result;
          for (const unsigned int k : found)
            result.push_back(boundary[k]);
          return result;
        }

      private:
        std::vector<Geometry::Region<2>>       domain;
        const double                           boundary_h;
        std::vector<Segment>                   boundary;
        double                                 bucket = 0;
        int                                    bx = 1, by = 1;
        std::vector<std::vector<unsigned int>> buckets;
        std::vector<unsigned int>              seen; ///< i + 1 once cell i has found a segment

        std::array<int, 4>
        bucket_range(const Point &a, const Point &b) const
        {
          const auto at = [&](const double x, const double origin, const int n) {
            return std::clamp(static_cast<int>(std::floor((x - origin) / bucket)), 0, n - 1);
          };
          return std::array<int, 4>{{at(a[0], lo[0], bx), at(b[0], lo[0], bx), at(a[1], lo[1], by), at(b[1], lo[1], by)}};
        }
      };



      /// The Voronoi neighbours of every nucleus from the Delaunay triangulation.
      std::vector<std::vector<unsigned int>>
      delaunay_neighbours(const std::vector<Point> &nuclei, const std::string &where)
      {
        using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
        using Vb     = CGAL::Triangulation_vertex_base_with_info_2<unsigned int, Kernel>;
        using Tds    = CGAL::Triangulation_data_structure_2<Vb>;
        using DT     = CGAL::Delaunay_triangulation_2<Kernel, Tds>;
        DT dt;
        {
          std::vector<std::pair<Kernel::Point_2, unsigned int>> input;
          for (unsigned int i = 0; i < nuclei.size(); ++i)
            input.emplace_back(Kernel::Point_2(nuclei[i][0], nuclei[i][1]), i);
          dt.insert(input.begin(), input.end());
        }
        require(dt.number_of_vertices() == nuclei.size(), where, "two points coincide");
        std::vector<std::vector<unsigned int>> neighbours(nuclei.size());
        if (dt.dimension() < 2)
          {
            // Collinear nuclei (e.g. a single element of two cells): the Voronoi
            // neighbours are the next points along the line.
            std::vector<unsigned int> order(nuclei.size());
            for (unsigned int i = 0; i < order.size(); ++i)
              order[i] = i;
            const dealii::Tensor<1, 2> direction = nuclei[1] - nuclei[0];
            std::sort(order.begin(), order.end(), [&](const unsigned int a, const unsigned int b) {
              return nuclei[a] * direction < nuclei[b] * direction;
            });
            for (unsigned int k = 0; k + 1 < order.size(); ++k)
              {
                neighbours[order[k]].push_back(order[k + 1]);
                neighbours[order[k + 1]].push_back(order[k]);
              }
          }
        else
          for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v)
            {
              auto c = dt.incident_vertices(v), done = c;
              if (c != nullptr)
                do
                  if (!dt.is_infinite(c))
                    neighbours[v->info()].push_back(c->info());
                while (++c != done);
              std::sort(neighbours[v->info()].begin(), neighbours[v->info()].end());
            }
        return neighbours;
      }



      /**
       * The convex Voronoi cell of nucleus @p i: the box around the domain clipped by the
       * bisector of every neighbour, counter-clockwise; tag[k] is the neighbour across the
       * edge poly[k] -> poly[k + 1] (-1: the box).
       */
      void
      voronoi_polygon(const std::vector<Point>        &nuclei,
                      const unsigned int               i,
                      const std::vector<unsigned int> &neighbours,
                      const PolygonalDomain           &domain,
                      std::vector<Point>              &poly,
                      std::vector<int>                &tag)
      {
        const Point &lo = domain.lo, &hi = domain.hi;
        const double margin = 0.5 * domain.scale;
        poly = {Point(lo[0] - margin, lo[1] - margin), Point(hi[0] + margin, lo[1] - margin),
                Point(hi[0] + margin, hi[1] + margin), Point(lo[0] - margin, hi[1] + margin)};
        tag.assign(4, -1);
        for (const unsigned int j : neighbours)
          {
            const dealii::Tensor<1, 2> n = nuclei[j] - nuclei[i];
            const Point                m = 0.5 * (nuclei[i] + nuclei[j]);
            const auto                 f = [&](const Point &p) { return (p - m) * n; }; // <= 0 inside
            std::vector<Point>         out;
            std::vector<int>           out_tag;
            for (unsigned int k = 0; k < poly.size(); ++k)
              {
                const Point &p = poly[k], &q = poly[(k + 1) % poly.size()];
                const double fp = f(p), fq = f(q);
                if (fp <= 0)
                  {
                    out.push_back(p);
                    out_tag.push_back(tag[k]);
                  }
                if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0))
                  {
                    out.push_back(p + fp / (fp - fq) * (q - p));
                    out_tag.push_back(fp < 0 ? static_cast<int>(j) : tag[k]);
                  }
                else if (fp == 0 && fq > 0)
                  out_tag.back() = j; // p on the bisector: the edge from p runs along it
              }
            poly.swap(out);
            tag.swap(out_tag);
          }
        // Drop repeated vertices (a bisector through a vertex, as for cocircular
        // nuclei): a zero-length edge has no direction, and the inside tests of
        // clip_cell() need one for every edge. The edge that follows keeps its tag.
        std::vector<Point> kept;
        std::vector<int>   kept_tag;
        for (unsigned int k = 0; k < poly.size(); ++k)
          if (poly[k].distance(poly[(k + 1) % poly.size()]) >= 1e-14 * domain.scale)
            {
              kept.push_back(poly[k]);
              kept_tag.push_back(tag[k]);
            }
        poly.swap(kept);
        tag.swap(kept_tag);
      }



      /// The pieces of the cells' edges on the Voronoi edge between two nuclei (a < b).
      using FacetPieces = std::map<std::pair<unsigned int, unsigned int>, std::vector<Segment>>;

      /**
       * The cell's edges inside the domain (appended to @p pieces, @p moments and, on a
       * Voronoi edge to a nucleus b > i, to @p facet_pieces): each edge split where the
       * @p near boundary segments cross it, the parts whose left side lies in the domain.
       */
      void
      edges_in_domain(const std::vector<Point>   &poly,
                      const std::vector<int>     &tag,
                      const unsigned int          i,
                      const std::vector<Segment> &near,
                      const PolygonalDomain      &domain,
                      const double                eps,
                      std::vector<Segment>       &pieces,
                      Moments                    &moments,
                      FacetPieces                &facet_pieces)
      {
        const unsigned int m = poly.size();
        for (unsigned int k = 0; k < m; ++k)
          {
            const Point &p = poly[k], &q = poly[(k + 1) % m];
            std::vector<double> cuts{0.0, 1.0};
            for (const auto &s : near)
              {
                double a, b;
                if (intersect(p, q, s[0], s[1], a, b))
                  cuts.push_back(a);
              }
            std::sort(cuts.begin(), cuts.end());
            const dealii::Tensor<1, 2> r = q - p;
            const dealii::Tensor<1, 2> left({-r[1] / r.norm(), r[0] / r.norm()});
            for (unsigned int c = 0; c + 1 < cuts.size(); ++c)
              {
                if (cuts[c + 1] - cuts[c] < 1e-12)
                  continue;
                const Point a = p + cuts[c] * r, b = p + cuts[c + 1] * r;
                if (!near.empty() && !domain.contains(0.5 * (a + b) + eps * left, 0.0))
                  continue;
                pieces.push_back(Segment{{a, b}});
                moments.add(a, b);
                if (tag[k] >= 0 && static_cast<unsigned int>(tag[k]) > i)
                  facet_pieces[{i, static_cast<unsigned int>(tag[k])}].push_back(Segment{{a, b}});
              }
          }
      }



      /**
       * The parts of the @p near boundary segments strictly inside the convex cell
       * @p poly (appended to @p pieces, @p moments and the cell's @p boundary).
       */
      void
      boundary_in_cell(const std::vector<Point>   &poly,
                       const std::vector<Segment> &near,
                       const double                eps,
                       std::vector<Segment>       &pieces,
                       Moments                    &moments,
                       std::vector<Segment>       &boundary)
      {
        const unsigned int m = poly.size();
        for (const auto &s : near)
          {
            // Cyrus-Beck: the part of s inside the convex cell.
            double t0 = 0, t1 = 1;
            const dealii::Tensor<1, 2> r = s[1] - s[0];
            for (unsigned int k = 0; k < m && t0 < t1; ++k)
              {
                const Point               &p = poly[k], &q = poly[(k + 1) % m];
                const dealii::Tensor<1, 2> e = q - p;
                // inside: cross(e, x - p) >= 0 (counter-clockwise cell)
                const double g0 = cross(e, s[0] - p), dg = cross(e, r);
                if (std::abs(dg) < 1e-300)
                  {
                    if (g0 < 0)
                      t1 = -1;
                    continue;
                  }
                const double t = -g0 / dg;
                if (dg > 0)
                  t0 = std::max(t0, t);
                else
                  t1 = std::min(t1, t);
              }
            if (t1 - t0 < 1e-12)
              continue;
            const Point a = s[0] + t0 * r, b = s[0] + t1 * r, mid = 0.5 * (a + b);
            // Strictly inside the cell (a piece on the cell's edge came from the edge).
            bool strict = true;
            for (unsigned int k = 0; k < m && strict; ++k)
              {
                const dealii::Tensor<1, 2> e = poly[(k + 1) % m] - poly[k];
                strict = cross(e, mid - poly[k]) > eps * e.norm();
              }
            if (!strict)
              continue;
            pieces.push_back(Segment{{a, b}});
            moments.add(a, b);
            boundary.push_back(Segment{{a, b}});
          }
      }



      /// The facets: the Voronoi edges in the domain (pieces across a hole joined).
      void
      add_facets(const FacetPieces &facet_pieces, const std::vector<Point> &nuclei, const double scale, Tessellation<2> &result)
      {
        for (const auto &[cells, pieces] : facet_pieces)
          {
            Facet<2> f;
            f.a = cells.first;
            f.b = cells.second;
            dealii::Tensor<1, 2> weighted;
            double               longest = 0;
            for (const auto &s : pieces)
              {
                const double l = s[0].distance(s[1]);
                f.length += l;
                weighted += l * (0.5 * (s[0] + s[1]));
                if (l > longest)
                  {
                    longest = l;
                    f.p3    = s[0];
                    f.p4    = s[1];
                  }
              }
            if (f.length < 1e-12 * scale)
              continue;
            f.midpoint = Point(weighted[0] / f.length, weighted[1] / f.length);
            const dealii::Tensor<1, 2> d = nuclei[f.b] - nuclei[f.a];
            f.distance                   = d.norm();
            f.normal                     = d / f.distance;
            f.h_a                        = (f.midpoint - nuclei[f.a]) * f.normal;
            f.h_b                        = (nuclei[f.b] - f.midpoint) * f.normal;
            result.facets.push_back(f);
          }
      }
    } // namespace



    Tessellation<2>
    voronoi(const std::vector<dealii::Point<2>>            &nuclei,
            const std::vector<const Geometry::Region<2> *> &bodies,
            const double                                    boundary_h,
            const std::string                              &where,
            const std::vector<bool>                        &wanted)
    {
      require(nuclei.size() >= 2, where, "a network needs at least two cells");
      PolygonalDomain domain(bodies, boundary_h);
      const double    scale = domain.scale;
      for (const auto &p : nuclei)
        require(domain.contains(p, 1e-9 * scale), where, "the point " + text(p) + " lies outside the bodies");
      domain.sort_boundary(nuclei.size());
      const std::vector<std::vector<unsigned int>> neighbours = delaunay_neighbours(nuclei, where);

      Tessellation<2> result;
      result.cells.resize(nuclei.size());
      FacetPieces        facet_pieces;
      const double       eps = 1e-9 * scale;
      std::vector<Point> poly;
      std::vector<int>   tag;
      for (unsigned int i = 0; i < nuclei.size(); ++i)
        {
          if (!wanted.empty() && !wanted[i])
            continue;
          // The boundary of cell and domain: the cell's edges inside the domain, and the
          // domain's boundary inside the cell; Green's theorem over it gives the integrals.
          voronoi_polygon(nuclei, i, neighbours[i], domain, poly, tag);
          const std::vector<Segment> near = domain.near(poly, i, eps);
          Cell<2>                   &cell = result.cells[i];
          std::vector<Segment>       pieces;
          Moments                    moments;
          edges_in_domain(poly, tag, i, near, domain, eps, pieces, moments, facet_pieces);
          boundary_in_cell(poly, near, eps, pieces, moments, cell.boundary);

          cell.nucleus = nuclei[i];
          for (const auto &piece : pieces)
            for (const auto &p : piece)
              cell.reach = std::max(cell.reach, p.distance(nuclei[i]));
          cell.area    = moments.area;
          require(cell.area > 0, where, "the cell of the point " + text(nuclei[i]) + " has no area in the bodies");
          cell.centroid     = Point(moments.sx / moments.area, moments.sy / moments.area);
          cell.polar_moment = moments.polar - moments.area * cell.centroid.square();
          cell.outline      = chain(pieces, 1e-8 * scale);
        }
      add_facets(facet_pieces, nuclei, scale, result);
      return result;
    }
  } // namespace RBSN
} // namespace hysteron

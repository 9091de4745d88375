// The sharp edges of the 3D boundary: where the surface turns, their corners, and the points along them.
#include "rbsn/tessellation.h"

#include "rbsn/sharp_edges_3d.h"
#include "rbsn/spread.h"

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
        /// Whether x lies on the convex polygon (within @p tolerance of its plane and edges).
        bool
        on_polygon(const ConvexPolygon &P, const Point &x, const double tolerance)
        {
          const auto &v = P.vertices;
          if (std::abs(P.normal * (x - v[0])) > tolerance)
            return false;
          for (unsigned int k = 0; k < v.size(); ++k)
            {
              const Vector e = v[(k + 1) % v.size()] - v[k];
              const Vector out = cross_product_3d(e, P.normal);
              if ((x - v[k]) * out > tolerance * out.norm())
                return false;
            }
          return true;
        }



        /**
         * The sharp edges of the boundary: the edges of the boundary polygons (split where
         * another polygon's vertex lies on them) along which the surface turns by more than
         * 20 degrees, found by the polygons that hold an edge's midpoint. Points closer
         * than @p match are the same.
         */
        std::vector<std::array<Point, 2>>
        sharp_edges(const std::vector<BoundaryPolygon> &polygons, const double match)
        {
          const double        sharp = std::cos(20.0 * M_PI / 180.0);
          BoxTree polygon_tree, vertex_tree;
          std::vector<Point>  vertices;
          {
            std::vector<Box> boxes, vertex_boxes;
            for (const auto &b : polygons)
              {
                boxes.push_back(b.polygon.bounding_box());
                for (const auto &v : b.polygon.vertices)
                  {
                    vertices.push_back(v);
                    vertex_boxes.emplace_back();
                    vertex_boxes.back().add(v);
                  }
              }
            polygon_tree.build(boxes);
            vertex_tree.build(vertex_boxes);
          }
          std::vector<std::array<Point, 2>> segments;
          std::vector<unsigned int>         found;
          for (unsigned int i = 0; i < polygons.size(); ++i)
            {
              const auto &v = polygons[i].polygon.vertices;
              for (unsigned int e = 0; e < v.size(); ++e)
                {
                  const Point &a = v[e], &b = v[(e + 1) % v.size()];
                  const Vector r = b - a;
                  if (r.norm() <= match)
                    continue;
                  Box box;
                  box.add(a);
                  box.add(b);
                  found.clear();
                  vertex_tree.query(box, match, found);
                  std::vector<double> cuts{0.0, 1.0};
                  for (const unsigned int k : found)
                    {
                      const double t = (vertices[k] - a) * r / r.norm_square();
                      if (t > 0 && t < 1 && (a + t * r).distance(vertices[k]) < match)
                        cuts.push_back(t);
                    }
                  std::sort(cuts.begin(), cuts.end());
                  for (unsigned int c = 0; c + 1 < cuts.size(); ++c)
                    {
                      if ((cuts[c + 1] - cuts[c]) * r.norm() <= match)
                        continue;
                      const Point m = a + (0.5 * (cuts[c] + cuts[c + 1])) * r;
                      Box         mb;
                      mb.add(m);
                      std::vector<unsigned int> around;
                      polygon_tree.query(mb, match, around);
                      bool neighbour = false, turn = false;
                      for (const unsigned int k : around)
                        if (k != i && on_polygon(polygons[k].polygon, m, match))
                          {
                            neighbour = true;
                            turn      = turn || polygons[k].polygon.normal * polygons[i].polygon.normal < sharp;
                          }
                      if (!neighbour || turn)
                        segments.push_back({{a + cuts[c] * r, a + cuts[c + 1] * r}});
                    }
                }
            }
          return segments;
        }



        /**
         * The graph of the sharp edges: their end points merged within `match` into
         * nodes, every edge once, and its corners: the nodes where the number of sharp
         * edges is not 2, or where the two turn by more than 20 degrees.
         */
        class EdgeGraph
        {
        public:
          EdgeGraph(const std::vector<std::array<Point, 2>> &segments, const double match)
            : match(match)
            , bucket_size(10 * match)
          {
            for (const auto &s : segments)
              {
                const unsigned int a = node_of(s[0]), b = node_of(s[1]);
                if (a != b)
                  edges.emplace_back(std::min(a, b), std::max(a, b));
              }
            std::sort(edges.begin(), edges.end());
            edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
            incident.resize(node.size());
            for (unsigned int e = 0; e < edges.size(); ++e)
              {
                incident[edges[e].first].push_back(e);
                incident[edges[e].second].push_back(e);
              }
            corner.assign(node.size(), false);
            for (unsigned int v = 0; v < node.size(); ++v)
              if (incident[v].size() != 2)
                corner[v] = !incident[v].empty();
              else
                {
                  const Vector a = node[v] - node[other(incident[v][0], v)], b = node[other(incident[v][1], v)] - node[v];
                  corner[v] = std::atan2(cross_product_3d(a, b).norm(), a * b) > 20.0 * M_PI / 180.0;
                }
          }

          /**
           * The corners, then points along the runs of sharp edges from corner to corner
           * (and around the closed runs without a corner, from their first node).
           */
          void
          spread_points(const Spacing<3> &spacing, std::vector<Point> &points)
          {
            for (unsigned int v = 0; v < node.size(); ++v)
              if (corner[v])
                points.push_back(node[v]);
            visited.assign(edges.size(), false);
            for (unsigned int v = 0; v < node.size(); ++v)
              if (corner[v])
                for (const unsigned int e : incident[v])
                  if (!visited[e])
                    spread(walk(v, e), spacing, false, points);
            for (unsigned int e = 0; e < edges.size(); ++e)
              if (!visited[e])
                spread(walk(edges[e].first, e), spacing, true, points);
          }

        private:
          const double                                                  match, bucket_size;
          std::vector<Point>                                            node;
          std::map<std::array<long long, 3>, std::vector<unsigned int>> bucket; ///< nodes by cubes of bucket_size
          std::vector<std::pair<unsigned int, unsigned int>>            edges;
          std::vector<std::vector<unsigned int>>                        incident;
          std::vector<bool>                                             corner, visited;

          /// The node within `match` of p (a new one if none).
          unsigned int
          node_of(const Point &p)
          {
            std::array<long long, 3> key;
            for (unsigned int k = 0; k < 3; ++k)
              key[k] = static_cast<long long>(std::floor(p[k] / bucket_size));
            for (int dz = -1; dz <= 1; ++dz)
              for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                  {
                    const auto b = bucket.find({{key[0] + dx, key[1] + dy, key[2] + dz}});
                    if (b != bucket.end())
                      for (const unsigned int q : b->second)
                        if (node[q].distance(p) < match)
                          return q;
                  }
            bucket[key].push_back(node.size());
            node.push_back(p);
            return static_cast<unsigned int>(node.size() - 1);
          }

          unsigned int
          other(const unsigned int e, const unsigned int v) const
          {
            return edges[e].first == v ? edges[e].second : edges[e].first;
          }

          /// The run from node @p start along edge @p e to the next corner (or back to start).
          std::vector<Point>
          walk(const unsigned int start, unsigned int e)
          {
            std::vector<Point> path{node[start]};
            unsigned int       v = start;
            while (true)
              {
                visited[e] = true;
                v          = other(e, v);
                path.push_back(node[v]);
                if (corner[v] || v == start)
                  break;
                const unsigned int f = incident[v][0] == e ? incident[v][1] : incident[v][0];
                if (visited[f])
                  break;
                e = f;
              }
            return path;
          }
        };
      } // namespace



      std::vector<Point>
      sharp_edge_points(const std::vector<BoundaryPolygon> &polygons, const double match, const Spacing<3> &spacing)
      {
        std::vector<Point> points;
        EdgeGraph(sharp_edges(polygons, match), match).spread_points(spacing, points);
        return points;
      }
    } // namespace Polyhedral
  }   // namespace RBSN
} // namespace hysteron

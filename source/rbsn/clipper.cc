// Clipper: convex polyhedra and polygons clipped by a plane.
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
        if (const Cut c = classify(in.vertices, plane); c != Cut::cut)
          return c;
        const unsigned int n_kept = cut_faces(in, out);
        merge_cap_vertices(in.vertices.size(), n_kept, out);
        add_cap_face(plane, tag, out);
        if (out.n_faces() < 4)
          {
            out.clear();
            return Cut::outside; // nothing of volume is left
          }
        drop_unused_vertices(out);
        return Cut::cut;
      }



      unsigned int
      Clipper::cut_faces(const ConvexPolyhedron &in, ConvexPolyhedron &out)
      {
        // The vertices kept (in the half-space or on the plane), then one new vertex on
        // every edge from strictly inside to strictly outside, shared by its two faces.
        const unsigned int nv = in.vertices.size();
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
                  out.face_vertices.push_back(cut_vertex(in, a, b, out));
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
        return n_kept;
      }



      unsigned int
      Clipper::cut_vertex(const ConvexPolyhedron &in, const unsigned int a, const unsigned int b, ConvexPolyhedron &out)
      {
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
      }



      void
      Clipper::merge_cap_vertices(const unsigned int n_in, const unsigned int n_kept, ConvexPolyhedron &out)
      {
        // The vertices on the plane: merge those closer than the tolerance (the first
        // one stays), then drop repeated vertices from the loops.
        const unsigned int nout = out.vertices.size();
        cap.clear();
        for (unsigned int v = 0; v < n_in; ++v)
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
        if (!any_merged)
          return;
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



      void
      Clipper::add_cap_face(const Plane &plane, const int tag, ConvexPolyhedron &out)
      {
        // The (merged) vertices on the plane that the faces use, sorted by their angle
        // about the plane's normal (counter-clockwise seen from outside).
        const unsigned int nout = out.vertices.size();
        used.assign(nout, false);
        for (const unsigned int v : out.face_vertices)
          used[v] = true;
        order.clear();
        for (const unsigned int v : cap)
          if (used[v] && merged[v] == v)
            order.push_back(v);
        if (order.size() < 3)
          return;
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



      void
      Clipper::drop_unused_vertices(ConvexPolyhedron &out)
      {
        // Merged vertices and those of dropped faces.
        const unsigned int nout = out.vertices.size();
        used.assign(nout, false);
        for (const unsigned int v : out.face_vertices)
          used[v] = true;
        if (std::find(used.begin(), used.end(), false) == used.end())
          return;
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
    } // namespace Polyhedral
  }   // namespace RBSN
} // namespace hysteron

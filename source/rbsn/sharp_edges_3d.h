#ifndef hysteron_source_rbsn_sharp_edges_3d_h
#define hysteron_source_rbsn_sharp_edges_3d_h

#include <deal.II/base/point.h>

#include "rbsn/tessellation.h"

#include "rbsn/polyhedron.h"

#include <vector>

/**
 * @file
 * The first boundary points of the 3D RBSN (boundary_points()): those on the sharp
 * edges of the polyhedral domain.
 */
namespace hysteron
{
  namespace RBSN
  {
    namespace Polyhedral
    {
      /**
       * The corners and the points along the sharp edges of the domain's boundary
       * @p polygons (Domain::boundary()): the edges along which the surface turns by
       * more than 20 degrees, the corners where such edges meet or turn by more than 20
       * degrees, and between corners points at equal steps of int ds / d (at most the
       * local d apart). Points closer than @p match are the same.
       */
      std::vector<Point>
      sharp_edge_points(const std::vector<BoundaryPolygon> &polygons, const double match, const Spacing<3> &spacing);
    } // namespace Polyhedral
  }   // namespace RBSN
} // namespace hysteron

#endif

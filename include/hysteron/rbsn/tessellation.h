#ifndef hysteron_rbsn_tessellation_h
#define hysteron_rbsn_tessellation_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <hysteron/geometry/region.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * The Rigid-Body-Spring Network (dissertation chapter 3): Voronoi cells as
   * rigid bodies, joined at their common facets by zero-length springs.
   */
  namespace RBSN
  {
    /**
     * Nuclei for the Voronoi cells: the @p fixed points first (user points, points
     * along the boundary; kept as given), then random points in @p domain with a
     * minimum distance @p d_m to every other point, added until the domain is
     * saturated (Bridson's Poisson-disk sampling, seeded: the same seed gives the
     * same points). A saturated random sequential addition approaches
     * n = 0.68 A / d_m^2 points in an area A (Bolander & Saito; dissertation §3.3.3).
     * Fixed points closer than d_m to each other are kept; random ones keep d_m
     * from all. Throws InputError(@p where) for d_m <= 0 or an estimate of more
     * than 5e6 points.
     */
    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const double                         d_m,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where);

    /**
     * Points at spacing of at most @p spacing along the boundary of @p domain
     * (every straight piece of the polygonized boundary gets its end points and
     * equally spaced points between), so that the cells of the boundary have
     * their nuclei on it (supports and loads act there).
     */
    std::vector<dealii::Point<2>>
    boundary_points(const Geometry::Region<2> &domain, const double spacing, const double boundary_h);

    /// A Voronoi cell clipped to the domain: a rigid body.
    struct Cell
    {
      dealii::Point<2> nucleus;  ///< the computational point (its DoFs u, v, theta)
      double           area = 0; ///< of the clipped cell [m^2]
      dealii::Point<2> centroid;
      double           polar_moment = 0; ///< integral of |x - centroid|^2 over the cell [m^4]
      /// The outline of the clipped cell: closed loops of vertices (output).
      std::vector<std::vector<dealii::Point<2>>> outline;
      /// The pieces of the domain's boundary that bound this cell (tractions act there).
      std::vector<std::array<dealii::Point<2>, 2>> boundary;
    };

    /// The common facet of two cells: one element with its three springs.
    struct Facet
    {
      unsigned int           a = 0, b = 0;  ///< the cells, a < b
      dealii::Point<2>       p3, p4;        ///< end points (of the longest piece in the domain)
      dealii::Point<2>       midpoint;      ///< P: the springs' location
      double                 length   = 0;  ///< l: in the domain (all pieces)
      double                 distance = 0;  ///< h = |x_b - x_a|
      double                 h_a = 0, h_b = 0; ///< distances of the nuclei from the facet line
      dealii::Tensor<1, 2>   normal;        ///< from a to b
    };

    struct Tessellation
    {
      std::vector<Cell>  cells;
      std::vector<Facet> facets;
    };

    /**
     * The Voronoi tessellation of @p nuclei clipped to the union of @p bodies
     * (polygonized with segments of @p boundary_h): the cells are the
     * intersections of the Voronoi cells (from CGAL's Delaunay triangulation)
     * with the domain, by exact boundary integrals (Green's theorem over the
     * cell's edges inside the domain and the domain's boundary inside the
     * cell), so that straight boundaries, curved ones and holes are all cut
     * exactly (for a straight edge this equals the dissertation's mirror
     * points). Facets are the Voronoi edges inside the domain; a facet cut into
     * pieces by a hole keeps their total length and their mean midpoint.
     * Deterministic. Throws InputError(@p where) if a nucleus lies outside the
     * domain or two coincide.
     */
    Tessellation
    voronoi(const std::vector<dealii::Point<2>>          &nuclei,
            const std::vector<const Geometry::Region<2> *> &bodies,
            const double                                   boundary_h,
            const std::string                             &where);
  } // namespace RBSN
} // namespace hysteron

#endif

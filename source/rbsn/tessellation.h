#ifndef hysteron_rbsn_tessellation_h
#define hysteron_rbsn_tessellation_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/point.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>
#include <deal.II/base/timer.h>

#include <hysteron/geometry/region.h>

#include <array>
#include <cstdint>
#include <functional>
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
     * The minimum distance of the nuclei, d(x) > 0 (`RBSN/Minimum distance`): a
     * constant d_m, or a function of the point for a graded network (finer where
     * d is smaller). sample() evaluates it over the bodies for its bounds, its
     * gradient and the predicted number of points.
     */
    template <int dim>
    class Spacing
    {
    public:
      /// A constant d_m (not checked here: the parameter is read as a positive number).
      Spacing(const double d_m = 0);

      /// d(x) from @p function; @p expression and @p where name it in errors.
      Spacing(std::function<double(const dealii::Point<dim> &)> function,
              const std::string                                &expression,
              const std::string                                &where);

      /// d(p); throws InputError(where) naming the expression and p unless d(p) > 0 and finite.
      double
      operator()(const dealii::Point<dim> &p) const;

      bool
      is_constant() const
      {
        return !function;
      }

      /**
       * Evaluate d at the midpoints of a grid of about 2^16 square cells (2D) or 2^18
       * cubes (3D) over the bounding box of @p bodies (the points in a body): the
       * bounds of d, its largest gradient (finite differences of neighbouring samples)
       * and the predicted number of points of a saturated set, 0.68 int 1/d^2 dA in 2D
       * and 0.70 int 1/d^3 dV in 3D (midpoint rule; exact for a constant d up to the
       * measure's estimate). The 3D coefficient is measured (doc/rbsn/geometry_3d.md):
       * n d^3 / V = 0.702 away from the faces of a unit cube with d = 0.02, 4 seeds,
       * standard deviation 0.0007; random sequential addition of spheres of diameter
       * d jams at 0.384 = (pi/6) n d^3, n d^3 = 0.734, which the front and the darts
       * approach to 96 %.
       */
      void
      sample(const std::vector<const Geometry::Region<dim> *> &bodies);

      /// The density coefficient of a saturated set: n = coefficient int d^-dim.
      static constexpr double density = dim == 2 ? 0.68 : 0.70;

      /// The smallest and largest d over the bodies (sampled; the constant).
      double min = 0, max = 0;
      /// The largest |grad d| over the bodies (sampled; 0 for a constant).
      double gradient = 0;
      /// density int d^-dim over the bodies (after sample()).
      double predicted_points = 0;
      /// The area (2D) or volume (3D) of the bodies (after sample(); the midpoint rule).
      double measure = 0;

      /**
       * The predicted points of the samples of sample() in each block of a tiling: the
       * blocks of side @p size from @p origin, @p n per direction, numbered i + n_0 (j +
       * n_1 k); a sample belongs to the block of its midpoint (clamped to the tiling).
       */
      std::vector<double>
      predicted_in_blocks(const dealii::Point<dim> &origin, double size, const std::array<int, dim> &n) const;

    private:
      std::function<double(const dealii::Point<dim> &)> function;
      std::string                                       expression, where;
      /// The samples of sample(): midpoints lo + (i + 1/2) step, density / d^dim times
      /// the sample's measure (0 outside the bodies), x fastest.
      dealii::Point<dim>            sample_lo;
      dealii::Tensor<1, dim>        sample_step;
      std::array<unsigned int, dim> sample_n{};
      std::vector<double>           sample_weight;
    };

    /**
     * Nuclei for the Voronoi cells: the @p fixed points first (user points, points
     * along the boundary; kept as given), then random points in @p domain added
     * until it is saturated, each keeping |p - q| >= min(d(p), d(q)) from every
     * point q (Poisson-disk sampling, seeded: the same seed gives the same
     * points). A saturated random sequential addition approaches n = 0.68 A / d^2
     * points in an area A (Bolander & Saito; dissertation §3.3.3), 0.70 V / d^3 in a
     * volume V. Fixed points closer than that to each other are kept. @p d must have
     * been sampled over (at least) @p domain; its bounds only set the background
     * grid, so a sampling that misses an extreme of d costs time, never the distance
     * rule. Bridson's front grows from the points; when it dies out, every background
     * grid cell that no point's exclusion ball covers gets 30 random trials, and
     * the front restarts from each point found: O(n) in all.
     */
    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const Spacing<2>                    &d,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where);

    /**
     * 3D: as above in the polyhedral domain of voronoi() at the resolution
     * @p boundary_h (0: 0.25 d.min, the RBSN's default `Curved boundary resolution`;
     * pass the one given to voronoi() so that every point lies in its domain). The
     * front grows on the unit sphere's directions at radii [d, 2 d]; the gaps are
     * swept with darts per uncovered cube of side d_min / sqrt(3), then per eighth of
     * it for 2 levels. Fixed points own the domain's boundary: where they cover it
     * (rho(x), the distance of a boundary point x from the nearest fixed point, below
     * 1.25 d), no random point comes closer to x than rho(x), so that no random point's
     * cell reaches the boundary (the balls B(v, rho(v)) at the vertices of the fixed
     * points' Voronoi regions restricted to every boundary polygon). Throws InputError(@p where) unless d > 0, for an
     * unbounded body (`all`), and for more than 5e6 points predicted (density V / d^3
     * for a constant d, d.predicted_points otherwise).
     */
    std::vector<dealii::Point<3>>
    poisson_disk_points(const Geometry::Region<3>           &domain,
                        const Spacing<3>                    &d,
                        const std::vector<dealii::Point<3>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where,
                        const double                         boundary_h = 0);

    /// As above for a constant d_m > 0 (throws InputError(@p where) otherwise).
    std::vector<dealii::Point<2>>
    poisson_disk_points(const Geometry::Region<2>           &domain,
                        const double                         d_m,
                        const std::vector<dealii::Point<2>> &fixed,
                        const std::uint64_t                  seed,
                        const std::string                   &where);

    /**
     * Points along the boundary of @p domain, spaced by at most the local d
     * (@p spacing): the corners of the polygonized boundary (a turn of more than
     * 20 degrees) and, between two corners, points at equal steps of the
     * normalised arc length int ds / d(s) (equal arc lengths for a constant d),
     * so that the cells of the boundary have their nuclei on it (supports and
     * loads act there).
     */
    std::vector<dealii::Point<2>>
    boundary_points(const Geometry::Region<2> &domain, const Spacing<2> &spacing, const double boundary_h);

    /**
     * 3D: points on the boundary of the polyhedral domain (the region with its
     * curved primitives as polyhedra at resolution @p boundary_h, see voronoi()):
     * the corners (where sharp edges meet or turn by more than 20 degrees), points
     * along the sharp edges (where the surface turns by more than 20 degrees) at
     * equal steps of int ds / d between corners (at most the local d apart), and
     * Poisson-disk points on every planar face (Bridson's front in its plane from
     * the points on its edges, then darts into the uncovered squares of a grid of
     * side d_min / sqrt(2) and their quarters, 2 levels), each keeping
     * min(d(p), d(q)) from all points so far. Order: corners, edge points, face
     * points. With the random points of poisson_disk_points() (given these as
     * fixed points), the cells that touch a face have their nuclei on it (supports
     * and loads act there). Deterministic for a @p seed. Throws InputError for an
     * unbounded body.
     */
    std::vector<dealii::Point<3>>
    boundary_points(const Geometry::Region<3> &domain,
                    const Spacing<3>          &spacing,
                    const double               boundary_h,
                    const std::uint64_t        seed = 0);

    /**
     * Console lines of a large network's set-up, one per stage: "rbsn: <what> in
     * <t> s" with the time since the last line. Silent unless @p enabled.
     */
    class StageReport
    {
    public:
      StageReport(const dealii::ConditionalOStream &console, const bool enabled);

      /// Print "rbsn: @p what in <t> s" (if enabled) and restart the clock.
      void
      operator()(const std::string &what);

      bool
      enabled() const
      {
        return on;
      }

      /// @p n with thousands separators: 101,234.
      static std::string
      count(const std::size_t n);

    private:
      const dealii::ConditionalOStream &console;
      const bool                        on;
      dealii::Timer                     clock;
    };

    /// A Voronoi cell clipped to the domain: a rigid body.
    template <int dim>
    struct Cell;

    /// The common facet of two cells: one element with its springs.
    template <int dim>
    struct Facet;

    template <>
    struct Cell<2>
    {
      dealii::Point<2> nucleus;  ///< the computational point (its DoFs u, v, theta)
      double           area = 0; ///< of the clipped cell [m^2]
      dealii::Point<2> centroid;
      double           polar_moment = 0; ///< integral of |x - centroid|^2 over the cell [m^4]
      /// The largest distance of a point of the clipped cell from the nucleus [m].
      double reach = 0;
      /// The outline of the clipped cell: closed loops of vertices (output).
      std::vector<std::vector<dealii::Point<2>>> outline;
      /// The pieces of the domain's boundary that bound this cell (tractions act there).
      std::vector<std::array<dealii::Point<2>, 2>> boundary;
    };

    template <>
    struct Facet<2>
    {
      unsigned int           a = 0, b = 0;  ///< the cells, a < b
      dealii::Point<2>       p3, p4;        ///< end points (of the longest piece in the domain)
      dealii::Point<2>       midpoint;      ///< P: the springs' location
      double                 length   = 0;  ///< l: in the domain (all pieces)
      double                 distance = 0;  ///< h = |x_b - x_a|
      double                 h_a = 0, h_b = 0; ///< distances of the nuclei from the facet line
      dealii::Tensor<1, 2>   normal;        ///< from a to b
    };

    /**
     * A 3D cell: the Voronoi polyhedron of its nucleus clipped to the polyhedral
     * domain. The clipped cell is a union of disjoint convex polyhedra (one for a
     * cell that no subtracted primitive cuts), each given by its faces.
     */
    template <>
    struct Cell<3>
    {
      dealii::Point<3> nucleus;    ///< the computational point (its DoFs u, theta)
      double           volume = 0; ///< of the clipped cell [m^3]
      dealii::Point<3> centroid;
      /// int (x - centroid) (x - centroid)^T dV over the cell [m^5] (the inertia tensor
      /// per unit density is trace(S) I - S).
      dealii::SymmetricTensor<2, 3> second_moment;
      /// The largest distance of a point of the clipped cell from the nucleus [m].
      double reach = 0;
      /// The convex pieces of the clipped cell: for each, its faces, each a planar loop
      /// of vertices counter-clockwise seen from outside (output).
      std::vector<std::vector<std::vector<dealii::Point<3>>>> pieces;
      /// The parts of the domain's boundary that bound this cell (tractions act there):
      /// planar loops counter-clockwise seen from outside the domain.
      std::vector<std::vector<dealii::Point<3>>> boundary;
    };

    template <>
    struct Facet<3>
    {
      unsigned int     a = 0, b = 0; ///< the cells, a < b
      /// The springs' location: the centroid of the facet's area in the domain.
      dealii::Point<3> midpoint;
      double           area     = 0; ///< A: in the domain (all pieces) [m^2]
      double           distance = 0; ///< h = |x_b - x_a|
      double           h_a = 0, h_b = 0; ///< distances of the nuclei from the facet's plane
      dealii::Tensor<1, 3> normal;       ///< unit, from a to b
      /// The principal axes of the facet's second moment of area (in its plane; (normal,
      /// axis_1, axis_2) right-handed), and the principal second moments about the
      /// centroid: I_1 = int (xi . axis_2)^2 dA about axis_1, I_2 = int (xi . axis_1)^2 dA
      /// about axis_2 [m^4] (xi from the centroid), I_1 >= I_2.
      dealii::Tensor<1, 3> axis_1, axis_2;
      double               second_moment_1 = 0, second_moment_2 = 0;
      /// The facet's pieces in the domain: planar loops, counter-clockwise about normal
      /// (the faces of cell a's pieces on the bisector; output).
      std::vector<std::vector<dealii::Point<3>>> polygons;
    };

    template <int dim>
    struct Tessellation
    {
      std::vector<Cell<dim>>  cells;
      std::vector<Facet<dim>> facets;
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
     *
     * With @p wanted (one flag per nucleus) only the cells of the flagged nuclei are
     * built (the others stay empty), and the facets are those between a flagged
     * nucleus a and any b > a, each from the cell of a: a cell's geometry depends only
     * on the nuclei near it, so a rank of a distributed network builds its own cells
     * from its nuclei and a halo of nuclei around them (Cell::reach tells whether the
     * halo was wide enough: every nucleus within 2 reach of the nucleus must be given).
     * The facets are sorted by (a, b).
     */
    Tessellation<2>
    voronoi(const std::vector<dealii::Point<2>>            &nuclei,
            const std::vector<const Geometry::Region<2> *> &bodies,
            const double                                    boundary_h,
            const std::string                              &where,
            const std::vector<bool>                        &wanted = {});

    /**
     * 3D: the Voronoi cells of @p nuclei (from CGAL's 3D Delaunay triangulation,
     * each cell the intersection of the half-spaces of the bisectors of its Delaunay
     * neighbours; coplanar or collinear nuclei work too) clipped exactly to the union
     * of @p bodies, whose curved primitives are polyhedra: a cylinder the inscribed
     * prism of Region<2>::n_disk_sides(r, boundary_h) sides, a sphere an inscribed
     * geodesic polyhedron (a subdivided icosahedron) with edges of at most
     * @p boundary_h. A clipped cell is a union of disjoint convex pieces (one for a
     * cell that no subtracted primitive or union cuts); its volume, centroid and
     * second moment are exact integrals over them. A facet is the common face of two
     * cells inside the domain: its area, centroid, the principal second moments
     * of area and axes over all its pieces; facets of area below 1e-12 scale^2 are
     * dropped. Cell::boundary holds the parts of the domain's boundary in the cell
     * (not the cuts between its pieces). @p wanted, the order of the facets and the
     * errors as in 2D, and a cell with no volume in the bodies is an error.
     * doc/rbsn/geometry_3d.md derives the clipping and the integrals.
     */
    Tessellation<3>
    voronoi(const std::vector<dealii::Point<3>>            &nuclei,
            const std::vector<const Geometry::Region<3> *> &bodies,
            const double                                    boundary_h,
            const std::string                              &where,
            const std::vector<bool>                        &wanted = {});
  } // namespace RBSN
} // namespace hysteron

#endif

#ifndef hysteron_geometry_region_h
#define hysteron_geometry_region_h

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/point.h>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * Solids described by a small constructive expression language: bodies filled
   * with material points, regions for boundary conditions, load sets and probes.
   * See doc/geometry.md for the user documentation.
   */
  namespace Geometry
  {
    /**
     * A solid given by an expression of primitives combined by union and
     * difference:
     * @code
     *   expr := term (('+' | '-') term)*      // left to right: '+' union, '-' difference
     *   term := primitive [ '(' number (',' number)* ')' ] | '(' expr ')'
     * @endcode
     * Primitives in 2D: rectangle(x0, y0, x1, y1), disk(cx, cy, r),
     * polygon(x1, y1, x2, y2, x3, y3, ...); in 3D: box(x0, y0, z0, x1, y1, z1),
     * sphere(cx, cy, cz, r), cylinder(x0, y0, z0, x1, y1, z1, r); in both:
     * `all` (or `all()`), the whole space. Coordinates in m.
     *
     * Every primitive is a closed set. The expression is compiled into a flat
     * postfix program over a flat vector of primitives (a switch per primitive,
     * no virtual call, no allocation in contains()).
     */
    template <int dim>
    class Region
    {
    public:
      /// The empty region: contains no point.
      Region();

      /**
       * Parse @p expression. Throws InputError(@p where, problem) on any error;
       * the problem names the offending token and its 1-based character position.
       */
      static Region
      parse(const std::string &expression, const std::string &where);

      /**
       * Whether @p p lies in the (closed) region. With @p tolerance > 0 every
       * primitive that is added is inflated by @p tolerance and every primitive
       * that is subtracted is deflated by it (signs follow nested parentheses),
       * so that points on the boundary are robustly inside.
       */
      bool
      contains(const dealii::Point<dim> &p, const double tolerance = 0) const;

      /**
       * A box containing the region: the union of the boxes of the added terms
       * (subtracted terms are ignored, so the box may be larger than needed).
       * Infinite coordinates if `all` is added; the degenerate box at the origin
       * for the empty region.
       */
      dealii::BoundingBox<dim>
      bounding_box() const;

      /**
       * The area (2D) or volume (3D) in m^2 or m^3. Exact for an expression that is
       * a single primitive (area of a rectangle, pi r^2, shoelace formula for a
       * polygon, box, 4/3 pi r^3, pi r^2 L for a cylinder). For composites, a
       * midpoint-rule estimate on a grid of 512^2 (2D) or 96^3 (3D) cells over
       * bounding_box() (relative error about 1e-3 for smooth shapes). Infinity
       * if `all` is added, 0 for the empty region.
       */
      double
      volume_estimate() const;

      /// The expression this region was parsed from ("" for the empty region).
      const std::string &
      expression() const;

      /// Whether this is the default constructed (empty) region.
      bool
      is_empty() const;

      /// Primitive kinds (public only for the implementation's helper functions).
      enum class Kind : std::uint8_t
      {
        rectangle,
        disk,
        polygon,
        box,
        sphere,
        cylinder,
        all
      };

      /// One primitive with its parameters (meaning depends on kind).
      struct Primitive
      {
        Kind kind;
        /// +1 if the primitive is added, -1 if subtracted (tolerance sign).
        double sign;
        /// rectangle/box: lower corner then upper corner; disk/sphere: centre,
        /// r; cylinder: p0 (0..2), axis p1 - p0 (3..5), r (6), |axis|^2 (7).
        std::array<double, 8> p;
        /// polygon: index of the first vertex in vertices and their number.
        unsigned int first_vertex;
        unsigned int n_vertices;
      };

      /// Instructions of the postfix program.
      enum class Op : std::uint8_t
      {
        push,       ///< evaluate primitive `index` and push the result
        unite,      ///< pop b, pop a, push a || b
        subtract    ///< pop b, pop a, push a && !b
      };

      struct Instruction
      {
        Op           op;
        unsigned int index;
      };

      /// The maximal depth of the evaluation stack (limits nesting).
      static constexpr unsigned int max_stack_depth = 64;

      /**
       * @name Read access for mesh generators (see Geometry::structured_mesh() and
       * Geometry::unstructured_mesh() in hysteron/geometry/mesh.h)
       * @{
       */

      /// The primitives, in the order they appear in the expression.
      const std::vector<Primitive> &
      get_primitives() const;

      /// The postfix program over get_primitives() that contains() evaluates.
      const std::vector<Instruction> &
      get_program() const;

      /// The vertices of a polygon primitive of this region, in the order given.
      std::vector<dealii::Point<2>>
      polygon_vertices(const Primitive &polygon) const;

      /**
       * The number of sides of the regular polygon that stands for a disk of
       * radius @p radius at resolution @p h: n = max(16, ceil(2 pi r / h)),
       * rounded up to a multiple of 4 (so that the 4 axis points are vertices).
       * Every side is at most 2 pi r / n <= h long. Requires h > 0.
       */
      static unsigned int
      n_disk_sides(const double radius, const double h);

      /**
       * The vertices of that regular polygon, counter-clockwise, the first one at
       * (cx + r, cy): vertex j is the centre plus r (cos, sin)(2 pi j / n),
       * evaluated for the first quarter and rotated by multiples of 90 degrees
       * exactly, so the axis points are exactly cx +- r, cy +- r and the polygon
       * lies inside the disk. polygonized() and boundary_segments() use exactly
       * these points.
       */
      static std::vector<dealii::Point<2>>
      disk_polygon(const dealii::Point<2> &centre, const double radius, const double h);

      /**
       * 2D only: the same expression with every disk replaced by its
       * disk_polygon() at resolution @p h (bit for bit the same vertices), so that
       * contains() agrees with a mesh whose boundary is made of those polygons.
       * expression() returns the original expression; bounding_box() is unchanged
       * (the polygon's extreme points are the disk's axis points). Throws
       * dealii::ExcNotImplemented in 3D.
       */
      Region<2>
      polygonized(const double h) const;

      /**
       * 2D only: the boundary of every primitive as straight segments: the 4
       * sides of a rectangle, the sides of a polygon, and the sides of a disk's
       * disk_polygon() at resolution @p h; nothing for `all`. The segments of
       * subtracted primitives are included (they bound the region too), in the
       * order of the primitives; each closed loop is traversed counter-clockwise
       * for rectangles and disks, in the order given for polygons. Throws
       * dealii::ExcNotImplemented in 3D.
       */
      std::vector<std::array<dealii::Point<2>, 2>>
      boundary_segments(const double h) const;

      /** @} */

    private:
      bool
      primitive_contains(const Primitive        &primitive,
                         const dealii::Point<dim> &p,
                         const double              tolerance) const;

      std::string                   expression_string;
      std::vector<Primitive>        primitives;
      /// Polygon vertices of all polygons, each polygon's consecutively.
      std::vector<dealii::Point<2>> vertices;
      std::vector<Instruction>      program;
      dealii::BoundingBox<dim>      box;
      struct Parser;

      template <int>
      friend class Region;
    };

    /**
     * A Cartesian lattice of n_cells[0] x ... cells of side h (m), the first
     * cell's lower corner at origin.
     */
    template <int dim>
    struct FillLattice
    {
      dealii::Point<dim>              origin;
      double                          h;
      std::array<unsigned int, dim>   n_cells;
    };

    /**
     * Material points filling @p region: every lattice cell is split into
     * @p k^dim sub-cells of side h/k, and the centre p of each sub-cell with
     * region.contains(p, 1e-12 h) is returned; each point stands for the volume
     * fill_particle_volume(lattice, k) = (h/k)^dim. Order: cells
     * lexicographically (x fastest), within a cell sub-cells lexicographically
     * (x fastest). Only cells whose box intersects the region's bounding box
     * are visited. Throws dealii::ExcMessage unless h > 0 and k >= 1.
     */
    template <int dim>
    std::vector<dealii::Point<dim>>
    fill(const Region<dim> &region, const FillLattice<dim> &lattice, unsigned int k);

    /**
     * As above, but only the cells with first[d] <= c[d] <= last[d] (a box of
     * the lattice, e.g. the cells of one MPI rank) for which @p keep_cell (if
     * given) returns true. The points are computed from the whole lattice, so
     * they are bit-identical to the full fill's, and in the same order.
     */
    template <int dim>
    std::vector<dealii::Point<dim>>
    fill(const Region<dim>                                                    &region,
         const FillLattice<dim>                                               &lattice,
         unsigned int                                                          k,
         const std::array<unsigned int, dim>                                  &first,
         const std::array<unsigned int, dim>                                  &last,
         const std::function<bool(const std::array<unsigned int, dim> &cell)> &keep_cell = {});

    /// The volume (h/k)^dim (m^dim) of one point returned by fill().
    template <int dim>
    double
    fill_particle_volume(const FillLattice<dim> &lattice, unsigned int k);
  } // namespace Geometry
} // namespace hysteron

#endif

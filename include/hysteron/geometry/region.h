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
     * As above, but only cells for which @p keep_cell(cell index) returns true
     * are filled (called once per visited cell, e.g. to keep the cells a rank
     * owns). The order of the kept points is the same as in the full fill.
     */
    template <int dim>
    std::vector<dealii::Point<dim>>
    fill(const Region<dim>                                            &region,
         const FillLattice<dim>                                       &lattice,
         unsigned int                                                  k,
         const std::function<bool(const std::array<unsigned int, dim> &cell)> &keep_cell);

    /// The volume (h/k)^dim (m^dim) of one point returned by fill().
    template <int dim>
    double
    fill_particle_volume(const FillLattice<dim> &lattice, unsigned int k);
  } // namespace Geometry
} // namespace hysteron

#endif

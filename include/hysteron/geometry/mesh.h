#ifndef hysteron_geometry_mesh_h
#define hysteron_geometry_mesh_h

#include <deal.II/base/point.h>

#include <deal.II/grid/tria_description.h>

#include <hysteron/geometry/region.h>

#include <string>
#include <vector>

namespace hysteron
{
  namespace Geometry
  {
    /**
     * A coarse mesh ready for
     * `Triangulation::create_triangulation(vertices, cells, SubCellData())`:
     * quadrilaterals (2D) / hexahedra (3D) in deal.II's vertex order
     * (lexicographic: 0 = (0,0), 1 = (1,0), 2 = (0,1), 3 = (1,1), and in 3D the
     * same square again at z = 1), every cell positively oriented and the lines
     * consistently oriented (so a parallel::distributed::Triangulation accepts
     * it), material_id = index of the body (in the order given) that contains the
     * cell's centre. Every vertex is used by some cell. See doc/geometry.md,
     * "Meshes for the FEM".
     */
    template <int dim>
    struct CoarseMesh
    {
      std::vector<dealii::Point<dim>>    vertices;
      std::vector<dealii::CellData<dim>> cells;

      /// Sum of the cell measures (m^dim); exact for these straight-sided cells.
      double
      volume() const;
    };

    /**
     * Whether every primitive of @p region is an axis-aligned rectangle/box (or
     * `all`): then structured_mesh() represents it exactly.
     */
    template <int dim>
    bool
    is_rectilinear(const Region<dim> &region);

    /**
     * A tensor-product ("rectilinear") mesh of the bounding box of all bodies.
     *
     * Along each axis the breakpoints are the two ends of the box and every
     * coordinate of every rectangle/box primitive of the bodies (added or
     * subtracted) inside the box; breakpoints closer than 1e-12 times the box
     * size are merged. Each interval between consecutive breakpoints of length L
     * is split uniformly into max(1, ceil(L / h)) cells (a relative slack of 1e-9
     * absorbs round-off, so 0.1 / 0.025 gives 4 cells). A cell of the tensor grid
     * is kept if its centre lies in a body; the first body that contains it gives
     * its material_id. Vertices that no kept cell uses are dropped; the others
     * are numbered lexicographically (x fastest), the cells likewise.
     *
     * Exact for rectilinear bodies (is_rectilinear()): every face of every box
     * lies on grid planes. Otherwise a staircase approximation (the caller can
     * compare volume() with the expected volume). Interfaces between touching
     * bodies are conforming by construction. Short intervals give thin cells
     * through the whole grid (tensor product): a flange of thickness t < h makes
     * a layer of cells of height t across the box.
     *
     * @p boundary_h (0: h) is the segment length of curved boundaries (disks as
     * regular polygons with n_disk_sides(r, boundary_h) sides); a value below h
     * resolves them more finely than the cells (graded refinement along them).
     *
     * Throws InputError(@p where, ...) for h <= 0, no body, a null, empty or
     * unbounded body, a tensor grid of more than 5e6 cells, or if a body (or the
     * union) gets no cell.
     */
    template <int dim>
    CoarseMesh<dim>
    structured_mesh(const std::vector<const Region<dim> *> &bodies,
                    const double                             h,
                    const std::string                       &where);

    /**
     * A structured_mesh() as a coarse mesh that `levels` global refinements (bisection of
     * every cell) turn into the mesh, so that a distributed triangulation (p4est) needs
     * to replicate only the coarse cells on every rank.
     */
    template <int dim>
    struct StructuredMesh
    {
      CoarseMesh<dim> coarse;     ///< empty if the mesh cannot be coarsened (see below)
      unsigned int    levels = 0; ///< global refinements of `coarse`
      double          n_cells = 0; ///< cells after the refinements
      std::string     note;        ///< how the counts were changed, for the log (or empty)
    };

    /**
     * The cells of structured_mesh() with the same breakpoints, built from a coarse mesh
     * of at most @p max_coarse_cells cells (counted in the tensor grid):
     *
     * 1. exact: L is the smallest level that gives at most @p max_coarse_cells coarse cells
     *    with every interval's count n a multiple of 2^L; the coarse mesh has n / 2^L cells per
     *    interval and L refinements give structured_mesh()'s cells (vertex positions to
     *    round-off: refinement bisects). A mesh of at most @p max_coarse_cells cells is its own
     *    coarse mesh (L = 0);
     * 2. otherwise, rounded: the smallest L > 0 for which counts rounded up to multiples
     *    of 2^L give a small enough coarse mesh, if that adds at most a fraction
     *    @p max_growth - 1 of cells (the cells of some intervals shrink; `note` says by how
     *    much);
     * 3. otherwise (or if a body is not rectilinear, where the coarse cells' centres would
     *    assign other staircase cells to the bodies), `coarse` is empty: the caller builds
     *    structured_mesh() and distributes it as an unstructured mesh.
     *
     * InputError(@p where, ...) as structured_mesh(); the coarse tensor grid obeys its
     * 5e6-cell limit, the refined mesh only an overflow bound (1e12 cells).
     */
    template <int dim>
    StructuredMesh<dim>
    coarse_structured_mesh(const std::vector<const Region<dim> *> &bodies,
                           const double                             h,
                           const std::string                       &where,
                           const double                             max_coarse_cells,
                           const double                             max_growth);

    /// What check_cells() found.
    struct CellCheck
    {
      bool         valid    = false; ///< every cell can carry finite elements (after repairs)
      std::size_t  inverted = 0;     ///< cells that were inverted and are repaired
      unsigned int cell     = 0;     ///< if not valid: the index of the first bad cell
      std::string  problem;          ///< if not valid: what is wrong with it
    };

    /**
     * What is wrong with the cell of vertices @p x (deal.II's order: a triangle or
     * tetrahedron, or a quadrilateral or hexahedron numbered lexicographically), or "" if
     * it can carry finite elements; @p inverted tells whether it is merely inverted
     * (negative Jacobian everywhere: mirrored, clockwise in 2D), which a reordering of its
     * vertices repairs. The checks, in this order: two vertices closer than 1e-12 of the
     * diameter (coincident nodes); a Jacobian whose scaled determinant det J / prod |J e_d|
     * takes both signs beyond 1e-6 at the vertices and at the 2- and 3-point Gauss points
     * (a bow-tie or a non-convex cell); a measure below 1e-8 diameter^dim (a sliver); a
     * scaled determinant within 1e-6 of zero (a flat corner).
     */
    template <int dim>
    std::string
    cell_defect(const std::vector<dealii::Point<dim>> &x, bool &inverted);

    /**
     * Check every cell with cell_defect(); if none is defective, repair the inverted ones
     * (dealii::GridTools::invert_cells_with_negative_measure(), then
     * consistently_order_cells() for quadrilaterals and hexahedra) and check them again.
     * @p cells is changed only by the repair.
     */
    template <int dim>
    CellCheck
    check_cells(const std::vector<dealii::Point<dim>> &vertices, std::vector<dealii::CellData<dim>> &cells);

    /// The vertices of @p cell as "(x, y), ...", around the cell as Gmsh lists them.
    template <int dim>
    std::string
    vertex_list(const std::vector<dealii::Point<dim>> &vertices, const dealii::CellData<dim> &cell);

    /**
     * 2D only: an unstructured, body-fitted quadrilateral mesh.
     *
     * 1. The boundaries of all primitives of all bodies (rectangle sides, polygon
     *    sides, disks as the regular polygons of Region::disk_polygon(), n =
     *    max(16, ceil(2 pi r / h)) sides rounded up to a multiple of 4), clipped
     *    to the bounding box of the bodies, are inserted as constraints into one
     *    CGAL constrained Delaunay triangulation (exact predicates, exactly
     *    computed and rounded intersections: crossing and overlapping constraints
     *    are allowed).
     * 2. Every triangle whose centroid lies (within 1e-6 h) in a body is marked as
     *    the domain, and the domain is refined by CGAL::Delaunay_mesher_2 with
     *    Delaunay_mesh_size_criteria_2(0.125, h): every edge of a domain triangle
     *    is at most h long and, away from input angles below 60 degrees, every
     *    angle is at least arcsin(sqrt(0.125)) = 20.7 degrees.
     * 3. A refined triangle is kept if its centroid lies in a body's polygonized()
     *    region (first body wins: material_id); since the constraints are mesh
     *    edges, each triangle lies on one side of every primitive's boundary, and
     *    its centroid is well away from all of them: the classification agrees
     *    with the mesh boundary.
     * 4. Each kept triangle is split into three quadrilaterals (vertex, two edge
     *    midpoints, centroid; midpoints of shared edges shared). The quads are
     *    convex; their edges are at most h/2 long; their angles are at least the
     *    triangle's smallest angle (>= 20.7 degrees, where CGAL guarantees it) and
     *    at most about 166 degrees.
     *
     * The triangles are ordered along a Hilbert curve through their centroids
     * (contiguous p4est partitions), vertices are numbered in order of first use;
     * the result depends on the input only (every MPI rank builds the same mesh).
     * Cells are oriented counter-clockwise, and their lines are consistently
     * oriented by construction (every line runs from a triangle vertex to an edge
     * midpoint or from a midpoint to a centroid; vertex 0 of each quad is the
     * triangle vertex, vertex 3 the centroid), so
     * dealii::GridTools::consistently_order_cells() is not needed.
     *
     * The mesh represents the polygonized bodies exactly: volume() equals the
     * area of Region::polygonized(h) up to round-off. About 15 area / h^2 quads
     * (measured; 5 triangles per h^2): the quads are about h/3 in size, so this
     * mesh is much finer than structured_mesh() at the same h. Features smaller
     * than h (nearly touching primitives, tangencies) are resolved by graded local
     * refinement.
     *
     * @p boundary_h (0: h) is the segment length of curved boundaries (disks as
     * regular polygons with n_disk_sides(r, boundary_h) sides); a value below h
     * resolves them more finely than the cells (graded refinement along them).
     *
     * Throws InputError(@p where, ...) for h <= 0, no body, a null, empty or
     * unbounded body, a disk needing more than 1e6 sides, an estimated mesh of
     * more than 5e6 cells (estimated from the bounding boxes), a refinement that
     * needs more than max(1e5, 2 x estimated cells) vertices (e.g. a sliver 1e-9
     * wide along a side, where overlapping bodies nearly coincide), or if a body
     * (or the union) gets no cell.
     */
    CoarseMesh<2>
    unstructured_mesh(const std::vector<const Region<2> *> &bodies,
                      const double                           h,
                      const std::string                     &where,
                      const double                           boundary_h = 0);
  } // namespace Geometry
} // namespace hysteron

#endif

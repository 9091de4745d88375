// The entries of the named subsections of a scene (Body, Set, Boundary, Load): their
// types, defaults and documentation.
#include <deal.II/base/parameter_handler.h>

#include <hysteron/scene/description.h>

#include <string>
#include <vector>

namespace hysteron
{
  namespace
  {
    namespace Patterns = dealii::Patterns;

    /// `subsection Body <name>`: a solid, its material, shape, thickness and motion.
    void
    declare_body_entries(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Material",
                        "",
                        Patterns::Anything(),
                        "Name of the body's material (one of `Material names`); empty: the "
                        "default `subsection Material`.");
      prm.declare_entry("Shape",
                        "",
                        Patterns::Anything(),
                        "The body's region [m], e.g. 'rectangle(0, 0, 2, 0.1) - disk(1, 0.05, "
                        "0.01)'; see doc/geometry.md. Required.");
      prm.declare_entry("Particles per cell",
                        "2",
                        Patterns::Integer(1, 16),
                        "MPM: material points per grid cell and direction (k^dim per cell).");
      prm.declare_entry("Thickness",
                        "1",
                        Patterns::Anything(),
                        "2D: out-of-plane thickness [m], > 0 (plane strain: the length along "
                        "z that the results refer to): a number, or a function of x, y, e.g. "
                        "the flanges and web of an I-section, 'abs(y) > 0.15 ? 0.3 : 0.015' "
                        "(doc/geometry.md). It weights the mass, volume, internal forces and "
                        "loads of the MPM's points (at each point), the FEM's quadrature points "
                        "and the RBSN's cells and facets; it must be > 0 wherever it is "
                        "evaluated. Ignored in 3D; left at 1 in an axisymmetric scene (the "
                        "ring 2 pi r takes its place).");
      prm.declare_entry("Initial velocity",
                        "",
                        Patterns::Anything(),
                        "Initial velocity [m/s] as functions of x, y (, z), components "
                        "separated by ';', e.g. '0; -373'. Empty: at rest.");
      prm.declare_entry("Rigid",
                        "false",
                        Patterns::Bool(),
                        "A rigid body moves with the prescribed `Velocity` and imposes it on "
                        "the grid nodes it touches; it has no stress (its material is unused).");
      prm.declare_entry("Velocity",
                        "",
                        Patterns::Anything(),
                        "Rigid bodies: velocity [m/s] as functions of t, components separated "
                        "by ';', e.g. '0.01; 0' or '0.01*sin(2*pi*t); 0'.");
      prm.declare_entry("Amplitude",
                        "",
                        Patterns::Anything(),
                        "Rigid bodies: the name of an amplitude (`Amplitude names`) a(t) that "
                        "multiplies `Velocity`; empty: none.");
    }

    /// `subsection Set <name>`: faces of the domain box, a region or a Gmsh physical group.
    void
    declare_set_entries(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Faces",
                        "",
                        Patterns::Anything(),
                        "Faces of the domain box (the grid's, the mesh's or the network's "
                        "bounding box): a list of x-, x+, y-, y+, z-, z+.");
      prm.declare_entry("Region",
                        "",
                        Patterns::Anything(),
                        "And/or the nodes, points or cells inside this region [m]; see "
                        "doc/geometry.md.");
      prm.declare_entry("Physical group",
                        "",
                        Patterns::Anything(),
                        "Or a physical group of the FEM's Gmsh mesh file, by name or number: a "
                        "group of boundary lines (2D) or faces (3D) selects the nodes of its "
                        "faces, a group of cells (surfaces in 2D, volumes in 3D) the nodes and "
                        "quadrature points of its cells. The fem method with `Generator = "
                        "file` only; not together with Faces or Region.");
    }

    /// `subsection Boundary <name>`: a kinematic condition and the nodes it acts on.
    void
    declare_boundary_entries(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Type",
                        "fixed",
                        Patterns::Selection("fixed|roller|wall|velocity|displacement|absorbing"),
                        "fixed: all velocity components zero; roller: the normal component "
                        "zero (slip); wall: rigid frictionless wall, the body may slide and "
                        "separate but not penetrate (normal velocity into the wall set to zero); "
                        "velocity: the `Components` follow `Velocity`(t); displacement: the "
                        "`Components` follow `Displacement`(t) (displacement control; the MPM "
                        "imposes the mean velocity of each step); absorbing (fem dynamic analyses "
                        "and mpm): viscous Lysmer-Kuhlemeyer dashpots that let waves leave, the "
                        "traction t = -rho c_p (v.n) n - rho c_s (v - (v.n) n) with c_p, c_s the "
                        "wave speeds of the elastic constants of the body next to the face "
                        "(exact at normal incidence, see doc/fem.md and doc/mpm.md); it needs "
                        "`Faces` or a `Set` of boundary faces (a Gmsh group of faces, fem) for "
                        "the normal n, not a region.");
      prm.declare_entry("Faces",
                        "",
                        Patterns::Anything(),
                        "Faces of the domain box the condition acts on: a list of x-, x+, y-, "
                        "y+, z-, z+ (roller and wall need faces: the face gives the normal).");
      prm.declare_entry("Region",
                        "",
                        Patterns::Anything(),
                        "Alternatively (or additionally) the nodes inside this region [m] "
                        "(fixed, velocity and displacement types); see doc/geometry.md.");
      prm.declare_entry("Set",
                        "",
                        Patterns::Anything(),
                        "Or the name of a set (`Set names`) that gives the faces, the region or "
                        "a Gmsh physical group; then Faces and Region stay empty.");
      prm.declare_entry("Components",
                        "all",
                        Patterns::Anything(),
                        "velocity and displacement types: the prescribed components, a list of "
                        "x, y, z or 'all'.");
      prm.declare_entry("Velocity",
                        "",
                        Patterns::Anything(),
                        "velocity type: the velocity [m/s] as functions of t, one per space "
                        "direction separated by ';' (entries of free components are unused).");
      prm.declare_entry("Displacement",
                        "",
                        Patterns::Anything(),
                        "displacement type: the displacement [m] as functions of x, y (, z) and "
                        "t, one per space direction separated by ';' (entries of free components "
                        "are unused); a node at x moves by u(x, t) - u(x, 0).");
      prm.declare_entry("Amplitude",
                        "",
                        Patterns::Anything(),
                        "velocity and displacement types: the name of an amplitude (`Amplitude "
                        "names`) a(t) that multiplies `Velocity` or `Displacement` (a node then "
                        "moves by u(x, t) a(t) - u(x, 0) a(0)); empty: none.");
    }

    /// `subsection Load <name>`: a force or traction on the points of a region or set.
    void
    declare_load_entries(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Type",
                        "force",
                        Patterns::Selection("force|traction"),
                        "force: `Value` is the total force [N], shared evenly by the points "
                        "selected by `Region`; traction: `Value` is a force per unit area [Pa] "
                        "on the selected points, which should be the body's outer layer.");
      prm.declare_entry("Region",
                        "",
                        Patterns::Anything(),
                        "The region whose material points (at t = 0) carry the load [m]; "
                        "see doc/geometry.md. Required unless `Set` is given.");
      prm.declare_entry("Set",
                        "",
                        Patterns::Anything(),
                        "Or the name of a set (`Set names`) with a Region or a Gmsh physical "
                        "group (the FEM loads its faces: traction, or a force spread as a "
                        "uniform traction; or its cells: a force spread over their volume); "
                        "then Region stays empty.");
      prm.declare_entry("Value",
                        "",
                        Patterns::Anything(),
                        "The load as functions of t, one component per space direction "
                        "separated by ';', e.g. '0; -60e3*t/20'. Required.");
      prm.declare_entry("Amplitude",
                        "",
                        Patterns::Anything(),
                        "The name of an amplitude (`Amplitude names`) a(t) that multiplies "
                        "`Value`, e.g. a cyclic history '0; -60e3' times a table; empty: none.");
    }
  } // namespace



  void
  declare_scene_descriptions(dealii::ParameterHandler &prm, const SceneNames &names)
  {
    // Every name N of a list gets `subsection <Kind> N` with the same entries.
    const auto declare = [&prm](const std::string              &kind,
                                const std::vector<std::string> &list,
                                void (*declare_entries)(dealii::ParameterHandler &)) {
      for (const auto &name : list)
        {
          prm.enter_subsection(kind + " " + name);
          declare_entries(prm);
          prm.leave_subsection();
        }
    };
    declare("Body", names.bodies, declare_body_entries);
    declare("Set", names.sets, declare_set_entries);
    declare("Boundary", names.boundaries, declare_boundary_entries);
    declare("Load", names.loads, declare_load_entries);
  }
} // namespace hysteron

// The RBSN's parameters: their declaration and their parsing and checks.
#include <deal.II/base/utilities.h>

#include <hysteron/base/parameters.h>
#include "rbsn/model.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /// The entries of the network: its nuclei, the springs' stiffnesses and law.
      template <int dim>
      void
      declare_network_parameters(dealii::ParameterHandler &prm)
      {
        using namespace dealii;
        prm.declare_entry("Minimum distance",
                          "0.05",
                          Patterns::Anything(),
                          "d_m [m] > 0: random nuclei keep at least this distance from each other "
                          "(Poisson-disk sampling up to saturation, about 0.68 A / d_m^2 points in "
                          "an area A; dissertation §3.3.3). A function of x, y gives a graded "
                          "network (e.g. 0.002 + 0.02 * abs(x - 1), finer where d is smaller; of x, y, z "
                          "in 3D): a new point p keeps |p - q| >= min(d(p), d(q)) from every point "
                          "q, about 0.68 int 1/d^2 dA points (0.70 int 1/d^3 dV in 3D); d must be "
                          "finite and > 0 in the bodies and "
                          "should vary slowly (|grad d| well below 1; doc/rbsn.md).");
        prm.declare_entry("Sampling block size",
                          "0",
                          Patterns::Double(),
                          "Side [m] of the blocks in which the random nuclei are sampled, >= 0; "
                          "0: automatic, one block for a network of at most 20,000 predicted points "
                          "(10,000 in 3D), else blocks of about 4,096 points (2,048 in 3D). A "
                          "network of several blocks is sampled block by block, in parallel on the "
                          "MPI ranks, each rank holding only the nuclei near its cells, and is the "
                          "same on any number of ranks; a given size must be at least 2 d_max "
                          "(doc/rbsn.md, MPI). One block (a size above the bodies' box) samples "
                          "the whole network at once, on every rank.");
        prm.declare_entry("Points on the boundary",
                          "true",
                          Patterns::Bool(),
                          "Place nuclei along the bodies' boundaries (corners kept, spacing about "
                          "d_m), so that boundary cells have their computational point on the "
                          "boundary, where supports and loads act.");
        prm.declare_entry("Additional points",
                          "",
                          Patterns::Anything(),
                          "Nuclei placed by the user [m], 'x, y; x, y; ...' ('x, y, z; ...' in 3D; "
                          "supports, load points); the random points keep d_m from them.");
        prm.declare_entry("Curved boundary resolution",
                          "0",
                          Patterns::Double(),
                          "Segment length [m] of curved boundaries (disks as polygons; in 3D the "
                          "edges of the polyhedra that stand for spheres and cylinders), >= 0; 0: "
                          "d_m / 4 (the smallest d_m over the bodies for a graded network).");
        prm.declare_entry("Shear stiffness ratio",
                          "0",
                          Patterns::Double(),
                          "k_t / k_n, >= 0; 0: from the material, k_t = G A / h and k_n = "
                          "E' A / h (eq. 3.9; A = t l in 2D, the facet's area in 3D; E' = "
                          "E / (1 - nu^2) in plane stress, lambda + 2 mu in plane strain and 3D). 1 "
                          "makes the network elastically uniform under any uniform strain (with nu = 0).");
        prm.declare_entry("Moment yield factor",
                          "0.25",
                          Patterns::Double(),
                          "The rotational spring yields at M_y = factor sigma_y t l^2 (0.25: the "
                          "plastic moment of the facet's section), > 0. The normal and tangential "
                          "springs yield at sigma_y t l and sigma_y t l / sqrt(3). 3D: the bending "
                          "springs at factor sigma_y A sqrt(12 I / A), the torsion spring at factor "
                          "sigma_y / sqrt(3) A sqrt(12 J / A) (doc/rbsn3d.md).");
        prm.declare_entry("Spring law",
                          "uncoupled",
                          Patterns::Selection(SpringLawRegistry<dim>::pattern_string()),
                          "The law of the facet springs, a registered plugin (doc/rbsn.md; plugins "
                          "from Additional shared libraries too). The springs follow the uniaxial "
                          "spring law of the cells' material (bouc-wen, a plugin's; linear "
                          "elastic ones have linear springs); "
                          "Analysis = static has linear springs throughout:" +
                            SpringLawRegistry<dim>::documentation());
        SpringLawRegistry<dim>::declare_parameters(prm);
      }



      /// The entries of the analysis, the linear solver and the tables.
      void
      declare_analysis_parameters(dealii::ParameterHandler &prm)
      {
        using namespace dealii;
        prm.declare_entry("Analysis",
                          "quasi-static",
                          Patterns::Selection("static|quasi-static|implicit dynamics|variable order"),
                          "static: elastic springs (the material's plasticity ignored), one "
                          "linear solve per step; quasi-static: Bouc-Wen springs, load stepping "
                          "with Newton; implicit dynamics: Newmark / HHT-alpha with Newton (mass "
                          "matrix eq. 3.12, Rayleigh damping); variable order: the state-space "
                          "system of eq. 3.43-3.48 (displacements, velocities and the springs' "
                          "Bouc-Wen states) integrated by SUNDIALS IDA, variable-order (1-5) "
                          "variable-step BDF with error control (subsection Variable order; the "
                          "Bouc-Wen Integrator is not used; fracture is refused).");
        prm.declare_entry("Time step",
                          "0",
                          Patterns::Double(),
                          "Step [s], >= 0; 0: Time/Time step if > 0, else End time / Number of "
                          "increments. Newton failures halve it. Variable order: the interval "
                          "between the outputs (IDA chooses its own steps).");
        prm.declare_entry("Number of increments", "100", Patterns::Integer(1), "See Time step.");
        prm.declare_entry("Tangent reuse tolerance",
                          "0",
                          Patterns::Double(),
                          "The LU factorization of the tangent is kept while the assembled tangent "
                          "differs from the factorized one by at most this fraction (Frobenius "
                          "norm), >= 0, and Newton's residual still falls at least twofold per "
                          "iteration. 0: exact Newton, a factorization is reused only for an "
                          "unchanged matrix (elastic steps, Analysis = static). 0.01-0.1: modified "
                          "Newton, more iterations with far fewer factorizations; the converged "
                          "result is the same (same residual tolerance).");
        prm.declare_entry("Incremental assembly",
                          "true",
                          Patterns::Bool(),
                          "true: within an increment (its Newton iterations and fracture cycles) "
                          "the tangent matrix keeps every facet's part, and an assembly adds only "
                          "the change of the facets whose tangent changed (a broken facet's part "
                          "is taken out); built from zero at the start of every increment and "
                          "when cells are released. false: every assembly from zero. The results "
                          "agree to round-off.");
        prm.declare_entry("Distributed direct solver",
                          "UMFPACK",
                          Patterns::Selection("UMFPACK|Amesos_Klu|Amesos_Mumps"),
                          "Under mpirun (more than one rank) the cells are split over the ranks "
                          "(shares along the sampling blocks, coordinate bisection within a block), "
                          "each rank builds and assembles its cells and "
                          "facets, and the distributed tangent "
                          "goes to: UMFPACK (the default: gathered on rank 0 and factorized there "
                          "with the symbolic analysis kept, as on one rank; reproducible bit for "
                          "bit), Amesos_Klu (Trilinos, gathered on one rank; reproducible) or "
                          "Amesos_Mumps (factorized in parallel; its results vary at round-off "
                          "from run to run). The Amesos solves are refined iteratively."),
        prm.declare_entry("Linear solver",
                          "direct",
                          Patterns::Selection("direct|cg|gmres"),
                          "direct: UMFPACK on one rank, `Distributed direct solver` on several; "
                          "cg (the uncoupled and elastic springs: a symmetric tangent) or gmres: "
                          "Krylov iterations with ML algebraic multigrid that knows the rigid-body "
                          "modes of every cell (3 in 2D, 6 in 3D: translations and rotations about "
                          "the network's centre), to `Linear solver tolerance` of the residual. "
                          "In 3D the direct solver's fill grows fast (about 0.3 MB per cell at "
                          "14,000 cells): from a few thousand 3D cells cg or gmres is faster "
                          "and smaller (doc/benchmarks.md).");
        prm.declare_entry("Linear solver tolerance",
                          "1e-10",
                          Patterns::Double(),
                          "cg / gmres: the linear residual relative to the right-hand side, in "
                          "(0, 1); below Newton's tolerance.");
        prm.declare_entry("Linear solver iterations",
                          "1000",
                          Patterns::Integer(1),
                          "cg / gmres: iterations before the attempt fails (and the increment is cut).");
        prm.declare_entry("Write cell table",
                          "false",
                          Patterns::Bool(),
                          "Write cells.csv at the end: every cell (its number, nucleus, body, area "
                          "or volume, displacement and rotation).");
        prm.declare_entry("Write spring table",
                          "false",
                          Patterns::Bool(),
                          "Write springs.csv at the end: every facet (cells, midpoint, length or "
                          "area, distance, stiffnesses, deformations, forces, H1 of its springs "
                          "(Spring law = coupled: the facet's Phi^n in all), broken).");
      }



      /// `subsection Fracture`.
      void
      declare_fracture_parameters(dealii::ParameterHandler &prm)
      {
        using namespace dealii;
        prm.declare_entry("Enabled", "false", Patterns::Bool(), "Brittle fracture of the facets (eq. 3.49-3.51).");
        prm.declare_entry("Tensile strength",
                          "0",
                          Patterns::Double(),
                          "f_t [Pa] > 0: a facet breaks when its normal stress s_n = F_n / A "
                          "exceeds it (tension cut-off; A = t l in 2D, the facet's area in 3D).");
        prm.declare_entry("Cohesion",
                          "0",
                          Patterns::Double(),
                          "c [Pa] > 0: ... or when |s_t| + tan(phi) s_n > c (Mohr-Coulomb; "
                          "s_t = F_t / A, in 3D the resultant |(V_1, V_2)| / A; tension positive).");
        prm.declare_entry("Friction angle", "0", Patterns::Double(), "phi [degrees] in [0, 90).");
        prm.declare_entry("Maximum breaks per step",
                          "1000",
                          Patterns::Integer(1),
                          "A step is solved again after every break (one facet, the one with the "
                          "largest R = max(s_n / f_t, (|s_t| + tan(phi) s_n) / c)); more breaks "
                          "than this in one step stop the run.");
      }
    } // namespace



    template <int dim>
    void
    Model<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.enter_subsection("RBSN");
      {
        declare_network_parameters<dim>(prm);
        declare_analysis_parameters(prm);
        prm.enter_subsection("Newton");
        NewtonParameters::declare_parameters(prm);
        prm.leave_subsection();
        prm.enter_subsection("Dynamics");
        ImplicitDynamicsParameters::declare_parameters(prm);
        prm.leave_subsection();
        prm.enter_subsection("Fracture");
        declare_fracture_parameters(prm);
        prm.leave_subsection();
        declare_variable_order_parameters(prm);
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Model<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      scene().refuse_fem_only_sets("rbsn", true);
      {
        Section s(prm, {"RBSN"});
        // A number is a constant d_m; anything else an expression in x, y (and z),
        // sampled over the bodies in build_network().
        const std::string distance = dealii::Utilities::trim(s.get("Minimum distance"));
        char             *end      = nullptr;
        std::strtod(distance.c_str(), &end);
        if (!distance.empty() && end == distance.c_str() + distance.size())
          {
            d_m     = s.get_positive("Minimum distance");
            spacing = Spacing<dim>(d_m);
          }
        else
          {
            const std::shared_ptr<const dealii::FunctionParser<dim>> d =
              parse_function<dim>(distance, dim == 2 ? "x,y" : "x,y,z", false, s.where("Minimum distance"));
            spacing = Spacing<dim>([d](const dealii::Point<dim> &p) { return d->value(p); },
                                   distance,
                                   s.where("Minimum distance"));
          }
        points_on_boundary = s.get_bool("Points on the boundary");
        block_size         = s.get_non_negative("Sampling block size");
        extra_points       = parse_points<dim>(s.get("Additional points"), s.where("Additional points"));
        boundary_h         = s.get_non_negative("Curved boundary resolution"); // 0: in build_network()
        shear_ratio  = s.get_non_negative("Shear stiffness ratio");
        moment_yield = s.get_positive("Moment yield factor");
        spring_law_name = s.get("Spring law");
        spring_law      = SpringLawRegistry<dim>::create(spring_law_name, s.where("Spring law"));
        spring_law->parse_parameters(s);
        const std::string type = s.get("Analysis");
        analysis = type == "static"            ? Analysis::linear_static :
                   type == "quasi-static"      ? Analysis::quasi_static :
                   type == "implicit dynamics" ? Analysis::implicit_dynamics :
                                                 Analysis::variable_order;
        require(dynamic() || scene().ground_motion().empty(),
                "Ground motion/File",
                "a ground motion is a base excitation, which needs inertia: use RBSN/Analysis = "
                "implicit dynamics or variable order");
        time_step    = s.get_non_negative("Time step");
        n_increments = s.get_integer("Number of increments");
        spring_table = s.get_bool("Write spring table");
        cell_table   = s.get_bool("Write cell table");
        reuse_tolerance = s.get_non_negative("Tangent reuse tolerance");
        incremental_assembly = s.get_bool("Incremental assembly");
        distributed_solver = s.get("Distributed direct solver");
        linear_solver      = s.get("Linear solver");
        solver_tolerance   = s.get_positive("Linear solver tolerance");
        require(solver_tolerance < 1, s.where("Linear solver tolerance"), "must be below 1");
        solver_max_iterations = s.get_integer("Linear solver iterations");
        require(linear_solver != "cg" || spring_law->diagonal_tangent() || analysis == Analysis::linear_static,
                s.where("Linear solver"),
                "cg needs a symmetric tangent; the " + spring_law_name +
                  " spring law couples its springs (unsymmetric): use gmres or direct");
      }
      newton.parse_parameters(Section(prm, {"RBSN", "Newton"}));
      dynamics.parse_parameters(Section(prm, {"RBSN", "Dynamics"}));
      {
        Section s(prm, {"RBSN", "Fracture"});
        fracture.enabled = s.get_bool("Enabled");
        if (fracture.enabled)
          {
            fracture.tensile_strength = s.get_positive("Tensile strength");
            fracture.cohesion         = s.get_positive("Cohesion");
            const double phi          = s.get_non_negative("Friction angle");
            require(phi < 90, s.where("Friction angle"), "must be below 90 degrees");
            fracture.friction   = std::tan(phi * M_PI / 180);
            fracture.max_cycles = s.get_integer("Maximum breaks per step");
          }
      }
      parse_variable_order_parameters(prm);
      check_bodies();
    }



    template <int dim>
    void
    Model<dim>::check_bodies()
    {
      const auto &bodies = scene().body_descriptions();
      require(!bodies.empty(), "Body names", "the rbsn method needs at least one body");
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (!bodies[b].rigid)
          {
            // The cells are clipped to the bodies: an unbounded one (`all`) has no network
            // (refused here, naming the body, rather than by the sampling or the clipping).
            for (const auto &primitive : bodies[b].shape.get_primitives())
              require(primitive.kind != Geometry::Region<dim>::Kind::all,
                      "Body " + bodies[b].name + "/Shape",
                      "the shape '" + bodies[b].shape.expression() +
                        "' contains 'all', which is unbounded: the rbsn method needs bounded "
                        "bodies (its cells are clipped to them)");
            body_shapes.push_back(&bodies[b].shape);
            mesh_body.push_back(b);
            const auto &m = scene().material(bodies[b].material, "Body " + bodies[b].name + "/Material");
            if constexpr (dim == 2)
              {
                require(m.elasticity().stress_state != Material::StressState::three_dimensional,
                        "Body " + bodies[b].name + "/Material",
                        "a 2D network needs a plane material (Stress state = plane stress or plane strain)");
                require(m.elasticity().stress_state != Material::StressState::axisymmetric,
                        "Body " + bodies[b].name + "/Material",
                        "the rbsn method has no axisymmetric form (its cells are plane rigid "
                        "bodies): use Stress state = plane stress or plane strain");
              }
            else
              require(!bodies[b].varying_thickness() && bodies[b].thickness == 1.0,
                      "Body " + bodies[b].name + "/Thickness",
                      "a 3D body has no thickness (the 2D out-of-plane depth; its cells are "
                      "volumes and its facets areas): leave it at 1 and give the body its "
                      "depth in its Shape");
            // The springs follow the material's uniaxial law (Bouc-Wen, linear, a plugin's).
            const std::unique_ptr<Material::UniaxialSpringLaw> law = m.uniaxial_spring_law();
            require(law != nullptr,
                    "Body " + bodies[b].name + "/Material",
                    "the rbsn method's springs follow the uniaxial spring law of the body's "
                    "material, which this material does not offer (e.g. 'bouc-wen' or 'linear "
                    "elastic' do)");
            require(law->scales_with_yield_value(),
                    "Body " + bodies[b].name + "/Material",
                    "the network gives each spring a yield value from its facet, which this "
                    "uniaxial law ignores (OpenSees BoucWen: its yield deformation is (Ao / (beta "
                    "+ gamma))^(1/n) for every spring): use a law that scales with it (smooth, "
                    "pinching, asymmetric, OpenSees BoucWenOriginal)");
            require(analysis != Analysis::variable_order || law->linear() ||
                      law->bouc_wen_parameters(),
                    "RBSN/Analysis",
                    "the variable-order analysis integrates the rates of uniaxial Bouc-Wen springs; "
                    "the springs of the material of body " + bodies[b].name +
                      " do not follow the smooth Bouc-Wen law: use Analysis = implicit dynamics");
            consistent_tangent = consistent_tangent && spring_law->has_consistent_tangent(m);
            const std::string why = spring_law->unsupported(m);
            require(why.empty(), "RBSN/Spring law", why + " (body " + bodies[b].name + ")");
            require(bodies[b].initial_velocity == nullptr || dynamic(),
                    "Body " + bodies[b].name + "/Initial velocity",
                    "only dynamic analyses have velocities");
          }
      require(!body_shapes.empty(), "Body names", "the rbsn method needs a body that is not rigid");
      std::vector<const Material::Interface<dim> *> materials;
      for (const unsigned int b : mesh_body)
        {
          const auto *m = &scene().material(bodies[b].material, "Body " + bodies[b].name + "/Material");
          if (std::find(materials.begin(), materials.end(), m) == materials.end())
            materials.push_back(m);
        }
      spring_law->initialize(materials);
      for (const auto &b : scene().boundary_descriptions())
        {
          require(b.type != BoundaryDescription<dim>::Type::wall,
                  "Boundary " + b.name + "/Type",
                  "the rbsn method has no walls (use fixed, roller, velocity or displacement)");
          require(b.type != BoundaryDescription<dim>::Type::absorbing,
                  "Boundary " + b.name + "/Type",
                  "absorbing boundaries are FEM-only for now (Method = fem, a dynamic analysis)");
        }
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

#include <deal.II/base/utilities.h>

#include <Epetra_CrsMatrix.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <hysteron/base/parameters.h>
#include "base/sparse_lu.h"
#include <hysteron/rbsn/model.h>
#include <hysteron/scene/output_column.h>
#include <hysteron/rbsn/rbsn.h>

#include "rbsn/collective.h"

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("RBSN");
      {
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
                          "from Additional shared libraries too). The built-in laws take the facets "
                          "between Bouc-Wen cells (linear-elastic ones have linear springs); "
                          "Analysis = static has linear springs throughout:" +
                            SpringLawRegistry<dim>::documentation());
        SpringLawRegistry<dim>::declare_parameters(prm);
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
        prm.enter_subsection("Newton");
        NewtonParameters::declare_parameters(prm);
        prm.leave_subsection();
        prm.enter_subsection("Dynamics");
        ImplicitDynamicsParameters::declare_parameters(prm);
        prm.leave_subsection();
        prm.enter_subsection("Fracture");
        {
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
        prm.leave_subsection();
        declare_variable_order_parameters(prm);
      }
      prm.leave_subsection();
    }



    template <int dim>
    Model<dim>::Model(const Scene<dim> &scene, const Methods::Interface<dim> &method, dealii::ParameterHandler &prm)
      : scene(scene)
      , method(method)
      , direct(std::make_unique<SparseLU>())
    {
      scene.refuse_fem_only_sets("rbsn", true);
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

      const auto &bodies = scene.body_descriptions();
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
            const auto &m = scene.material(bodies[b].material, "Body " + bodies[b].name + "/Material");
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
            require(m.spring_behaviour().type != Material::SpringBehaviour::Type::none,
                    "Body " + bodies[b].name + "/Material",
                    "the rbsn method's springs follow the uniaxial Bouc-Wen law: the body's "
                    "material must be 'bouc-wen' or 'linear elastic'");
            consistent_tangent = consistent_tangent && spring_law->has_consistent_tangent(m);
            const std::string why = spring_law->unsupported(m);
            require(why.empty(), "RBSN/Spring law", why + " (body " + bodies[b].name + ")");
            require(bodies[b].initial_velocity == nullptr || dynamic(),
                    "Body " + bodies[b].name + "/Initial velocity",
                    "only dynamic analyses have velocities");
          }
      require(!body_shapes.empty(), "Body names", "the rbsn method needs a body that is not rigid");
      for (const auto &b : scene.boundary_descriptions())
        require(b.type != BoundaryDescription<dim>::Type::wall,
                "Boundary " + b.name + "/Type",
                "the rbsn method has no walls (use fixed, roller, velocity or displacement)");
    }



    template <int dim>
    Model<dim>::~Model() = default;



    template <int dim>
    void
    Model<dim>::facet_dofs(const unsigned int e, std::vector<dof_index> &dofs) const
    {
      const auto &f = network.facets[e];
      for (unsigned int k = 0; k < n_dofs; ++k)
        {
          dofs[k]          = n_dofs * cell_block[f.a] + k;
          dofs[n_dofs + k] = n_dofs * cell_block[f.b] + k;
        }
    }



    template <int dim>
    std::array<unsigned int, 2 * Model<dim>::n_dofs>
    Model<dim>::facet_local_dofs(const unsigned int e) const
    {
      const auto                          &f = network.facets[e];
      std::array<unsigned int, 2 * n_dofs> dofs;
      for (unsigned int k = 0; k < n_dofs; ++k)
        {
          dofs[k]          = n_dofs * f.a + k;
          dofs[n_dofs + k] = n_dofs * f.b + k;
        }
      return dofs;
    }



    template <int dim>
    void
    Model<dim>::setup_springs()
    {
      const auto &bodies = scene.body_descriptions();
      springs.assign(network.facets.size(), Springs<dim>());
      std::string out_of_range, where; // the first facet whose springs overflow
      for (unsigned int e = 0; e < network.facets.size() && out_of_range.empty(); ++e)
        {
          const Facet<dim> &f  = network.facets[e];
          Springs<dim>     &sp = springs[e];
          const auto       &ba = bodies[cell_body[f.a]], &bb = bodies[cell_body[f.b]];
          const auto       &ma = scene.material(ba.material, "Body " + ba.name + "/Material");
          const auto       &mb = scene.material(bb.material, "Body " + bb.name + "/Material");
          FacetSprings<dim> facet;
          facet.moment_yield_factor = moment_yield;
          // B (eq. 3.6, with the corrections in doc/theory.md): the displacement of the
          // facet's point P as a point of cell b minus as a point of cell a, u_P = u_i +
          // theta_i x (P - x_i), in the facet's axes, and the relative rotation
          // theta_b - theta_a in them.
          const dealii::Tensor<1, dim> ra = f.midpoint - local_nuclei[f.a];
          const dealii::Tensor<1, dim> rb = f.midpoint - local_nuclei[f.b];
          if constexpr (dim == 2)
            {
              // The thinner side at the facet's midpoint (two bodies may meet there).
              const double t = std::min(ba.thickness_at(f.midpoint), bb.thickness_at(f.midpoint));
              const double l = f.length;
              // Voronoi scaling (eq. 3.9), the two half-cells in series:
              // k_n = t l / (h_a / E'_a + h_b / E'_b), k_t likewise with G, k_phi = k_n l^2 / 12.
              sp.k[0] = t * l / (f.h_a / ma.elasticity().p_wave_modulus() + f.h_b / mb.elasticity().p_wave_modulus());
              sp.k[1] = shear_ratio > 0 ? shear_ratio * sp.k[0] :
                                          t * l / (f.h_a / ma.elasticity().shear_modulus() +
                                                   f.h_b / mb.elasticity().shear_modulus());
              sp.k[2]                  = sp.k[0] * l * l / 12;
              sp.thickness             = t;
              sp.area                  = t * l;
              facet.thickness          = t;
              facet.length             = l;
              facet.area               = t * l;
              facet.second_moments[0]  = t * l * l * l / 12;
              // u_P = u_i - (y_P - y_i) theta_i, v_P = v_i + (x_P - x_i) theta_i.
              const dealii::Tensor<1, 2> n = f.normal, tt({-n[1], n[0]});
              const auto cross = [](const dealii::Tensor<1, 2> &r, const dealii::Tensor<1, 2> &w) {
                return r[0] * w[1] - r[1] * w[0];
              };
              sp.B[0] = {{-n[0], -n[1], -cross(ra, n), n[0], n[1], cross(rb, n)}};
              sp.B[1] = {{-tt[0], -tt[1], -cross(ra, tt), tt[0], tt[1], cross(rb, tt)}};
              sp.B[2] = {{0, 0, -1, 0, 0, 1}};
            }
          else
            {
              // k_n = A / (h_a / E'_a + h_b / E'_b), the shear springs likewise with G, the
              // bending springs k_n I_i / A (E I_i / h of the beam between the nuclei), the
              // torsion spring k_s J / A (G J / h), J = I_1 + I_2 (doc/rbsn3d.md).
              const double A = f.area, I1 = f.second_moment_1, I2 = f.second_moment_2;
              const double kn = A / (f.h_a / ma.elasticity().p_wave_modulus() + f.h_b / mb.elasticity().p_wave_modulus());
              const double ks = shear_ratio > 0 ? shear_ratio * kn :
                                                  A / (f.h_a / ma.elasticity().shear_modulus() +
                                                       f.h_b / mb.elasticity().shear_modulus());
              sp.k = {{kn, ks, ks, kn * I1 / A, kn * I2 / A, ks * (I1 + I2) / A}};
              sp.area                 = A;
              facet.area              = A;
              facet.length            = std::sqrt(A);
              facet.second_moments[0] = I1;
              facet.second_moments[1] = I2;
              // Rows of the translations along t: t . (u_b + theta_b x r_b - u_a - theta_a x r_a)
              // = t . u_b + theta_b . (r_b x t) - t . u_a - theta_a . (r_a x t); rotations
              // about t: t . (theta_b - theta_a).
              const std::array<dealii::Tensor<1, 3>, 3> axes{{f.normal, f.axis_1, f.axis_2}};
              for (unsigned int i = 0; i < 3; ++i)
                {
                  const dealii::Tensor<1, 3> &t  = axes[i];
                  const dealii::Tensor<1, 3>  ca = dealii::cross_product_3d(ra, t), cb = dealii::cross_product_3d(rb, t);
                  for (unsigned int d = 0; d < 3; ++d)
                    {
                      sp.B[i][d]     = -t[d];
                      sp.B[i][3 + d] = -ca[d];
                      sp.B[i][6 + d] = t[d];
                      sp.B[i][9 + d] = cb[d];
                    }
                }
              // The rotations in the order of the springs: about axis_1, axis_2, the normal.
              const std::array<dealii::Tensor<1, 3>, 3> rotation_axes{{f.axis_1, f.axis_2, f.normal}};
              for (unsigned int i = 0; i < 3; ++i)
                for (unsigned int d = 0; d < 3; ++d)
                  {
                    sp.B[3 + i][3 + d] = -rotation_axes[i][d];
                    sp.B[3 + i][9 + d] = rotation_axes[i][d];
                  }
            }
          facet.k = sp.k;
          // Finite inputs can still overflow here (a thickness of 1e300): the stiffnesses
          // and the forces they lead to (E A bounds the yield forces) must be numbers.
          if (out_of_range.empty())
            for (unsigned int i = 0; i < n_dofs; ++i)
              if (!(sp.k[i] > 0 && std::isfinite(sp.k[i]) &&
                    std::isfinite(sp.area * std::max(ma.elasticity().youngs_modulus, mb.elasticity().youngs_modulus))))
                {
                  std::ostringstream m;
                  m << "the facet between the cells at " << local_nuclei[f.a] << " and " << local_nuclei[f.b]
                    << " gets a spring stiffness of " << sp.k[i] << " (area " << sp.area << ", Young's modulus "
                    << ma.elasticity().youngs_modulus << "): the geometry and the material are out of the range "
                    << "of double precision together";
                  out_of_range = m.str();
                  where        = dim == 2 ? "Body " + ba.name + "/Thickness" : "Material/Young's modulus";
                  break;
                }
          if (!out_of_range.empty())
            continue;

          // The spring law's springs (static: linear springs, the plasticity ignored).
          if (analysis != Analysis::linear_static)
            {
              sp.state.assign(spring_law->n_state_variables(), 0.0);
              sp.hysteretic = spring_law->setup_facet(e, facet, ma, mb, sp.state.data());
              if (!sp.hysteretic)
                sp.state.clear();
            }
          for (unsigned int i = 0; i < n_dofs; ++i)
            sp.tangent[i][i] = sp.k[i]; // the first predictor's
          sp.trial_state = sp.state;
        }
      // Every rank refuses, with the first rank's facet.
      const auto found = dealii::Utilities::MPI::all_gather(scene.mpi_communicator(), std::make_pair(where, out_of_range));
      for (const auto &[place, problem] : found)
        if (!problem.empty())
          throw InputError(place, problem);
    }



    template <int dim>
    void
    Model<dim>::setup_system()
    {
      setup_parallel_system();
      // The serial matrix: one part, or rank 0 under the gathered UMFPACK solver.
      const bool gathered = distributed() && linear_solver == "direct" && distributed_solver == "UMFPACK";
      if (!trilinos_system() || (gathered && scene.is_root()))
        {
          const dof_index                n = n_dofs * n_cells;
          dealii::DynamicSparsityPattern dsp(n, n);
          const auto block = [&](const dof_index p, const dof_index q) {
            for (unsigned int i = 0; i < n_dofs; ++i)
              for (unsigned int j = 0; j < n_dofs; ++j)
                dsp.add(n_dofs * p + i, n_dofs * q + j);
          };
          if (!distributed())
            {
              for (unsigned int c = 0; c < cell_id.size(); ++c)
                block(c, c);
              for (const auto &f : network.facets)
                for (const unsigned int p : {f.a, f.b})
                  for (const unsigned int q : {f.a, f.b})
                    block(p, q);
            }
          else
            {
              // Rank 0 holds the whole pattern: the cells' blocks and every rank's facets'
              // pairs of blocks (gathered once).
              for (dof_index c = 0; c < n_cells; ++c)
                block(c, c);
              std::vector<unsigned long long> pairs;
              for (const auto &f : network.facets)
                pairs.insert(pairs.end(), {cell_block[f.a], cell_block[f.b]});
              const auto all = Collective::gather(pairs, scene.mpi_communicator(), 0);
              for (std::size_t k = 0; k < all.size(); k += 2)
                for (const auto p : {all[k], all[k + 1]})
                  for (const auto q : {all[k], all[k + 1]})
                    block(p, q);
            }
          pattern.copy_from(dsp);
          matrix.reinit(pattern);
          factored_matrix.reinit(pattern);
        }
      else if (gathered)
        {
          std::vector<unsigned long long> pairs;
          for (const auto &f : network.facets)
            pairs.insert(pairs.end(), {cell_block[f.a], cell_block[f.b]});
          Collective::gather(pairs, scene.mpi_communicator(), 0);
        }
      factorized = false;
      direct->clear();
    }



    template <int dim>
    void
    Model<dim>::setup_conditions()
    {
      using Type         = typename BoundaryDescription<dim>::Type;
      const auto &bodies = scene.body_descriptions();
      const auto &lo = nuclei_box[0], &hi = nuclei_box[1];
      const double tolerance = 1e-9 * scale;
      const MPI_Comm comm    = network_communicator();
      const unsigned int n_local = cell_id.size();
      const auto nucleus = [&](const unsigned int c) -> const dealii::Point<dim> & { return local_nuclei[c]; };
      const auto count   = [&](const std::size_t n) { return dealii::Utilities::MPI::sum<unsigned long>(n, comm); };
      // History sets: the cells whose nucleus lies on the set's faces of the nuclei's box
      // or in its region (the rule of the boundary conditions).
      history_cells.clear();
      history_size.clear();
      for (const unsigned int k : scene.output_control().history_sets)
        {
          const SetDescription<dim> &d = scene.set_descriptions()[k];
          std::vector<unsigned int>  cells;
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            {
              const auto &x  = nucleus(c);
              bool        in = d.has_region && d.region.contains(x, tolerance);
              for (const unsigned int face : d.faces)
                in = in || std::abs(x[face / 2] - (face % 2 == 0 ? lo[face / 2] : hi[face / 2])) <= tolerance;
              if (in)
                cells.push_back(c);
            }
          const unsigned long n = count(cells.size());
          require(n > 0,
                  d.where(),
                  "selects no cell of the network (a cell is selected by its nucleus: on the face "
                  "of the nuclei's bounding box, or in the region)");
          history_cells.push_back(std::move(cells));
          history_size.push_back(n);
        }
      dof_set.assign(n_dofs * n_local, -1);
      dirichlet.clear();
      // A DoF that two conditions select belongs to the first (its reaction); the two must
      // prescribe the same motion there (ConditionOverlaps), else the scene is refused.
      ConditionOverlaps<dim> overlaps(scene.boundary_descriptions(), scene.time_control().end_time, "cell of the network (its nucleus)");
      bool selects_owned = false; // the current condition selects an owned cell
      const auto take = [&](Dirichlet &set, const unsigned int dof) {
        selects_owned = selects_owned || dof < n_dofs * n_owned_cells;
        if (dof_set[dof] < 0)
          {
            dof_set[dof] = dirichlet.size();
            set.dofs.push_back(dof);
          }
        else if (const Dirichlet &first = dirichlet[dof_set[dof]]; first.boundary >= 0 && set.boundary >= 0)
          {
            // The same DoF's history under either condition (prescribed_increment() reads
            // only the set's boundary), translations and rotations alike.
            const unsigned int k = dof % n_dofs;
            static const char *const axes[3] = {"x", "y", "z"};
            const std::string  name = k < dim ? std::string(axes[k]) :
                                      dim == 2 ? std::string("rotation") :
                                                 "rotation about " + std::string(axes[k - dim]);
            overlaps.check(first.boundary,
                           set.boundary,
                           name,
                           nucleus(dof / n_dofs),
                           [&](const double t) { return prescribed_increment(first, dof, 0, t); },
                           [&](const double t) { return prescribed_increment(set, dof, 0, t); });
          }
      };
      // The translations by the boundary's rule; the rotations with all of them (fixed,
      // or velocity / displacement of every component: the rigid motion the field gives
      // the nucleus), not for a roller. Every local cell, ghosts included.
      for (unsigned int b = 0; b < scene.boundary_descriptions().size(); ++b)
        {
          const auto &d = scene.boundary_descriptions()[b];
          Dirichlet   set;
          set.name      = d.name;
          set.boundary  = b;
          selects_owned = false;
          for (unsigned int c = 0; c < n_local; ++c)
            {
              const auto &x   = nucleus(c);
              bool        all = d.type != Type::roller;
              for (unsigned int k = 0; k < dim; ++k)
                if (d.prescribes(x, k, lo, hi, tolerance))
                  take(set, n_dofs * c + k);
                else
                  all = false;
              if (all)
                for (unsigned int k = dim; k < n_dofs; ++k)
                  take(set, n_dofs * c + k);
            }
          require(count(selects_owned ? 1 : 0) > 0,
                  d.where(),
                  "selects no cell of the network (a cell is selected by its nucleus: on the face "
                  "of the nuclei's bounding box, or in the region)");
          dirichlet.push_back(std::move(set));
        }
      overlaps.throw_if_any(comm);
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (bodies[b].rigid)
          {
            Dirichlet set;
            set.name      = bodies[b].name;
            set.rigid     = b;
            selects_owned = false;
            for (unsigned int c = 0; c < n_local; ++c)
              if (bodies[b].shape.contains(nucleus(c), tolerance))
                for (unsigned int k = 0; k < n_dofs; ++k)
                  take(set, n_dofs * c + k);
            require(count(selects_owned ? 1 : 0) > 0,
                    "Body " + bodies[b].name + "/Shape",
                    "the rigid body holds no nucleus of the network (it moves the cells whose "
                    "nuclei lie in its shape)");
            dirichlet.push_back(std::move(set));
          }

      // Loads: a total force shared evenly by the cells whose nucleus is in the
      // region; a traction on the boundary pieces of the cells in the region.
      load_sets.clear();
      const auto &loads = scene.load_descriptions();
      for (unsigned int l = 0; l < loads.size(); ++l)
        {
          LoadSet set;
          set.load = l;
          if (loads[l].type == LoadDescription<dim>::Type::force)
            {
              for (unsigned int c = 0; c < n_owned_cells; ++c)
                if (loads[l].region.contains(nucleus(c), tolerance))
                  {
                    set.cells.push_back(c);
                    set.arm.emplace_back();
                  }
              const unsigned long n = count(set.cells.size());
              for (unsigned int k = 0; k < set.cells.size(); ++k)
                set.weight.push_back(1.0 / n);
            }
          else
            for (unsigned int c = 0; c < n_owned_cells; ++c)
              for (const auto &piece : network.cells[c].boundary)
                {
                  // The piece's centroid and area (a segment times the thickness in 2D).
                  dealii::Point<dim> mid;
                  double             weight = 0;
                  if constexpr (dim == 2)
                    {
                      mid    = 0.5 * (piece[0] + piece[1]);
                      weight = piece[0].distance(piece[1]) * bodies[cell_body[c]].thickness_at(mid);
                    }
                  else
                    {
                      // A planar polygon: fan triangles from its first vertex.
                      dealii::Tensor<1, 3> moment;
                      for (unsigned int k = 1; k + 1 < piece.size(); ++k)
                        {
                          const double a = 0.5 * dealii::cross_product_3d(piece[k] - piece[0], piece[k + 1] - piece[0]).norm();
                          weight += a;
                          moment += a / 3 * (piece[0] + piece[k] + piece[k + 1]);
                        }
                      if (weight <= 0)
                        continue;
                      mid = dealii::Point<3>(moment / weight);
                    }
                  if (!loads[l].region.contains(mid, tolerance))
                    continue;
                  set.cells.push_back(c);
                  set.arm.push_back(mid - nucleus(c));
                  set.weight.push_back(weight);
                }
          require(count(set.cells.size()) > 0,
                  "Load " + loads[l].name + "/Region",
                  loads[l].type == LoadDescription<dim>::Type::force ?
                    "contains no nucleus of the network" :
                    "contains no boundary piece of the network");
          load_sets.push_back(std::move(set));
        }
    }



    template <int dim>
    void
    Model<dim>::make_constraints(const double t0, const double t1, const bool predictor)
    {
      constraints.clear();
      constraints.reinit(relevant_dofs);
      for (unsigned int s = 0; s < dirichlet.size(); ++s)
        {
          const auto &set = dirichlet[s];
          for (const unsigned int dof : set.dofs)
            {
              constraints.add_line(global_dof(dof));
              if (predictor)
                constraints.set_inhomogeneity(global_dof(dof), prescribed_increment(set, dof, t0, t1));
            }
        }
      // Released cells (a fragment nothing holds) keep their displacements.
      if (n_released > 0)
        for (unsigned int c = 0; c < released.size(); ++c)
          if (released[c])
            for (unsigned int k = 0; k < n_dofs; ++k)
              if (!constraints.is_constrained(global_dof(n_dofs * c + k)))
                constraints.add_line(global_dof(n_dofs * c + k));
      constraints.close();
    }



    template <int dim>
    double
    Model<dim>::prescribed_increment(const Dirichlet &set, const unsigned int dof, const double t0, const double t1) const
    {
      const unsigned int c = dof / n_dofs, k = dof % n_dofs;
      if (set.rigid >= 0)
        return k < dim ? scene.body_descriptions()[set.rigid].rigid_displacement(t0, t1)[k] : 0.0;
      const auto &d = scene.boundary_descriptions()[set.boundary];
      const auto &x = local_nuclei[c];
      if (k < dim && (d.velocity || d.displacement))
        return d.displacement_increment(t0, t1, x)[k];
      if (k >= dim && d.displacement)
        {
          // The rotation 1/2 curl u of the field, by central differences: in 2D
          // 1/2 (du_y/dx - du_x/dy); in 3D component i is 1/2 (du_k/dx_j - du_j/dx_k) for
          // (i, j, k) cyclic.
          const double e  = 1e-4 * scale;
          const auto   du = [&](const unsigned int direction, const double h) {
            dealii::Tensor<1, dim> shift;
            shift[direction] = h;
            return d.displacement_increment(t0, t1, x + shift);
          };
          if constexpr (dim == 2)
            return 0.25 / e * ((du(0, e)[1] - du(0, -e)[1]) - (du(1, e)[0] - du(1, -e)[0]));
          else
            {
              const unsigned int i = k - dim, j = (i + 1) % 3, l = (i + 2) % 3;
              return 0.25 / e * ((du(j, e)[l] - du(j, -e)[l]) - (du(l, e)[j] - du(l, -e)[j]));
            }
        }
      return 0;
    }



    template <int dim>
    double
    Model<dim>::prescribed_velocity(const Dirichlet &set, const unsigned int dof, const double t) const
    {
      const unsigned int k = dof % n_dofs;
      if (set.rigid >= 0)
        return k < dim ? scene.body_descriptions()[set.rigid].rigid_velocity_at(t)[k] : 0.0;
      const auto &d = scene.boundary_descriptions()[set.boundary];
      if (d.velocity)
        return k < dim ? d.velocity_at(t)[k] : 0.0;
      if (!d.displacement)
        return 0; // fixed, roller
      // g'(t) = (g(t + h) - g(t - h)) / 2h, error O(h^2).
      const double h = 1e-6 * std::max(scene.time_control().end_time, 1e-300);
      return prescribed_increment(set, dof, t - h, t + h) / (2 * h);
    }



    template <int dim>
    void
    Model<dim>::cell_mass_matrix(const unsigned int c, dealii::FullMatrix<double> &M) const
    {
      // Rigid cell of mass m, centroid at o from the nucleus, inertia J about the nucleus:
      // the kinetic energy 1/2 m |u' + omega x o|^2 + 1/2 omega . J_c omega (eq. 3.12), i.e.
      // M = [m I, -m [o]x; m [o]x, J] with [o]x w = o x w (in 2D omega = theta' e_z).
      const double                  m = cell_mass[c];
      const dealii::Tensor<1, dim> &o = cell_offset[c];
      M.reinit(n_dofs, n_dofs);
      for (unsigned int d = 0; d < dim; ++d)
        M(d, d) = m;
      if constexpr (dim == 2)
        {
          M(0, 2) = M(2, 0) = -m * o[1];
          M(1, 2) = M(2, 1) = m * o[0];
          M(2, 2)           = cell_inertia[c][0][0];
        }
      else
        {
          // -m [o]x = m [[0, o_z, -o_y], [-o_z, 0, o_x], [o_y, -o_x, 0]] (rows u, columns theta).
          const double C[3][3] = {{0, m * o[2], -m * o[1]}, {-m * o[2], 0, m * o[0]}, {m * o[1], -m * o[0], 0}};
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
              {
                M(i, 3 + j) = C[i][j];
                M(3 + j, i) = C[i][j];
                M(3 + i, 3 + j) = cell_inertia[c][i][j];
              }
        }
    }



    template <int dim>
    void
    Model<dim>::external_forces(const double t, Vector &f) const
    {
      // Loads, and gravity at the centroids (a force and its moment about the nucleus),
      // on the owned cells.
      f                 = 0;
      const auto &loads = scene.load_descriptions();
      const auto  add   = [&](const unsigned int c, const dealii::Tensor<1, dim> &arm, const dealii::Tensor<1, dim> &F) {
        for (unsigned int d = 0; d < dim; ++d)
          f.local_element(n_dofs * c + d) += F[d];
        if constexpr (dim == 2)
          f.local_element(n_dofs * c + 2) += arm[0] * F[1] - arm[1] * F[0];
        else
          {
            const dealii::Tensor<1, 3> m = dealii::cross_product_3d(arm, F);
            for (unsigned int d = 0; d < 3; ++d)
              f.local_element(n_dofs * c + 3 + d) += m[d];
          }
      };
      for (const auto &set : load_sets)
        {
          const dealii::Tensor<1, dim> value = loads[set.load].value_at(t);
          for (unsigned int k = 0; k < set.cells.size(); ++k)
            add(set.cells[k], set.arm[k], set.weight[k] * value);
        }
      const dealii::Tensor<1, dim> &g = scene.gravity();
      if (g.norm() > 0)
        for (unsigned int c = 0; c < n_owned_cells; ++c)
          add(c, cell_offset[c], cell_mass[c] * g);
    }



    template <int dim>
    bool
    Model<dim>::renew_factors()
    {
      // Refactorize only on change: an unchanged tangent (elastic steps, static analyses)
      // keeps its factors; with a reuse tolerance, a tangent within it of the factorized
      // one too (modified Newton), unless the last correction with stale factors reduced
      // the residual less than twofold. The change is ||K - K_f||_F / ||K_f||_F against the
      // copy K_f kept at the last factorization (summed over the ranks' rows).
      double change = std::numeric_limits<double>::infinity();
      if (factorized)
        {
          double sums[2] = {0, 0}; // ||K - K_f||^2, ||K_f||^2
          const auto add = [&](const double k, const double f) {
            sums[0] += (k - f) * (k - f);
            sums[1] += f * f;
          };
          if (trilinos_system())
            {
              // The two matrices share their graph (copy_from): compare the local rows.
              const Epetra_CrsMatrix &A = parallel_matrix.trilinos_matrix(),
                                     &F = factored_parallel.trilinos_matrix();
              for (int row = 0; row < A.NumMyRows(); ++row)
                {
                  int     n_a = 0, n_f = 0;
                  double *a = nullptr, *f = nullptr;
                  A.ExtractMyRowView(row, n_a, a);
                  F.ExtractMyRowView(row, n_f, f);
                  for (int k = 0; k < std::min(n_a, n_f); ++k)
                    add(a[k], f[k]);
                }
              const int ierr = MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, network_communicator());
              AssertThrowMPI(ierr);
            }
          else
            for (auto p = matrix.begin(), q = factored_matrix.begin(); p != matrix.end(); ++p, ++q)
              add(p->value(), q->value());
          change = std::sqrt(sums[0] / sums[1]);
        }
      const double residual = rhs.l2_norm();
      const bool   slow     = stale_factors && residual > 0.5 * previous_residual;
      const bool   renew    = !(change <= reuse_tolerance) || slow;
      stale_factors         = !renew && change > 0;
      previous_residual     = residual;
      return renew;
    }



    template <int dim>
    RuntimeError
    Model<dim>::singular_tangent()
    {
      return RuntimeError("rbsn: the tangent stiffness matrix is singular: the network is a "
                          "mechanism (springs without stiffness, e.g. perfectly plastic ones at "
                          "their limit, or a part that only such springs hold)");
    }



    template <int dim>
    void
    Model<dim>::solve_linear(Vector &x)
    {
      if (trilinos_system())
        return solve_distributed(x);
      try
        {
          if (renew_factors())
            {
              direct->factorize(matrix);
              factored_matrix.copy_from(matrix);
              factorized = true;
              ++n_factorizations;
            }
          // One part: the local entries are the global ones.
          dealii::Vector<double> b(rhs.begin(), rhs.begin() + rhs.locally_owned_size()), y(b.size());
          direct->solve(y, b);
          std::copy(y.begin(), y.end(), x.begin());
        }
      catch (const std::runtime_error &)
        {
          throw singular_tangent();
        }
    }



    template <int dim>
    std::string
    Model<dim>::summary(const unsigned long steps, const unsigned int outputs) const
    {
      std::ostringstream s;
      s << n_cells << " cells, " << n_global_facets << " facets, "
        << (analysis == Analysis::variable_order ? n_steps : steps) << " steps, " << n_newton
        << " Newton iterations";
      s << ", " << n_factorizations << " factorizations";
      if (incremental_assembly && n_facet_evaluations > 0)
        {
          const MPI_Comm      comm    = network_communicator();
          const unsigned long updates = dealii::Utilities::MPI::sum(n_facet_updates, comm);
          const unsigned long total   = dealii::Utilities::MPI::sum(n_facet_evaluations, comm);
          std::ostringstream  share;
          share << std::fixed << std::setprecision(1) << 100.0 * updates / total;
          s << " (" << n_matrix_assemblies - n_full_assemblies << " of " << n_matrix_assemblies
            << " tangents updated in place, " << share.str() << " % of the facets' matrices)";
        }
      if (linear_solver != "direct")
        s << " (" << linear_solver << " + AMG, " << n_linear_iterations << " iterations)";
      else if (distributed())
        s << " (" << distributed_solver << " on " << n_parts << " MPI ranks)";
      if (n_exact_retries > 0)
        s << " (" << n_exact_retries << " steps again with exact Newton)";
      if (fracture.enabled)
        {
          s << ", " << n_broken << " broken facets, " << n_fragments << (n_fragments == 1 ? " fragment" : " fragments");
          if (n_released > 0)
            s << " (" << n_released << (n_released == 1 ? " cell" : " cells") << " released)";
          if (fracture_energy > 0)
            s << ", fracture energy " << fracture_energy << " J";
        }
      s << ", " << outputs << " outputs";
      return s.str();
    }



    template class Model<2>;
    template class Model<3>;



    template <int dim>
    Solver<dim>::Solver() = default;

    template <int dim>
    Solver<dim>::~Solver() = default;

    template <int dim>
    void
    Solver<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      Model<dim>::declare_parameters(prm);
    }

    template <int dim>
    void
    Solver<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      // The network's tables have cell and facet columns, not continuum points.
      require(this->get_scene().output_control().additional_columns.empty(),
              "Output/Additional columns",
              "the rbsn method's probe tables hold cell and facet values; additional point "
              "columns apply to the mpm and fem methods");
      model = std::make_unique<Model<dim>>(this->get_scene(), *this, prm);
    }

    // The driver's hooks.
    template <int dim>
    void
    Solver<dim>::setup()
    {
      model->setup();
    }

    template <int dim>
    double
    Solver<dim>::size_of_state() const
    {
      // u and theta per cell.
      return model ? double(Model<dim>::n_dofs) * model->n_global_cells() : 0.0;
    }

    template <int dim>
    std::string
    Solver<dim>::checkpoint_unsupported() const
    {
      return model ? model->checkpoint_unsupported() : std::string();
    }

    template <int dim>
    void
    Solver<dim>::open_outputs()
    {
      model->open_outputs();
    }

    template <int dim>
    void
    Solver<dim>::initialize()
    {
      model->initialize();
    }

    template <int dim>
    double
    Solver<dim>::propose_step(const double t)
    {
      return model->propose_step(t);
    }

    template <int dim>
    bool
    Solver<dim>::advance(double &t, const double dt)
    {
      return model->advance(t, dt, [this](const double time) { this->step_finished(time); });
    }

    template <int dim>
    void
    Solver<dim>::write_rows(const double t)
    {
      model->write_rows(t);
    }

    template <int dim>
    void
    Solver<dim>::write_fields(const double t, Output::FieldWriter &writer)
    {
      model->write_fields(t, writer);
    }

    template <int dim>
    void
    Solver<dim>::finish(const double)
    {
      model->finish();
    }

    template <int dim>
    void
    Solver<dim>::save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const
    {
      model->save(global, rank, directory);
    }

    template <int dim>
    void
    Solver<dim>::load(CheckpointReader              &global,
                      std::vector<CheckpointReader> &rank_parts,
                      const CheckpointDirectory     &directory)
    {
      model->load(global, rank_parts, directory);
    }

    template <int dim>
    std::string
    Solver<dim>::summary() const
    {
      return model ? model->summary(this->n_steps(), this->n_outputs()) : std::string();
    }

    template class Solver<2>;
    template class Solver<3>;
  } // namespace RBSN
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::RBSN::Solver,
                         "rbsn",
                         "the Rigid-Body-Spring Network: Voronoi cells as rigid bodies joined by "
                         "Bouc-Wen springs at their facets, static, quasi-static and dynamic, with "
                         "brittle fracture; 2D and 3D; see doc/rbsn.md");

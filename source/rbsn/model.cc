#include <deal.II/base/utilities.h>

#include <Epetra_CrsMatrix.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <hysteron/base/parameters.h>
#include "base/sparse_lu.h"
#include <hysteron/rbsn/model.h>
#include <hysteron/scene/output_column.h>
#include <hysteron/rbsn/rbsn.h>

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
    void
    Model::declare_parameters(dealii::ParameterHandler &prm)
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
                          "network (e.g. 0.002 + 0.02 * abs(x - 1), finer where d is smaller): a new "
                          "point p keeps |p - q| >= min(d(p), d(q)) from every point q, about "
                          "0.68 int 1/d^2 dA points; d must be finite and > 0 in the bodies and "
                          "should vary slowly (|grad d| well below 1; doc/rbsn.md).");
        prm.declare_entry("Points on the boundary",
                          "true",
                          Patterns::Bool(),
                          "Place nuclei along the bodies' boundaries (corners kept, spacing about "
                          "d_m), so that boundary cells have their computational point on the "
                          "boundary, where supports and loads act.");
        prm.declare_entry("Additional points",
                          "",
                          Patterns::Anything(),
                          "Nuclei placed by the user [m], 'x, y; x, y; ...' (supports, load "
                          "points); the random points keep d_m from them.");
        prm.declare_entry("Curved boundary resolution",
                          "0",
                          Patterns::Double(),
                          "Segment length [m] of curved boundaries (disks as polygons), >= 0; 0: "
                          "d_m / 4 (the smallest d_m over the bodies for a graded network).");
        prm.declare_entry("Shear stiffness ratio",
                          "0",
                          Patterns::Double(),
                          "k_t / k_n, >= 0; 0: from the material, k_t = G t l / h and k_n = "
                          "E' t l / h (eq. 3.9; E' = E / (1 - nu^2) in plane stress). 1 makes the "
                          "network elastically uniform under any uniform strain (with nu = 0).");
        prm.declare_entry("Moment yield factor",
                          "0.25",
                          Patterns::Double(),
                          "The rotational spring yields at M_y = factor sigma_y t l^2 (0.25: the "
                          "plastic moment of the facet's section), > 0. The normal and tangential "
                          "springs yield at sigma_y t l and sigma_y t l / sqrt(3).");
        prm.declare_entry("Spring law",
                          "uncoupled",
                          Patterns::Selection(SpringLawRegistry<2>::pattern_string()),
                          "The law of the facet springs, a registered plugin (doc/rbsn.md; plugins "
                          "from Additional shared libraries too). The built-in laws take the facets "
                          "between Bouc-Wen cells (linear-elastic ones have linear springs); "
                          "Analysis = static has linear springs throughout:" +
                            SpringLawRegistry<2>::documentation());
        SpringLawRegistry<2>::declare_parameters(prm);
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
                          "(METIS), each rank assembles its facets, and the distributed tangent "
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
                          "Krylov iterations with ML algebraic multigrid that knows the three "
                          "rigid-body modes of every cell (translations and the rotation about the "
                          "origin), to `Linear solver tolerance` of the residual.");
        prm.declare_entry("Linear solver tolerance",
                          "1e-10",
                          Patterns::Double(),
                          "cg / gmres: the linear residual relative to the right-hand side, in "
                          "(0, 1); below Newton's tolerance.");
        prm.declare_entry("Linear solver iterations",
                          "1000",
                          Patterns::Integer(1),
                          "cg / gmres: iterations before the attempt fails (and the increment is cut).");
        prm.declare_entry("Write spring table",
                          "false",
                          Patterns::Bool(),
                          "Write springs.csv at the end: every facet (cells, midpoint, length, "
                          "distance, stiffnesses, forces, H1 of the three springs (Spring law = "
                          "coupled: the facet's Phi^n in all three), broken).");
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
                            "f_t [Pa] > 0: a facet breaks when its normal stress s_n = F_n / (t l) "
                            "exceeds it (tension cut-off).");
          prm.declare_entry("Cohesion",
                            "0",
                            Patterns::Double(),
                            "c [Pa] > 0: ... or when |s_t| + tan(phi) s_n > c (Mohr-Coulomb; "
                            "s_t = F_t / (t l), tension positive).");
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



    Model::Model(const Scene<2> &scene, const Methods::Interface<2> &method, dealii::ParameterHandler &prm)
      : scene(scene)
      , method(method)
      , direct(std::make_unique<SparseLU>())
    {
      scene.refuse_fem_only_sets("rbsn", true);
      {
        Section s(prm, {"RBSN"});
        // A number is a constant d_m; anything else an expression in x and y,
        // sampled over the bodies in build_network().
        const std::string distance = dealii::Utilities::trim(s.get("Minimum distance"));
        char             *end      = nullptr;
        std::strtod(distance.c_str(), &end);
        if (!distance.empty() && end == distance.c_str() + distance.size())
          {
            d_m     = s.get_positive("Minimum distance");
            spacing = Spacing<2>(d_m);
          }
        else
          {
            const std::shared_ptr<const dealii::FunctionParser<2>> d =
              parse_function<2>(distance, "x,y", false, s.where("Minimum distance"));
            spacing = Spacing<2>([d](const dealii::Point<2> &p) { return d->value(p); },
                              distance,
                              s.where("Minimum distance"));
          }
        points_on_boundary = s.get_bool("Points on the boundary");
        extra_points       = parse_points<2>(s.get("Additional points"), s.where("Additional points"));
        boundary_h         = s.get_non_negative("Curved boundary resolution"); // 0: in build_network()
        shear_ratio  = s.get_non_negative("Shear stiffness ratio");
        moment_yield = s.get_positive("Moment yield factor");
        spring_law_name = s.get("Spring law");
        spring_law      = SpringLawRegistry<2>::create(spring_law_name, s.where("Spring law"));
        spring_law->parse_parameters(s);
        const std::string type = s.get("Analysis");
        analysis = type == "static"            ? Analysis::linear_static :
                   type == "quasi-static"      ? Analysis::quasi_static :
                   type == "implicit dynamics" ? Analysis::implicit_dynamics :
                                                 Analysis::variable_order;
        time_step    = s.get_non_negative("Time step");
        n_increments = s.get_integer("Number of increments");
        spring_table = s.get_bool("Write spring table");
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
            body_shapes.push_back(&bodies[b].shape);
            mesh_body.push_back(b);
            const auto &m = scene.material(bodies[b].material, "Body " + bodies[b].name + "/Material");
            require(m.elasticity().stress_state != Material::StressState::three_dimensional,
                    "Body " + bodies[b].name + "/Material",
                    "the rbsn method is two-dimensional");
            require(m.elasticity().stress_state != Material::StressState::axisymmetric,
                    "Body " + bodies[b].name + "/Material",
                    "the rbsn method has no axisymmetric form (its cells are plane rigid "
                    "bodies): use Stress state = plane stress or plane strain");
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
        require(b.type != BoundaryDescription<2>::Type::wall,
                "Boundary " + b.name + "/Type",
                "the rbsn method has no walls (use fixed, roller, velocity or displacement)");
    }



    Model::~Model() = default;



    void
    Model::build_network()
    {
      const auto &bodies = scene.body_descriptions();
      // d over the bodies: its smallest value (d_m for the messages and the default
      // resolution of curved boundaries) and the predicted number of points,
      // 0.68 int 1/d^2 dA, which guards the memory and announces a long set-up.
      spacing.sample(body_shapes);
      d_m = spacing.min;
      if (boundary_h == 0)
        boundary_h = 0.25 * d_m;
      std::ostringstream range;
      if (spacing.is_constant())
        range << "d_m = " << d_m;
      else
        range << "d = " << spacing.min << " ... " << spacing.max;
      const std::string distance = range.str();
      require(spacing.predicted_points <= 5e6,
              "RBSN/Minimum distance",
              "about " + std::to_string(static_cast<long>(spacing.predicted_points)) +
                " points predicted at this minimum distance (0.68 int 1/d^2 dA over the bodies; at most 5e6)");
      StageReport stage(scene.console(), spacing.predicted_points > 5e4);
      if (stage.enabled())
        scene.console() << "rbsn: about " << StageReport::count(static_cast<std::size_t>(spacing.predicted_points))
                        << " cells predicted (0.68 int 1/d^2 dA, " << distance << " m)" << std::endl;

      // The nuclei: the user's points, points along every body's boundary, then
      // random points (one set for all bodies; each point belongs to the body
      // that contains it).
      std::vector<dealii::Point<2>> fixed = extra_points;
      for (const auto &p : extra_points)
        {
          bool inside = false;
          for (const auto *shape : body_shapes)
            inside = inside || shape->contains(p, 1e-9 * d_m);
          std::ostringstream point;
          point << p;
          require(inside, "RBSN/Additional points", "the point (" + point.str() + ") lies in no deformable body");
        }
      if (points_on_boundary)
        for (const auto *shape : body_shapes)
          {
            const auto p = boundary_points(*shape, spacing, boundary_h);
            fixed.insert(fixed.end(), p.begin(), p.end());
          }
      // Merge points closer than 1e-6 d_m (corners shared by touching bodies), the
      // first kept: each point is compared with the kept ones in its and the
      // neighbouring cells of a hash grid of that size.
      std::vector<dealii::Point<2>> points;
      {
        const double tolerance = 1e-6 * d_m;
        const auto   key       = [&](const dealii::Point<2> &p, const int dx, const int dy) {
          return std::make_pair(static_cast<long long>(std::floor(p[0] / tolerance)) + dx,
                                static_cast<long long>(std::floor(p[1] / tolerance)) + dy);
        };
        std::map<std::pair<long long, long long>, std::vector<unsigned int>> kept;
        for (const auto &p : fixed)
          {
            bool seen = false;
            for (int dy = -1; dy <= 1 && !seen; ++dy)
              for (int dx = -1; dx <= 1 && !seen; ++dx)
                if (const auto k = kept.find(key(p, dx, dy)); k != kept.end())
                  for (const unsigned int q : k->second)
                    seen = seen || p.distance(points[q]) < tolerance;
            if (!seen)
              {
                kept[key(p, 0, 0)].push_back(points.size());
                points.push_back(p);
              }
          }
      }
      for (unsigned int s = 0; s < body_shapes.size(); ++s)
        {
          // Each body is filled in turn, keeping the distance from every point so far.
          auto filled = poisson_disk_points(*body_shapes[s], spacing, points,
                                            scene.random_seed() + 7919 * s, "RBSN/Minimum distance");
          points.swap(filled);
        }
      require(points.size() >= 2,
              "RBSN/Minimum distance",
              "leaves room for " + std::to_string(points.size()) +
                " nucleus in the bodies, and a network needs at least two cells: the minimum "
                "distance must be well below the size of the bodies (got " + distance + " m)");
      stage(StageReport::count(points.size()) + " nuclei");
      network = voronoi(points, body_shapes, boundary_h, "Body names");
      stage("Voronoi cells");

      // The bodies and the rigid-body mass properties about the nuclei (eq. 3.12).
      const unsigned int n = network.cells.size();
      cell_body.assign(n, 0);
      cell_mass.assign(n, 0);
      cell_inertia.assign(n, 0);
      cell_offset.assign(n, dealii::Tensor<1, 2>());
      const auto lo = bodies[mesh_body[0]].shape.bounding_box().get_boundary_points();
      scale         = lo.first.distance(lo.second);
      for (unsigned int c = 0; c < n; ++c)
        {
          const auto &cell = network.cells[c];
          for (unsigned int s = 0; s < body_shapes.size(); ++s)
            if (body_shapes[s]->contains(cell.nucleus, 1e-9 * scale))
              {
                cell_body[c] = mesh_body[s];
                break;
              }
          const auto  &body = bodies[cell_body[c]];
          const double rho  = scene.material(body.material, "Body " + body.name + "/Material").density();
          // A varying thickness is taken at the cell's centroid (midpoint rule over the cell).
          const double t    = body.thickness_at(cell.centroid);
          const double m    = rho * t * cell.area;
          cell_mass[c]      = m;
          cell_offset[c]    = cell.centroid - cell.nucleus;
          // I_c + m r^2: the polar moment about the nucleus.
          cell_inertia[c] = rho * t * cell.polar_moment + m * cell_offset[c].norm_square();
        }
    }



    void
    Model::setup_springs()
    {
      const auto &bodies = scene.body_descriptions();
      springs.assign(network.facets.size(), Springs());
      for (unsigned int e = 0; e < network.facets.size(); ++e)
        {
          const Facet<2> &f  = network.facets[e];
          Springs     &sp = springs[e];
          const auto  &ba = bodies[cell_body[f.a]], &bb = bodies[cell_body[f.b]];
          const auto  &ma = scene.material(ba.material, "Body " + ba.name + "/Material");
          const auto  &mb = scene.material(bb.material, "Body " + bb.name + "/Material");
          // The thinner side at the facet's midpoint (two bodies may meet there).
          const double t  = std::min(ba.thickness_at(f.midpoint), bb.thickness_at(f.midpoint));
          const double l  = f.length;
          // Voronoi scaling (eq. 3.9), the two half-cells in series:
          // k_n = t l / (h_a / E'_a + h_b / E'_b), k_t likewise with G, k_phi = k_n l^2 / 12.
          sp.k[0] = t * l / (f.h_a / ma.elasticity().p_wave_modulus() + f.h_b / mb.elasticity().p_wave_modulus());
          sp.k[1] = shear_ratio > 0 ? shear_ratio * sp.k[0] :
                                      t * l / (f.h_a / ma.elasticity().shear_modulus() +
                                               f.h_b / mb.elasticity().shear_modulus());
          sp.k[2]      = sp.k[0] * l * l / 12;
          sp.thickness = t;
          FacetSprings<2> facet;
          facet.k                   = sp.k;
          facet.thickness           = t;
          facet.length              = l;
          facet.moment_yield_factor = moment_yield;
          // B (eq. 3.6, with the corrections in doc/theory.md): the displacement of P as a
          // point of cell b minus as a point of cell a, in the facet's (n, t) axes,
          // u_P = u_i - (y_P - y_i) theta_i, v_P = v_i + (x_P - x_i) theta_i.
          const dealii::Tensor<1, 2> n = f.normal, tt({-n[1], n[0]});
          const dealii::Tensor<1, 2> ra = f.midpoint - network.cells[f.a].nucleus;
          const dealii::Tensor<1, 2> rb = f.midpoint - network.cells[f.b].nucleus;
          const auto cross = [](const dealii::Tensor<1, 2> &r, const dealii::Tensor<1, 2> &w) {
            return r[0] * w[1] - r[1] * w[0];
          };
          sp.B_n = {{-n[0], -n[1], -cross(ra, n), n[0], n[1], cross(rb, n)}};
          sp.B_t = {{-tt[0], -tt[1], -cross(ra, tt), tt[0], tt[1], cross(rb, tt)}};

          // The spring law's springs (static: linear springs, the plasticity ignored).
          if (analysis != Analysis::linear_static)
            {
              sp.state.assign(spring_law->n_state_variables(), 0.0);
              sp.hysteretic = spring_law->setup_facet(e, facet, ma, mb, sp.state.data());
              if (!sp.hysteretic)
                sp.state.clear();
            }
          for (unsigned int i = 0; i < 3; ++i)
            sp.tangent[i][i] = sp.k[i]; // the first predictor's
          sp.trial_state = sp.state;
        }
    }



    void
    Model::setup_system()
    {
      const unsigned int n = 3 * network.cells.size();
      partition();
      // The serial matrix: one rank, or rank 0 under the gathered UMFPACK solver.
      if (!trilinos_system() ||
          (distributed() && linear_solver == "direct" && distributed_solver == "UMFPACK" && rank == 0))
        {
          dealii::DynamicSparsityPattern dsp(n, n);
          for (unsigned int c = 0; c < network.cells.size(); ++c)
            for (unsigned int i = 0; i < 3; ++i)
              for (unsigned int j = 0; j < 3; ++j)
                dsp.add(3 * c + i, 3 * c + j);
          for (const auto &f : network.facets)
            for (const unsigned int p : {f.a, f.b})
              for (const unsigned int q : {f.a, f.b})
                for (unsigned int i = 0; i < 3; ++i)
                  for (unsigned int j = 0; j < 3; ++j)
                    dsp.add(3 * p + i, 3 * q + j);
          pattern.copy_from(dsp);
          matrix.reinit(pattern);
          factored_matrix.reinit(pattern);
        }
      factorized = false;
      direct->clear();
      for (Vector *w : {&u, &u_trial, &v, &a, &rhs, &f_int, &f_ext, &f_ext_old, &inertia, &reaction_old})
        w->reinit(n);
    }



    void
    Model::setup_conditions()
    {
      using Type         = BoundaryDescription<2>::Type;
      const auto &bodies = scene.body_descriptions();
      const auto  box    = [&] {
        dealii::Point<2> lo(1e300, 1e300), hi(-1e300, -1e300);
        for (const auto &c : network.cells)
          for (unsigned int d = 0; d < 2; ++d)
            {
              lo[d] = std::min(lo[d], c.nucleus[d]);
              hi[d] = std::max(hi[d], c.nucleus[d]);
            }
        return std::make_pair(lo, hi);
      }();
      const double tolerance = 1e-9 * scale;
      // History sets: the cells whose nucleus lies on the set's faces of the nuclei's box
      // or in its region (the rule of the boundary conditions).
      history_cells.clear();
      for (const unsigned int k : scene.output_control().history_sets)
        {
          const SetDescription<2>  &d = scene.set_descriptions()[k];
          std::vector<unsigned int> cells;
          for (unsigned int c = 0; c < network.cells.size(); ++c)
            {
              const auto &x  = network.cells[c].nucleus;
              bool        in = d.has_region && d.region.contains(x, tolerance);
              for (const unsigned int face : d.faces)
                in = in || std::abs(x[face / 2] - (face % 2 == 0 ? box.first[face / 2] : box.second[face / 2])) <= tolerance;
              if (in)
                cells.push_back(c);
            }
          require(!cells.empty(),
                  d.where(),
                  "selects no cell of the network (a cell is selected by its nucleus: on the face "
                  "of the nuclei's bounding box, or in the region)");
          history_cells.push_back(std::move(cells));
        }
      dof_set.assign(3 * network.cells.size(), -1);
      dirichlet.clear();
      const auto take = [&](Dirichlet &set, const unsigned int dof) {
        if (dof_set[dof] < 0)
          {
            dof_set[dof] = dirichlet.size();
            set.dofs.push_back(dof);
          }
      };
      // u and v by the boundary's rule; the rotation with both (fixed, or velocity /
      // displacement of x and y: the rigid motion the field gives the nucleus), not
      // for a roller.
      for (unsigned int b = 0; b < scene.boundary_descriptions().size(); ++b)
        {
          const auto &d = scene.boundary_descriptions()[b];
          Dirichlet   set;
          set.name     = d.name;
          set.boundary = b;
          for (unsigned int c = 0; c < network.cells.size(); ++c)
            {
              const auto &x = network.cells[c].nucleus;
              bool        both = d.type != Type::roller;
              for (unsigned int k = 0; k < 2; ++k)
                if (d.prescribes(x, k, box.first, box.second, tolerance))
                  take(set, 3 * c + k);
                else
                  both = false;
              if (both)
                take(set, 3 * c + 2);
            }
          require(!set.dofs.empty(),
                  "Boundary " + d.name + (!d.set.empty() ? "/Set" : d.has_region ? "/Region" : "/Faces"),
                  "selects no cell of the network (a cell is selected by its nucleus: on the face "
                  "of the nuclei's bounding box, or in the region)");
          dirichlet.push_back(std::move(set));
        }
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (bodies[b].rigid)
          {
            Dirichlet set;
            set.name  = bodies[b].name;
            set.rigid = b;
            for (unsigned int c = 0; c < network.cells.size(); ++c)
              if (bodies[b].shape.contains(network.cells[c].nucleus, tolerance))
                for (unsigned int k = 0; k < 3; ++k)
                  take(set, 3 * c + k);
            require(!set.dofs.empty(),
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
          if (loads[l].type == LoadDescription<2>::Type::force)
            {
              for (unsigned int c = 0; c < network.cells.size(); ++c)
                if (loads[l].region.contains(network.cells[c].nucleus, tolerance))
                  {
                    set.cells.push_back(c);
                    set.arm.emplace_back();
                  }
              for (unsigned int k = 0; k < set.cells.size(); ++k)
                set.weight.push_back(1.0 / set.cells.size());
            }
          else
            for (unsigned int c = 0; c < network.cells.size(); ++c)
              for (const auto &piece : network.cells[c].boundary)
                {
                  const dealii::Point<2> mid = 0.5 * (piece[0] + piece[1]);
                  if (!loads[l].region.contains(mid, tolerance))
                    continue;
                  set.cells.push_back(c);
                  set.arm.push_back(mid - network.cells[c].nucleus);
                  set.weight.push_back(piece[0].distance(piece[1]) * bodies[cell_body[c]].thickness_at(mid));
                }
          require(!set.cells.empty(),
                  "Load " + loads[l].name + "/Region",
                  loads[l].type == LoadDescription<2>::Type::force ?
                    "contains no nucleus of the network" :
                    "contains no boundary piece of the network");
          load_sets.push_back(std::move(set));
        }
    }



    void
    Model::make_constraints(const double t0, const double t1, const bool predictor)
    {
      constraints.clear();
      for (unsigned int s = 0; s < dirichlet.size(); ++s)
        {
          const auto &set = dirichlet[s];
          for (const unsigned int dof : set.dofs)
            {
              constraints.add_line(dof);
              if (predictor)
                constraints.set_inhomogeneity(dof, prescribed_increment(set, dof, t0, t1));
            }
        }
      // Released cells (a fragment nothing holds) keep their displacements.
      if (n_released > 0)
        for (unsigned int c = 0; c < released.size(); ++c)
          if (released[c])
            for (unsigned int k = 0; k < 3; ++k)
              if (!constraints.is_constrained(3 * c + k))
                constraints.add_line(3 * c + k);
      constraints.close();
    }



    double
    Model::prescribed_increment(const Dirichlet &set, const unsigned int dof, const double t0, const double t1) const
    {
      const unsigned int c = dof / 3, k = dof % 3;
      if (set.rigid >= 0)
        return k < 2 ? scene.body_descriptions()[set.rigid].rigid_displacement(t0, t1)[k] : 0.0;
      const auto &d = scene.boundary_descriptions()[set.boundary];
      const auto &x = network.cells[c].nucleus;
      if (k < 2 && (d.velocity || d.displacement))
        return d.displacement_increment(t0, t1, x)[k];
      if (k == 2 && d.displacement)
        {
          // The rotation 1/2 (du_y/dx - du_x/dy) of the field, by central differences.
          const double e  = 1e-4 * scale;
          const auto   du = [&](const double dx, const double dy) {
            return d.displacement_increment(t0, t1, x + dealii::Tensor<1, 2>({dx, dy}));
          };
          return 0.25 / e * ((du(e, 0)[1] - du(-e, 0)[1]) - (du(0, e)[0] - du(0, -e)[0]));
        }
      return 0;
    }



    double
    Model::prescribed_velocity(const Dirichlet &set, const unsigned int dof, const double t) const
    {
      const unsigned int k = dof % 3;
      if (set.rigid >= 0)
        return k < 2 ? scene.body_descriptions()[set.rigid].rigid_velocity_at(t)[k] : 0.0;
      const auto &d = scene.boundary_descriptions()[set.boundary];
      if (d.velocity)
        return k < 2 ? d.velocity_at(t)[k] : 0.0;
      if (!d.displacement)
        return 0; // fixed, roller
      // g'(t) = (g(t + h) - g(t - h)) / 2h, error O(h^2).
      const double h = 1e-6 * std::max(scene.time_control().end_time, 1e-300);
      return prescribed_increment(set, dof, t - h, t + h) / (2 * h);
    }



    void
    Model::cell_mass_matrix(const unsigned int c, dealii::FullMatrix<double> &M) const
    {
      // Rigid cell of mass m, centroid at o from the nucleus, polar moment I about the
      // nucleus: the kinetic energy 1/2 m |v + omega x o|^2 + 1/2 I_c omega^2 (eq. 3.12).
      const double m = cell_mass[c], ox = cell_offset[c][0], oy = cell_offset[c][1];
      M.reinit(3, 3);
      M(0, 0) = M(1, 1) = m;
      M(0, 2) = M(2, 0) = -m * oy;
      M(1, 2) = M(2, 1) = m * ox;
      M(2, 2)           = cell_inertia[c];
    }



    void
    Model::external_forces(const double t, Vector &f) const
    {
      // Loads, and gravity at the centroids (a force and its moment about the nucleus).
      f                      = 0;
      const auto          &loads = scene.load_descriptions();
      const auto           cross = [](const dealii::Tensor<1, 2> &r, const dealii::Tensor<1, 2> &w) {
        return r[0] * w[1] - r[1] * w[0];
      };
      for (const auto &set : load_sets)
        {
          const dealii::Tensor<1, 2> value = loads[set.load].value_at(t);
          for (unsigned int k = 0; k < set.cells.size(); ++k)
            {
              const dealii::Tensor<1, 2> F = set.weight[k] * value;
              f(3 * set.cells[k]) += F[0];
              f(3 * set.cells[k] + 1) += F[1];
              f(3 * set.cells[k] + 2) += cross(set.arm[k], F);
            }
        }
      const dealii::Tensor<1, 2> &g = scene.gravity();
      if (g.norm() > 0)
        for (unsigned int c = 0; c < network.cells.size(); ++c)
          {
            const dealii::Tensor<1, 2> F = cell_mass[c] * g;
            f(3 * c) += F[0];
            f(3 * c + 1) += F[1];
            f(3 * c + 2) += cross(cell_offset[c], F);
          }
    }



    bool
    Model::renew_factors()
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
              const int ierr = MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, scene.mpi_communicator());
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



    RuntimeError
    Model::singular_tangent()
    {
      return RuntimeError("rbsn: the tangent stiffness matrix is singular: the network is a "
                          "mechanism (springs without stiffness, e.g. perfectly plastic ones at "
                          "their limit, or a part that only such springs hold)");
    }



    void
    Model::solve_linear(Vector &x)
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
          direct->solve(x, rhs);
        }
      catch (const std::runtime_error &)
        {
          throw singular_tangent();
        }
    }



    std::string
    Model::summary(const unsigned long steps, const unsigned int outputs) const
    {
      std::ostringstream s;
      s << network.cells.size() << " cells, " << network.facets.size() << " facets, "
        << (analysis == Analysis::variable_order ? n_steps : steps) << " steps, " << n_newton
        << " Newton iterations";
      s << ", " << n_factorizations << " factorizations";
      if (incremental_assembly && n_facet_evaluations > 0)
        {
          std::ostringstream share;
          share << std::fixed << std::setprecision(1) << 100.0 * n_facet_updates / n_facet_evaluations;
          s << " (" << n_matrix_assemblies - n_full_assemblies << " of " << n_matrix_assemblies
            << " tangents updated in place, " << share.str() << " % of the facets' matrices)";
        }
      if (linear_solver != "direct")
        s << " (" << linear_solver << " + AMG, " << n_linear_iterations << " iterations)";
      else if (distributed())
        s << " (" << distributed_solver << " on " << n_ranks << " MPI ranks)";
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



    template <int dim>
    Solver<dim>::Solver() = default;

    template <int dim>
    Solver<dim>::~Solver() = default;

    template <int dim>
    void
    Solver<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      Model::declare_parameters(prm);
    }

    template <int dim>
    void
    Solver<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      // The network's tables have cell and facet columns, not continuum points.
      require(PointData::additional_columns<dim>().empty(),
              "Output/Additional columns",
              "the rbsn method's probe tables hold cell and facet values; additional point "
              "columns apply to the mpm and fem methods");
      if constexpr (dim == 2)
        model = std::make_unique<Model>(this->get_scene(), *this, prm);
      else
        {
          (void)prm;
          throw InputError("Dimension", "the rbsn method is two-dimensional (set Dimension = 2)");
        }
    }

    // The driver's hooks: the network is two-dimensional, so only Solver<2> has a
    // model (a 3D scene is refused when the parameters are read).
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
      return model ? 3.0 * model->tessellation().cells.size() : 0.0; // u, v, theta per cell
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
    Solver<dim>::save(CheckpointWriter &out) const
    {
      model->save(out);
    }

    template <int dim>
    void
    Solver<dim>::load(CheckpointReader &in)
    {
      model->load(in);
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
                         "brittle fracture; 2D; see doc/rbsn.md");

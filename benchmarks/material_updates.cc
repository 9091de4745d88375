// Benchmark: stress updates per second per core of the material models, with the error of each
// integrator against a converged reference on the same cyclic, non-proportional strain path.
//
//   benchmarks/material_updates [--repeats 5] [--points 1000] [--csv FILE]
//                               [--only "plane stress/adaptive/8"]  (one case, no reference)
//                               [--sweep FILE]  (error against cost, written to FILE)
//
// For every stress state (plane stress, plane strain, 3D), Bouc-Wen integrator (forward Euler,
// adaptive, backward Euler) and smoothness n in {2, 8, 32}, a batch of points follows the path
//   eps(t) = A [sin 2 pi t, -0.3 sin(2 pi t + 0.5), (0.7 sin 2 pi t), 0.2 sin 4 pi t, ...]
// (A = 5 eps_y, 2 cycles, `steps` increments per cycle) and the wall time of the update loop is
// measured (median of the repeats). The error is max_t |sigma - sigma_ref| / sigma_y, where the
// reference integrates the same piecewise-linear path with the adaptive integrator at tolerance
// 1e-12. Hooke's law is measured as the floor. Output: a Markdown table on stdout and a CSV.
//
// --sweep: error against cost at n = 8 for the smooth path itself, so that the increment size
// counts: forward and backward Euler at 150 ... 9600 increments per cycle, the adaptive
// integrator at tolerances 1e-2 ... 1e-8 and 150 ... 2400 increments per cycle. The error is
// max |sigma - sigma_ref| / sigma_y over the 300 states at t = k/150, against the adaptive
// integrator at tolerance 1e-12 with 150 * 1024 increments per cycle (the piecewise-linear
// path then differs from the sinusoids by O((2 pi / 153600)^2)); the cost is the wall time of
// the update loop per point and cycle (median of the repeats).
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include <hysteron/material/interface.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace
{
  using namespace dealii;

  constexpr double E       = 210e9;
  constexpr double sigma_y = 235e6;
  constexpr double eps_y   = sigma_y / E;

  struct Case
  {
    std::string state;      // "plane stress", "plane strain", "3D"
    std::string model;      // "linear elastic" or "bouc-wen"
    std::string integrator; // Bouc-Wen only
    double      n = 8;
  };

  template <int dim>
  std::unique_ptr<hysteron::Material::Interface<dim>>
  make_material(const Case &c, const double tolerance)
  {
    ParameterHandler prm;
    prm.enter_subsection("Material");
    hysteron::Material::declare_parameters(prm);
    prm.set("Model", c.model);
    if (dim == 2)
      prm.set("Stress state", c.state);
    prm.set("Young's modulus", "210e9");
    prm.set("Poisson's ratio", "0.3");
    prm.enter_subsection("Bouc-Wen");
    prm.set("Yield stress", "235e6");
    prm.set("Post-yield stiffness ratio", "0.02");
    prm.set("Smoothness n", std::to_string(c.n));
    prm.set("Isotropic hardening fraction", "0.5");
    if (!c.integrator.empty())
      prm.set("Integrator", c.integrator);
    std::ostringstream tol;
    tol << tolerance;
    prm.set("Tolerance", tol.str());
    prm.leave_subsection();
    prm.leave_subsection();
    return hysteron::Material::create<dim>(hysteron::Section(prm, {"Material"}));
  }

  /// The strain at pseudo-time t (cycles): non-proportional, every component active.
  template <int dim>
  SymmetricTensor<2, dim>
  strain_path(const double t)
  {
    const double            A = 5 * eps_y;
    SymmetricTensor<2, dim> e;
    e[0][0] = A * std::sin(2 * M_PI * t);
    e[1][1] = -0.3 * A * std::sin(2 * M_PI * t + 0.5);
    e[0][1] = 0.2 * A * std::sin(4 * M_PI * t);
    if (dim == 3)
      {
        e[2][2] = 0.1 * A * std::sin(2 * M_PI * t + 1.0);
        e[1][dim - 1] = 0.15 * A * std::cos(2 * M_PI * t);
        e[0][dim - 1] = -0.1 * A * std::sin(6 * M_PI * t);
      }
    return e;
  }

  struct Result
  {
    double updates_per_second = 0;
    double error              = 0;
  };

  /// Run the path on `points` identical points; return the stress history of point 0.
  template <int dim>
  std::vector<SymmetricTensor<2, dim>>
  run_path(const hysteron::Material::Interface<dim> &material,
           const unsigned int                        points,
           const unsigned int                        steps_per_cycle,
           double                                   &seconds)
  {
    const unsigned int                   n_state = material.n_state_variables();
    const unsigned int                   steps   = 2 * steps_per_cycle;
    std::vector<double>                  state(points * n_state);
    std::vector<SymmetricTensor<2, dim>> stress(points), increment(points);
    for (unsigned int p = 0; p < points; ++p)
      material.initialize_state(ArrayView<double>(state.data() + p * n_state, n_state));
    std::vector<SymmetricTensor<2, dim>> history;
    history.reserve(steps);

    Timer timer;
    double elapsed = 0;
    for (unsigned int s = 1; s <= steps; ++s)
      {
        const SymmetricTensor<2, dim> d =
          strain_path<dim>(double(s) / steps_per_cycle) -
          strain_path<dim>(double(s - 1) / steps_per_cycle);
        std::fill(increment.begin(), increment.end(), d);
        timer.restart();
        material.update(make_array_view(std::as_const(increment)),
                        make_array_view(stress),
                        make_array_view(state),
                        ArrayView<SymmetricTensor<4, dim>>());
        elapsed += timer.wall_time();
        history.push_back(stress[0]);
      }
    seconds = elapsed;
    return history;
  }

  /// The median wall time of @p repeats runs of the path; @p history: point 0's stresses.
  template <int dim>
  double
  median_time(const hysteron::Material::Interface<dim> &material,
              const unsigned int                        points,
              const unsigned int                        steps_per_cycle,
              const unsigned int                        repeats,
              std::vector<SymmetricTensor<2, dim>>     &history)
  {
    std::vector<double> times;
    for (unsigned int r = 0; r < repeats; ++r)
      {
        double seconds = 0;
        history        = run_path<dim>(material, points, steps_per_cycle, seconds);
        times.push_back(seconds);
      }
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
  }

  template <int dim>
  Result
  measure(const Case &c, const unsigned int points, const unsigned int steps_per_cycle,
          const unsigned int repeats)
  {
    std::vector<SymmetricTensor<2, dim>> history;
    const double seconds = median_time<dim>(*make_material<dim>(c, 1e-6), points, steps_per_cycle, repeats, history);
    Result       result;
    result.updates_per_second = double(points) * 2 * steps_per_cycle / seconds;

    if (c.model != "linear elastic")
      {
        Case reference_case       = c;
        reference_case.integrator = "adaptive";
        const auto reference      = make_material<dim>(reference_case, 1e-12);
        double     ignored        = 0;
        const auto ref            = run_path<dim>(*reference, 1, steps_per_cycle, ignored);
        for (unsigned int s = 0; s < ref.size(); ++s)
          result.error = std::max(result.error, (history[s] - ref[s]).norm() / sigma_y);
      }
    return result;
  }

  /// One row of the --sweep: the run's stress at t = k/150 against the reference's.
  template <int dim>
  void
  sweep_state(const std::string &state, const unsigned int points, const unsigned int repeats,
              hysteron::Output::CsvWriter &csv, const double dim_id, const double ps_id)
  {
    constexpr unsigned int coarsest = 150, refinement = 1024;
    Case                   c{state, "bouc-wen", "adaptive", 8};
    double                 ignored = 0;
    const auto             ref =
      run_path<dim>(*make_material<dim>(c, 1e-12), 1, coarsest * refinement, ignored);

    const auto run = [&](const std::string &integrator, const double tolerance,
                         const unsigned int steps_per_cycle) {
      c.integrator = integrator;
      std::vector<SymmetricTensor<2, dim>> history;
      const double                         seconds =
        median_time<dim>(*make_material<dim>(c, tolerance), points, steps_per_cycle, repeats, history);
      const unsigned int stride = steps_per_cycle / coarsest;
      double             error  = 0;
      for (unsigned int k = 1; k <= 2 * coarsest; ++k)
        error = std::max(error,
                         (history[k * stride - 1] - ref[k * refinement - 1]).norm() / sigma_y);
      const double integrator_id =
        integrator == "forward euler" ? 1 : (integrator == "adaptive" ? 2 : 3);
      csv.add_row({dim_id, ps_id, integrator_id, tolerance, double(steps_per_cycle),
                   seconds / points / 2, error});
      std::cout << state << ", " << integrator << ", tolerance " << tolerance << ", "
                << steps_per_cycle << " increments per cycle: error " << error << std::endl;
    };
    for (const std::string integrator : {"forward euler", "backward euler"})
      for (const unsigned int steps : {150u, 300u, 600u, 1200u, 2400u, 4800u, 9600u})
        run(integrator, 1e-6, steps);
    for (const double tolerance : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8})
      for (const unsigned int steps : {150u, 600u, 2400u})
        run("adaptive", tolerance, steps);
  }
} // namespace

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  unsigned int repeats = 5, points = 1000, steps_per_cycle = 600;
  std::string  csv_file = "material_updates.csv";
  std::string  only; // "state/integrator/n": time this case alone (profiling), no error
  std::string  sweep_file; // error against cost (see the header)
  for (int i = 1; i + 1 < argc; i += 2)
    {
      const std::string a = argv[i];
      if (a == "--repeats")
        repeats = std::atoi(argv[i + 1]);
      else if (a == "--points")
        points = std::atoi(argv[i + 1]);
      else if (a == "--steps")
        steps_per_cycle = std::atoi(argv[i + 1]);
      else if (a == "--csv")
        csv_file = argv[i + 1];
      else if (a == "--only")
        only = argv[i + 1];
      else if (a == "--sweep")
        sweep_file = argv[i + 1];
      else
        {
          std::cerr << "usage: material_updates [--repeats R] [--points P] [--steps S] [--csv F]"
                       " [--only 'state/integrator/n'] [--sweep F]\n";
          return 1;
        }
    }

  if (!only.empty())
    {
      const auto parts = Utilities::split_string_list(only, '/');
      if (parts.size() != 3)
        {
          std::cerr << "material_updates: --only needs 'state/integrator/n'\n";
          return 1;
        }
      const Case c{parts[0], "bouc-wen", parts[1], Utilities::string_to_double(parts[2])};
      double     seconds = 0;
      if (c.state == "3D")
        run_path<3>(*make_material<3>(c, 1e-6), points, steps_per_cycle, seconds);
      else
        run_path<2>(*make_material<2>(c, 1e-6), points, steps_per_cycle, seconds);
      std::cout << only << ": " << double(points) * 2 * steps_per_cycle / seconds / 1e6
                << " M updates/s" << std::endl;
      return 0;
    }

  if (!sweep_file.empty())
    {
      hysteron::Output::CsvWriter sweep(sweep_file,
                                        {"dim", "plane_stress", "integrator", "tolerance",
                                         "steps_per_cycle", "seconds_per_point_cycle", "error"});
      sweep_state<2>("plane stress", points, repeats, sweep, 2, 1);
      sweep_state<2>("plane strain", points, repeats, sweep, 2, 0);
      sweep_state<3>("3D", points, repeats, sweep, 3, 0);
      sweep.commit();
      return 0;
    }

  hysteron::Output::CsvWriter csv(csv_file,
                                  {"dim", "plane_stress", "n", "integrator", "updates_per_second",
                                   "error"});
  std::cout << "| stress state | model / integrator | n | M updates/s | max error / sigma_y |\n"
            << "|---|---|---|---|---|\n";
  const std::vector<std::string> integrators{"forward euler", "adaptive", "backward euler"};
  unsigned int                   integrator_id = 0;
  for (const std::string state : {"plane stress", "plane strain", "3D"})
    {
      std::vector<Case> cases{{state, "linear elastic", "", 0}};
      for (const double n : {2.0, 8.0, 32.0})
        for (const auto &integrator : integrators)
          cases.push_back({state, "bouc-wen", integrator, n});
      for (const auto &c : cases)
        {
          const Result r = state == "3D" ? measure<3>(c, points, steps_per_cycle, repeats) :
                                           measure<2>(c, points, steps_per_cycle, repeats);
          std::cout << "| " << state << " | "
                    << (c.integrator.empty() ? c.model : c.integrator) << " | "
                    << (c.integrator.empty() ? std::string("-") : std::to_string(int(c.n)))
                    << " | " << std::fixed << std::setprecision(2) << r.updates_per_second / 1e6
                    << " | " << std::scientific << std::setprecision(2) << r.error << " |"
                    << std::endl;
          integrator_id = c.integrator.empty() ?
                            0 :
                            1 + std::find(integrators.begin(), integrators.end(), c.integrator) -
                              integrators.begin();
          csv.add_row({state == "3D" ? 3.0 : 2.0,
                       state == "plane stress" ? 1.0 : 0.0,
                       c.n,
                       double(integrator_id),
                       r.updates_per_second,
                       r.error});
        }
    }
  csv.commit();
  return 0;
}

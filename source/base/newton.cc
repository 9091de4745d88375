#include <hysteron/base/newton.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hysteron
{
  void
  NewtonParameters::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii;
    prm.declare_entry("Tolerance",
                      "1e-8",
                      Patterns::Double(),
                      "Convergence when the residual norm is below this fraction of the force "
                      "level (the largest of the internal, external and inertia forces), > 0.");
    prm.declare_entry("Maximum iterations",
                      "25",
                      Patterns::Integer(1),
                      "Newton iterations per increment before the increment is cut.");
    prm.declare_entry("Line search",
                      "true",
                      Patterns::Bool(),
                      "Backtracking line search on the residual norm (halving, up to 6 times) "
                      "when a full Newton step does not reduce it.");
    prm.declare_entry("Maximum increment cuts",
                      "8",
                      Patterns::Integer(0, 30),
                      "How often a failing increment may be halved before the run stops with an "
                      "error (the last good state is written).");
  }



  void
  NewtonParameters::parse_parameters(const Section &s)
  {
    tolerance      = s.get_positive("Tolerance");
    max_iterations = s.get_integer("Maximum iterations");
    line_search    = s.get_bool("Line search");
    max_cuts       = s.get_integer("Maximum increment cuts");
  }



  unsigned int
  newton_iterate(NewtonProblem &problem, const NewtonParameters &parameters, const double relative_floor)
  {
    const double tolerance = std::max(parameters.tolerance, relative_floor);
    double       residual  = problem.residual();
    for (unsigned int iteration = 1; iteration <= parameters.max_iterations; ++iteration)
      {
        if (!std::isfinite(residual))
          return 0;
        if (residual <= tolerance * problem.force_level())
          return iteration;
        problem.solve_correction();
        problem.remember_start();
        // Below 1e-10 of the force level the residual is round-off: full steps only.
        const bool   noise = residual <= 1e-10 * problem.force_level();
        double       alpha = 1.0, trial = 0;
        bool         ok    = true;
        for (unsigned int k = 0; k <= (parameters.line_search && !noise ? 6u : 0u); ++k)
          {
            problem.move(alpha);
            ok    = problem.evaluate(k == 0);
            trial = ok ? problem.residual() : std::numeric_limits<double>::infinity();
            if ((ok && trial <= (1 - 1e-4 * alpha) * residual) || !parameters.line_search || noise)
              break;
            alpha *= 0.5;
          }
        if (!ok)
          return 0;
        if (alpha < 1.0)
          {
            // The accepted iterate (the last tried, possibly not a descent) with its matrix.
            if (!problem.evaluate(true))
              return 0;
            trial = problem.residual();
          }
        // Converged to round-off: no progress any more below 1e-10 of the force level.
        const bool stagnated = trial > 0.5 * residual && trial <= 1e-10 * problem.force_level();
        residual             = trial;
        problem.log(iteration, residual, alpha);
        if (stagnated && std::isfinite(residual))
          return iteration;
      }
    return residual <= tolerance * problem.force_level() ? parameters.max_iterations : 0;
  }
} // namespace hysteron

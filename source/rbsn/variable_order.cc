#include <hysteron/base/parameters.h>
#include "rbsn/variable_order.h"
#include <hysteron/run/stepping_method.h>

#include <algorithm>
#include <cmath>
#include <sstream>

// Analysis = variable order: its parameters, and IDA's run over the output times. The DAE
// is in rbsn/variable_order.h and variable_order_dae.cc.

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::declare_variable_order_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Variable order");
      {
        prm.declare_entry("Relative tolerance",
                          "1e-6",
                          Patterns::Double(),
                          "IDA's relative tolerance of the local error, in (0, 1).");
        prm.declare_entry("Absolute tolerance",
                          "0",
                          Patterns::Double(),
                          "IDA's absolute tolerance [m] on the displacements, >= 0; 0: the relative "
                          "tolerance times 1e-3 of the network's size. Rotations and the rotational "
                          "springs' z get it divided by the network's size, velocities divided by "
                          "the output interval (Time step), eta the relative tolerance, e_h it times "
                          "the spring's yield force, the work quadratures 1e-2 k_n atol^2 / rtol (k_n: the "
                          "stiffest normal spring).");
        prm.declare_entry("Maximum order", "5", Patterns::Integer(), "Of the BDF, 1..5.");
        prm.declare_entry("Maximum step", "0", Patterns::Double(), "[s], >= 0; 0: unlimited.");
        prm.declare_entry("Initial step", "0", Patterns::Double(), "[s], >= 0; 0: IDA's estimate.");
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Model<dim>::parse_variable_order_parameters(dealii::ParameterHandler &prm)
    {
      Section s(prm, {"RBSN", "Variable order"});
      auto   &p            = variable_order;
      p.relative_tolerance = s.get_in_open_interval("Relative tolerance", 0, 1);
      p.absolute_tolerance = s.get_non_negative("Absolute tolerance");
      const long order     = s.get_integer("Maximum order");
      require(order >= 1 && order <= 5, s.where("Maximum order"),
              "must be 1, 2, 3, 4 or 5 (got " + s.get("Maximum order") + ")");
      p.maximum_order = order;
      p.maximum_step  = s.get_non_negative("Maximum step");
      p.initial_step  = s.get_non_negative("Initial step");
      require(p.maximum_step == 0 || p.initial_step <= p.maximum_step, s.where("Initial step"),
              "must not exceed the Maximum step (got " + s.get("Initial step") + " > " +
                s.get("Maximum step") + ")");
      if (analysis == Analysis::variable_order)
        require(!fracture.enabled, "RBSN/Fracture/Enabled",
                "the variable-order analysis has no fracture (a break is a discontinuity of the "
                "DAE that IDA integrates): use Analysis = implicit dynamics, or switch fracture off");
      if (analysis == Analysis::variable_order)
        {
          const std::string why = spring_law->variable_order_unsupported();
          require(why.empty(), "RBSN/Spring law", why);
        }
    }



    template <int dim>
    double
    Model<dim>::integrate_variable_order(const double output_interval)
    {
      const auto  &p        = variable_order;
      const double end_time = scene().time_control().end_time;
      VariableOrder dae(*this);
      dealii::Vector<double> y, yp;
      dae.initial_values(y, yp);

      IdaIntegrator::Settings settings;
      settings.relative_tolerance  = p.relative_tolerance;
      settings.absolute_tolerances = dae.tolerances;
      settings.differential        = dae.differential_components();
      // The prescribed velocities (algebraic) stay out of the error test.
      settings.suppress_algebraic_errors = true;
      settings.initial_step              = p.initial_step;
      settings.maximum_step              = p.maximum_step;
      settings.stop_time                 = end_time;
      settings.maximum_order             = p.maximum_order;
      settings.maximum_newton_iterations = 10; // IDA's default is 4
      settings.maximum_steps             = 1000000;
      IdaIntegrator ida(settings, 0, dealii::make_array_view(y), dealii::make_array_view(yp));
      ida.residual = [&](const double t, const auto values, const auto rates, const auto F) {
        return dae.residual(t, values, rates, F);
      };
      ida.setup_jacobian = [&](const double, const auto values, const auto, const double cj) {
        return dae.setup_jacobian(values, cj);
      };
      ida.solve_jacobian = [&](const auto rhs, const auto x) { return dae.solve(rhs, x); };

      // The output times are sums of output intervals, which accumulate round-off: the
      // tables get the nominal time k output_interval, and a last interval of round-off
      // length is not written again. t = 0 is written by run().
      const double eps = 1e-12 * end_time;
      double       t = 0, t_out = 0, last_good = 0;
      for (unsigned int k = 1; t < end_time; ++k)
        {
          t_out += output_interval;
          const bool   reached  = ida.advance(t_out, t);
          const double expected = std::min(k * output_interval, end_time);
          const auto   stats    = ida.statistics();
          n_ida_steps           = stats.steps;
          n_newton              = stats.newton_iterations;
          if (!reached || std::abs(t - expected) > eps)
            {
              std::ostringstream s;
              s << "rbsn: IDA did not reach t = " << expected << " s (it stopped at t = " << stats.time
                << " s with the step " << stats.step << " s after " << stats.steps << " steps, "
                << stats.error_test_failures << " error test and " << stats.convergence_failures
                << " convergence failures): a stiff or non-smooth response beyond the tolerances, an "
                << "unsupported network, or too many steps (1e6 per output interval).";
              if (!ida.error().empty())
                s << " IDA: " << ida.error();
              throw Run::StepFailure(s.str());
            }
          if (expected - last_good < eps)
            continue;
          dae.to_model(expected, y, yp);
          last_good = expected;
          if (newton_table)
            newton_table->add_row({expected, double(stats.steps), double(stats.order), stats.step,
                                   double(stats.residuals), double(stats.jacobians),
                                   double(stats.newton_iterations), double(stats.error_test_failures),
                                   double(stats.convergence_failures)});
          this->step_finished(expected);
        }
      return end_time;
    }

    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

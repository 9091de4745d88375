#ifndef hysteron_source_base_ida_integrator_h
#define hysteron_source_base_ida_integrator_h

#include <deal.II/base/array_view.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * SUNDIALS IDA (variable-order, variable-step BDF with local error control) for an
   * implicit DAE F(t, y, y') = 0 on one process, through SUNDIALS' C API.
   *
   * deal.II 9.4's SUNDIALS::IDA keeps IDA's memory private, so it offers neither the
   * integrator's statistics nor a maximum step; this class is the small part of it that
   * hysteron needs, plus those. The vectors are nvector_serial views of the caller's
   * arrays (IDA's own work vectors are nvector_serial too, seen by the callbacks as
   * ArrayViews). Newton's matrix dF/dy + c_j dF/dy' is the caller's: a matrix-based direct
   * SUNLinearSolver calls setup_jacobian() when IDA decides to refresh it (Jacobian
   * evaluation and factorisation at once) and solve_jacobian() for each Newton
   * correction. The library is IDAS (IDA with sensitivities, the same integrator), which
   * deal.II links already: IDA's and IDAS' libraries export the same function names, and
   * one process must not load both.
   *
   * The callbacks return 0 on success, > 0 for a recoverable failure (IDA retries with a
   * smaller step) and < 0 for an unrecoverable one.
   */
  class IdaIntegrator
  {
  public:
    using ConstView = dealii::ArrayView<const double>;
    using View      = dealii::ArrayView<double>;

    struct Settings
    {
      double              relative_tolerance = 1e-6;
      std::vector<double> absolute_tolerances; ///< per component
      /// Per component: 1 differential (y' appears in F), 0 algebraic.
      std::vector<double> differential;
      /// Keep the algebraic components out of the local error test.
      bool   suppress_algebraic_errors = false;
      double initial_step              = 0; ///< 0: IDA's estimate
      double maximum_step              = 0; ///< 0: unlimited
      double stop_time                 = 0; ///< IDA never steps past it
      int    maximum_order             = 5;
      int    maximum_newton_iterations = 4;   ///< per step
      long   maximum_steps             = 500; ///< per call of advance()
    };

    /// IDA's counters since the start and its last step.
    struct Statistics
    {
      long   steps = 0, residuals = 0, jacobians = 0, newton_iterations = 0;
      long   error_test_failures = 0, convergence_failures = 0;
      int    order = 0; ///< of the last step
      double step  = 0; ///< the last step's size
      double time  = 0; ///< the time IDA has reached (its last step's end)
    };

    /// F(t, y, y').
    std::function<int(double t, ConstView y, ConstView yp, View F)> residual;
    /// Assemble and factorise Newton's matrix dF/dy + c_j dF/dy' at (t, y, y').
    std::function<int(double t, ConstView y, ConstView yp, double c_j)> setup_jacobian;
    /// x = the last factorised matrix's inverse times rhs.
    std::function<int(ConstView rhs, View x)> solve_jacobian;

    /// IDA at t0 with y(t0) and y'(t0), which must be consistent (IDA does not correct
    /// them). y and yp stay the caller's: advance() writes the solution into them.
    IdaIntegrator(const Settings &settings, double t0, View y, View yp);
    ~IdaIntegrator();

    /// Integrate to t_out (IDA steps past it unless it is the stop time, and interpolates
    /// y and y' there); t: the time of y and y'. False if IDA failed (see error()).
    bool
    advance(double t_out, double &t);

    Statistics
    statistics() const;

    /// IDA's last error message ("function: message"), empty if none.
    const std::string &
    error() const;

  private:
    struct Data;
    std::unique_ptr<Data> data;
  };
} // namespace hysteron

#endif

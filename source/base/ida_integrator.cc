#include "base/ida_integrator.h"

#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <stdexcept>

namespace hysteron
{
  struct IdaIntegrator::Data
  {
    SUNContext      context = nullptr;
    void           *memory  = nullptr;
    N_Vector        y = nullptr, yp = nullptr, tolerances = nullptr, id = nullptr;
    SUNMatrix       matrix = nullptr; ///< empty: the caller holds the Newton matrix
    SUNLinearSolver solver = nullptr;
    std::string     error;

    ~Data()
    {
      // IDAFree leaves the linear solver, the matrix and the vectors to us.
      if (memory)
        IDAFree(&memory);
      if (solver)
        SUNLinSolFreeEmpty(solver);
      if (matrix)
        SUNMatFreeEmpty(matrix);
      for (N_Vector v : {y, yp, tolerances, id})
        if (v)
          N_VDestroy(v);
      if (context)
        SUNContext_Free(&context);
    }

    /// Stop with IDA's message if a set-up call failed (a programming error).
    void
    check(const int status, const char *call) const
    {
      if (status < 0)
        throw std::logic_error(std::string("IdaIntegrator: ") + call + " failed (" +
                               std::to_string(status) + ")" + (error.empty() ? "" : ": " + error));
    }
  };



  namespace
  {
    IdaIntegrator::ConstView
    const_view(N_Vector v)
    {
      return {NV_DATA_S(v), static_cast<std::size_t>(NV_LENGTH_S(v))};
    }

    IdaIntegrator::View
    view(N_Vector v)
    {
      return {NV_DATA_S(v), static_cast<std::size_t>(NV_LENGTH_S(v))};
    }

    IdaIntegrator &
    owner(void *user_data)
    {
      return *static_cast<IdaIntegrator *>(user_data);
    }

    int
    residual_function(realtype t, N_Vector y, N_Vector yp, N_Vector F, void *user_data)
    {
      return owner(user_data).residual(t, const_view(y), const_view(yp), view(F));
    }

    int
    jacobian_function(realtype t, realtype c_j, N_Vector y, N_Vector yp, N_Vector, SUNMatrix,
                      void *user_data, N_Vector, N_Vector, N_Vector)
    {
      return owner(user_data).setup_jacobian(t, const_view(y), const_view(yp), c_j);
    }

    int
    solve_function(SUNLinearSolver solver, SUNMatrix, N_Vector x, N_Vector b, realtype)
    {
      return owner(solver->content).solve_jacobian(const_view(b), view(x));
    }
  } // namespace



  IdaIntegrator::IdaIntegrator(const Settings &settings, const double t0, const View y, const View yp)
    : data(std::make_unique<Data>())
  {
    Data &d = *data;
    const auto n = static_cast<sunindextype>(y.size());
    if (yp.size() != y.size() || settings.absolute_tolerances.size() != y.size() ||
        settings.differential.size() != y.size())
      throw std::logic_error("IdaIntegrator: vectors of different sizes");
    d.check(SUNContext_Create(nullptr, &d.context), "SUNContext_Create");
    d.memory = IDACreate(d.context);
    if (d.memory == nullptr)
      throw std::runtime_error("IdaIntegrator: IDACreate failed");
    d.check(IDASetErrHandlerFn(
              d.memory,
              [](int code, const char *, const char *function, char *message, void *error) {
                // Errors are kept for the caller; warnings are not reported.
                if (code < 0)
                  *static_cast<std::string *>(error) = std::string(function) + ": " + message;
              },
              &d.error),
            "IDASetErrHandlerFn");

    d.y          = N_VMake_Serial(n, y.data(), d.context);
    d.yp         = N_VMake_Serial(n, yp.data(), d.context);
    d.tolerances = N_VNew_Serial(n, d.context);
    d.id         = N_VNew_Serial(n, d.context);
    for (sunindextype i = 0; i < n; ++i)
      {
        NV_Ith_S(d.tolerances, i) = settings.absolute_tolerances[i];
        NV_Ith_S(d.id, i)         = settings.differential[i];
      }
    d.check(IDAInit(d.memory, residual_function, t0, d.y, d.yp), "IDAInit");
    d.check(IDASVtolerances(d.memory, settings.relative_tolerance, d.tolerances), "IDASVtolerances");
    d.check(IDASetUserData(d.memory, this), "IDASetUserData");
    d.check(IDASetId(d.memory, d.id), "IDASetId");
    d.check(IDASetSuppressAlg(d.memory, settings.suppress_algebraic_errors), "IDASetSuppressAlg");
    d.check(IDASetInitStep(d.memory, settings.initial_step), "IDASetInitStep");
    d.check(IDASetMaxStep(d.memory, settings.maximum_step), "IDASetMaxStep");
    d.check(IDASetStopTime(d.memory, settings.stop_time), "IDASetStopTime");
    d.check(IDASetMaxOrd(d.memory, settings.maximum_order), "IDASetMaxOrd");
    d.check(IDASetMaxNonlinIters(d.memory, settings.maximum_newton_iterations), "IDASetMaxNonlinIters");
    d.check(IDASetMaxNumSteps(d.memory, settings.maximum_steps), "IDASetMaxNumSteps");

    // A direct solver on a matrix IDA does not see: IDA calls the Jacobian function to
    // refresh it (after "zeroing" it, which is the caller's business) and the solve for
    // each Newton correction, which it scales by 2 / (1 + c_j / c_j,old) when c_j has
    // changed since the factorisation.
    d.matrix                = SUNMatNewEmpty(d.context);
    d.matrix->ops->getid    = [](SUNMatrix) { return SUNMATRIX_CUSTOM; };
    d.matrix->ops->zero     = [](SUNMatrix) { return 0; };
    d.solver                = SUNLinSolNewEmpty(d.context);
    d.solver->content       = this;
    d.solver->ops->gettype  = [](SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; };
    d.solver->ops->solve    = solve_function;
    d.check(IDASetLinearSolver(d.memory, d.solver, d.matrix), "IDASetLinearSolver");
    d.check(IDASetJacFn(d.memory, jacobian_function), "IDASetJacFn");
  }



  IdaIntegrator::~IdaIntegrator() = default;



  bool
  IdaIntegrator::advance(const double t_out, double &t)
  {
    return IDASolve(data->memory, t_out, &t, data->y, data->yp, IDA_NORMAL) >= 0;
  }



  IdaIntegrator::Statistics
  IdaIntegrator::statistics() const
  {
    void      *m = data->memory;
    Statistics s;
    IDAGetNumSteps(m, &s.steps);
    IDAGetNumResEvals(m, &s.residuals);
    IDAGetNumLinSolvSetups(m, &s.jacobians);
    IDAGetNumNonlinSolvIters(m, &s.newton_iterations);
    IDAGetNumErrTestFails(m, &s.error_test_failures);
    IDAGetNumNonlinSolvConvFails(m, &s.convergence_failures);
    IDAGetLastOrder(m, &s.order);
    IDAGetLastStep(m, &s.step);
    IDAGetCurrentTime(m, &s.time);
    return s;
  }



  const std::string &
  IdaIntegrator::error() const
  {
    return data->error;
  }
} // namespace hysteron

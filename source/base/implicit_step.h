// One increment of an implicit method (FEM, RBSN): predictor, Newton's iterations, constraints, failure message.
#ifndef hysteron_source_base_implicit_step_h
#define hysteron_source_base_implicit_step_h

#include <deal.II/base/index_set.h>
#include <deal.II/lac/affine_constraints.h>

#include <hysteron/base/newton.h>

#include <functional>
#include <string>
#include <vector>

namespace hysteron
{
  /**
   * The increment control of an implicit method: nominal increments @p nominal, halved at
   * most @p max_cuts times when Newton fails, and with @p load_steps the nominal
   * increments of the scene's load steps (@p time a TimeControl: `Time/Steps`, each
   * step's length over its number of increments) instead.
   */
  template <typename Time>
  IncrementControl
  increment_control(const double nominal, const unsigned int max_cuts, const Time &time, const bool load_steps)
  {
    IncrementControl increments(nominal, max_cuts);
    if (load_steps && !time.steps.empty())
      {
        std::vector<double> ends, nominals;
        time.step_grid(ends, nominals);
        increments.set_steps(ends, nominals);
      }
    return increments;
  }

  /**
   * What one increment from the converged state u to t1 asks of an implicit method whose
   * unknowns are one vector (the FEM's and the RBSN's displacements): the residual r, the
   * tangent K and the linear solver are the method's.
   */
  template <typename VectorType>
  struct ImplicitIncrement
  {
    /// Newton's callbacks at the iterate u_trial (base/newton.h); the correction callback
    /// also solves the predictor.
    typename VectorNewtonProblem<VectorType>::Callbacks newton;
    /// The constraints of the step: with @p predictor the prescribed increments g of the
    /// step as inhomogeneities, else homogeneous ones (Newton's corrections).
    std::function<void(bool predictor)> constrain;
    /// r and K at the converged state (u_trial = u), with the predictor's constraints.
    std::function<bool()> evaluate_predictor;
    /// The round-off floor of the relative residual at the predicted iterate (base/newton.h).
    std::function<double()> floor;
  };

  /**
   * The increment: the predictor solves K du = -r(u) with du = g on the prescribed DoFs
   * (the tangent of the converged state spreads the motion of the boundary over the
   * body), then Newton iterates from u_trial = u + du with homogeneous constraints. @p du
   * is a zero vector of the layout of u. The predictor's residual ||r(u)||, the force
   * level of a step that moves the body without loading it (a rigid motion), goes to
   * @p predictor_level; Newton's iterations are added to @p n_iterations (Maximum
   * iterations when they did not converge). Returns whether the increment converged.
   */
  template <typename VectorType>
  bool
  implicit_increment(const VectorType                    &u,
                     VectorType                          &u_trial,
                     VectorType                           du,
                     const ImplicitIncrement<VectorType> &step,
                     const NewtonParameters              &parameters,
                     double                              &predictor_level,
                     unsigned long                       &n_iterations)
  {
    step.constrain(true);
    u_trial = u;
    if (!step.evaluate_predictor())
      return false;
    predictor_level = step.newton.residual();
    VectorType correction(du);
    step.newton.solve_correction(du);
    step.constrain(false);
    u_trial = u;
    u_trial += du;
    if (!step.newton.evaluate(true))
      return false;
    step.newton.log(0, step.newton.residual(), 1.0);
    VectorNewtonProblem<VectorType> problem(u_trial, correction, step.newton);
    const unsigned int iterations = newton_iterate(problem, parameters, step.floor());
    n_iterations += iterations > 0 ? iterations : parameters.max_iterations;
    return iterations > 0;
  }

  /**
   * The constraints of a step into @p constraints (on @p relevant_dofs): u_i = g_i on the
   * @p prescribed DoFs, with the increment g_k = @p increment(k) of the k-th in the
   * predictor and 0 without @p increment (Newton's corrections); then the DoFs @p held
   * that are not prescribed keep their values.
   */
  void
  constrain_prescribed(dealii::AffineConstraints<double>                  &constraints,
                       const dealii::IndexSet                             &relevant_dofs,
                       const std::vector<dealii::types::global_dof_index> &prescribed,
                       const std::function<double(unsigned int)>          &increment,
                       const std::vector<dealii::types::global_dof_index> &held = {});

  /// "the last residual was r of the force level (tolerance tol)": a cause for
  /// increment_failure().
  std::string
  residual_cause(const double relative_residual, const double tolerance);

  /**
   * The message of an increment from @p t of length @p dt that failed after the last cut
   * @p increments allow, for @p method ("fem", "rbsn"), with the @p causes the method
   * knows (each a clause).
   */
  std::string
  increment_failure(const std::string &method, const double t, const double dt, const IncrementControl &increments,
                    const std::vector<std::string> &causes);
} // namespace hysteron

#endif

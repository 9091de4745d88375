#ifndef hysteron_base_newton_h
#define hysteron_base_newton_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/parameters.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace hysteron
{
  /// `subsection Newton` of an implicit method (FEM, RBSN).
  struct NewtonParameters
  {
    double       tolerance      = 1e-8;
    unsigned int max_iterations = 25;
    bool         line_search    = true;
    unsigned int max_cuts       = 8;

    /// Declare the entries in the current subsection.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(const Section &section);
  };

  /**
   * What Newton's method needs from a discretisation: the current iterate
   * u_k, its residual r(u_k) on the free DoFs (with the tangent when asked) and
   * the solution of the linearised system for the correction du.
   */
  class NewtonProblem
  {
  public:
    virtual ~NewtonProblem() = default;

    /// Evaluate at the current iterate (residual, and the matrix if @p matrix);
    /// false if it failed (a material, a non-finite value).
    virtual bool
    evaluate(const bool matrix) = 0;

    /// The norm of the residual of the last evaluation.
    virtual double
    residual() const = 0;

    /// The force level the residual is measured against (> 0 once anything is loaded).
    virtual double
    force_level() const = 0;

    /// du from the matrix and residual of the last evaluation with a matrix.
    virtual void
    solve_correction() = 0;

    /// u_k = u_start + alpha du (u_start: the iterate when du was computed).
    virtual void
    move(const double alpha) = 0;

    /// Remember the current iterate as u_start.
    virtual void
    remember_start() = 0;

    /// A row of the iteration log.
    virtual void
    log(const unsigned int iteration, const double residual, const double alpha) = 0;
  };

  /**
   * The NewtonProblem of a method whose iterate is one vector u (the FEM's and the
   * RBSN's displacements): the line search moves u = u_start + alpha du; the
   * method supplies the evaluation, the correction and the log as callbacks
   * (called once per iteration, not per DoF).
   */
  template <typename VectorType>
  class VectorNewtonProblem : public NewtonProblem
  {
  public:
    struct Callbacks
    {
      std::function<bool(bool)>                                 evaluate;
      std::function<double()>                                   residual;
      std::function<double()>                                   force_level;
      /// Solve for @p du (with the constraints of the correction applied).
      std::function<void(VectorType &du)>                       solve_correction;
      std::function<void(unsigned int, double, double)>         log;
    };

    /// @p u: the iterate, @p du: where the correction is kept.
    VectorNewtonProblem(VectorType &u, VectorType &du, Callbacks callbacks)
      : u(u)
      , du(du)
      , start(u)
      , callbacks(std::move(callbacks))
    {}

    bool
    evaluate(const bool matrix) override
    {
      return callbacks.evaluate(matrix);
    }

    double
    residual() const override
    {
      return callbacks.residual();
    }

    double
    force_level() const override
    {
      return callbacks.force_level();
    }

    void
    solve_correction() override
    {
      callbacks.solve_correction(du);
    }

    void
    remember_start() override
    {
      start = u;
    }

    void
    move(const double alpha) override
    {
      u = start;
      u.add(alpha, du);
    }

    void
    log(const unsigned int iteration, const double residual, const double alpha) override
    {
      callbacks.log(iteration, residual, alpha);
    }

  private:
    VectorType &u, &du;
    VectorType  start;
    Callbacks   callbacks;
  };

  /// The round-off floor 64 eps sqrt(N) of a residual of @p n_dofs entries, relative to
  /// the force level (a tighter tolerance would iterate on noise).
  inline double
  residual_floor(const double n_dofs)
  {
    return 64 * std::numeric_limits<double>::epsilon() * std::sqrt(n_dofs);
  }

  /**
   * The round-off floor of a residual r = K u - f that stems from the iterate u itself,
   * relative to @p force_level: |fl(r_i) - r_i| <= eps sum_j |K_ij| |u_j| <= eps |K| |u|
   * (row-sum norm, max norm), whatever the forces themselves. It matters when large terms
   * cancel: a free flight (u a rigid motion, no strain, no acceleration: the inertia
   * M (u - u_n - dt v_n) / (beta dt^2) of K_eff = K + M / (beta dt^2) and the internal
   * forces are differences of large numbers), where the external force level is zero.
   * With the factor 64 sqrt(N) of residual_floor(); 0 without a force level.
   */
  inline double
  iterate_floor(const double n_dofs, const double matrix_norm, const double u_norm, const double force_level)
  {
    return force_level > 0 ? residual_floor(n_dofs) * matrix_norm * u_norm / force_level : 0.0;
  }

  /// The columns of newton.csv (FEM and RBSN).
  inline std::vector<std::string>
  newton_columns()
  {
    return {"time", "step", "iteration", "residual", "force_level", "relative_residual", "line_search"};
  }

  /// A row of newton.csv: the iteration of the step of length @p dt to @p t1.
  inline std::vector<double>
  newton_row(const double       t1,
             const double       dt,
             const unsigned int iteration,
             const double       residual,
             const double       force_level,
             const double       alpha)
  {
    return {t1, dt, double(iteration), residual, force_level,
            force_level > 0 ? residual / force_level : 0.0, alpha};
  }

  /**
   * Newton iterations from an evaluated iterate (with its matrix): converged
   * when the residual is at most max(Tolerance, @p relative_floor) times the
   * force level (the floor: the round-off level of the residual, e.g.
   * 64 eps sqrt(N) for N DoFs); each correction is backtracked
   * (halving, up to 6 times) while it does not reduce the residual by the
   * Armijo factor; below 1e-10 of the force level the residual is round-off, so
   * full steps are taken and a residual that stops falling counts as
   * converged. Returns the iterations needed (>= 1), or 0 if the iteration did
   * not converge or an evaluation failed.
   */
  unsigned int
  newton_iterate(NewtonProblem          &problem,
                 const NewtonParameters &parameters,
                 const double            relative_floor);

  /**
   * The increments of an implicit run: the nominal step, halved after each
   * failed increment (at most `Maximum increment cuts` times in a row), doubled
   * back after two good ones. Times that land on the nominal grid are snapped
   * to it (no drift of the sum of the steps). With a sequence of load steps
   * (`Time/Steps`), each step has its own nominal increment and grid, and no
   * increment crosses the end of a step.
   */
  class IncrementControl
  {
  public:
    IncrementControl(const double nominal, const unsigned int max_cuts)
      : nominal_step(nominal)
      , max_cuts(max_cuts)
    {}

    /// Load steps: step k ends at @p ends[k] (increasing) with the nominal increment
    /// @p nominals[k]; after the last, the last nominal increment.
    void
    set_steps(const std::vector<double> &ends, const std::vector<double> &nominals)
    {
      step_ends     = ends;
      step_nominals = nominals;
      if (!nominals.empty())
        nominal_step = nominals.front();
    }

    /// The step from @p t, not beyond @p end (nor beyond the end of the load step of @p t).
    double
    step(const double t, const double end) const
    {
      const unsigned int k = load_step(t);
      if (k == step_ends.size())
        return std::min(nominal_step / std::pow(2.0, level), end - t);
      return std::min(step_nominals[k] / std::pow(2.0, level), std::min(end, step_ends[k]) - t);
    }

    /// After a failed increment: halve; false when the cuts are used up.
    bool
    cut()
    {
      ++n_cuts;
      successes = 0;
      return ++level <= max_cuts;
    }

    /// After a converged increment of length @p dt: advance @p t.
    void
    accept(double &t, const double dt)
    {
      const unsigned int s = load_step(t);
      t += dt;
      if (s < step_ends.size())
        {
          // The grid of load step s starts at the end of the previous one.
          const double start = s > 0 ? step_ends[s - 1] : 0.0, h = step_nominals[s];
          if (const double k = std::round((t - start) / h); std::abs(t - (start + k * h)) < 1e-9 * h)
            t = start + k * h;
          if (std::abs(t - step_ends[s]) < 1e-9 * h)
            t = step_ends[s];
        }
      else if (const double k = std::round(t / nominal_step); std::abs(t - k * nominal_step) < 1e-9 * nominal_step)
        t = k * nominal_step;
      if (level > 0 && ++successes >= 2)
        {
          --level;
          successes = 0;
        }
    }

    double
    nominal() const
    {
      return nominal_step;
    }

    unsigned int
    cuts() const
    {
      return n_cuts;
    }

    /// `Maximum increment cuts`.
    unsigned int
    cut_limit() const
    {
      return max_cuts;
    }

    /// The state between increments (nominal step, level, successes, cuts), for a checkpoint.
    std::array<double, 4>
    state() const
    {
      return {{nominal_step, double(level), double(successes), double(n_cuts)}};
    }

    void
    restore(const std::array<double, 4> &s)
    {
      nominal_step = s[0];
      level        = static_cast<unsigned int>(s[1]);
      successes    = static_cast<unsigned int>(s[2]);
      n_cuts       = static_cast<unsigned int>(s[3]);
    }

  private:
    /// The load step that holds @p t (the first whose end is after it); size() if none.
    unsigned int
    load_step(const double t) const
    {
      unsigned int k = 0;
      while (k < step_ends.size() && !(t < step_ends[k] - 1e-9 * step_nominals[k]))
        ++k;
      return k;
    }

    double              nominal_step;
    unsigned int        max_cuts;
    unsigned int        level = 0, successes = 0, n_cuts = 0;
    std::vector<double> step_ends, step_nominals;
  };
} // namespace hysteron

#endif

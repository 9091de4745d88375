// The constraints and the failure message of an implicit increment (FEM, RBSN).
#include "implicit_step.h"

#include <sstream>

namespace hysteron
{
  void
  constrain_prescribed(dealii::AffineConstraints<double>                  &constraints,
                       const dealii::IndexSet                             &relevant_dofs,
                       const std::vector<dealii::types::global_dof_index> &prescribed,
                       const std::function<double(unsigned int)>          &increment,
                       const std::vector<dealii::types::global_dof_index> &held)
  {
    constraints.clear();
    constraints.reinit(relevant_dofs);
    for (unsigned int k = 0; k < prescribed.size(); ++k)
      {
        constraints.add_line(prescribed[k]);
        if (increment)
          constraints.set_inhomogeneity(prescribed[k], increment(k));
      }
    for (const auto dof : held)
      if (!constraints.is_constrained(dof))
        constraints.add_line(dof);
    constraints.close();
  }



  std::string
  residual_cause(const double relative_residual, const double tolerance)
  {
    std::ostringstream m;
    m << "the last residual was " << relative_residual << " of the force level (tolerance " << tolerance << ")";
    return m.str();
  }



  std::string
  increment_failure(const std::string              &method,
                    const double                    t,
                    const double                    dt,
                    const IncrementControl         &increments,
                    const std::vector<std::string> &causes)
  {
    const unsigned int max_cuts = increments.cut_limit();
    std::ostringstream m;
    m << method << ": Newton did not converge in the increment from t = " << t << " s to " << t + dt
      << " s (increment " << dt << " s = " << increments.nominal() << " s / 2^" << max_cuts << ") after " << max_cuts
      << " cuts: the structure may have reached its limit load (use displacement control), or the "
         "increments or the tangent are poor (newton.csv has the residuals)";
    for (const auto &cause : causes)
      m << "; " << cause;
    m << ".";
    return m.str();
  }
} // namespace hysteron

// The MPM step kernels for the cubic basis (one translation unit per basis).
#include "mpm/step.h"

namespace hysteron
{
  namespace MPM
  {
    template std::unique_ptr<StepPhases<2>> make_step_phases<2, CubicBSpline1D, false>(Solver<2> &);
    template std::unique_ptr<StepPhases<3>> make_step_phases<3, CubicBSpline1D, false>(Solver<3> &);
  } // namespace MPM
} // namespace hysteron

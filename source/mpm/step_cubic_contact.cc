// The MPM step kernels for the cubic basis with contact (MPM/Contact; one translation unit
// per basis and contact mode).
#include "mpm/step.h"

namespace hysteron
{
  namespace MPM
  {
    template std::unique_ptr<StepPhases<2>> make_step_phases<2, CubicBSpline1D, true>(Solver<2> &);
    template std::unique_ptr<StepPhases<3>> make_step_phases<3, CubicBSpline1D, true>(Solver<3> &);
  } // namespace MPM
} // namespace hysteron

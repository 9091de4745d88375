// The MPM step kernels for the cubic basis (one translation unit per basis).
#include "mpm/step.h"

namespace hysteron
{
  namespace MPM
  {
    template void Solver<2>::step<CubicBSpline1D>(double, double);
    template void Solver<3>::step<CubicBSpline1D>(double, double);
  } // namespace MPM
} // namespace hysteron

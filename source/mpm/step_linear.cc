// The MPM step kernels for the linear basis (one translation unit per basis).
#include "mpm/step.h"

namespace hysteron
{
  namespace MPM
  {
    template void Solver<2>::step<Linear1D>(double, double);
    template void Solver<3>::step<Linear1D>(double, double);
  } // namespace MPM
} // namespace hysteron

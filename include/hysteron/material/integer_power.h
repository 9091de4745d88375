#ifndef hysteron_material_integer_power_h
#define hysteron_material_integer_power_h

namespace hysteron
{
  namespace Material
  {
    /**
     * x^e for an integer e >= 1 by repeated squaring: the Bouc-Wen switch |z/z_y|^n and
     * (q/sigma_y)^n are evaluated at every rate evaluation, and std::pow is several times
     * slower for the usual integer n. The common exponents 1, 2, 4, 8, 16 need no loop.
     */
    inline double
    integer_power(double x, unsigned int e)
    {
      switch (e)
        {
          case 1:
            return x;
          case 2:
            return x * x;
          case 4:
            x *= x;
            return x * x;
          case 8:
            x *= x;
            x *= x;
            return x * x;
          case 16:
            x *= x;
            x *= x;
            x *= x;
            return x * x;
          default:
            break;
        }
      double result = 1;
      while (true)
        {
          if (e & 1u)
            result *= x;
          e >>= 1;
          if (e == 0)
            return result;
          x *= x;
        }
    }
  } // namespace Material
} // namespace hysteron

#endif

#ifndef hysteron_source_material_safeguarded_newton_h
#define hysteron_source_material_safeguarded_newton_h

// The scalar root finder of the implicit Bouc-Wen updates (the uniaxial law's
// z, the interaction surface's multiplier nu): Newton safeguarded by a bracket.

#include <cmath>
#include <limits>

namespace hysteron {
namespace Material {
/**
 * Find the root of a scalar function f in the bracket between @p lo (f < 0) and
 * @p x (f >= 0, its value in @p value): Newton from x, where each iterate
 * shrinks the bracket to the side of its sign, and bisection where the Newton
 * step is not finite or would leave the bracket. Newton from the end with f >=
 * 0 converges monotonically where f is convex and increasing (the loading
 * branch of the Bouc-Wen residuals); bisection covers non-convex branches and
 * kinks.
 *
 * @p evaluate(x) returns the value at x, @p residual(value) the pair (f,
 * df/dx). Stops when the step and |f| are at most @p tolerance(x) and df/dx is
 * finite, or when |hi - lo| <= @p collapse(hi) (the bracket has shrunk to
 * round-off).
 * @p fail(message, x, value) throws: after @p max_iterations iterations or at a
 * NaN. On return @p x is the root and @p value its evaluation. Returns the
 * iterations.
 */
template <typename Value, typename Evaluate, typename Residual,
          typename Tolerance, typename Collapse, typename Fail>
inline __attribute__((always_inline)) unsigned int
safeguarded_newton(double &x, double lo, Value &value, const Evaluate &evaluate,
                   const Residual &residual, const Tolerance &tolerance,
                   const Collapse &collapse, const unsigned int max_iterations,
                   const Fail &fail) {
  double hi = x;
  unsigned int iterations = 0;
  while (residual(value).first != 0) {
    const auto [f, df] = residual(value);
    if (++iterations > max_iterations)
      fail("too many iterations", x, value);
    if (f < 0)
      lo = x;
    else
      hi = x;
    double step = f / df;
    const double next = x - step;
    if (!std::isfinite(step) || (next - lo) * (next - hi) > 0)
      step = x - 0.5 * (lo + hi);
    x -= step;
    value = evaluate(x);
    const auto [f_new, df_new] = residual(value);
    if (std::isnan(f_new))
      fail("the residual is not a number", x, value);
    const double scale = tolerance(x);
    if (std::abs(step) <= scale && std::abs(f_new) <= scale &&
        std::isfinite(df_new))
      break;
    if (std::abs(lo - hi) <= collapse(hi))
      break; // the bracket has collapsed to round-off
  }
  return iterations;
}
} // namespace Material
} // namespace hysteron

#endif

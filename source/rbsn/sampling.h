#ifndef hysteron_source_rbsn_sampling_h
#define hysteron_source_rbsn_sampling_h

#include <deal.II/base/point.h>

#include <random>
#include <sstream>
#include <string>
#include <vector>

/**
 * @file
 * What the 2D and 3D Poisson-disk samplers and tessellations share: the
 * platform-independent uniform numbers, Bridson's advancing front and the
 * darts thrown into the gaps it leaves, and points in messages. The samplers
 * differ only in how a trial point is drawn (annulus or shell) and in their
 * background grids.
 */
namespace hysteron
{
  namespace RBSN
  {
    namespace Sampling
    {
      /// A uniform double in [0, 1) from the top 53 bits (the same on every platform).
      inline double
      uniform(std::mt19937_64 &rng)
      {
        return (rng() >> 11) * (1.0 / 9007199254740992.0);
      }

      /// "(x, y)" or "(x, y, z)" with 10 digits, for messages.
      template <int dim>
      std::string
      text(const dealii::Point<dim> &p)
      {
        std::ostringstream s;
        s.precision(10);
        s << "(";
        for (unsigned int k = 0; k < dim; ++k)
          s << (k > 0 ? ", " : "") << p[k];
        s << ")";
        return s.str();
      }

      /**
       * Bridson's advancing front: pick an active point c at random and draw up
       * to 30 trials `trial(c, d(c))` in the shell d(c) <= |x - c| <= 2 d(c);
       * the first that `try_add` accepts (it adds the point and makes it active)
       * keeps c active, 30 refusals retire it. Ends when no point is active;
       * @p points and @p radius are the sampler's points and their d, which
       * `try_add` appends to.
       */
      template <typename PointType, typename Trial, typename TryAdd>
      void
      grow_front(std::vector<unsigned int>    &active,
                 const std::vector<PointType> &points,
                 const std::vector<double>    &radius,
                 std::mt19937_64              &rng,
                 const Trial                  &trial,
                 const TryAdd                 &try_add)
      {
        while (!active.empty())
          {
            const unsigned int pick = static_cast<unsigned int>(uniform(rng) * active.size());
            const PointType    c    = points[active[pick]];
            const double       dc   = radius[active[pick]];
            bool               grew = false;
            for (unsigned int attempt = 0; attempt < 30 && !grew; ++attempt)
              grew = try_add(trial(c, dc));
            if (!grew)
              {
                active[pick] = active.back();
                active.pop_back();
              }
          }
      }

      /**
       * Up to @p trials points `draw()` into a gap of the front; the first that
       * `try_add` accepts starts the front again (`grow()`).
       */
      template <typename Draw, typename TryAdd, typename Grow>
      void
      throw_darts(const unsigned int trials, const Draw &draw, const TryAdd &try_add, const Grow &grow)
      {
        for (unsigned int attempt = 0; attempt < trials; ++attempt)
          if (try_add(draw()))
            {
              grow();
              return;
            }
      }
    } // namespace Sampling
  }   // namespace RBSN
} // namespace hysteron

#endif

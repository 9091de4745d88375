#ifndef hysteron_source_rbsn_sampling_h
#define hysteron_source_rbsn_sampling_h

#include <deal.II/base/point.h>

#include "rbsn/tessellation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

/**
 * @file
 * What the 2D and 3D Poisson-disk samplers and tessellations share: the
 * platform-independent uniform numbers, Bridson's advancing front and the
 * darts thrown into the gaps it leaves, points in messages, and the sampling of
 * one block of a tiled network (BlockSampler, blocks.cc). The samplers differ
 * only in how a trial point is drawn (annulus or shell) and in their background
 * grids.
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

      /**
       * One block of the tiling of a network (blocks.h): the half-open box
       * [origin + size index, origin + size (index + 1)) of the tiling's blocks, the
       * last block of each direction closed above so that the tiling covers its box.
       * A point belongs to the block whose index its coordinates give, the same
       * floating-point operations on every rank, so that exactly one block accepts it.
       */
      template <int dim>
      struct Clip
      {
        dealii::Point<dim>     origin;    ///< the lower corner of the tiling
        double                 size = 0;  ///< the side of a block [m]
        std::array<int, dim>   n{};       ///< blocks per direction
        std::array<int, dim>   index{};   ///< this block's
        double                 margin = 0; ///< the width of the known points around it [m]

        /// The block index of coordinate @p x in direction @p k.
        int
        coordinate(const double x, const unsigned int k) const
        {
          const double i = std::floor((x - origin[k]) / size);
          return i < 0 ? 0 : i >= n[k] ? n[k] - 1 : static_cast<int>(i);
        }

        bool
        contains(const dealii::Point<dim> &p) const
        {
          for (unsigned int k = 0; k < dim; ++k)
            if (coordinate(p[k], k) != index[k])
              return false;
          return true;
        }

        /// The block's box, closed (the first and the last blocks reach to infinity
        /// in their outward directions, where the clamped coordinate() puts points).
        std::pair<dealii::Point<dim>, dealii::Point<dim>>
        box() const
        {
          dealii::Point<dim> lo, hi;
          for (unsigned int k = 0; k < dim; ++k)
            {
              lo[k] = index[k] == 0 ? -1e300 : origin[k] + index[k] * size;
              hi[k] = index[k] == n[k] - 1 ? 1e300 : origin[k] + (index[k] + 1) * size;
            }
          return {lo, hi};
        }
      };

      /**
       * The random points of one body in the blocks of a tiled network (a Poisson-disk
       * sampler restricted to a block, blocks.cc): built once per body, then called per
       * block with the points known around the block. The 2D one is in poisson_disk_2d.cc,
       * the 3D one in poisson_disk_3d.cc (it keeps the body's polyhedral domain and the
       * forbidden balls of the boundary points).
       *
       * The constructor takes the network's fixed points (user and boundary points: the
       * 3D balls) and @p boundary_h as voronoi(). A call gives the new points in the part
       * of the body in @p clip, seeded with @p seed, each keeping min(d(p), d(q)) from the
       * @p known points (those within clip.margin of the block: the grid's and the
       * front's start, as the fixed points of poisson_disk_points()) and from each other.
       * A trial whose d exceeds the margin is refused (no point beyond it is known).
       */
      class BodySampler2
      {
      public:
        BodySampler2(const Geometry::Region<2>           &body,
                     const Spacing<2>                    &d,
                     const std::vector<dealii::Point<2>> &fixed,
                     double                               boundary_h,
                     const std::string                   &where);
        ~BodySampler2();

        std::vector<dealii::Point<2>>
        operator()(const std::vector<dealii::Point<2>> &known, std::uint64_t seed, const Clip<2> &clip) const;

      private:
        struct Data;
        std::unique_ptr<Data> data;
      };

      class BodySampler3
      {
      public:
        BodySampler3(const Geometry::Region<3>           &body,
                     const Spacing<3>                    &d,
                     const std::vector<dealii::Point<3>> &fixed,
                     double                               boundary_h,
                     const std::string                   &where);
        ~BodySampler3();

        std::vector<dealii::Point<3>>
        operator()(const std::vector<dealii::Point<3>> &known, std::uint64_t seed, const Clip<3> &clip) const;

      private:
        struct Data;
        std::unique_ptr<Data> data;
      };

      template <int dim>
      using BodySampler = std::conditional_t<dim == 2, BodySampler2, BodySampler3>;

      /// A 64-bit mixing function (splitmix64's finaliser): seeds of blocks from one seed.
      inline std::uint64_t
      mix(std::uint64_t x)
      {
        x += 0x9e3779b97f4a7c15ULL;
        x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
        x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
        return x ^ (x >> 31);
      }
    } // namespace Sampling
  }   // namespace RBSN
} // namespace hysteron

#endif

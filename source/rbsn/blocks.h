// The nuclei of a network sampled block by block (blocks.cc), so that each rank samples
// and holds only the nuclei near its own cells, and the network is the same on any
// number of ranks.
#ifndef hysteron_source_rbsn_blocks_h
#define hysteron_source_rbsn_blocks_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/point.h>

#include "rbsn/sampling.h"

#include <array>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    namespace Blocks
    {
      /**
       * The position of the cell @p x of a grid of 2^@p bits cells per direction along
       * the Hilbert curve through the grid (Skilling 2004, "Programming the Hilbert
       * curve": the coordinates turned into the transposed index, then its bits
       * interleaved). Consecutive positions are neighbouring cells, so that a range of
       * positions is a compact part of the grid. dim * bits <= 64.
       */
      template <int dim>
      std::uint64_t
      hilbert_index(std::array<std::uint32_t, dim> x, unsigned int bits);

      /**
       * The numbers of cells of @p n_parts parts of @p n cells, as recursive bisection
       * splits them: the first n_parts / 2 parts get round(n (n_parts / 2) / n_parts)
       * cells, recursively (the sizes of the former coordinate bisection of all nuclei).
       */
      std::vector<std::uint64_t>
      part_sizes(std::uint64_t n, unsigned int n_parts);

      /**
       * The part of each of @p points for parts of the given @p sizes (summing to their
       * number), by recursive coordinate bisection: each cut across the longest side
       * of the box of the points of a range of parts, the first half of the parts on
       * the lower side (the lower coordinate, then the lower index first).
       */
      template <int dim>
      std::vector<unsigned int>
      bisect(const std::vector<dealii::Point<dim>> &points, const std::vector<std::uint64_t> &sizes);

      /**
       * The blocks of the sampling: the tiling of the bodies' box by cubes of side size
       * from its lower corner, and the blocks that meet a body's box (the occupied ones),
       * ordered along the Hilbert curve of the tiling. The tiling depends on the bodies,
       * the spacing and `Sampling block size`, never on the number of ranks.
       */
      template <int dim>
      class Layout
      {
      public:
        using Point = dealii::Point<dim>;
        using Index = std::array<int, dim>;

        /// One block over [lo, hi] if @p size <= 0 (or the tiling has one block).
        Layout(const Point &lo, const Point &hi, double size, const std::vector<std::pair<Point, Point>> &body_boxes);

        /// Whether the network is one block: sampled as before the tiling.
        bool
        single() const
        {
          return tiles == 1;
        }

        /// The number of occupied blocks.
        unsigned int
        size() const
        {
          return index.size();
        }

        /// The position (in the Hilbert order) of the block of @p p; -1: none.
        int
        position(const Point &p) const;

        /// The position of the block with @p i; -1: not occupied.
        int
        position(const Index &i) const;

        /// The colour of block @p b, 0 ... 2^dim - 1: the parity of its indices (blocks
        /// of one colour are never neighbours).
        unsigned int
        colour(const unsigned int b) const;

        /// A number of block @p b fixed by the tiling (its index i + n_0 (j + n_1 k)).
        std::uint64_t
        linear(const unsigned int b) const;

        /// Block @p b with a margin of known points of width @p margin.
        Sampling::Clip<dim>
        clip(unsigned int b, double margin) const;

        /// The occupied blocks within @p ring blocks of block @p b in every direction
        /// (itself included), ascending.
        std::vector<unsigned int>
        neighbours(unsigned int b, unsigned int ring) const;

        Point                origin;
        double               side = 0;
        Index                n{};
        std::vector<Index>   index; ///< of the occupied blocks, in the Hilbert order

      private:
        std::uint64_t
        linear_of(const Index &i) const;

        std::size_t                                    tiles = 1;
        std::unordered_map<std::uint64_t, unsigned int> by_linear;
      };

      /**
       * The nuclei of the network by block: each block's nuclei in the order of their
       * cell numbers (its fixed points in their order, then the random points of each
       * body in turn), the blocks in their (Hilbert) order. A rank holds the nuclei of
       * the blocks it sampled, of their neighbours and of the blocks near its cells;
       * every rank knows how many nuclei each block has. The cells are numbered block
       * by block, and split over the ranks along the blocks' order into parts of the
       * sizes of part_sizes(); a block two ranks share is split between them by
       * bisect(). The DoFs are numbered rank by rank, and each rank's cells in the
       * order of their numbers.
       */
      template <int dim>
      class Nuclei
      {
      public:
        using Point = dealii::Point<dim>;

        Nuclei(const Layout<dim> &layout, MPI_Comm comm);

        /// One block that every rank holds (sampled as before the tiling).
        void
        hold_all(std::vector<Point> points);

        /// What the sampling of the blocks needs.
        struct Sources
        {
          const std::vector<Point>                           *fixed = nullptr; ///< user and boundary points
          std::vector<const Sampling::BodySampler<dim> *>    bodies;
          std::vector<std::pair<Point, Point>>               body_boxes;
          std::uint64_t                                      seed   = 0;
          double                                             margin = 0;  ///< 2 d_max
          std::vector<double>                                predicted;   ///< random points per block
        };

        /**
         * Sample the random points of every block (collective): in 2^dim phases, one
         * per colour, each rank samples its blocks of the colour (the sampler of a block
         * is fixed by the predicted points along the blocks' order), each body in turn,
         * knowing the fixed points and the points of the blocks around it sampled in
         * earlier phases, and then sends the new points to the samplers of the
         * neighbouring blocks.
         */
        void
        sample(const Sources &sources);

        /// The number of nuclei (cells) of the network.
        std::uint64_t
        size() const
        {
          return first.empty() ? 0 : first.back();
        }

        /// Every nucleus in the order of the cells (all blocks must be held).
        std::vector<Point>
        all() const;

        /// Split the cells over @p n_parts ranks (this one is part this_rank).
        void
        partition(unsigned int n_parts);

        /// Make sure that this rank holds the nuclei of every block within @p distance
        /// (rounded up to whole blocks) of a block of its cells (collective).
        void
        fetch(double distance);

        /**
         * This rank's cells and the nuclei within @p distance of one of them (fetch()ed),
         * ascending: their numbers into @p ids, nuclei into @p points and whether they
         * are this rank's into @p own.
         */
        void
        near_own(double distance, std::vector<std::uint64_t> &ids, std::vector<Point> &points, std::vector<bool> &own);

        /// The rank and the DoF block of cell @p id (a cell of a held block).
        std::pair<unsigned int, std::uint64_t>
        owner(std::uint64_t id);

        /**
         * The global number of the first facet of each of this rank's cells (ascending
         * ids), whose numbers of facets to higher cells are @p n_up: the facets are
         * numbered in the order of (lower, upper) cell over the whole network
         * (collective: the facets of every block summed, and the counts of the cells of
         * a shared block exchanged between its ranks).
         */
        std::vector<std::uint64_t>
        first_facets(const std::vector<unsigned int> &n_up);

      private:
        /// The ranks that share block @p b: [first rank, last rank].
        std::pair<unsigned int, unsigned int>
        sharers(unsigned int b) const;

        /// A block two ranks share: the rank and the DoF block of each of its nuclei.
        struct Split
        {
          std::vector<unsigned int>  rank;
          std::vector<std::uint64_t> dof;
        };
        const Split &
        split(unsigned int b);

        /// The blocks of this rank's cells.
        std::vector<unsigned int>
        own_blocks() const;

        /// Append each held block's nuclei (@p blocks) to the messages to @p ranks.
        void
        send_blocks(const std::vector<std::pair<unsigned int, unsigned int>> &block_rank);

        /// The known points of block @p b for the sampling of one body (see sample()).
        std::vector<Point>
        known_points(unsigned int b, unsigned int colour, const Sources &sources) const;

        const Layout<dim>                       &layout;
        MPI_Comm                                 comm;
        unsigned int                             n_ranks, rank;
        std::vector<std::vector<Point>>          points;    ///< of each held block
        std::vector<bool>                        held;
        std::vector<unsigned int>                n_fixed;   ///< fixed points of each block
        std::vector<std::vector<unsigned int>>   fixed_in;  ///< their indices
        std::vector<unsigned int>                sampler;   ///< the rank of each block
        std::vector<std::uint64_t>               first;     ///< first cell of each block; size() + 1
        std::vector<std::uint64_t>               cuts;      ///< first cell of each rank; n_parts + 1
        std::unordered_map<unsigned int, Split>  splits;
      };
    } // namespace Blocks
  }   // namespace RBSN
} // namespace hysteron

#endif

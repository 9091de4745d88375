#ifndef hysteron_source_mpm_grid_h
#define hysteron_source_mpm_grid_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/partitioner.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <boost/range/iterator_range.hpp>

#include "mpm/basis.h"
#include "mpm/zero_pages.h"

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <vector>

namespace hysteron
{
  namespace MPM
  {
    /**
     * The background grid of the MPM: a Cartesian lattice of n_cells cells of
     * size h, and a parallel::distributed::Triangulation whose cells are
     * *blocks* of block_size()^dim lattice cells, so that p4est partitions the
     * blocks between the ranks (weighted by the work in them) and the
     * ParticleHandler keeps each material point in its block.
     *
     * Why blocks and not one triangulation cell per lattice cell: the kernels
     * never use a cell of deal.II, only the lattice; a refined p4est cell costs
     * about 0.8 kB and 20-40 us to create in 3D, 30x the cost of the lattice's
     * own arrays, and would make the set-up of a large grid follow the
     * triangulation (doc/mpm.md, "Memory and set-up").
     *
     * Each rank keeps the nodal data of the nodes its points can reach -- the
     * nodes of its own blocks' cells plus `margin` node layers around them (a
     * point's support reaches one node beyond its cell with the cubic basis) --
     * in one dense array over the lattice box that holds them, node after node
     * with n_components doubles each, so that a point's 2^dim or 4^dim support
     * nodes are a base index plus constant strides. No array or loop of the set-up
     * or of a step is over the whole lattice.
     *
     * Nodes shared by several ranks are added up through a
     * LinearAlgebra::distributed::Vector over the shared nodes only: each
     * lattice node is owned by the owner of its block (the block that holds the
     * cell above it, the last one at the upper faces), the owned nodes that
     * other ranks reach are numbered rank by rank, and those ranks hold them as
     * ghosts (exchange()). On one rank nothing is communicated.
     */
    template <int dim>
    class BackgroundGrid
    {
    public:
      explicit BackgroundGrid(MPI_Comm comm);

      /// Lattice cells per block side (64 cells a block in 2D, 512 in 3D).
      static constexpr unsigned int
      block_size()
      {
        return 8;
      }

      /// A block's data in a checkpoint (or moving with it to another rank).
      using BlockPacker = std::function<std::vector<char>(const std::array<unsigned int, dim> &block)>;
      using BlockUnpacker =
        std::function<void(const std::array<unsigned int, dim>                              &block,
                           const boost::iterator_range<std::vector<char>::const_iterator> &data)>;

      /**
       * Create the lattice (cells of size @p h from @p lower, @p n_cells per
       * direction) and the triangulation of its blocks (a coarse mesh of few
       * cells refined to the blocks, so that p4est holds them distributed),
       * partitioned into equal numbers of blocks. A point reaches @p margin node
       * layers beyond its cell's own nodes (0: linear basis, 1: cubic B-splines).
       */
      void
      create(const dealii::Point<dim>            &lower,
             const double                          h,
             const std::array<unsigned int, dim> &n_cells,
             const unsigned int                    margin);

      /**
       * Save the triangulation into @p file (p4est's files) with @p pack's data of
       * every locally owned block (collective): what load() reads on any number
       * of ranks.
       */
      void
      save(const std::string &file, const BlockPacker &pack);

      /**
       * create() from a checkpoint: the same lattice, the blocks partitioned as
       * saved when @p same_ranks (as many ranks as then; else in equal numbers),
       * and @p unpack called with the data of every locally owned block.
       * Collective.
       */
      void
      load(const dealii::Point<dim>            &lower,
           const double                          h,
           const std::array<unsigned int, dim> &n_cells,
           const unsigned int                    margin,
           const std::string                    &file,
           const bool                            same_ranks,
           const BlockUnpacker                  &unpack);

      /**
       * Repartition the blocks so that the ranks get equal sums of @p weight
       * (of a locally owned block's multi-index; blocks outside the lattice
       * weigh nothing). With @p pack, the blocks' data moves with them and
       * arrives through @p unpack on the new owners. Collective; a no-op on one
       * rank.
       */
      void
      repartition(const std::function<unsigned int(const std::array<unsigned int, dim> &)> &weight,
                  const BlockPacker   &pack   = {},
                  const BlockUnpacker &unpack = {});

      /**
       * After the last (re)partition: the box of nodes this rank reaches, which
       * of them it owns, and the exchange of the shared nodes; @p n_components
       * doubles per node.
       */
      void
      setup_nodes(const unsigned int n_components);

      /// The lattice of the current step (moved by move() if the grid moves).
      const Lattice<dim> &
      lattice() const
      {
        return grid_lattice;
      }

      /// The lattice of the set-up: the geometry of the triangulation, and so the
      /// frame in which the ParticleHandler holds the points' locations.
      const Lattice<dim> &
      initial_lattice_geometry() const
      {
        return initial_lattice;
      }

      /**
       * Move the grid (`MPM/Grid/Motion`): the same cells and nodes, with a new
       * lower corner and new cell sizes. Only the lattice moves; the
       * triangulation keeps the set-up's geometry, and to_initial_frame() maps a
       * position to where the same lattice coordinates lie there.
       */
      void
      move(const Lattice<dim> &moved)
      {
        grid_lattice = moved;
      }

      /// The position with the same lattice coordinates in the set-up's lattice:
      /// o0 + h0 (x - o) / h per direction (the identity while the grid has not moved).
      dealii::Point<dim>
      to_initial_frame(const dealii::Point<dim> &x) const
      {
        dealii::Point<dim> y;
        for (unsigned int d = 0; d < dim; ++d)
          y[d] = initial_lattice.origin[d] +
                 (x[d] - grid_lattice.origin[d]) * (initial_lattice.h[d] / grid_lattice.h[d]);
        return y;
      }

      /// The inverse of to_initial_frame().
      dealii::Point<dim>
      from_initial_frame(const dealii::Point<dim> &y) const
      {
        dealii::Point<dim> x;
        for (unsigned int d = 0; d < dim; ++d)
          x[d] = grid_lattice.origin[d] +
                 (y[d] - initial_lattice.origin[d]) * (grid_lattice.h[d] / initial_lattice.h[d]);
        return x;
      }

      const dealii::parallel::distributed::Triangulation<dim> &
      triangulation() const
      {
        return tria;
      }

      dealii::parallel::distributed::Triangulation<dim> &
      triangulation()
      {
        return tria;
      }

      MPI_Comm
      mpi_communicator() const
      {
        return comm;
      }

      /// Lattice-lexicographic cell id of a cell multi-index.
      unsigned int
      cell_id(const std::array<unsigned int, dim> &c) const
      {
        unsigned int id = 0;
        for (int d = dim - 1; d >= 0; --d)
          id = id * grid_lattice.n_cells[d] + c[d];
        return id;
      }

      /// The block of the lattice cell @p c.
      std::array<unsigned int, dim>
      block_of(const std::array<unsigned int, dim> &c) const
      {
        std::array<unsigned int, dim> b;
        for (unsigned int d = 0; d < dim; ++d)
          b[d] = c[d] / block_size();
        return b;
      }

      /// Is the block @p b locally owned?
      bool
      owns_block(const std::array<unsigned int, dim> &b) const
      {
        const int k = local_block(b);
        return k >= 0 && block_state[k] == owned_block;
      }

      /// Is the lattice cell @p c locally owned (in a locally owned block)?
      bool
      owns_cell(const std::array<unsigned int, dim> &c) const
      {
        return owns_block(block_of(c));
      }

      /// The range [first, last] of lattice cells in this rank's blocks (a box that
      /// may hold other ranks' cells too; empty if first > last).
      std::pair<std::array<unsigned int, dim>, std::array<unsigned int, dim>>
      owned_cell_range() const
      {
        return owned_range;
      }

      /// The locally owned blocks (multi-indices) in the order of p4est's space-filling
      /// curve, which is the order of the ranks' parts.
      const std::vector<std::array<unsigned int, dim>> &
      owned_blocks() const
      {
        return owned_block_list;
      }

      /// The active cell of the triangulation that is the (locally owned) block of lattice cell @p c.
      typename dealii::Triangulation<dim>::active_cell_iterator
      cell_iterator(const std::array<unsigned int, dim> &c) const;

      /// The coordinates of @p x in the unit cell of the block of the lattice cell @p c
      /// (lattice coordinates: the same in every frame of a moving grid).
      dealii::Point<dim>
      unit_block_point(const dealii::Point<dim> &x, const std::array<unsigned int, dim> &c) const
      {
        const auto         b = block_of(c);
        dealii::Point<dim> r;
        for (unsigned int d = 0; d < dim; ++d)
          r[d] = ((x[d] - grid_lattice.origin[d]) / grid_lattice.h[d] - double(b[d]) * block_size()) /
                 block_size();
        return r;
      }

      /// Number of nodes of the local dense box.
      unsigned int
      n_local_nodes() const
      {
        return n_box_nodes;
      }

      unsigned int
      n_components() const
      {
        return n_comp;
      }

      /// First lattice node index of the local box in direction d.
      int
      box_lower(const unsigned int d) const
      {
        return box_low[d];
      }

      /// Stride of direction d in the local box (1 for x).
      unsigned int
      stride(const unsigned int d) const
      {
        return box_stride[d];
      }

      /// Local box index of the lattice node with multi-index @p i (which must be in the box).
      unsigned int
      local_node(const std::array<int, dim> &i) const
      {
        unsigned int n = 0;
        for (unsigned int d = 0; d < dim; ++d)
          n += (i[d] - box_low[d]) * box_stride[d];
        return n;
      }

      /// Lattice multi-index of local node @p n.
      std::array<int, dim>
      lattice_index(unsigned int n) const;

      /// Position of local node @p n.
      dealii::Point<dim>
      node_position(const unsigned int n) const;

      /// Can a point of this rank reach local node @p n (a node of its blocks or their margin)?
      bool
      is_relevant(const unsigned int n) const
      {
        return bit(relevant_node, n);
      }

      /// Is local node @p n owned by this rank (reactions and sums count owned nodes once)?
      bool
      is_owned(const unsigned int n) const
      {
        return bit(owned_node, n);
      }

      /// The nodal data: n_local_nodes() * n_components() doubles.
      ZeroPages<double> &
      data()
      {
        return nodes;
      }

      /**
       * Call @p f(n) for every local node a point of this rank can reach
       * (is_relevant()), in box order.
       */
      template <typename Function>
      void
      for_each_relevant_node(const Function &f) const;

      /// Whether the box holds many more nodes than this rank reaches (its arrays per
      /// node should then be sparse ZeroPages).
      bool
      sparse_box() const
      {
        return 2 * n_relevant < n_box_nodes;
      }

      /**
       * The nodes this rank reaches in the current step are those with
       * stamps[n] == *stamp (the kernels' marks): exchange() writes the sums at
       * the shared nodes that other ranks own only into these (a node this rank
       * does not reach is not read here, and writing it would take a page of
       * memory).
       */
      void
      track_reached_nodes(const unsigned int *stamps, const unsigned int *stamp)
      {
        reached_stamps  = stamps;
        current_stamp   = stamp;
      }

      /**
       * Add up the components [first, first + n) of the nodes shared with other
       * ranks, so that every rank holds the global sums at its owned nodes and at
       * the nodes it reaches in this step. A no-op on one rank.
       */
      void
      exchange(const unsigned int first, const unsigned int n);

      /**
       * A second array of nodal data on the same nodes (the per-body fields of
       * contact, source/mpm/contact.cc): @p n_blocks blocks of @p block_size
       * doubles per node. Only allocated when asked for.
       */
      void
      initialize_layer(const unsigned int n_blocks, const unsigned int block_size);

      /// The layer's data: n_local_nodes() * n_blocks * block_size doubles.
      ZeroPages<double> &
      layer_data()
      {
        return layer_nodes;
      }

      /// exchange() for the components first + b * block_size + [0, n) of every block b of the layer.
      void
      exchange_layer(const unsigned int first, const unsigned int n);

      /// zero_interface() for the layer (the components as in exchange_layer()).
      void
      zero_layer_interface(const unsigned int first, const unsigned int n);

      /// Set the components [first, first + n) of the owned shared nodes to zero
      /// (exchange() writes their sums whether this rank reaches them or not).
      void
      zero_interface(const unsigned int first, const unsigned int n);

      bool
      is_parallel() const
      {
        return n_ranks > 1;
      }

      /// Bytes of the grid's own arrays on this rank (nodes, flags, exchange lists).
      std::size_t
      memory_consumption() const;

    private:
      /**
       * The exchange of one nodal array (n_comp doubles per node): a distributed
       * vector over the shared nodes (owned, or reached as ghosts), and
       * (local box node, local vector index of component 0) of the ghosts and of
       * the owned nodes that other ranks reach.
       */
      struct Field
      {
        unsigned int                                       n_comp = 0;
        dealii::LinearAlgebra::distributed::Vector<double> buffer;
        std::vector<std::pair<unsigned int, unsigned int>> ghost_nodes;
        std::vector<std::pair<unsigned int, unsigned int>> import_nodes;
      };

      /// The partitioner of @p field from the node numbering (several ranks only).
      void
      connect(Field &field) const;

      /// Add up the blocks' components [first, first + n) of @p values at the shared nodes.
      void
      add_shared(Field             &field,
                 ZeroPages<double> &values,
                 const unsigned int   first,
                 const unsigned int   n,
                 const unsigned int   n_blocks,
                 const unsigned int   block_size);

      /// The index of block @p b in the local block box, or -1 outside it.
      int
      local_block(const std::array<unsigned int, dim> &b) const
      {
        int k = 0;
        for (int d = dim - 1; d >= 0; --d)
          {
            const int i = static_cast<int>(b[d]) - block_box_low[d];
            if (i < 0 || i >= static_cast<int>(block_box_size[d]))
              return -1;
            k = k * block_box_size[d] + i;
          }
        return k;
      }

      /// The block of the triangulation cell @p cell (from its centre).
      std::array<unsigned int, dim>
      block_of_cell(const typename dealii::Triangulation<dim>::cell_iterator &cell) const;

      /// Is the block @p b one of the lattice's (not one of the triangulation's padding)?
      bool
      in_lattice(const std::array<unsigned int, dim> &b) const
      {
        for (unsigned int d = 0; d < dim; ++d)
          if (b[d] >= n_blocks[d])
            return false;
        return true;
      }

      /// The blocks of this rank and their neighbours (states and triangulation cells).
      void
      setup_blocks();

      /// Register the blocks' data with the triangulation before a save or repartition:
      /// each block's partition weight and @p pack's data. Returns the two handles.
      std::pair<unsigned int, unsigned int>
      attach(const BlockPacker &pack);

      /// After a load or repartition: the blocks' weights, and their data to @p unpack.
      void
      receive(const std::pair<unsigned int, unsigned int> &handles, const BlockUnpacker &unpack);

      /// The lattice and the unrefined coarse mesh of its blocks.
      void
      make_coarse_mesh(const dealii::Point<dim>            &lower,
                       const double                          h,
                       const std::array<unsigned int, dim> &n_cells,
                       const unsigned int                    margin);

      /// The shared nodes' numbers in the exchange: the owners number the nodes the
      /// other ranks ask for.
      void
      number_nodes();

      MPI_Comm                                          comm;
      unsigned int                                      n_ranks;
      dealii::parallel::distributed::Triangulation<dim> tria;
      Lattice<dim>                                      grid_lattice, initial_lattice;
      unsigned int                                      margin = 0;
      /// The refinements from the coarse mesh to the blocks.
      unsigned int                                      coarse_level = 0;
      unsigned int                                      n_comp = 0;

      /// Blocks of lattice cells per direction (the triangulation may have more: padding).
      std::array<unsigned int, dim> n_blocks{};

      /// The weight of each owned block in the last repartition (none: equal numbers).
      std::map<std::array<unsigned int, dim>, unsigned int> block_weight;

      /// The box of the blocks this rank owns or sees as ghosts: their state and the
      /// triangulation cell (level, index) of each.
      static constexpr unsigned char            no_block = 0, owned_block = 1, ghost_block = 2;
      std::array<int, dim>                      block_box_low{};
      std::array<unsigned int, dim>             block_box_size{};
      std::vector<unsigned char>                block_state;
      std::vector<unsigned int>                 block_owner;
      std::vector<std::pair<int, int>>          block_cell;
      std::vector<std::array<unsigned int, dim>> owned_block_list;
      std::pair<std::array<unsigned int, dim>, std::array<unsigned int, dim>> owned_range;

      std::array<int, dim>          box_low;
      std::array<unsigned int, dim> box_size;
      std::array<unsigned int, dim> box_stride;
      unsigned int                  n_box_nodes = 0;
      /// Per box node, one bit each: reached by this rank's points; owned.
      ZeroPages<std::uint64_t>      relevant_node;
      ZeroPages<std::uint64_t>      owned_node;
      std::size_t                   n_relevant = 0;
      ZeroPages<double>             nodes;

      static bool
      bit(const ZeroPages<std::uint64_t> &bits, const unsigned int n)
      {
        return (bits[n >> 6] >> (n & 63)) & 1;
      }

      static void
      set_bit(ZeroPages<std::uint64_t> &bits, const unsigned int n)
      {
        bits[n >> 6] |= std::uint64_t(1) << (n & 63);
      }

      /// The nodes block @p b's points reach, per direction: [first, last] lattice indices.
      std::array<std::pair<int, int>, dim>
      node_range(const std::array<unsigned int, dim> &b) const;

      /// Several ranks: the numbers in the exchange of the owned nodes that other ranks
      /// reach (box order) and of the ghost nodes (the reached nodes this rank does not
      /// own), by box node.
      std::vector<std::pair<unsigned int, unsigned int>> owned_numbers, ghost_numbers;
      std::uint64_t                                      n_global_nodes = 0;
      unsigned int                                       first_owned_number = 0;
      Field                                              main;

      /// The marks of the nodes reached in the current step (track_reached_nodes()).
      const unsigned int *reached_stamps = nullptr;
      const unsigned int *current_stamp  = nullptr;

      /// The optional second array (initialize_layer()).
      ZeroPages<double>   layer_nodes;
      Field               layer;
      unsigned int        layer_blocks = 0, layer_block_size = 0;
    };



    template <int dim>
    template <typename Function>
    void
    BackgroundGrid<dim>::for_each_relevant_node(const Function &f) const
    {
      // The set bits in box order: a word without one costs a compare (and a page of
      // the box that no node of this rank lies in is the kernel's zero page).
      const std::size_t n_words = (std::size_t(n_box_nodes) + 63) / 64;
      for (std::size_t w = 0; w < n_words; ++w)
        for (std::uint64_t word = relevant_node[w]; word != 0; word &= word - 1)
          f(static_cast<unsigned int>(64 * w + __builtin_ctzll(word)));
    }
  } // namespace MPM
} // namespace hysteron

#endif

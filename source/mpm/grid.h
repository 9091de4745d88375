#ifndef hysteron_source_mpm_grid_h
#define hysteron_source_mpm_grid_h

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/lac/la_parallel_vector.h>

#include "mpm/basis.h"

#include <array>
#include <memory>
#include <vector>

namespace hysteron
{
  namespace MPM
  {
    /**
     * The background grid of the MPM: a Cartesian box of cubic cells on a
     * parallel::distributed::Triangulation (one coarse cell per grid cell, so
     * that p4est partitions the cells) with a DoFHandler whose vertex DoFs are
     * the grid nodes (an FESystem of n_components FE_Q(1), one per nodal
     * quantity).
     *
     * The kernels do not go through the DoFHandler. Each rank keeps the nodal
     * data of the lattice box that covers its locally relevant nodes in one
     * dense array, node after node with n_components doubles each, so that the
     * 2^dim or 4^dim nodes of a particle's support are a base index plus
     * constant strides. The distributed vector of the DoFHandler is used only to
     * add the contributions of the nodes shared by several ranks (exchange());
     * on one rank nothing is communicated.
     */
    template <int dim>
    class BackgroundGrid
    {
    public:
      explicit BackgroundGrid(MPI_Comm comm);

      /**
       * Create the grid: cells of size @p h from @p lower; @p n_cells per
       * direction; @p n_components doubles per node. With @p work_per_cell (in
       * lattice order, e.g. the material points of each cell) p4est balances
       * that work instead of the number of cells between the ranks.
       */
      void
      initialize(const dealii::Point<dim>            &lower,
                 const double                          h,
                 const std::array<unsigned int, dim> &n_cells,
                 const unsigned int                    n_components,
                 const std::vector<unsigned int>      &work_per_cell = {});

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

      /// Is the lattice cell @p id locally owned?
      bool
      owns_cell(const unsigned int id) const
      {
        return owned_cell[id] != 0;
      }

      /// The active cell of the triangulation that is lattice cell @p id (locally owned).
      typename dealii::Triangulation<dim>::active_cell_iterator
      cell_iterator(const unsigned int id) const;

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

      /// Is local node @p n one of the grid's locally relevant nodes?
      bool
      is_relevant(const unsigned int n) const
      {
        return relevant_node[n] != 0;
      }

      /// Is local node @p n owned by this rank (reactions and sums count owned nodes once)?
      bool
      is_owned(const unsigned int n) const
      {
        return owned_node[n] != 0;
      }

      /// The nodal data: n_local_nodes() * n_components() doubles.
      std::vector<double> &
      data()
      {
        return nodes;
      }

      /**
       * Add up the components [first, first + n) of the nodes shared with other
       * ranks, so that every rank holds the global sums at all its relevant
       * nodes. A no-op on one rank.
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
      std::vector<double> &
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

      /// Set the components [first, first + n) of the interface nodes to zero
      /// (the nodes whose values exchange() may have changed without this rank
      /// touching them).
      void
      zero_interface(const unsigned int first, const unsigned int n);

      bool
      is_parallel() const
      {
        return n_ranks > 1;
      }

    private:
      /**
       * The DoFs of one nodal array (n_comp FE_Q(1) per node) and, for the
       * nodes shared with other ranks, (local box node, local vector index of
       * component 0): what exchange() needs.
       */
      struct Field
      {
        unsigned int                                       n_comp = 0;
        std::unique_ptr<dealii::FESystem<dim>>             fe;
        dealii::DoFHandler<dim>                            dof_handler;
        dealii::LinearAlgebra::distributed::Vector<double> buffer;
        std::vector<std::pair<unsigned int, unsigned int>> ghost_nodes;
        std::vector<std::pair<unsigned int, unsigned int>> import_nodes;
      };

      /// Distribute the field's DoFs and list its shared nodes (with @p set_node_flags
      /// also which nodes are relevant and owned).
      void
      connect(Field &field, const bool set_node_flags);

      /// Add up the blocks' components [first, first + n) of @p values at the shared nodes.
      void
      add_shared(Field               &field,
                 std::vector<double> &values,
                 const unsigned int   first,
                 const unsigned int   n,
                 const unsigned int   n_blocks,
                 const unsigned int   block_size);

      MPI_Comm                                          comm;
      unsigned int                                      n_ranks;
      dealii::parallel::distributed::Triangulation<dim> tria;
      Lattice<dim>                                      grid_lattice, initial_lattice;
      unsigned int                                      n_comp = 0;

      /// Per lattice cell: owned (1) or not (0); the triangulation index of the cell.
      std::vector<unsigned char> owned_cell;
      std::vector<int>           cell_index;

      std::array<int, dim>          box_low;
      std::array<unsigned int, dim> box_size;
      std::array<unsigned int, dim> box_stride;
      unsigned int                  n_box_nodes = 0;
      std::vector<unsigned char>    relevant_node;
      std::vector<unsigned char>    owned_node;
      std::vector<double>           nodes;
      Field                         main;

      /// The optional second array (initialize_layer()).
      std::vector<double> layer_nodes;
      Field               layer;
      unsigned int        layer_blocks = 0, layer_block_size = 0;
    };
  } // namespace MPM
} // namespace hysteron

#endif

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/grid/grid_generator.h>

#include <hysteron/base/exceptions.h>
#include "mpm/grid.h"

#include <algorithm>
#include <climits>
#include <cmath>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    BackgroundGrid<dim>::BackgroundGrid(MPI_Comm comm)
      : comm(comm)
      , n_ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
      , tria(comm)
    {}



    template <int dim>
    void
    BackgroundGrid<dim>::initialize(const dealii::Point<dim>            &lower,
                                    const double                          h,
                                    const std::array<unsigned int, dim> &n_cells,
                                    const unsigned int                    n_components,
                                    const std::vector<unsigned int>      &work_per_cell)
    {
      using namespace dealii;
      grid_lattice.origin  = lower;
      grid_lattice.h       = uniform_h<dim>(h);
      grid_lattice.n_cells = n_cells;
      initial_lattice      = grid_lattice;
      n_comp               = n_components;

      std::vector<unsigned int> repetitions(n_cells.begin(), n_cells.end());
      Point<dim>                upper = lower;
      unsigned int              n_lattice_cells = 1;
      for (unsigned int d = 0; d < dim; ++d)
        {
          upper[d] += n_cells[d] * h;
          n_lattice_cells *= n_cells[d];
        }
      GridGenerator::subdivided_hyper_rectangle(tria, repetitions, lower, upper);
      if (n_ranks > 1 && !work_per_cell.empty())
        {
          // p4est adds up these weights along its space-filling curve; a cell
          // without points still costs a little (its share of the grid).
          auto connection = tria.signals.weight.connect(
            [&](const typename Triangulation<dim>::cell_iterator &cell,
                const typename Triangulation<dim>::CellStatus) -> unsigned int {
              std::array<unsigned int, dim> c;
              for (unsigned int d = 0; d < dim; ++d)
                c[d] = static_cast<unsigned int>(std::floor((cell->center()[d] - lower[d]) / h));
              return 1000u * work_per_cell[cell_id(c)];
            });
          tria.repartition();
          connection.disconnect();
        }

      // Which lattice cell is which triangulation cell, and who owns it.
      owned_cell.assign(n_lattice_cells, 0);
      cell_index.assign(n_lattice_cells, -1);
      std::array<int, dim> low, high;
      low.fill(INT_MAX);
      high.fill(INT_MIN);
      for (const auto &cell : tria.active_cell_iterators())
        if (!cell->is_artificial())
          {
            std::array<unsigned int, dim> c;
            const Point<dim>              center = cell->center();
            for (unsigned int d = 0; d < dim; ++d)
              {
                c[d] = static_cast<unsigned int>(std::floor((center[d] - lower[d]) / h));
                low[d]  = std::min<int>(low[d], c[d]);
                high[d] = std::max<int>(high[d], c[d] + 1);
              }
            const unsigned int id = cell_id(c);
            cell_index[id]        = cell->index();
            owned_cell[id]        = cell->is_locally_owned() ? 1 : 0;
          }

      // The dense box of the locally relevant nodes (a rank without cells gets an empty box).
      n_box_nodes = 1;
      for (unsigned int d = 0; d < dim; ++d)
        {
          if (high[d] < low[d])
            low[d] = high[d] = 0;
          box_low[d]    = low[d];
          box_size[d]   = high[d] - low[d] + 1;
          box_stride[d] = n_box_nodes;
          n_box_nodes *= box_size[d];
        }
      relevant_node.assign(n_box_nodes, 0);
      owned_node.assign(n_box_nodes, 0);

      main.n_comp = n_comp;
      connect(main, true);
      nodes.assign(std::size_t(n_box_nodes) * n_comp, 0.0);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::connect(Field &field, const bool set_node_flags)
    {
      using namespace dealii;
      field.fe = std::make_unique<FESystem<dim>>(FE_Q<dim>(1), field.n_comp);
      field.dof_handler.reinit(tria);
      field.dof_handler.distribute_dofs(*field.fe);

      IndexSet relevant;
      DoFTools::extract_locally_relevant_dofs(field.dof_handler, relevant);
      const IndexSet &owned = field.dof_handler.locally_owned_dofs();
      field.buffer.reinit(owned, relevant, comm);
      const auto &partitioner = *field.buffer.get_partitioner();

      std::vector<int>           box_of_local(owned.n_elements() + partitioner.n_ghost_indices(), -1);
      std::vector<unsigned char> seen(n_box_nodes, 0);
      field.ghost_nodes.clear();
      field.import_nodes.clear();
      // The triangulation keeps the geometry of the set-up.
      const Point<dim> &lower = initial_lattice.origin;
      const double      h     = initial_lattice.h[0];
      for (const auto &cell : field.dof_handler.active_cell_iterators())
        if (!cell->is_artificial())
          for (const unsigned int v : cell->vertex_indices())
            {
              std::array<int, dim> i;
              for (unsigned int d = 0; d < dim; ++d)
                i[d] = static_cast<int>(std::lround((cell->vertex(v)[d] - lower[d]) / h));
              const unsigned int n = local_node(i);
              if (seen[n])
                continue;
              seen[n]                         = 1;
              const types::global_dof_index g = cell->vertex_dof_index(v, 0);
              for (unsigned int c = 1; c < field.n_comp; ++c)
                Assert(cell->vertex_dof_index(v, c) == g + c, ExcInternalError());
              const bool is_owned = owned.is_element(g);
              if (set_node_flags)
                {
                  relevant_node[n] = 1;
                  owned_node[n]    = is_owned ? 1 : 0;
                }
              const unsigned int l = partitioner.global_to_local(g);
              box_of_local[l]      = n;
              if (!is_owned)
                field.ghost_nodes.emplace_back(n, l);
            }
      // Owned nodes that other ranks also touch: their sums arrive through compress().
      for (const auto &range : partitioner.import_indices())
        for (unsigned int l = range.first; l < range.second; ++l)
          if (box_of_local[l] >= 0)
            field.import_nodes.emplace_back(box_of_local[l], l);
      std::sort(field.import_nodes.begin(), field.import_nodes.end());
      field.import_nodes.erase(std::unique(field.import_nodes.begin(), field.import_nodes.end()),
                               field.import_nodes.end());
    }



    template <int dim>
    void
    BackgroundGrid<dim>::initialize_layer(const unsigned int n_blocks, const unsigned int block_size)
    {
      layer_blocks     = n_blocks;
      layer_block_size = block_size;
      layer.n_comp     = n_blocks * block_size;
      if (n_ranks > 1)
        connect(layer, false);
      layer_nodes.assign(std::size_t(n_box_nodes) * layer.n_comp, 0.0);
    }



    template <int dim>
    typename dealii::Triangulation<dim>::active_cell_iterator
    BackgroundGrid<dim>::cell_iterator(const unsigned int id) const
    {
      Assert(cell_index[id] >= 0, dealii::ExcInternalError());
      return typename dealii::Triangulation<dim>::active_cell_iterator(&tria, 0, cell_index[id]);
    }



    template <int dim>
    std::array<int, dim>
    BackgroundGrid<dim>::lattice_index(unsigned int n) const
    {
      std::array<int, dim> i;
      for (unsigned int d = 0; d < dim; ++d)
        {
          i[d] = box_low[d] + n % box_size[d];
          n /= box_size[d];
        }
      return i;
    }



    template <int dim>
    dealii::Point<dim>
    BackgroundGrid<dim>::node_position(const unsigned int n) const
    {
      const auto         i = lattice_index(n);
      dealii::Point<dim> x = grid_lattice.origin;
      for (unsigned int d = 0; d < dim; ++d)
        x[d] += i[d] * grid_lattice.h[d];
      return x;
    }



    template <int dim>
    void
    BackgroundGrid<dim>::add_shared(Field             &field,
                                    std::vector<double> &values,
                                    const unsigned int   first,
                                    const unsigned int   n,
                                    const unsigned int   n_blocks,
                                    const unsigned int   block_size)
    {
      // Ghost entries carry this rank's contributions (only the exchanged
      // components are non-zero), owned shared entries this rank's own part;
      // compress() adds the ghosts into their owners, update_ghost_values()
      // returns the sums. Components first + b * block_size + [0, n) of every
      // block b are exchanged.
      const unsigned int stride = field.n_comp;
      const auto         copy   = [&](const auto &list, const bool to_buffer) {
        for (const auto &[box, l] : list)
          for (unsigned int b = 0; b < n_blocks; ++b)
            for (unsigned int c = first + b * block_size; c < first + b * block_size + n; ++c)
              if (to_buffer)
                field.buffer.local_element(l + c) = values[std::size_t(box) * stride + c];
              else
                values[std::size_t(box) * stride + c] = field.buffer.local_element(l + c);
      };
      field.buffer.zero_out_ghost_values();
      copy(field.ghost_nodes, true);
      copy(field.import_nodes, true);
      field.buffer.compress(dealii::VectorOperation::add);
      field.buffer.update_ghost_values();
      copy(field.import_nodes, false);
      copy(field.ghost_nodes, false);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::exchange(const unsigned int first, const unsigned int n)
    {
      if (n_ranks > 1)
        add_shared(main, nodes, first, n, 1, n_comp);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::exchange_layer(const unsigned int first, const unsigned int n)
    {
      if (n_ranks > 1)
        add_shared(layer, layer_nodes, first, n, layer_blocks, layer_block_size);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::zero_interface(const unsigned int first, const unsigned int n)
    {
      for (const auto *list : {&main.ghost_nodes, &main.import_nodes})
        for (const auto &entry : *list)
          for (unsigned int c = first; c < first + n; ++c)
            nodes[std::size_t(entry.first) * n_comp + c] = 0.0;
    }



    template <int dim>
    void
    BackgroundGrid<dim>::zero_layer_interface(const unsigned int first, const unsigned int n)
    {
      for (const auto *list : {&layer.ghost_nodes, &layer.import_nodes})
        for (const auto &entry : *list)
          for (unsigned int b = 0; b < layer_blocks; ++b)
            for (unsigned int c = first + b * layer_block_size; c < first + b * layer_block_size + n; ++c)
              layer_nodes[std::size_t(entry.first) * layer.n_comp + c] = 0.0;
    }



    template class BackgroundGrid<2>;
    template class BackgroundGrid<3>;
  } // namespace MPM
} // namespace hysteron

#include <deal.II/base/index_set.h>
#include <deal.II/grid/grid_generator.h>

#include <hysteron/base/exceptions.h>
#include "mpm/grid.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <map>

namespace hysteron
{
  namespace MPM
  {
    namespace
    {
      /**
       * The coarse mesh of the blocks: r_d trees per direction, each refined L
       * times, with r_d 2^L >= n_d. The trees are replicated on every rank, the
       * refined blocks distributed, and the padding (r_d 2^L - n_d blocks) holds
       * no lattice cell and weighs nothing. The choice of L minimises
       * (trees) + (all blocks) / 64, i.e. a tree is counted as costly as 64 blocks
       * (it is kept on every rank); it depends on the lattice only, so that a
       * checkpoint's triangulation can be loaded on any number of ranks.
       */
      template <int dim>
      std::pair<std::array<unsigned int, dim>, unsigned int>
      coarse_mesh_of_blocks(const std::array<unsigned int, dim> &n)
      {
        std::array<unsigned int, dim> best_r{};
        unsigned int                  best_level = 0;
        double                        best_cost  = std::numeric_limits<double>::max();
        for (unsigned int level = 0; level < 20; ++level)
          {
            const unsigned int            side = 1u << level;
            std::array<unsigned int, dim> r;
            double                        trees = 1, blocks = 1;
            for (unsigned int d = 0; d < dim; ++d)
              {
                r[d] = (n[d] + side - 1) / side;
                trees *= r[d];
                blocks *= double(r[d]) * side;
              }
            const double cost = trees + blocks / 64;
            if (cost < best_cost)
              {
                best_cost  = cost;
                best_r     = r;
                best_level = level;
              }
            if (*std::max_element(r.begin(), r.end()) == 1)
              break;
          }
        return {best_r, best_level};
      }
    } // namespace



    template <int dim>
    BackgroundGrid<dim>::BackgroundGrid(MPI_Comm comm)
      : comm(comm)
      , n_ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
      , tria(comm)
    {}



    template <int dim>
    void
    BackgroundGrid<dim>::make_coarse_mesh(const dealii::Point<dim>            &lower,
                                          const double                          h,
                                          const std::array<unsigned int, dim> &n_cells,
                                          const unsigned int                    support_margin)
    {
      using namespace dealii;
      grid_lattice.origin  = lower;
      grid_lattice.h       = uniform_h<dim>(h);
      grid_lattice.n_cells = n_cells;
      initial_lattice      = grid_lattice;
      margin               = support_margin;

      for (unsigned int d = 0; d < dim; ++d)
        n_blocks[d] = (n_cells[d] + block_size() - 1) / block_size();
      const auto [trees, level] = coarse_mesh_of_blocks<dim>(n_blocks);
      coarse_level              = level;
      std::vector<unsigned int> repetitions(trees.begin(), trees.end());
      Point<dim>                upper = lower;
      for (unsigned int d = 0; d < dim; ++d)
        upper[d] += double(trees[d]) * (1u << level) * block_size() * h;
      tria.clear();
      GridGenerator::subdivided_hyper_rectangle(tria, repetitions, lower, upper);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::create(const dealii::Point<dim>            &lower,
                                const double                          h,
                                const std::array<unsigned int, dim> &n_cells,
                                const unsigned int                    support_margin)
    {
      make_coarse_mesh(lower, h, n_cells, support_margin);
      tria.refine_global(coarse_level);
      setup_blocks();
    }



    template <int dim>
    std::array<unsigned int, dim>
    BackgroundGrid<dim>::block_of_cell(const typename dealii::Triangulation<dim>::cell_iterator &cell) const
    {
      std::array<unsigned int, dim> b;
      const double                  side   = block_size() * initial_lattice.h[0];
      const dealii::Point<dim>      centre = cell->center();
      for (unsigned int d = 0; d < dim; ++d)
        b[d] = static_cast<unsigned int>(std::floor((centre[d] - initial_lattice.origin[d]) / side));
      return b;
    }



    template <int dim>
    void
    BackgroundGrid<dim>::setup_blocks()
    {
      using namespace dealii;
      // The box of the owned and ghost blocks that hold lattice cells.
      std::array<int, dim> low, high;
      low.fill(INT_MAX);
      high.fill(INT_MIN);
      std::vector<std::pair<CellId, std::array<unsigned int, dim>>> owned;
      for (const auto &cell : tria.active_cell_iterators())
        if (!cell->is_artificial())
          {
            const auto b = block_of_cell(cell);
            if (!in_lattice(b))
              continue;
            for (unsigned int d = 0; d < dim; ++d)
              {
                low[d]  = std::min<int>(low[d], b[d]);
                high[d] = std::max<int>(high[d], b[d] + 1);
              }
            if (cell->is_locally_owned())
              owned.emplace_back(cell->id(), b);
          }
      std::size_t n = 1;
      for (unsigned int d = 0; d < dim; ++d)
        {
          if (high[d] < low[d])
            low[d] = high[d] = 0;
          block_box_low[d]  = low[d];
          block_box_size[d] = high[d] - low[d];
          n *= block_box_size[d];
        }
      block_state.assign(n, no_block);
      block_owner.assign(n, 0);
      block_cell.assign(n, {-1, -1});
      for (const auto &cell : tria.active_cell_iterators())
        if (!cell->is_artificial())
          {
            const auto b = block_of_cell(cell);
            if (!in_lattice(b))
              continue;
            const int k    = local_block(b);
            block_state[k] = cell->is_locally_owned() ? owned_block : ghost_block;
            block_owner[k] = cell->subdomain_id();
            block_cell[k]  = {cell->level(), cell->index()};
          }
      // The owned blocks along the curve: CellIds compare as p4est orders its cells.
      std::sort(owned.begin(), owned.end(), [](const auto &a, const auto &b) { return a.first < b.first; });
      owned_block_list.clear();
      for (const auto &o : owned)
        owned_block_list.push_back(o.second);

      // The lattice cells of the owned blocks lie in this range.
      auto &[first, last] = owned_range;
      first.fill(UINT_MAX);
      last.fill(0);
      for (const auto &b : owned_block_list)
        for (unsigned int d = 0; d < dim; ++d)
          {
            first[d] = std::min(first[d], b[d] * block_size());
            last[d]  = std::max(last[d], std::min((b[d] + 1) * block_size(), grid_lattice.n_cells[d]) - 1);
          }
    }



    template <int dim>
    std::array<std::pair<int, int>, dim>
    BackgroundGrid<dim>::node_range(const std::array<unsigned int, dim> &b) const
    {
      // A block's cells' nodes and `margin` layers around them, within the lattice.
      std::array<std::pair<int, int>, dim> range;
      for (unsigned int d = 0; d < dim; ++d)
        {
          const int n = grid_lattice.n_cells[d];
          range[d]    = {std::max<int>(0, int(b[d] * block_size()) - int(margin)),
                         std::min<int>(n, std::min<int>(n, (b[d] + 1) * block_size()) + int(margin))};
        }
      return range;
    }



    template <int dim>
    void
    BackgroundGrid<dim>::setup_nodes(const unsigned int n_components)
    {
      n_comp = n_components;
      // The box of the nodes the owned blocks' points reach: a block's cells' nodes and
      // `margin` layers around them, within the lattice.
      std::array<int, dim> low, high;
      low.fill(INT_MAX);
      high.fill(INT_MIN);
      for (const auto &b : owned_block_list)
        {
          const auto range = node_range(b);
          for (unsigned int d = 0; d < dim; ++d)
            {
              low[d]  = std::min(low[d], range[d].first);
              high[d] = std::max(high[d], range[d].second);
            }
        }
      n_box_nodes = 1;
      for (unsigned int d = 0; d < dim; ++d)
        {
          if (high[d] < low[d])
            low[d] = high[d] = 0; // a rank without blocks: one node, never reached
          box_low[d]    = low[d];
          box_size[d]   = high[d] - low[d] + 1;
          box_stride[d] = n_box_nodes;
          n_box_nodes *= box_size[d];
        }
      // The box's arrays take memory only where the nodes this rank reaches lie; the
      // flags are bits (a row of the box in a few bytes).
      relevant_node.reset((n_box_nodes + 63) / 64);
      owned_node.reset((n_box_nodes + 63) / 64);
      // Reached: a block's range; owned: the nodes whose cell above lies in the block (the
      // last block also owns the lattice's upper faces). Bits set block by block, row by row.
      const auto mark = [&](ZeroPages<std::uint64_t> &bits, const std::array<std::pair<int, int>, dim> &range) {
        std::array<int, dim> i;
        for (unsigned int d = 0; d < dim; ++d)
          i[d] = range[d].first;
        while (true)
          {
            for (i[0] = range[0].first; i[0] <= range[0].second; ++i[0])
              set_bit(bits, local_node(i));
            unsigned int d = 1;
            for (; d < dim; ++d)
              if (++i[d] <= range[d].second)
                break;
              else
                i[d] = range[d].first;
            if (d >= dim)
              break;
          }
      };
      for (const auto &b : owned_block_list)
        {
          mark(relevant_node, node_range(b));
          std::array<std::pair<int, int>, dim> own;
          for (unsigned int d = 0; d < dim; ++d)
            own[d] = {int(b[d] * block_size()),
                      b[d] + 1 == n_blocks[d] ? int(grid_lattice.n_cells[d]) : int((b[d] + 1) * block_size()) - 1};
          mark(owned_node, own);
        }
      n_relevant = 0;
      for_each_relevant_node([&](const unsigned int) { ++n_relevant; });
      nodes.reset(std::size_t(n_box_nodes) * n_comp, sparse_box());
      if (n_ranks > 1)
        {
          number_nodes();
          main.n_comp = n_comp;
          connect(main);
        }
    }



    template <int dim>
    void
    BackgroundGrid<dim>::number_nodes()
    {
      using namespace dealii;
      // Only the nodes shared with other ranks go into the exchange's vector (a copy of
      // every node's values would double the grid's memory): a rank asks the owners of
      // the nodes it reaches but does not own for their numbers, and each owner numbers
      // the nodes it was asked for, rank by rank, in box order on each.
      owned_numbers.clear();
      ghost_numbers.clear();
      const auto lattice_node = [&](const std::array<int, dim> &i) {
        std::array<unsigned int, dim> u;
        for (unsigned int d = 0; d < dim; ++d)
          u[d] = i[d];
        return grid_lattice.node_number(u);
      };
      const auto owner_of = [&](const std::array<int, dim> &i) {
        std::array<unsigned int, dim> b;
        for (unsigned int d = 0; d < dim; ++d)
          b[d] = std::min<unsigned int>(i[d] / block_size(), n_blocks[d] - 1);
        const int k = local_block(b);
        AssertThrow(k >= 0 && block_state[k] == ghost_block,
                    ExcMessage("mpm grid: a reached node's block is not a ghost block"));
        return block_owner[k];
      };
      std::map<unsigned int, std::vector<unsigned int>> asked;
      std::vector<unsigned int>                         ghost_box_nodes;
      for_each_relevant_node([&](const unsigned int n) {
        if (!is_owned(n))
          ghost_box_nodes.push_back(n);
      });
      std::sort(ghost_box_nodes.begin(), ghost_box_nodes.end());
      for (const unsigned int n : ghost_box_nodes)
        {
          const auto i = lattice_index(n);
          asked[owner_of(i)].push_back(lattice_node(i));
        }
      const auto answers = Utilities::MPI::some_to_some(comm, asked);
      const auto box_node_of = [&](const unsigned int node) {
        const auto           u = grid_lattice.node_index(node);
        std::array<int, dim> i;
        for (unsigned int d = 0; d < dim; ++d)
          i[d] = u[d];
        const unsigned int n = local_node(i);
        AssertThrow(is_owned(n), ExcMessage("mpm grid: a node asked for is not owned here"));
        return n;
      };
      std::vector<unsigned int> shared;
      for (const auto &[rank, list] : answers)
        for (const unsigned int node : list)
          shared.push_back(box_node_of(node));
      std::sort(shared.begin(), shared.end());
      shared.erase(std::unique(shared.begin(), shared.end()), shared.end());
      const std::uint64_t n_owned = shared.size();
      std::uint64_t       first   = 0;
      const int ierr = MPI_Exscan(&n_owned, &first, 1, MPI_UINT64_T, MPI_SUM, comm);
      AssertThrowMPI(ierr);
      if (Utilities::MPI::this_mpi_process(comm) == 0)
        first = 0;
      n_global_nodes     = Utilities::MPI::sum(n_owned, comm);
      first_owned_number = static_cast<unsigned int>(first);
      for (unsigned int k = 0; k < shared.size(); ++k)
        owned_numbers.emplace_back(shared[k], first_owned_number + k);
      std::map<unsigned int, std::vector<unsigned int>> replies;
      for (const auto &[rank, list] : answers)
        {
          auto &reply = replies[rank];
          for (const unsigned int node : list)
            {
              const auto it = std::lower_bound(owned_numbers.begin(),
                                               owned_numbers.end(),
                                               std::make_pair(box_node_of(node), 0u));
              reply.push_back(it->second);
            }
        }
      const auto numbers = Utilities::MPI::some_to_some(comm, replies);
      // The replies come in the order of the questions, rank by rank.
      std::map<unsigned int, std::size_t> next;
      for (const unsigned int n : ghost_box_nodes)
        {
          const unsigned int rank = owner_of(lattice_index(n));
          ghost_numbers.emplace_back(n, numbers.at(rank)[next[rank]++]);
        }
    }



    template <int dim>
    void
    BackgroundGrid<dim>::connect(Field &field) const
    {
      using namespace dealii;
      field.ghost_nodes.clear();
      field.import_nodes.clear();
      if (n_global_nodes == 0)
        return; // no node is shared: nothing to exchange (and no vector of size 0)
      const std::uint64_t size = n_global_nodes * field.n_comp;
      AssertThrow(size < std::numeric_limits<types::global_dof_index>::max(),
                  ExcMessage("mpm grid: " + std::to_string(n_global_nodes) + " nodes x " +
                             std::to_string(field.n_comp) +
                             " values exceed the 32-bit index of this deal.II build"));
      IndexSet owned(size), ghosts(size);
      owned.add_range(std::uint64_t(first_owned_number) * field.n_comp,
                      (std::uint64_t(first_owned_number) + owned_numbers.size()) * field.n_comp);
      std::vector<types::global_dof_index> ghost_indices;
      ghost_indices.reserve(ghost_numbers.size() * field.n_comp);
      for (const auto &g : ghost_numbers)
        for (unsigned int c = 0; c < field.n_comp; ++c)
          ghost_indices.push_back(std::uint64_t(g.second) * field.n_comp + c);
      std::sort(ghost_indices.begin(), ghost_indices.end());
      ghosts.add_indices(ghost_indices.begin(), ghost_indices.end());
      field.buffer.reinit(owned, ghosts, comm);
      const auto &partitioner = *field.buffer.get_partitioner();

      for (const auto &g : ghost_numbers)
        field.ghost_nodes.emplace_back(g.first,
                                       partitioner.global_to_local(std::uint64_t(g.second) * field.n_comp));
      // Owned nodes that other ranks also reach: their sums arrive through compress().
      for (const auto &range : partitioner.import_indices())
        for (unsigned int l = range.first; l < range.second; ++l)
          {
            const unsigned int k = l / field.n_comp;
            field.import_nodes.emplace_back(owned_numbers[k].first, k * field.n_comp);
          }
      std::sort(field.import_nodes.begin(), field.import_nodes.end());
      field.import_nodes.erase(std::unique(field.import_nodes.begin(), field.import_nodes.end()),
                               field.import_nodes.end());
    }



    template <int dim>
    void
    BackgroundGrid<dim>::initialize_layer(const unsigned int n_blocks_per_node, const unsigned int size_of_block)
    {
      layer_blocks     = n_blocks_per_node;
      layer_block_size = size_of_block;
      layer.n_comp     = n_blocks_per_node * size_of_block;
      if (n_ranks > 1)
        connect(layer);
      layer_nodes.reset(std::size_t(n_box_nodes) * layer.n_comp, sparse_box());
    }



    template <int dim>
    typename dealii::Triangulation<dim>::active_cell_iterator
    BackgroundGrid<dim>::cell_iterator(const std::array<unsigned int, dim> &c) const
    {
      const int k = local_block(block_of(c));
      Assert(k >= 0 && block_cell[k].first >= 0, dealii::ExcInternalError());
      return typename dealii::Triangulation<dim>::active_cell_iterator(&tria,
                                                                       block_cell[k].first,
                                                                       block_cell[k].second);
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
                                    ZeroPages<double> &values,
                                    const unsigned int   first,
                                    const unsigned int   n,
                                    const unsigned int   n_blocks_per_node,
                                    const unsigned int   size_of_block)
    {
      // Ghost entries carry this rank's contributions (only the exchanged
      // components are non-zero), owned shared entries this rank's own part;
      // compress() adds the ghosts into their owners, update_ghost_values()
      // returns the sums. Components first + b * block_size + [0, n) of every
      // block b are exchanged.
      // Owned shared nodes get their sums whether this rank reaches them or not (their
      // reactions are counted here); the other ranks' nodes only where a point of this
      // rank reaches them.
      const unsigned int stride = field.n_comp;
      const auto         copy   = [&](const auto &list, const bool to_buffer, const bool reached_only) {
        for (const auto &[box, l] : list)
          if (!reached_only || reached_stamps == nullptr || reached_stamps[box] == *current_stamp)
            for (unsigned int b = 0; b < n_blocks_per_node; ++b)
              for (unsigned int c = first + b * size_of_block; c < first + b * size_of_block + n; ++c)
                {
                  if (to_buffer)
                    field.buffer.local_element(l + c) = values[std::size_t(box) * stride + c];
                  else if (double &v = values[std::size_t(box) * stride + c]; v != field.buffer.local_element(l + c))
                    v = field.buffer.local_element(l + c); // a zero stays unwritten: no page
                }
      };
      field.buffer.zero_out_ghost_values();
      copy(field.ghost_nodes, true, true);
      copy(field.import_nodes, true, false);
      field.buffer.compress(dealii::VectorOperation::add);
      field.buffer.update_ghost_values();
      copy(field.import_nodes, false, false);
      copy(field.ghost_nodes, false, true);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::exchange(const unsigned int first, const unsigned int n)
    {
      if (n_ranks > 1 && n_global_nodes > 0)
        add_shared(main, nodes, first, n, 1, n_comp);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::exchange_layer(const unsigned int first, const unsigned int n)
    {
      if (n_ranks > 1 && n_global_nodes > 0)
        add_shared(layer, layer_nodes, first, n, layer_blocks, layer_block_size);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::zero_interface(const unsigned int first, const unsigned int n)
    {
      // Only what is not zero: a page never written stays unmapped.
      for (const auto &entry : main.import_nodes)
        for (unsigned int c = first; c < first + n; ++c)
          if (double &v = nodes[std::size_t(entry.first) * n_comp + c]; v != 0.0)
            v = 0.0;
    }



    template <int dim>
    void
    BackgroundGrid<dim>::zero_layer_interface(const unsigned int first, const unsigned int n)
    {
      for (const auto &entry : layer.import_nodes)
        for (unsigned int b = 0; b < layer_blocks; ++b)
          for (unsigned int c = first + b * layer_block_size; c < first + b * layer_block_size + n; ++c)
            if (double &v = layer_nodes[std::size_t(entry.first) * layer.n_comp + c]; v != 0.0)
              v = 0.0;
    }



    template <int dim>
    std::size_t
    BackgroundGrid<dim>::memory_consumption() const
    {
      // The box's arrays hold pages where the reached nodes lie: count those nodes.
      std::size_t bytes = n_relevant * n_comp * sizeof(double) + n_box_nodes / 4 +
                          (layer_nodes.size() > 0 ? n_relevant * layer.n_comp * sizeof(double) : 0) +
                          block_state.capacity() + block_owner.capacity() * sizeof(unsigned int) +
                          block_cell.capacity() * sizeof(std::pair<int, int>) +
                          (owned_numbers.capacity() + ghost_numbers.capacity()) *
                            sizeof(std::pair<unsigned int, unsigned int>);
      for (const Field *f : {&main, &layer})
        bytes += f->buffer.memory_consumption() +
                 (f->ghost_nodes.capacity() + f->import_nodes.capacity()) *
                   sizeof(std::pair<unsigned int, unsigned int>);
      return bytes;
    }



    template class BackgroundGrid<2>;
    template class BackgroundGrid<3>;
  } // namespace MPM
} // namespace hysteron

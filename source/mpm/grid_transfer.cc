// The grid's blocks on the move: the partition's weight and a caller's data attached to
// each block's p4est cell, for checkpoints (save, load on any number of ranks) and for
// repartitioning by weights.
#include "mpm/grid.h"

#include <cstring>
#include <map>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    std::pair<unsigned int, unsigned int>
    BackgroundGrid<dim>::attach(const BlockPacker &pack)
    {
      using namespace dealii;
      using cell_iterator = typename Triangulation<dim>::cell_iterator;
      using CellStatus    = typename Triangulation<dim>::CellStatus;
      // The partition's weight of each block (4 bytes), then the caller's data.
      const unsigned int weights = tria.register_data_attach(
        [this](const cell_iterator &cell, const CellStatus) {
          const auto    it = block_weight.find(block_of_cell(cell));
          std::uint32_t w  = it == block_weight.end() ? 0 : it->second;
          return std::vector<char>(reinterpret_cast<const char *>(&w), reinterpret_cast<const char *>(&w) + 4);
        },
        /*returns_variable_size_data=*/false);
      const unsigned int data = tria.register_data_attach(
        [this, pack](const cell_iterator &cell, const CellStatus) {
          const auto b = block_of_cell(cell);
          return in_lattice(b) && pack ? pack(b) : std::vector<char>();
        },
        /*returns_variable_size_data=*/true);
      return {weights, data};
    }



    template <int dim>
    void
    BackgroundGrid<dim>::receive(const std::pair<unsigned int, unsigned int> &handles, const BlockUnpacker &unpack)
    {
      using namespace dealii;
      using cell_iterator = typename Triangulation<dim>::cell_iterator;
      using CellStatus    = typename Triangulation<dim>::CellStatus;
      using Range         = boost::iterator_range<std::vector<char>::const_iterator>;
      block_weight.clear();
      tria.notify_ready_to_unpack(handles.first, [this](const cell_iterator &cell, const CellStatus, const Range &data) {
        std::uint32_t w = 0;
        if (data.size() == 4)
          std::memcpy(&w, &*data.begin(), 4);
        const auto b = block_of_cell(cell);
        if (in_lattice(b))
          block_weight[b] = w;
      });
      tria.notify_ready_to_unpack(handles.second, [&](const cell_iterator &cell, const CellStatus, const Range &data) {
        const auto b = block_of_cell(cell);
        if (in_lattice(b) && unpack)
          unpack(b, data);
      });
    }



    template <int dim>
    void
    BackgroundGrid<dim>::save(const std::string &file, const BlockPacker &pack)
    {
      attach(pack);
      tria.save(file);
    }



    template <int dim>
    void
    BackgroundGrid<dim>::load(const dealii::Point<dim>            &lower,
                              const double                          h,
                              const std::array<unsigned int, dim> &n_cells,
                              const unsigned int                    support_margin,
                              const std::string                    &file,
                              const bool                            same_ranks,
                              const BlockUnpacker                  &unpack)
    {
      make_coarse_mesh(lower, h, n_cells, support_margin);
      tria.load(file);
      // p4est loads its cells in equal numbers: on as many ranks as the checkpoint's,
      // the saved weights give back the saved partition (p4est's partition is a function
      // of the weights along its curve).
      std::map<std::array<unsigned int, dim>, std::vector<char>> data;
      const auto keep = [&](const std::array<unsigned int, dim>                              &block,
                            const boost::iterator_range<std::vector<char>::const_iterator> &bytes) {
        data[block].assign(bytes.begin(), bytes.end());
      };
      receive(attach({}), keep);
      bool weighted = false;
      for (const auto &w : block_weight)
        weighted = weighted || w.second > 0;
      weighted = dealii::Utilities::MPI::logical_or(weighted, comm);
      if (same_ranks && weighted && n_ranks > 1)
        {
          const auto saved = block_weight;
          std::map<std::array<unsigned int, dim>, std::vector<char>> moving;
          moving.swap(data);
          repartition(
            [&](const std::array<unsigned int, dim> &b) {
              const auto it = saved.find(b);
              return it == saved.end() ? 0u : it->second;
            },
            [&](const std::array<unsigned int, dim> &b) {
              const auto it = moving.find(b);
              return it == moving.end() ? std::vector<char>() : it->second;
            },
            keep);
        }
      else
        setup_blocks();
      for (const auto &[block, bytes] : data)
        unpack(block, boost::make_iterator_range(bytes.cbegin(), bytes.cend()));
    }



    template <int dim>
    void
    BackgroundGrid<dim>::repartition(
      const std::function<unsigned int(const std::array<unsigned int, dim> &)> &weight,
      const BlockPacker                                                        &pack,
      const BlockUnpacker                                                      &unpack)
    {
      using namespace dealii;
      if (n_ranks == 1)
        return;
      // p4est adds up these weights along its space-filling curve; each block's weight and
      // data (if any) move with it, so that a checkpoint can restore this partition.
      block_weight.clear();
      for (const auto &cell : tria.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const auto b = block_of_cell(cell);
            if (in_lattice(b))
              block_weight[b] = weight(b);
          }
      auto connection = tria.signals.weight.connect(
        [&](const typename Triangulation<dim>::cell_iterator &cell,
            const typename Triangulation<dim>::CellStatus) -> unsigned int {
          const auto it = block_weight.find(block_of_cell(cell));
          return it == block_weight.end() ? 0u : it->second;
        });
      const auto handles = attach(pack);
      tria.repartition();
      connection.disconnect();
      receive(handles, unpack);
      setup_blocks();
    }



    template class BackgroundGrid<2>;
    template class BackgroundGrid<3>;
  } // namespace MPM
} // namespace hysteron

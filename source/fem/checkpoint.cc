// The FEM's part of a checkpoint, readable on any number of ranks:
//  - one record per active cell, keyed by its CellId (the same on any number of ranks:
//    the mesh is built anew from the scene), with the cell's values of every state
//    vector and its converged quadrature-point history (CellHistory::serialize);
//  - the global state (step control, counters, tables), and each rank's partial sums
//    (the works, the walls' forces).
// A resumed run puts each owned cell's values back into the owned entries of the
// vectors (every owned DoF lies in an owned cell, and the cells that share it hold
// the same value), so the state is the checkpoint's bit for bit on any partition; on
// another number of ranks the partial sums are gathered on rank 0.
#include <hysteron/fem/fem.h>

#include "run/keyed_records.h"
#include "run/rank_parts.h"

#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      /**
       * A key of an active cell that is the same on any number of ranks and dense:
       * coarse cell c at refinement level L with child indices i_1 ... i_L is
       * c 2^(dim L) + sum_k i_k 2^(dim (L - k)) (every active cell is on level L: the
       * mesh is refined globally).
       */
      std::uint64_t
      cell_key(const dealii::CellId &id, const unsigned int dim, const unsigned int level)
      {
        std::uint64_t key = id.get_coarse_cell_id();
        for (const auto child : id.get_child_indices())
          key = (key << dim) | child;
        return key << (dim * (level - id.get_child_indices().size()));
      }
    } // namespace



    template <int dim>
    template <class Archive>
    void
    Solver<dim>::serialize_global(Archive &ar)
    {
      ar.section("fem");
      auto increment_state = increments.state();
      ar &force_scale &last_force_level &predictor_level &current_dt &initial_kinetic &n_newton &n_cuts &n_linear
        &increment_state &step_checked;
      if constexpr (Archive::is_loading)
        increments.restore(increment_state);
      tables.serialize(ar);
    }



    template <int dim>
    template <class Archive>
    void
    Solver<dim>::serialize_rank(Archive &ar)
    {
      ar.section("fem rank");
      ar &internal_work &external_work &boundary_work &wall_forces;
    }



    template <int dim>
    void
    Solver<dim>::save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const
    {
      auto &self = const_cast<Solver<dim> &>(*this); // serialize() only reads when saving
      self.serialize_global(global);
      self.serialize_rank(rank);

      // The cells' values of the vectors need their ghost entries.
      MPI_Comm                           comm = this->get_scene().mpi_communicator();
      std::vector<dealii::TrilinosWrappers::MPI::Vector> ghosted;
      for (Vector *x : self.state_vectors())
        {
          ghosted.emplace_back(owned_dofs, relevant_dofs, comm);
          ghosted.back() = *x;
        }
      const unsigned int level = triangulation->n_global_levels() - 1;
      std::vector<std::pair<std::uint64_t, std::string>> records;
      std::vector<dealii::types::global_dof_index>       dofs(fe->n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            std::ostringstream bytes;
            CheckpointWriter   out(bytes);
            cell->get_dof_indices(dofs);
            for (const auto &x : ghosted)
              for (const auto i : dofs)
                out.put(x(i));
            out & *cell_history[cell->active_cell_index()];
            records.emplace_back(cell_key(cell->id(), dim, level), bytes.str());
          }
      const std::uint64_t n_keys = std::uint64_t(triangulation->n_global_coarse_cells()) << (dim * level);
      Run::write_records(directory.file("cells"), n_keys, records, comm);
    }



    template <int dim>
    void
    Solver<dim>::load(CheckpointReader              &global,
                      std::vector<CheckpointReader> &rank_parts,
                      const CheckpointDirectory     &directory)
    {
      serialize_global(global);
      if (directory.same_ranks())
        serialize_rank(rank_parts[0]);
      else
        {
          Run::sum_rank_parts(rank_parts, this->get_scene().is_root(),
                              [this](CheckpointReader &part) { serialize_rank(part); },
                              internal_work, external_work, boundary_work, wall_forces);
        }

      const unsigned int                   level = triangulation->n_global_levels() - 1;
      std::vector<std::uint64_t>           keys;
      std::vector<typename dealii::DoFHandler<dim>::active_cell_iterator> cells;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            keys.push_back(cell_key(cell->id(), dim, level));
            cells.push_back(cell);
          }
      const auto records = Run::read_records(directory.file("cells"), keys, this->get_scene().mpi_communicator());
      const auto vectors = state_vectors();
      std::vector<dealii::types::global_dof_index> dofs(fe->n_dofs_per_cell());
      Run::parse_collectively(this->get_scene().mpi_communicator(), [&]() {
        for (std::size_t k = 0; k < cells.size(); ++k)
          {
            std::istringstream bytes(records[k]);
            CheckpointReader   in(bytes, directory.file("cells"));
            cells[k]->get_dof_indices(dofs);
            for (Vector *x : vectors)
              for (const auto i : dofs)
                {
                  const double value = in.get<double>();
                  if (owned_dofs.is_element(i))
                    (*x)(i) = value;
                }
            CellHistory<dim> &h       = *cell_history[cells[k]->active_cell_index()];
            const std::size_t n_q     = h.stress.size();
            const std::size_t n_state = h.state.size();
            in &h;
            if (h.stress.size() != n_q || h.strain.size() != n_q || h.state.size() != n_state ||
                h.volume.size() != n_q || h.tangent.size() != n_q || !in.at_end())
              in.refuse("a cell's state has another size than the scene's (another mesh, element or material)");
            h.trial_volume = h.volume;
          }
      });
      for (Vector *x : vectors)
        x->compress(dealii::VectorOperation::insert);
      u_ghost = u;
      v_ghost = v;
      a_ghost = a;
    }

    template void Solver<2>::save(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &) const;
    template void Solver<3>::save(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &) const;
    template void Solver<2>::load(CheckpointReader &, std::vector<CheckpointReader> &, const CheckpointDirectory &);
    template void Solver<3>::load(CheckpointReader &, std::vector<CheckpointReader> &, const CheckpointDirectory &);
  } // namespace FEM
} // namespace hysteron

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
#include "fem/fem.h"

#include "run/record_archive.h"
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

      /// The locally owned active cells and their keys, in the DoF handler's order.
      template <int dim>
      std::pair<std::vector<std::uint64_t>, std::vector<typename dealii::DoFHandler<dim>::active_cell_iterator>>
      owned_cells(const dealii::DoFHandler<dim> &dof_handler)
      {
        const auto        &triangulation = dof_handler.get_triangulation();
        const unsigned int level         = triangulation.n_global_levels() - 1;
        std::pair<std::vector<std::uint64_t>, std::vector<typename dealii::DoFHandler<dim>::active_cell_iterator>> owned;
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              owned.first.push_back(cell_key(cell->id(), dim, level));
              owned.second.push_back(cell);
            }
        return owned;
      }

      /// The format of what this file stores: raise it with every change of a description below.
      constexpr std::uint32_t format = 3;

      /**
       * One cell's record, for save and load alike: the cell's values of the
       * @p n_vectors state vectors at its @p dofs, then its quadrature points' history.
       * @p vectors gives get(j, i) (saving) and set(j, i, value) (loading) of entry i of
       * vector j.
       */
      template <class Archive, class Vectors, int dim>
      void
      serialize_cell(Archive                                            &ar,
                     const std::vector<dealii::types::global_dof_index> &dofs,
                     Vectors                                            &vectors,
                     CellHistory<dim>                                   &h)
      {
        for (unsigned int j = 0; j < vectors.size(); ++j)
          for (const auto i : dofs)
            {
              double value = 0;
              if constexpr (!Archive::is_loading)
                value = vectors.get(j, i);
              ar &value;
              if constexpr (Archive::is_loading)
                vectors.set(j, i, value);
            }
        const std::size_t n_q = h.stress.size(), n_state = h.state.size();
        ar               &h;
        if constexpr (Archive::is_loading)
          {
            if (h.stress.size() != n_q || h.strain.size() != n_q || h.state.size() != n_state ||
                h.volume.size() != n_q || h.tangent.size() != n_q)
              ar.refuse("a cell's state has another size than the scene's (another mesh, element or material)");
            h.trial_volume = h.volume;
          }
      }
    } // namespace



    template <int dim>
    template <class Archive>
    void
    Solver<dim>::serialize_global(Archive &ar)
    {
      ar.section("fem", format);
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
      ar.section("fem rank", format);
      ar &internal_work &external_work &boundary_work &wall_forces &damping_work;
    }



    template <int dim>
    void
    Solver<dim>::save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const
    {
      auto &self = const_cast<Solver<dim> &>(*this); // serialize() only reads when saving
      self.serialize_global(global);
      self.serialize_rank(rank);

      // The cells' values of the vectors need their ghost entries.
      MPI_Comm comm = this->get_scene().mpi_communicator();
      struct Ghosted
      {
        std::vector<dealii::TrilinosWrappers::MPI::Vector> x;
        std::size_t
        size() const
        {
          return x.size();
        }
        double
        get(const unsigned int j, const dealii::types::global_dof_index i) const
        {
          return x[j](i);
        }
      } ghosted;
      for (Vector *x : self.state_vectors())
        {
          ghosted.x.emplace_back(owned_dofs, relevant_dofs, comm);
          ghosted.x.back() = *x;
        }
      const auto owned = owned_cells(dof_handler);
      const auto &keys = owned.first;
      const auto &cells = owned.second;
      std::vector<dealii::types::global_dof_index> dofs(fe->n_dofs_per_cell());
      const unsigned int level  = triangulation->n_global_levels() - 1;
      const std::uint64_t n_keys = std::uint64_t(triangulation->n_global_coarse_cells()) << (dim * level);
      Run::save_records(directory.file("cells"), n_keys, keys, comm, [&](CheckpointWriter &out, const std::size_t k) {
        cells[k]->get_dof_indices(dofs);
        serialize_cell(out, dofs, ghosted, *cell_history[cells[k]->active_cell_index()]);
      });
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
                              internal_work, external_work, boundary_work, wall_forces, damping_work);
        }

      // Each owned cell's values go into the owned entries (the cells that share a DoF
      // hold the same value).
      struct Owned
      {
        std::array<Vector *, 10> x;
        const dealii::IndexSet  &owned;
        std::size_t
        size() const
        {
          return x.size();
        }
        void
        set(const unsigned int j, const dealii::types::global_dof_index i, const double value)
        {
          if (owned.is_element(i))
            (*x[j])(i) = value;
        }
      } vectors{state_vectors(), owned_dofs};
      const auto owned = owned_cells(dof_handler);
      const auto &keys = owned.first;
      const auto &cells = owned.second;
      std::vector<dealii::types::global_dof_index> dofs(fe->n_dofs_per_cell());
      Run::load_records(directory.file("cells"), keys, this->get_scene().mpi_communicator(),
                        [&](CheckpointReader &in, const std::size_t k) {
                          cells[k]->get_dof_indices(dofs);
                          serialize_cell(in, dofs, vectors, *cell_history[cells[k]->active_cell_index()]);
                        });
      for (Vector *x : vectors.x)
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

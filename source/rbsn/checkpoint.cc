// The RBSN's part of a checkpoint, readable on any number of ranks:
//  - one record per cell, keyed by its global number (the same on any number of
//    ranks: the same parameters and Random seed give the same network), with the
//    cell's values of the DoF vectors and the springs of the facets it owns (those
//    whose other cell has the higher number), each marked with that other cell;
//  - the global state (step control, counters, works, tables);
//  - each rank's incrementally assembled tangent (its rows of the matrix), used only
//    on as many ranks: on another number the first step assembles it anew.
#include "rbsn/model.h"

#include <Epetra_CrsMatrix.h>

#include "run/record_archive.h"

#include <map>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /// The format of what this file stores: raise it with every change of a description below.
      constexpr std::uint32_t format = 3;

      /// A facet's springs: the converged and trial state and the tangent.
      template <int dim, class Archive, class SpringsType>
      void
      serialize_springs(Archive &ar, SpringsType &sp)
      {
        ar &sp.delta &sp.force &sp.trial_delta &sp.trial_force &sp.state &sp.trial_state &sp.tangent &sp.broken;
      }
    } // namespace



    template <int dim>
    template <class Archive>
    void
    Model<dim>::serialize_global(Archive &ar)
    {
      ar.section("rbsn", format);
      // Not the count of factorizations: it counts this process's work (a resumed run
      // factorizes its first matrix anew), not state.
      auto increment_state = increments.state();
      ar &force_scale &last_force_level &predictor_level &internal_work &external_work &boundary_work &n_ida_steps
        &n_newton &n_broken &n_cuts &increment_state &fracture_energy &damping_work;
      if constexpr (Archive::is_loading)
        increments.restore(increment_state);
      tables.serialize(ar);
    }



    template <int dim>
    template <class Archive>
    void
    Model<dim>::serialize_cell(Archive &ar, const unsigned int c)
    {
      // The cell's values of the DoF vectors.
      for (Vector *x : {&u, &u_trial, &v, &a, &f_int, &f_ext, &f_ext_old, &inertia, &reaction_old})
        for (unsigned int k = 0; k < n_dofs; ++k)
          ar &x->local_element(n_dofs * c + k);

      // The springs of the facets it owns, each marked with its other cell: the local
      // order of the facets may differ on another partition.
      const std::string cell = "cell " + std::to_string(cell_id[c]);
      std::map<std::uint64_t, unsigned int> facet_of;
      for (unsigned int e = owned_facet_start[c]; e < owned_facet_start[c + 1]; ++e)
        facet_of[cell_id[network.facets[e].b]] = e;
      std::uint64_t n_facets = owned_facet_start[c + 1] - owned_facet_start[c];
      ar &n_facets;
      if constexpr (Archive::is_loading)
        if (n_facets != facet_of.size())
          ar.refuse(cell + " has another number of facets than in the checkpoint (the same parameters and "
                    "Random seed give the same network)");
      for (std::uint64_t f = 0; f < n_facets; ++f)
        {
          std::uint64_t other = Archive::is_loading ? 0 : cell_id[network.facets[owned_facet_start[c] + f].b];
          ar           &other;
          const auto    found = facet_of.find(other);
          if (found == facet_of.end())
            {
              if constexpr (Archive::is_loading)
                ar.refuse(cell + " has other neighbours than in the checkpoint");
            }
          else
            {
              auto             &sp      = springs[found->second];
              const std::size_t n_state = sp.state.size();
              serialize_springs<dim>(ar, sp);
              if constexpr (Archive::is_loading)
                if (sp.state.size() != n_state || sp.trial_state.size() != n_state)
                  ar.refuse("the facets' spring states differ from the checkpoint's (another RBSN/Spring law or "
                            "Analysis)");
            }
        }
    }



    template <int dim>
    template <class Archive>
    void
    Model<dim>::serialize_tangent(Archive &ar)
    {
      // The incrementally assembled tangent: which facets' tangents it holds, and its values.
      ar.section("rbsn assembled tangent", format);
      ar &matrix_current &matrix_dt &incremental_updates;
      if (!matrix_current)
        return;
      std::vector<double> values;
      if constexpr (!Archive::is_loading)
        values = matrix_values();
      ar &facet_in_matrix &assembled_tangent &values;
      if constexpr (Archive::is_loading)
        {
          if (facet_in_matrix.size() != springs.size() || assembled_tangent.size() != springs.size())
            ar.refuse("the checkpoint's assembled tangent does not match the network");
          set_matrix_values(values);
        }
    }



    template <int dim>
    void
    Model<dim>::save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const
    {
      auto &self = const_cast<Model<dim> &>(*this); // serialize() only reads when saving
      self.serialize_global(global);
      self.serialize_tangent(rank);
      // A replicated network (every rank holds all of it) is written by rank 0.
      const MPI_Comm             comm = scene().mpi_communicator();
      std::vector<std::uint64_t> keys;
      if (distributed() || dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        keys.assign(cell_id.begin(), cell_id.begin() + n_owned_cells);
      Run::save_records(directory.file("cells"), n_cells, keys, comm,
                        [&](CheckpointWriter &out, const std::size_t c) { self.serialize_cell(out, c); });
    }



    template <int dim>
    void
    Model<dim>::load(CheckpointReader              &global,
                     std::vector<CheckpointReader> &rank_parts,
                     const CheckpointDirectory     &directory)
    {
      serialize_global(global);
      const std::vector<std::uint64_t> keys(cell_id.begin(), cell_id.begin() + n_owned_cells);
      Run::load_records(directory.file("cells"), keys, scene().mpi_communicator(),
                        [&](CheckpointReader &in, const std::size_t c) { serialize_cell(in, c); });
      for (Vector *x : {&u, &u_trial, &v, &a})
        x->update_ghost_values();
      update_fragments(); // from the broken facets

      // The tangent of as many ranks only: on another partition the first step assembles anew.
      matrix_current = false;
      if (directory.same_ranks())
        serialize_tangent(rank_parts[0]);
    }



    namespace
    {
      /// Every stored value of the system matrix (this rank's rows of the Trilinos matrix,
      /// or the serial matrix), in the pattern's order: @p visit gets a reference to it.
      template <typename SerialMatrix, typename Visit>
      void
      for_each_matrix_value(const bool                                    trilinos,
                            const dealii::TrilinosWrappers::SparseMatrix &parallel,
                            SerialMatrix                                 &serial,
                            Visit                                         visit)
      {
        if (!trilinos)
          {
            for (auto &entry : serial)
              visit(entry.value());
            return;
          }
        const Epetra_CrsMatrix &A = parallel.trilinos_matrix();
        for (int row = 0; row < A.NumMyRows(); ++row)
          {
            int     n = 0;
            double *a = nullptr;
            A.ExtractMyRowView(row, n, a);
            for (int j = 0; j < n; ++j)
              visit(a[j]);
          }
      }
    } // namespace



    template <int dim>
    std::vector<double>
    Model<dim>::matrix_values() const
    {
      std::vector<double> values;
      for_each_matrix_value(trilinos_system(), parallel_matrix, matrix, [&](const double v) { values.push_back(v); });
      return values;
    }



    template <int dim>
    void
    Model<dim>::set_matrix_values(const std::vector<double> &values)
    {
      // The pattern is rebuilt by set-up as it was: the values go back in the same order.
      std::size_t k     = 0;
      const auto  error = RuntimeError("the checkpoint's tangent matrix does not match the network's pattern");
      for_each_matrix_value(trilinos_system(), parallel_matrix, matrix, [&](auto &&v) {
        if (k >= values.size())
          throw error;
        v = values[k++];
      });
      if (k != values.size())
        throw error;
    }

    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

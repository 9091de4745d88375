// The RBSN's part of a checkpoint, readable on any number of ranks:
//  - one record per cell, keyed by its global number (the same on any number of
//    ranks: the same parameters and Random seed give the same network), with the
//    cell's values of the DoF vectors and the springs of the facets it owns (those
//    whose other cell has the higher number), each marked with that other cell;
//  - the global state (step control, counters, works, tables);
//  - each rank's incrementally assembled tangent (its rows of the matrix), used only
//    on as many ranks: on another number the first step assembles it anew.
#include <hysteron/rbsn/model.h>

#include <Epetra_CrsMatrix.h>

#include "run/keyed_records.h"

#include <map>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
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
      ar.section("rbsn");
      auto increment_state = increments.state();
      ar &force_scale &last_force_level &predictor_level &internal_work &external_work &boundary_work &n_steps
        &n_newton &n_broken &n_cuts &increment_state &fracture_energy &n_factorizations;
      if constexpr (Archive::is_loading)
        increments.restore(increment_state);
      tables.serialize(ar);
    }



    template <int dim>
    void
    Model<dim>::save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const
    {
      auto &self = const_cast<Model<dim> &>(*this); // serialize() only reads when saving
      self.serialize_global(global);

      // The incrementally assembled tangent: which facets' tangents it holds, and its values.
      rank.section("rbsn assembled tangent");
      rank.put(matrix_current);
      rank.put(matrix_dt);
      rank.put(incremental_updates);
      if (matrix_current)
        {
          rank.put(facet_in_matrix);
          rank.put(assembled_tangent);
          rank.put(matrix_values());
        }

      // A replicated network (every rank holds all of it) is written by rank 0.
      const MPI_Comm comm = scene.mpi_communicator();
      std::vector<std::pair<std::uint64_t, std::string>> records;
      if (distributed() || dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        for (unsigned int c = 0; c < n_owned_cells; ++c)
          {
            std::ostringstream bytes;
            CheckpointWriter   out(bytes);
            for (const Vector *x : {&u, &u_trial, &v, &a, &f_int, &f_ext, &f_ext_old, &inertia, &reaction_old})
              for (unsigned int k = 0; k < n_dofs; ++k)
                out.put(x->local_element(n_dofs * c + k));
            out.put<std::uint64_t>(owned_facet_start[c + 1] - owned_facet_start[c]);
            for (unsigned int e = owned_facet_start[c]; e < owned_facet_start[c + 1]; ++e)
              {
                out.put<std::uint64_t>(cell_id[network.facets[e].b]);
                serialize_springs<dim>(out, self.springs[e]);
              }
            records.emplace_back(cell_id[c], bytes.str());
          }
      Run::write_records(directory.file("cells"), n_cells, records, comm);
    }



    template <int dim>
    void
    Model<dim>::load(CheckpointReader              &global,
                     std::vector<CheckpointReader> &rank_parts,
                     const CheckpointDirectory     &directory)
    {
      serialize_global(global);

      std::vector<std::uint64_t> keys(cell_id.begin(), cell_id.begin() + n_owned_cells);
      const auto records = Run::read_records(directory.file("cells"), keys, scene.mpi_communicator());
      const std::string file = directory.file("cells");
      Run::parse_collectively(scene.mpi_communicator(), [&]() {
        for (unsigned int c = 0; c < n_owned_cells; ++c)
          {
            std::istringstream bytes(records[c]);
            CheckpointReader   in(bytes, file);
            for (Vector *x : {&u, &u_trial, &v, &a, &f_int, &f_ext, &f_ext_old, &inertia, &reaction_old})
              for (unsigned int k = 0; k < n_dofs; ++k)
                in.get(x->local_element(n_dofs * c + k));
            // The facets by their other cell: the local order may differ on another partition.
            std::map<std::uint64_t, unsigned int> facet_of;
            for (unsigned int e = owned_facet_start[c]; e < owned_facet_start[c + 1]; ++e)
              facet_of[cell_id[network.facets[e].b]] = e;
            const auto n_facets = in.get<std::uint64_t>();
            if (n_facets != facet_of.size())
              in.refuse("cell " + std::to_string(cell_id[c]) + " has another number of facets than in the "
                        "checkpoint (the same parameters and Random seed give the same network)");
            for (std::uint64_t f = 0; f < n_facets; ++f)
              {
                const auto found = facet_of.find(in.get<std::uint64_t>());
                if (found == facet_of.end())
                  in.refuse("cell " + std::to_string(cell_id[c]) + " has other neighbours than in the checkpoint");
                auto             &sp      = springs[found->second];
                const std::size_t n_state = sp.state.size();
                serialize_springs<dim>(in, sp);
                if (sp.state.size() != n_state || sp.trial_state.size() != n_state)
                  in.refuse("the facets' spring states differ from the checkpoint's (another RBSN/Spring law or "
                            "Analysis)");
              }
            if (!in.at_end())
              in.refuse("a cell's record is longer than this network's cell (another network)");
          }
      });
      for (Vector *x : {&u, &u_trial, &v, &a})
        x->update_ghost_values();
      update_fragments(); // from the broken facets

      matrix_current = false; // on another partition the first step assembles anew
      if (!directory.same_ranks())
        return;
      CheckpointReader &in = rank_parts[0];
      in.section("rbsn assembled tangent");
      in.get(matrix_current);
      in.get(matrix_dt);
      in.get(incremental_updates);
      if (matrix_current)
        {
          in.get(facet_in_matrix);
          in.get(assembled_tangent);
          std::vector<double> values;
          in.get(values);
          if (facet_in_matrix.size() != springs.size() || assembled_tangent.size() != springs.size())
            throw RuntimeError("the checkpoint's assembled tangent does not match the network");
          set_matrix_values(values);
        }
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

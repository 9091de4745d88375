// The RBSN's part of a checkpoint: the DoF vectors, every facet's springs (converged
// and trial state, tangent, broken or not), the increment control and the work sums.
// Every rank writes (and reads) its own cells' DoFs and its own facets; a checkpoint of
// N ranks resumes on N ranks, which build the same network.
#include <hysteron/rbsn/model.h>

#include <Epetra_CrsMatrix.h>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::save(CheckpointWriter &out) const
    {
      const auto put_vector = [&](const Vector &x) {
        out.put(std::vector<double>(x.begin(), x.begin() + x.locally_owned_size()));
      };
      out.section("rbsn vectors");
      out.put<std::uint64_t>(u.size());
      for (const Vector *x : {&u, &u_trial, &v, &a, &f_int, &f_ext, &f_ext_old, &inertia,
                              &reaction_old})
        put_vector(*x);
      out.section("rbsn spring laws");
      out.put<std::uint64_t>(springs.size());
      for (const auto &sp : springs)
        {
          out.put(sp.delta);
          out.put(sp.force);
          out.put(sp.trial_delta);
          out.put(sp.trial_force);
          out.put(sp.state);
          out.put(sp.trial_state);
          out.put(sp.tangent);
          out.put(sp.broken);
        }
      out.section("rbsn sums");
      out.put(force_scale);
      out.put(last_force_level);
      out.put(predictor_level);
      out.put(internal_work);
      out.put(external_work);
      out.put(boundary_work);
      out.put(n_steps);
      out.put(n_newton);
      out.put(n_broken);
      out.put(n_cuts);
      out.put(increments.state());
      out.section("rbsn fracture energy, factorizations");
      out.put(fracture_energy);
      out.put(n_factorizations);
      // The incrementally assembled tangent: which facets' tangents it holds, and its values.
      out.section("rbsn assembled tangent");
      out.put(matrix_current);
      out.put(matrix_dt);
      out.put(incremental_updates);
      if (matrix_current)
        {
          out.put(facet_in_matrix);
          out.put(assembled_tangent);
          out.put(matrix_values());
        }
      const_cast<PointData::Tables<dim> &>(tables).serialize(out);
    }



    template <int dim>
    void
    Model<dim>::load(CheckpointReader &in)
    {
      const auto get_vector = [&](Vector &x) {
        std::vector<double> values;
        in.get(values);
        if (values.size() != x.locally_owned_size())
          in.refuse("the network has another number of DoFs than the checkpoint's");
        x = 0;
        std::copy(values.begin(), values.end(), x.begin());
      };
      in.section("rbsn vectors");
      if (in.get<std::uint64_t>() != u.size())
        in.refuse("the network has another number of DoFs than the checkpoint's (the same "
                  "parameters and Random seed give the same network)");
      for (Vector *x : {&u, &u_trial, &v, &a, &f_int, &f_ext, &f_ext_old, &inertia, &reaction_old})
        get_vector(*x);
      for (Vector *x : {&u, &u_trial, &v, &a})
        x->update_ghost_values();
      in.section("rbsn spring laws");
      if (in.get<std::uint64_t>() != springs.size())
        in.refuse("the network has another number of facets than the checkpoint's");
      for (auto &sp : springs)
        {
          in.get(sp.delta);
          in.get(sp.force);
          in.get(sp.trial_delta);
          in.get(sp.trial_force);
          // The spring law's state: as many doubles per facet as this run's law keeps.
          const std::size_t n_state = sp.state.size();
          in.get(sp.state);
          in.get(sp.trial_state);
          if (sp.state.size() != n_state || sp.trial_state.size() != n_state)
            in.refuse("the facets' spring states differ from the checkpoint's (another "
                      "RBSN/Spring law or Analysis)");
          in.get(sp.tangent);
          in.get(sp.broken);
        }
      in.section("rbsn sums");
      in.get(force_scale);
      in.get(last_force_level);
      in.get(predictor_level);
      in.get(internal_work);
      in.get(external_work);
      in.get(boundary_work);
      in.get(n_steps);
      in.get(n_newton);
      in.get(n_broken);
      in.get(n_cuts);
      increments.restore(in.get<std::array<double, 4>>());
      in.section("rbsn fracture energy, factorizations");
      in.get(fracture_energy);
      in.get(n_factorizations);
      update_fragments(); // from the broken facets
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
      tables.serialize(in);
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

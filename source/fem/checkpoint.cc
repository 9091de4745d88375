// The FEM's part of a checkpoint: this rank's DoF values of the state vectors and
// the converged quadrature-point history of its cells (in the order of the cells,
// which the same mesh on the same ranks reproduces), and the sums a step carries over.
#include <hysteron/fem/fem.h>

namespace hysteron
{
  namespace FEM
  {
    namespace
    {
      template <typename VectorType>
      void
      put_owned(CheckpointWriter &out, const VectorType &v, const dealii::IndexSet &owned)
      {
        std::vector<double> values;
        values.reserve(owned.n_elements());
        for (const auto i : owned)
          values.push_back(v(i));
        out.put(values);
      }

      template <typename VectorType>
      void
      get_owned(CheckpointReader &in, VectorType &v, const dealii::IndexSet &owned)
      {
        std::vector<double> values;
        in.get(values);
        if (values.size() != owned.n_elements())
          in.refuse("the mesh has another number of DoFs on this rank than the checkpoint");
        std::size_t k = 0;
        for (const auto i : owned)
          v(i) = values[k++];
        v.compress(dealii::VectorOperation::insert);
      }
    } // namespace

    template <int dim>
    void
    Solver<dim>::save(CheckpointWriter &, CheckpointWriter &out, const CheckpointDirectory &) const
    {
      out.section("fem vectors");
      out.put<std::uint64_t>(dof_handler.n_dofs());
      for (const Vector *vector : {&u, &v, &a, &u_trial, &f_int, &f_ext, &f_int_old, &f_ext_old,
                              &inertia, &reaction_old})
        put_owned(out, *vector, owned_dofs);
      out.section("fem history");
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            out.put(h.stress);
            out.put(h.strain);
            out.put(h.state);
            out.put(h.volume);
            // The tangent of the converged state: the predictor of the next step uses it.
            out.put(h.tangent);
          }
      out.section("fem sums");
      out.put(internal_work);
      out.put(external_work);
      out.put(boundary_work);
      out.put(force_scale);
      out.put(last_force_level);
      out.put(predictor_level);
      out.put(current_dt);
      out.put(initial_kinetic);
      out.put(wall_forces);
      out.put(n_newton);
      out.put(n_cuts);
      out.put(n_linear);
      out.put(increments.state());
      out.put(step_checked);
      const_cast<PointData::Tables<dim> &>(tables).serialize(out);
    }



    template <int dim>
    void
    Solver<dim>::load(CheckpointReader &, std::vector<CheckpointReader> &parts, const CheckpointDirectory &directory)
    {
      if (!directory.same_ranks())
        throw InputError("--resume",
                         "the fem method resumes on as many MPI ranks as wrote the checkpoint (" +
                           std::to_string(directory.saved_ranks) + ")");
      CheckpointReader &in = parts[0];
      in.section("fem vectors");
      if (in.get<std::uint64_t>() != dof_handler.n_dofs())
        in.refuse("the mesh has another number of DoFs than the checkpoint's");
      for (Vector *vector : {&u, &v, &a, &u_trial, &f_int, &f_ext, &f_int_old, &f_ext_old, &inertia,
                        &reaction_old})
        get_owned(in, *vector, owned_dofs);
      u_ghost = u;
      v_ghost = v;
      a_ghost = a;
      in.section("fem history");
      for (const auto &cell : triangulation->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
            const std::size_t n_q = h.stress.size(), n_state = h.state.size();
            in.get(h.stress);
            in.get(h.strain);
            in.get(h.state);
            in.get(h.volume);
            in.get(h.tangent);
            if (h.stress.size() != n_q || h.strain.size() != n_q || h.state.size() != n_state ||
                h.volume.size() != n_q || h.tangent.size() != n_q)
              in.refuse("a cell's quadrature-point history has another size than the scene's");
            h.trial_volume = h.volume;
          }
      in.section("fem sums");
      in.get(internal_work);
      in.get(external_work);
      in.get(boundary_work);
      in.get(force_scale);
      in.get(last_force_level);
      in.get(predictor_level);
      in.get(current_dt);
      in.get(initial_kinetic);
      in.get(wall_forces);
      in.get(n_newton);
      in.get(n_cuts);
      in.get(n_linear);
      increments.restore(in.get<std::array<double, 4>>());
      in.get(step_checked);
      tables.serialize(in);
    }

    template void Solver<2>::save(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &) const;
    template void Solver<3>::save(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &) const;
    template void Solver<2>::load(CheckpointReader &, std::vector<CheckpointReader> &, const CheckpointDirectory &);
    template void Solver<3>::load(CheckpointReader &, std::vector<CheckpointReader> &, const CheckpointDirectory &);
  } // namespace FEM
} // namespace hysteron

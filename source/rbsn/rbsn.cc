// The rbsn method the driver registers: Run::SteppingMethod's hooks on a Model.
#include "rbsn/model.h"
#include <hysteron/rbsn/rbsn.h>
#include <hysteron/scene/output_column.h>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    Solver<dim>::Solver() = default;

    template <int dim>
    Solver<dim>::~Solver() = default;

    template <int dim>
    void
    Solver<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      Model<dim>::declare_parameters(prm);
    }

    template <int dim>
    void
    Solver<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      // The network's tables have cell and facet columns, not continuum points.
      require(this->get_scene().output_control().additional_columns.empty(),
              "Output/Additional columns",
              "the rbsn method's probe tables hold cell and facet values; additional point "
              "columns apply to the mpm and fem methods");
      model = std::make_unique<Model<dim>>(this->get_scene(), *this, prm);
    }

    // The driver's hooks.
    template <int dim>
    void
    Solver<dim>::setup()
    {
      model->setup();
    }

    template <int dim>
    double
    Solver<dim>::size_of_state() const
    {
      // u and theta per cell.
      return model ? double(Model<dim>::n_dofs) * model->n_global_cells() : 0.0;
    }

    template <int dim>
    std::string
    Solver<dim>::checkpoint_unsupported() const
    {
      return model ? model->checkpoint_unsupported() : std::string();
    }

    template <int dim>
    void
    Solver<dim>::open_outputs()
    {
      model->open_outputs();
    }

    template <int dim>
    void
    Solver<dim>::initialize()
    {
      model->initialize();
    }

    template <int dim>
    double
    Solver<dim>::propose_step(const double t)
    {
      return model->propose_step(t);
    }

    template <int dim>
    bool
    Solver<dim>::advance(double &t, const double dt)
    {
      return model->advance(t, dt, [this](const double time) { this->step_finished(time); });
    }

    template <int dim>
    void
    Solver<dim>::write_rows(const double t)
    {
      model->write_rows(t);
    }

    template <int dim>
    void
    Solver<dim>::write_fields(const double t, Output::FieldWriter &writer)
    {
      model->write_fields(t, writer);
    }

    template <int dim>
    void
    Solver<dim>::finish(const double)
    {
      model->finish();
    }

    template <int dim>
    void
    Solver<dim>::save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const
    {
      model->save(global, rank, directory);
    }

    template <int dim>
    void
    Solver<dim>::load(CheckpointReader              &global,
                      std::vector<CheckpointReader> &rank_parts,
                      const CheckpointDirectory     &directory)
    {
      model->load(global, rank_parts, directory);
    }

    template <int dim>
    std::string
    Solver<dim>::summary() const
    {
      return model ? model->summary(this->n_steps(), this->n_outputs(), this->resuming()) : std::string();
    }

    template class Solver<2>;
    template class Solver<3>;
  } // namespace RBSN
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::RBSN::Solver,
                         "rbsn",
                         "the Rigid-Body-Spring Network: Voronoi cells as rigid bodies joined by "
                         "Bouc-Wen springs at their facets, static, quasi-static and dynamic, with "
                         "brittle fracture; 2D and 3D; see doc/rbsn.md");

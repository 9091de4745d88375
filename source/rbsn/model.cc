// The RBSN's model: its construction and the run's summary.
#include "rbsn/model.h"

#include "base/sparse_lu.h"

#include <iomanip>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    Model<dim>::Model()
      : direct(std::make_unique<SparseLU>())
    {}



    template <int dim>
    Model<dim>::~Model() = default;



    template <int dim>
    std::string
    Model<dim>::summary() const
    {
      std::ostringstream s;
      s << n_cells << " cells, " << n_global_facets << " facets, "
        << (analysis == Analysis::variable_order ? n_ida_steps : this->n_steps()) << " steps, " << n_newton
        << " Newton iterations";
      s << ", " << n_factorizations << " factorizations" << (this->resuming() ? " since the resume" : "");
      if (incremental_assembly && n_facet_evaluations > 0)
        {
          const MPI_Comm      comm    = network_communicator();
          const unsigned long updates = dealii::Utilities::MPI::sum(n_facet_updates, comm);
          const unsigned long total   = dealii::Utilities::MPI::sum(n_facet_evaluations, comm);
          std::ostringstream  share;
          share << std::fixed << std::setprecision(1) << 100.0 * updates / total;
          s << " (" << n_matrix_assemblies - n_full_assemblies << " of " << n_matrix_assemblies
            << " tangents updated in place, " << share.str() << " % of the facets' matrices)";
        }
      if (linear_solver != "direct")
        s << " (" << linear_solver << " + AMG, " << n_linear_iterations << " iterations)";
      else if (distributed())
        s << " (" << distributed_solver << " on " << n_parts << " MPI ranks)";
      if (n_exact_retries > 0)
        s << " (" << n_exact_retries << " steps again with exact Newton)";
      if (fracture.enabled)
        {
          s << ", " << n_broken << " broken facets, " << n_fragments << (n_fragments == 1 ? " fragment" : " fragments");
          if (n_released > 0)
            s << " (" << n_released << (n_released == 1 ? " cell" : " cells") << " released)";
          if (fracture_energy > 0)
            s << ", fracture energy " << fracture_energy << " J";
        }
      s << ", " << this->n_outputs() << " outputs";
      return s.str();
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

// The assembly of the RBSN's residual and tangent at an iterate: the facets' springs, the cells' inertia.
#ifndef hysteron_source_rbsn_assembly_h
#define hysteron_source_rbsn_assembly_h

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include "rbsn/model.h"

#include <string>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    /// One evaluation of the residual (and the tangent) at u_trial for the step of
    /// length dt to t1 (assembly.cc has the equations).
    template <int dim>
    class Model<dim>::Assembly
    {
    public:
      Assembly(Model &model, const double t1, const double dt, const bool with_matrix, const bool update_springs);

      /// The residual into rhs, the forces into f_int, f_ext and inertia, the tangent into
      /// the matrix; false if a spring failed (spring_failure) or a value is not finite.
      bool
      run();

      /// K0 = B^T diag(k) B of @p sp into @p M: the elastic springs.
      static void
      elastic_matrix(const Springs<dim> &sp, dealii::FullMatrix<double> &M);

    private:
      /// The matrix kept (incremental) or zeroed.
      void
      begin();
      /// B^T D B of @p sp into @p M (times 1 + alpha in dynamics).
      void
      spring_matrix(const Springs<dim> &sp, const SpringMatrix &D, dealii::FullMatrix<double> &M) const;
      /// The facet's matrix for the tangent @p D, with its damping, into K.
      void
      facet_matrix(const Springs<dim> &sp, const SpringMatrix &D);
      /// Take broken facet @p e out of the incrementally updated matrix.
      void
      remove_facet(const unsigned int e);
      /// Facet @p e's trial deformations and forces (and tangent) at u_trial; false, with
      /// the spring law's message, if the law failed.
      bool
      update_facet_springs(const unsigned int e);
      /// -r of facet @p e into r, its forces into f_int and inertia.
      void
      facet_residual(const unsigned int e);
      /// Add facet @p e's residual (and matrix) to the system.
      void
      add_facet(const unsigned int e);
      /// A diagonal for the cells without an intact facet.
      void
      hold_lone_cells();
      /// The cells' inertia and mass-proportional damping (dynamics).
      void
      add_cell_inertia();
      /// Compress, gather a spring failure, add the external forces.
      bool
      finish();
      /// Whether any of @p indices is constrained.
      bool
      any_constrained(const std::vector<dof_index> &indices) const;

      Model       &m;
      const double t1, dt;
      const bool   with_matrix, update_springs;
      const bool   dynamic;             ///< a Newmark / HHT step
      bool         incremental = false; ///< the matrix is updated, not rebuilt
      bool         failed      = false;
      std::string  message; ///< of the last spring that failed

      // A facet's local matrices and vectors.
      dealii::FullMatrix<double> K, K0;
      dealii::Vector<double>     r, fe, fe0, ve0, ve1, tmp;
      std::vector<dof_index>     dofs;
    };
  } // namespace RBSN
} // namespace hysteron

#endif

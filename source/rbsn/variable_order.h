#ifndef hysteron_source_rbsn_variable_order_h
#define hysteron_source_rbsn_variable_order_h

#include "rbsn/model.h"
#include "base/ida_integrator.h"
#include "base/sparse_lu.h"

#include <hysteron/material/bouc_wen_uniaxial.h>

#include <array>
#include <vector>

/*
 * Analysis = variable order: the state-space form of eq. 3.43-3.48 as an
 * implicit DAE F(t, y, y') = 0 in y = (u, v, s, W), integrated by SUNDIALS IDA
 * (variable-order, variable-step BDF with local error control; base/ida_integrator.h).
 * With n = 3 (2D) or 6 (3D) DoFs per cell, s the Bouc-Wen states of the hysteretic
 * springs (z, and eta, e_h with degradation), and W four work quadratures:
 *
 *   free DoF i:        u_i' - v_i = 0,
 *                      (M v' + C v + f_int(u, s) - f_ext(t))_i = 0,
 *   prescribed DoF i:  u_i' - w_i(t) = 0,   v_i - w_i(t) = 0   (algebraic),
 *   spring states:     s' - R(s, delta') = 0,   delta' = B v   (the Bouc-Wen rates),
 *   works:             W_int' = f_int . v,  W_ext' = f_ext . v,  W_bnd' = r . w,
 *                      W_damp' = v . C v,
 *
 * with M the cell mass matrices (eq. 3.12), C = a0 M + a1 K0 (K0: the elastic
 * springs, as in the Newmark analysis), f_int = sum_e B^T F, F_i = a k delta_i +
 * (1 - a) k z_i (linear springs: k delta_i), w the prescribed velocities and r
 * the reactions f_int + M v' + C v - f_ext on the prescribed DoFs. IDA's Newton
 * matrix dF/dy + c_j dF/dy' is assembled exactly (the quadratures' rows keep only
 * c_j: they do not feed back) and factorised by UMFPACK. Fracture is refused at
 * parse time: a break is a discontinuity of the right-hand side.
 */

namespace hysteron
{
  namespace RBSN
  {
    /// The DAE of the variable-order analysis and its Newton matrix (see above).
    template <int dim>
    class Model<dim>::VariableOrder
    {
    public:
      // IDA's vectors: the whole network on every rank.
      using Vector    = dealii::Vector<double>;
      using ConstView = IdaIntegrator::ConstView;
      using View      = IdaIntegrator::View;
      static constexpr unsigned int n_dofs = Model<dim>::n_dofs;

      explicit VariableOrder(Model<dim> &model);

      /// F(t, y, y'); returns 0, or 1 (recoverable: IDA retries with a smaller step).
      int
      residual(const double t, const ConstView y, const ConstView yp, const View F);
      /// Assemble dF/dy + cj dF/dy' at y (it does not depend on t and y') and factorise it.
      int
      setup_jacobian(const ConstView y, const double cj);
      /// x = J^-1 rhs with the factorisation of the last setup_jacobian().
      int
      solve(const ConstView rhs, const View x);

      /// The initial y and a consistent y' from the model's initial state.
      void
      initial_values(Vector &y, Vector &yp);
      /// y (and y') into the model's vectors and springs, for its output.
      void
      to_model(const double t, const Vector &y, const Vector &yp);

      /// Per component: 1 differential, 0 algebraic (the prescribed DoFs' velocities).
      std::vector<double>
      differential_components() const;

      std::vector<double> tolerances; ///< IDA's absolute tolerances

    private:
      Model<dim>  &m;
      unsigned int n = 0, n_states = 0, n_total = 0;
      /// Per spring (index 3 e + i): the offset of its Bouc-Wen state within s, -1 if linear.
      std::vector<int>              state_offset;
      /// Per spring (index 3 e + i) of a hysteretic facet: its uniaxial law and the
      /// offset of its state in the facet's state (SpringLaw<2>::uniaxial_spring()).
      std::vector<typename SpringLaw<dim>::UniaxialSpring> uniaxial;
      std::vector<double>           w; ///< prescribed velocities at the last t
      Vector                        reaction;
      Vector                        lu_rhs, lu_x; ///< the direct solver's vectors
      typename Model<dim>::Vector   f_ext; ///< the model's layout (one part: all DoFs)
      dealii::SparsityPattern       pattern;
      dealii::SparseMatrix<double>  jacobian;
      SparseLU                      direct; ///< the symbolic analysis kept over the Jacobians

      const Material::BoucWenUniaxial &
      law(const unsigned int e, const unsigned int i) const
      {
        return *uniaxial[n_dofs * e + i].law;
      }
      /// Spring i's state in the facet's state.
      unsigned int
      facet_offset(const unsigned int e, const unsigned int i) const
      {
        return uniaxial[n_dofs * e + i].offset;
      }
      unsigned int
      s_index(const unsigned int e, const unsigned int i) const
      {
        return 2 * n + state_offset[n_dofs * e + i];
      }
      void
      prescribed_velocities(const double t);
      /// The facet's DoF indices (a's, then b's).
      std::array<unsigned int, 2 * n_dofs>
      facet_dofs(const unsigned int e) const
      {
        return m.facet_local_dofs(e);
      }
    };
  } // namespace RBSN
} // namespace hysteron

#endif

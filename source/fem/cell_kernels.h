#ifndef hysteron_source_fem_cell_kernels_h
#define hysteron_source_fem_cell_kernels_h

// The cell kernels of the FEM's assembly (private to source/fem): what Solver::assemble()
// forms on one cell, split by job into the kinematics and material update (cell_kernels.cc),
// the small-strain material part with its B-bar and axisymmetric variants
// (cell_kernels_small_strain.cc), the updated-Lagrangian material and geometric part
// (cell_kernels_finite_strain.cc), the body and surface loads (cell_kernels_loads.cc) and the
// inertia and damping of HHT-alpha (cell_kernels_dynamics.cc). The equations are written out
// at the top of assembly.cc.

#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include "fem/fem.h"

#include <string>
#include <vector>

namespace hysteron
{
  namespace FEM
  {
    /// The strain-displacement operator of a cell: B[q][i], the symmetric gradient of vector
    /// shape function i at quadrature point q.
    template <int dim>
    using StrainOperator = std::vector<std::vector<dealii::SymmetricTensor<2, dim>>>;

    /**
     * B-bar (mean dilatation): B_i <- B_i + (b_i - tr B_i) I / dim at every point, with
     * b_i = sum_q tr B_i(x_q) w_q / sum_q w_q the mean of div N_i over the cell. The
     * dilatation tr eps of every strain is then its mean over the cell (one volumetric
     * constraint per cell instead of one per point, so Q1 does not lock in isochoric
     * flow), and B_i : sigma, B_i : C : B_j are the consistent forces and tangent. In 2D
     * the trace is the in-plane one (plane strain: eps_zz = 0).
     */
    template <int dim>
    void
    mean_dilatation(StrainOperator<dim> &B, const std::vector<double> &weights);

    /// The small-strain operator B_i = sym grad N_i at the points of the cell @p fv is on
    /// (gradients needed), with B-bar over the point volumes @p weights if @p b_bar.
    template <int dim>
    void
    small_strain_operator(const dealii::FEValues<dim> &fv,
                          const std::vector<double>   &weights,
                          const bool                   b_bar,
                          StrainOperator<dim>         &B);

    /// sym(e_c (x) g): the symmetric gradient of a shape function that moves component c
    /// with the scalar gradient g.
    template <int dim>
    inline dealii::SymmetricTensor<2, dim>
    component_gradient(const unsigned int c, const dealii::Tensor<1, dim> &g)
    {
      dealii::SymmetricTensor<2, dim> B;
      for (unsigned int b = 0; b < dim; ++b)
        B[c][b] = b == c ? g[b] : 0.5 * g[b];
      return B;
    }

    /// The tangent @p T as a plain array: C[((a dim + b) dim + c) dim + d] = T_abcd.
    template <int dim>
    inline void
    plain_tangent(const dealii::SymmetricTensor<4, dim> &T, std::vector<double> &C)
    {
      for (unsigned int a = 0; a < dim; ++a)
        for (unsigned int b = 0; b < dim; ++b)
          for (unsigned int c = 0; c < dim; ++c)
            for (unsigned int d = 0; d < dim; ++d)
              C[((a * dim + b) * dim + c) * dim + d] = T[a][b][c][d];
    }

    /// The material part's scratch (both kinematics): the shape gradients at one point, the
    /// material tangent as a plain array C[((a dim + b) dim + c) dim + d], and H, the
    /// products w C : B_j (also the hoop terms' (n_i, B_i : S, H : B_i), or a copy of C).
    template <int dim>
    struct MaterialScratch
    {
      explicit MaterialScratch(const unsigned int n)
        : G(n)
        , C(dim * dim * dim * dim)
        , H(n * dim * dim)
      {}
      std::vector<dealii::Tensor<1, dim>> G;
      std::vector<double>                 C, H;
    };

    /// The updated-Lagrangian kernel's scratch (see assembly.cc): B of the forces (trial
    /// configuration, B-bar) and of f_int(u_n); the shape gradients in the midpoint, trial and
    /// converged configurations; the volumes w det F there; the half rotations R_h and
    /// P = I - L/2 at every point; sigma grad N_j at one point; the converged nodal values.
    template <int dim>
    struct FiniteStrainScratch
    {
      FiniteStrainScratch(const unsigned int n, const unsigned int n_q)
        : u0(n)
        , Bf(n_q, std::vector<dealii::SymmetricTensor<2, dim>>(n))
        , B0(Bf)
        , Gs(n_q, std::vector<dealii::Tensor<1, dim>>(n))
        , Gf(Gs)
        , G0(Gs)
        , w0(n_q)
        , wm(n_q)
        , w1(n_q)
        , R(n_q)
        , P(n_q)
        , sG(n)
      {}
      dealii::Vector<double>                           u0;
      StrainOperator<dim>                              Bf, B0;
      std::vector<std::vector<dealii::Tensor<1, dim>>> Gs, Gf, G0;
      std::vector<double>                              w0, wm, w1;
      std::vector<dealii::Tensor<2, dim>>              R, P;
      std::vector<dealii::Tensor<1, dim>>              sG;
    };

    /// The dynamic kernel's scratch: mass, elastic stiffness and dashpots of the cell, the forces of
    /// the converged state, and the Newmark kinematics of its nodes.
    struct DynamicsScratch
    {
      explicit DynamicsScratch(const unsigned int n)
        : M(n, n)
        , K0(n, n)
        , Cb(n, n)
      {
        for (auto *x : {&fx0, &fi0, &v0, &a0, &a1, &v1, &Cv0, &Cv1, &tmp})
          x->reinit(n);
      }
      dealii::FullMatrix<double> M, K0, Cb; ///< Cb: the absorbing boundaries' dashpots
      dealii::Vector<double>     fx0, fi0, v0, a0, a1, v1, Cv0, Cv1, tmp;
    };

    /// WorkStream's scratch (one per thread): the values of the cell and of its loaded faces,
    /// the nodal increment du = u_iterate - u_n, the strain operator (updated Lagrangian: of
    /// the midpoint configuration) and every kernel's own scratch.
    template <int dim>
    struct CellScratch
    {
      CellScratch(const dealii::Mapping<dim>        &mapping,
                  const dealii::FiniteElement<dim>  &fe,
                  const dealii::Quadrature<dim>     &quadrature,
                  const dealii::Quadrature<dim - 1> &face_quadrature)
        : fv(mapping, fe, quadrature, dealii::update_values | dealii::update_gradients)
        , ffv(mapping,
              fe,
              face_quadrature,
              dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values |
                dealii::update_normal_vectors)
        , du(fe.n_dofs_per_cell())
        , B(quadrature.size(), std::vector<dealii::SymmetricTensor<2, dim>>(fe.n_dofs_per_cell()))
        , material(fe.n_dofs_per_cell())
        , finite(fe.n_dofs_per_cell(), quadrature.size())
        , dynamics(fe.n_dofs_per_cell())
      {}
      CellScratch(const CellScratch &other)
        : CellScratch(other.fv.get_mapping(), other.fv.get_fe(), other.fv.get_quadrature(), other.ffv.get_quadrature())
      {}
      dealii::FEValues<dim>     fv;
      dealii::FEFaceValues<dim> ffv;
      dealii::Vector<double>    du;
      StrainOperator<dim>       B;
      MaterialScratch<dim>      material;
      FiniteStrainScratch<dim>  finite;
      DynamicsScratch           dynamics;
    };

    /// WorkStream's copy data: what one cell adds to the global system and force vectors.
    struct CellCopy
    {
      explicit CellCopy(const unsigned int n)
        : A(n, n)
        , r(n)
        , fi(n)
        , fx(n)
        , Mv(n)
        , dofs(n)
      {}
      dealii::FullMatrix<double>                   A;             ///< (effective) tangent
      dealii::Vector<double>                       r, fi, fx, Mv; ///< -residual, f_int, f_ext, inertia
      std::vector<dealii::types::global_dof_index> dofs;
      bool                                         active = false, failed = false;
      std::string                                  message;
      double                                       material_seconds = 0;
    };

    /**
     * The cell kernels of one evaluation of the discrete equations (Solver::assemble()):
     * the settings of the evaluation (iterate, step, loads at t1 and t0) and the solver's
     * data, read only; the cells' material points are updated through their histories.
     */
    template <int dim>
    class CellKernels
    {
    public:
      using CellIterator = typename dealii::DoFHandler<dim>::active_cell_iterator;
      using Vector       = dealii::TrilinosWrappers::MPI::Vector;

      CellKernels(const Solver<dim> &solver,
                  const Scene<dim>  &scene,
                  const Vector      &u_iterate,
                  const double       t1,
                  const double       dt,
                  const bool         matrix,
                  const bool         update_material);

      /// WorkStream's worker: everything of one locally owned cell.
      void
      assemble(const CellIterator &cell, CellScratch<dim> &scratch, CellCopy &copy) const;

      const bool matrix;  ///< the tangent too
      const bool dynamic; ///< HHT-alpha (dt = 0: the forces of the state only)
      /// The load sets' values at t1 and (dynamic) at t0 = t1 - dt.
      std::vector<dealii::Tensor<1, dim>> load1, load0;
      /// The body force per unit mass at t1 and t0: gravity, minus the ground's
      /// acceleration (Scene::body_acceleration()).
      dealii::Tensor<1, dim> body1, body0;

    private:
      // Kinematics and material update (cell_kernels.cc).
      /// h.increment (and the hoop increments) from du and the strain operator.
      void
      strain_increments(CellScratch<dim> &scratch, CellHistory<dim> &h) const;
      /// The material points from the converged to the trial state; false on failure.
      bool
      update_material_points(const CellIterator     &cell,
                             CellHistory<dim>       &h,
                             const CellScratch<dim> &scratch,
                             CellCopy               &copy) const;
      /// f_i += B_i : sigma w for shape functions of one component with gradients @p G.
      void
      add_component_forces(const std::vector<dealii::Tensor<1, dim>> &G,
                           const dealii::SymmetricTensor<2, dim>     &s,
                           const double                               w,
                           dealii::Vector<double>                    &fi) const;
      /// A_ij += g_i[b] H_j[c_i][b] (H from the material kernels).
      void
      add_component_tangent(const std::vector<dealii::Tensor<1, dim>> &G,
                            const std::vector<double>                 &H,
                            dealii::FullMatrix<double>                &A) const;
      /// The B-bar form: f_i += Bf_i : sigma w, A_ij += Bf_i : (R_h)(C : B_j) w (no R_h: nullptr).
      void
      add_b_bar_terms(const std::vector<dealii::SymmetricTensor<2, dim>> &Bf,
                      const std::vector<dealii::SymmetricTensor<2, dim>> &B,
                      const CellHistory<dim>                             &h,
                      const unsigned int                                  q,
                      const dealii::Tensor<2, dim>                       *R,
                      const double                                        w,
                      CellCopy                                           &copy) const;

      // Small strain (cell_kernels_small_strain.cc).
      /// f_int and the tangent K of the cell.
      void
      small_strain_forces(const CellHistory<dim> &h, CellScratch<dim> &scratch, CellCopy &copy) const;
      /// Axisymmetric: f_i += n_i sigma_tt w_q with sigma_tt of the @p trial (or converged)
      /// state and (if @p K) the hoop terms of the tangent @p T at point q (see assembly.cc),
      /// n_i = N_i delta(c_i, x) / r_q.
      void
      add_hoop_terms(const Material::HoopTangent<dim> &T,
                     const CellHistory<dim>           &h,
                     const unsigned int                q,
                     const bool                        trial,
                     CellScratch<dim>                 &scratch,
                     dealii::FullMatrix<double>       *K,
                     dealii::Vector<double>           &f) const;

      // Updated Lagrangian (cell_kernels_finite_strain.cc).
      /// The increment's kinematics at every point; false if the element turns inside out.
      bool
      finite_strain_kinematics(const CellIterator &cell,
                               CellHistory<dim>   &h,
                               CellScratch<dim>   &scratch,
                               CellCopy           &copy) const;
      /// The trial stress and state: @p stress and the trial state turned by R_h.
      void
      rotate_trial_state(CellHistory<dim>                                   &h,
                         const std::vector<dealii::SymmetricTensor<2, dim>> &stress,
                         const std::vector<dealii::Tensor<2, dim>>          &R) const;
      /// f_int and the tangent K (material and geometric) of the cell.
      void
      finite_strain_forces(const CellHistory<dim> &h, CellScratch<dim> &scratch, CellCopy &copy) const;

      // Loads (cell_kernels_loads.cc).
      /// f = sum_q N_i (rho g + volume loads) w_q + tractions on the loaded boundary faces,
      /// with the body force per unit mass @p g.
      void
      external_forces(const CellIterator                        &cell,
                      const CellHistory<dim>                    &h,
                      const dealii::Tensor<1, dim>              &g,
                      const std::vector<dealii::Tensor<1, dim>> &value,
                      dealii::Vector<double>                    &f,
                      CellScratch<dim>                          &scratch) const;

      // Dynamics (cell_kernels_dynamics.cc).
      /// M, the elastic K0 of the damping and f_int(u_n) of the cell.
      void
      converged_state_terms(const CellHistory<dim> &h, CellScratch<dim> &scratch) const;
      /// The HHT-alpha residual and effective tangent (see assembly.cc), inertia in Mv.
      void
      hht_terms(const CellIterator &cell, const CellHistory<dim> &h, CellScratch<dim> &scratch, CellCopy &copy) const;

      const Solver<dim>        &solver;
      const Scene<dim>         &scene;
      const Vector             &u_iterate;
      const double              t1, dt;
      const bool                update_material;
      const bool                finite_strain, b_bar, axisymmetric;
      const double              alpha, beta, gamma; ///< HHT-alpha
      const unsigned int        n, n_q;
      std::vector<unsigned int> comp; ///< the component of every shape function
    };
  } // namespace FEM
} // namespace hysteron

#endif

#ifndef hysteron_base_direct_solver_h
#define hysteron_base_direct_solver_h

#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include <memory>
#include <string>

class Amesos_BaseSolver;
class Epetra_LinearProblem;

namespace hysteron
{
  /**
   * A Trilinos Amesos direct solver (KLU or MUMPS) of one matrix whose sparsity pattern stays
   * fixed: the symbolic analysis (ordering, elimination tree) is done at the first solve (after
   * construction or clear()) and kept, each further solve repeats only the numeric
   * factorization of the matrix's new values. After a reinit() of the matrix (a new pattern or
   * a new Epetra matrix), call clear(). (deal.II 9.4's TrilinosWrappers::SolverDirect analyses
   * at every initialize(); see doc/architecture.md.)
   */
  class KeptDirectSolver
  {
  public:
    /// @p package: "Amesos_Klu" or "Amesos_Mumps".
    explicit KeptDirectSolver(const std::string &package);
    ~KeptDirectSolver();

    /// Factorize the current values of @p matrix (the one analysed since the last clear(), or
    /// analyse it) and solve matrix x = b.
    void
    solve(const dealii::TrilinosWrappers::SparseMatrix &matrix,
          dealii::TrilinosWrappers::MPI::Vector        &x,
          const dealii::TrilinosWrappers::MPI::Vector  &b);

    /// Forget the analysis: the matrix was reinit()ed (the next solve analyses it).
    void
    clear();

  private:
    std::string                           package;
    std::unique_ptr<Epetra_LinearProblem> problem;
    std::unique_ptr<Amesos_BaseSolver>    solver;
  };
} // namespace hysteron

#endif

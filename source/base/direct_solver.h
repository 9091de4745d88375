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
   * fixed: the symbolic analysis (ordering, elimination tree) is done at the first solve and
   * kept, each solve with new values repeats only the numeric factorization. The matrix
   * object must outlive the solver and keep its pattern (set its values, not reinit() it).
   */
  class KeptDirectSolver
  {
  public:
    /// @p package: "Amesos_Klu" or "Amesos_Mumps".
    explicit KeptDirectSolver(const std::string &package);
    ~KeptDirectSolver();

    /// Factorize the current values of @p matrix (the same object as before) and solve
    /// matrix x = b.
    void
    solve(const dealii::TrilinosWrappers::SparseMatrix &matrix,
          dealii::TrilinosWrappers::MPI::Vector        &x,
          const dealii::TrilinosWrappers::MPI::Vector  &b);

    /// Forget the analysis (the next solve analyses the pattern again).
    void
    clear();

  private:
    std::string                           package;
    const void                           *analysed = nullptr; ///< the matrix of the analysis
    std::unique_ptr<Epetra_LinearProblem> problem;
    std::unique_ptr<Amesos_BaseSolver>    solver;
  };
} // namespace hysteron

#endif

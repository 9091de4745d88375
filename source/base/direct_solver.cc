#include "base/direct_solver.h"
#include <hysteron/base/exceptions.h>

#include <Amesos.h>
#include <Amesos_BaseSolver.h>
#include <Epetra_LinearProblem.h>

namespace hysteron
{
  KeptDirectSolver::KeptDirectSolver(const std::string &package)
    : package(package)
  {}



  KeptDirectSolver::~KeptDirectSolver() = default;



  void
  KeptDirectSolver::clear()
  {
    solver.reset();
    problem.reset();
  }



  void
  KeptDirectSolver::solve(const dealii::TrilinosWrappers::SparseMatrix &matrix,
                          dealii::TrilinosWrappers::MPI::Vector        &x,
                          const dealii::TrilinosWrappers::MPI::Vector  &b)
  {
    // Amesos takes non-const pointers; it reads the matrix and the right-hand side only.
    auto *A = const_cast<Epetra_CrsMatrix *>(&matrix.trilinos_matrix());
    if (!solver)
      {
        problem = std::make_unique<Epetra_LinearProblem>();
        problem->SetOperator(A);
        Amesos factory;
        solver.reset(factory.Create(package.c_str(), *problem));
        if (!solver)
          throw RuntimeError("the direct solver package " + package + " is not available in this Trilinos");
        if (solver->SymbolicFactorization() != 0)
          {
            clear();
            throw RuntimeError(package + ": the symbolic factorization failed");
          }
      }
    Assert(problem->GetOperator() == A, dealii::ExcMessage("the matrix was reinit()ed without clear()"));
    problem->SetLHS(&x.trilinos_vector());
    problem->SetRHS(const_cast<Epetra_MultiVector *>(
      static_cast<const Epetra_MultiVector *>(&b.trilinos_vector())));
    if (solver->NumericFactorization() != 0)
      throw RuntimeError(package + ": the numeric factorization failed (a singular matrix: is every "
                                   "rigid-body motion held?)");
    if (solver->Solve() != 0)
      throw RuntimeError(package + ": the solve failed");
  }
} // namespace hysteron

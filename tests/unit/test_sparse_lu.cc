// SparseLU: the analysis is kept over refactorizations of one pattern and redone only
// after clear().
#include <deal.II/base/exceptions.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include "base/sparse_lu.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace
{
  /// The tridiagonal pattern of size @p n and the matrix tridiag(-1, 2 + scale, -1) on it.
  void
  tridiagonal(const unsigned int n, const double scale, dealii::SparsityPattern &pattern,
              dealii::SparseMatrix<double> &A)
  {
    dealii::DynamicSparsityPattern dsp(n, n);
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = (i > 0 ? i - 1 : 0); j < std::min(n, i + 2); ++j)
        dsp.add(i, j);
    pattern.copy_from(dsp);
    A.reinit(pattern);
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = (i > 0 ? i - 1 : 0); j < std::min(n, i + 2); ++j)
        A.set(i, j, i == j ? 2 + scale : -1.0 + 0.1 * i);
  }



  /// max_i |(A x - b)_i|
  double
  residual(const dealii::SparseMatrix<double> &A, const dealii::Vector<double> &x, const dealii::Vector<double> &b)
  {
    dealii::Vector<double> r(b.size());
    A.vmult(r, x);
    r -= b;
    return r.linfty_norm();
  }
} // namespace



TEST(SparseLU, RefactorizesOnePatternAndAnalysesAnotherAfterClear)
{
  dealii::SparsityPattern      pattern, other_pattern;
  dealii::SparseMatrix<double> A, other;
  tridiagonal(6, 1, pattern, A);
  dealii::Vector<double> b(6), x(6);
  for (unsigned int i = 0; i < 6; ++i)
    b[i] = 1 + i;

  hysteron::SparseLU lu;
  for (const double scale : {1.0, 3.0})
    {
      // New values on the same pattern (Newton's next tangent).
      for (unsigned int i = 0; i < 6; ++i)
        A.set(i, i, 2 + scale);
      lu.factorize(A);
      lu.solve(x, b);
      EXPECT_LT(residual(A, x, b), 1e-12);
    }

  // Another pattern needs clear() first.
  tridiagonal(8, 1, other_pattern, other);
  EXPECT_THROW(lu.factorize(other), dealii::ExceptionBase);
  lu.clear();
  dealii::Vector<double> c(8), y(8);
  c = 1;
  lu.factorize(other);
  lu.solve(y, c);
  EXPECT_LT(residual(other, y, c), 1e-12);
}

#ifndef hysteron_source_base_sparse_lu_h
#define hysteron_source_base_sparse_lu_h

#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <memory>
#include <vector>

namespace hysteron
{
  /**
   * Sparse LU factors of a deal.II SparseMatrix by UMFPACK, for a sequence of
   * matrices with one sparsity pattern (Newton's tangents): the fill-reducing
   * ordering and symbolic analysis are computed for the first matrix (after
   * construction or clear()) and kept, so that each further matrix costs only
   * its numeric factorization. A new pattern needs clear() first. (deal.II 9.4's
   * SparseDirectUMFPACK analyses at every factorize(); see doc/architecture.md.)
   *
   * The matrix's rows are handed to UMFPACK as the columns of A^T (deal.II
   * stores rows with the diagonal first, so a permutation sorts each row once),
   * and A x = b is solved as the transposed system of A^T.
   */
  class SparseLU
  {
  public:
    SparseLU();
    ~SparseLU();

    /// Factorize @p matrix (with the pattern analysed since the last clear(), or analyse
    /// it). Throws std::runtime_error for a singular matrix.
    void
    factorize(const dealii::SparseMatrix<double> &matrix);

    /// x = A^{-1} b with the last factors (with UMFPACK's iterative refinement
    /// against the factorized matrix).
    void
    solve(dealii::Vector<double> &x, const dealii::Vector<double> &b) const;

    /// Forget the factors and the analysis (before a matrix of another pattern).
    void
    clear();

  private:
    struct Data;
    std::unique_ptr<Data> data;
  };
} // namespace hysteron

#endif

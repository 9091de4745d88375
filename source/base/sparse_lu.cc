#include "base/sparse_lu.h"

#include <suitesparse/umfpack.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace hysteron
{
  struct SparseLU::Data
  {
    std::size_t n_nonzero = 0; ///< of the analysed pattern (0: none)
    // A^T in compressed columns: the rows of A, each sorted by column.
    std::vector<SuiteSparse_long> starts, indices;
    std::vector<double>           values;
    std::vector<std::size_t>      order; ///< sorted position -> position in deal.II's row
    void                         *symbolic = nullptr, *numeric = nullptr;
    double                        control[UMFPACK_CONTROL];

    ~Data()
    {
      release();
    }

    void
    release()
    {
      if (numeric)
        umfpack_dl_free_numeric(&numeric);
      if (symbolic)
        umfpack_dl_free_symbolic(&symbolic);
      numeric = symbolic = nullptr;
    }
  };



  SparseLU::SparseLU()
    : data(std::make_unique<Data>())
  {
    umfpack_dl_defaults(data->control);
    // AMD first and METIS's nested dissection where AMD's fill is high: the same
    // ordering for 2D networks, 40 % of the time and 60 % of the memory for a
    // 14,000-cell 3D box.
    data->control[UMFPACK_ORDERING] = UMFPACK_ORDERING_CHOLMOD;
  }

  SparseLU::~SparseLU() = default;



  void
  SparseLU::clear()
  {
    data->release();
    data->n_nonzero = 0;
  }



  void
  SparseLU::factorize(const dealii::SparseMatrix<double> &matrix)
  {
    Data                          &d       = *data;
    const dealii::SparsityPattern &pattern = matrix.get_sparsity_pattern();
    const SuiteSparse_long         n       = matrix.m();
    if (d.n_nonzero == 0)
      {
        // A new pattern: the sorted layout and the symbolic analysis.
        d.n_nonzero = pattern.n_nonzero_elements();
        d.starts.assign(n + 1, 0);
        d.indices.resize(d.n_nonzero);
        d.values.resize(d.n_nonzero);
        d.order.resize(d.n_nonzero);
        std::size_t k = 0;
        for (SuiteSparse_long row = 0; row < n; ++row)
          {
            d.starts[row] = k;
            const std::size_t first = k;
            for (auto entry = pattern.begin(row); entry != pattern.end(row); ++entry, ++k)
              {
                d.indices[k] = entry->column();
                d.order[k]   = k;
              }
            // Sort the row's entries by column, remembering where each came from.
            std::vector<std::size_t> local(k - first);
            std::iota(local.begin(), local.end(), first);
            std::sort(local.begin(), local.end(), [&](const std::size_t a, const std::size_t b) {
              return d.indices[a] < d.indices[b];
            });
            std::vector<SuiteSparse_long> sorted(k - first);
            for (std::size_t i = 0; i < local.size(); ++i)
              sorted[i] = d.indices[local[i]];
            std::copy(sorted.begin(), sorted.end(), d.indices.begin() + first);
            std::copy(local.begin(), local.end(), d.order.begin() + first);
          }
        d.starts[n] = k;
      }
    AssertThrow(d.n_nonzero == pattern.n_nonzero_elements() && d.starts.size() == std::size_t(n) + 1,
                dealii::ExcMessage("a matrix of another pattern: call SparseLU::clear() first"));
    // The values in the sorted layout (deal.II's values are stored in pattern order).
    {
      std::size_t k = 0;
      std::vector<double> row_values;
      for (SuiteSparse_long row = 0; row < n; ++row)
        {
          const std::size_t first = d.starts[row];
          row_values.clear();
          for (auto entry = matrix.begin(row); entry != matrix.end(row); ++entry)
            row_values.push_back(entry->value());
          for (std::size_t i = first; i < static_cast<std::size_t>(d.starts[row + 1]); ++i, ++k)
            d.values[i] = row_values[d.order[i] - first];
        }
    }
    if (d.numeric)
      umfpack_dl_free_numeric(&d.numeric);
    int status = UMFPACK_OK;
    if (!d.symbolic)
      status = umfpack_dl_symbolic(n, n, d.starts.data(), d.indices.data(), d.values.data(), &d.symbolic,
                                   d.control, nullptr);
    if (status == UMFPACK_OK)
      status = umfpack_dl_numeric(d.starts.data(), d.indices.data(), d.values.data(), d.symbolic,
                                  &d.numeric, d.control, nullptr);
    if (status != UMFPACK_OK)
      {
        if (d.numeric)
          umfpack_dl_free_numeric(&d.numeric);
        d.numeric = nullptr;
        throw std::runtime_error(status == UMFPACK_WARNING_singular_matrix ?
                                   "the matrix is singular" :
                                   "UMFPACK failed with status " + std::to_string(status));
      }
  }



  void
  SparseLU::solve(dealii::Vector<double> &x, const dealii::Vector<double> &b) const
  {
    const Data &d = *data;
    if (!d.numeric)
      throw std::runtime_error("no factorization");
    // The stored matrix is A^T: solve (A^T)^T x = b.
    const int status = umfpack_dl_solve(UMFPACK_At, d.starts.data(), d.indices.data(), d.values.data(),
                                        x.data(), b.data(), d.numeric, d.control, nullptr);
    if (status != UMFPACK_OK)
      throw std::runtime_error(status == UMFPACK_WARNING_singular_matrix ?
                                 "the matrix is singular" :
                                 "UMFPACK failed with status " + std::to_string(status));
  }
} // namespace hysteron

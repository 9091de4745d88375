#ifndef hysteron_source_mpm_basis_h
#define hysteron_source_mpm_basis_h

#include <deal.II/base/exceptions.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <algorithm>
#include <array>

/**
 * @file
 * Shape-function bases of the MPM background grid, header-only so that the
 * particle-to-grid and grid-to-particle kernels inline them completely.
 *
 * <h3>Grid</h3>
 * The background grid is a Cartesian lattice with origin @f$\mathbf o@f$,
 * cell size @f$h_d@f$ and @f$n_d@f$ cells in direction @f$d@f$ (all @f$h_d@f$
 * equal unless the grid moves and stretches); node
 * @f$(i_0,\dots,i_{dim-1})@f$, @f$0\le i_d\le n_d@f$, sits at
 * @f$o_d + h_d\,i_d@f$ and has the lattice-lexicographic number
 * @f$i_0 + (n_0+1)\,(i_1 + (n_1+1)\,i_2)@f$. All 1D kernels work in the
 * lattice coordinate @f$\xi = (x - o_d)/h_d \in [0, n_d]@f$; the basis of the
 * grid is the tensor product @f$N_{\mathbf i}(\mathbf x) = \prod_d
 * N_{i_d}(\xi_d)@f$, with @f$\partial N/\partial x_d = h_d^{-1}\,\partial
 * N/\partial \xi_d@f$.
 *
 * <h3>Linear basis</h3>
 * The hat functions @f$N_i(\xi) = \max(0, 1 - |\xi - i|)@f$: in cell @f$c@f$
 * with local coordinate @f$t = \xi - c@f$ the two nonzero functions are
 * @f$N_c = 1 - t@f$ and @f$N_{c+1} = t@f$. They are C0 only: the gradient jumps
 * at cell faces (the source of the "cell-crossing error" of classical MPM).
 *
 * <h3>Cubic B-spline basis with boundary modification</h3>
 * In the interior the basis function of node @f$i@f$ is the uniform cubic
 * B-spline @f$B(\xi - i)@f$ with
 * @f[
 *   B(r) = \begin{cases}
 *     \tfrac23 - r^2 + \tfrac12|r|^3, & |r| \le 1,\\
 *     \tfrac16 (2-|r|)^3,              & 1 < |r| \le 2,\\
 *     0 & \text{otherwise,}
 *   \end{cases}
 * @f]
 * which is C2, nonnegative, and reproduces constants and linear functions
 * exactly on the infinite lattice: @f$\sum_i B(\xi-i) = 1@f$,
 * @f$\sum_i i\,B(\xi-i) = \xi@f$. In cell @f$c@f$ with @f$t = \xi - c \in
 * [0,1]@f$ the four nonzero functions are those of the nodes
 * @f$c-1,\dots,c+2@f$:
 * @f[
 *   \tfrac16 (1-t)^3,\quad \tfrac16(3t^3 - 6t^2 + 4),\quad
 *   \tfrac16(-3t^3 + 3t^2 + 3t + 1),\quad \tfrac16 t^3 .
 * @f]
 *
 * In cell 0 the spline of the ghost node @f$-1@f$ (outside the grid) is
 * nonzero, and dropping it would destroy the partition of unity. We eliminate
 * the ghost value by linear extrapolation, @f$f_{-1} = 2f_0 - f_1@f$, which is
 * exact for every linear @f$f@f$; substituting into @f$\sum_i N_i f_i@f$ gives
 * the modified functions
 * @f[
 *   N_0' = N_0 + 2N_{-1}, \qquad N_1' = N_1 - N_{-1},
 * @f]
 * and likewise at the upper boundary with the ghost @f$n+1@f$:
 * @f$N_n' = N_n + 2N_{n+1}@f$, @f$N_{n-1}' = N_{n-1} - N_{n+1}@f$. Since the
 * extrapolation is exact for linear functions, the modified basis keeps the
 * partition of unity and linear completeness (@f$\sum_i N_i' \xi_i = \xi@f$)
 * on all of @f$[0,n]@f$. @f$N_{-1}@f$ is nonzero only in cell 0 (and
 * @f$N_{n+1}@f$ only in cell @f$n-1@f$), so only these two cells change.
 * Worked out in cell 0 (node @f$-1@f$ spline @f$\tfrac16(1-t)^3@f$):
 * @f[
 *   N_0' = 1 - t + \tfrac16 t^3, \qquad
 *   N_1' = t - \tfrac13 t^3 = \tfrac13 t(3 - t^2), \qquad
 *   N_2  = \tfrac16 t^3 ,
 * @f]
 * with derivatives @f$-1 + \tfrac12 t^2@f$, @f$1 - t^2@f$, @f$\tfrac12 t^2@f$.
 * Properties: @f$N_0'(0) = 1@f$, @f$N_1'(0) = N_2(0) = 0@f$ (the basis is
 * interpolatory at the boundary node); @f$N_0' \ge 1 - t \ge 0@f$ and
 * @f$N_1' \ge 0@f$ on @f$[0,1]@f$ (all functions stay nonnegative); at
 * @f$t = 1@f$ the values @f$\tfrac16, \tfrac23@f$ and slopes @f$-\tfrac12,
 * 0@f$ match the interior pieces of cell 1, and since the removed
 * @f$\tfrac16(1-t)^3@f$ vanishes at @f$t=1@f$ with its first two derivatives,
 * the modified basis is still C2 across the face @f$\xi = 1@f$. The upper
 * boundary is the mirror image with @f$u = n - \xi@f$.
 *
 * The support of a particle is always the four consecutive nodes
 * @c first, ..., @c first+3. In the boundary cells only three functions are
 * nonzero; the stencil is shifted inward so that every entry refers to a real
 * node, and the extra entry (node 3 in cell 0, node @f$n-3@f$ in cell
 * @f$n-1@f$) has value and derivative exactly 0. Four real nodes require
 * @f$n \ge 3@f$ cells per direction: see CubicBSpline1D::minimum_cells().
 * (Mathematically the construction also works for @f$n = 1, 2@f$ -- for
 * @f$n=1@f$ it collapses to the linear hat functions -- but a fixed
 * four-node stencil does not fit on fewer than four nodes.)
 *
 * Points slightly outside the box (round-off after an update) are projected
 * onto it: @f$\xi@f$ is clamped into @f$[0, n]@f$, and a point on the upper
 * boundary @f$\xi = n@f$ belongs to the last cell @f$n-1@f$.
 */

namespace hysteron
{
  namespace MPM
  {
    /**
     * @p base to the power @p exponent at compile time.
     */
    constexpr unsigned int
    integer_pow(const unsigned int base, const unsigned int exponent)
    {
      return exponent == 0 ? 1u : base * integer_pow(base, exponent - 1);
    }



    /**
     * Cell index floor(xi) of the lattice coordinate @p xi, clamped into
     * [0, n_cells - 1]: xi = n_cells (upper boundary) gives the last cell,
     * negative xi (round-off) gives cell 0.
     */
    inline unsigned int
    clamped_cell(const double xi, const unsigned int n_cells)
    {
      if (!(xi > 0.))
        return 0;
      // truncation equals floor for positive arguments
      return static_cast<unsigned int>(std::min(xi, static_cast<double>(n_cells - 1)));
    }



    /// The cell sizes of a lattice of square (cubic) cells of size @p h.
    template <int dim>
    std::array<double, dim>
    uniform_h(const double h)
    {
      std::array<double, dim> a;
      a.fill(h);
      return a;
    }



    /**
     * The Cartesian background lattice: @p n_cells[d] cells of size @p h in
     * direction @p d starting at @p origin; nodes 0..n_cells[d] per direction.
     */
    template <int dim>
    struct Lattice
    {
      dealii::Point<dim>              origin;
      /// The cell size of each direction: all equal at set-up; a moving grid
      /// (`MPM/Grid/Motion`) stretches each direction on its own.
      std::array<double, dim>         h{};
      std::array<unsigned int, dim> n_cells{};

      /// The smallest cell size (of the critical time step).
      double
      min_h() const
      {
        return *std::min_element(h.begin(), h.end());
      }

      /// The upper corner origin + n_cells h.
      dealii::Point<dim>
      upper() const
      {
        dealii::Point<dim> p = origin;
        for (unsigned int d = 0; d < dim; ++d)
          p[d] += n_cells[d] * h[d];
        return p;
      }

      /// The lattice coordinate (x_d - o_d) / h_d of @p x minus @p cell: the point's
      /// coordinates in its unit cell (the reference location of a particle).
      dealii::Point<dim>
      unit_cell_point(const dealii::Point<dim> &x, const std::array<unsigned int, dim> &cell) const
      {
        dealii::Point<dim> r;
        for (unsigned int d = 0; d < dim; ++d)
          r[d] = (x[d] - origin[d]) / h[d] - cell[d];
        return r;
      }

      /**
       * Multi-index of the cell containing @p x. A point on an upper face of
       * the box lies in the last cell; indices are clamped into
       * [0, n_cells[d]-1], no further bounds check.
       */
      std::array<unsigned int, dim>
      cell_of(const dealii::Point<dim> &x) const
      {
        std::array<unsigned int, dim> cell;
        for (unsigned int d = 0; d < dim; ++d)
          cell[d] = clamped_cell((x[d] - origin[d]) * (1. / h[d]), n_cells[d]);
        return cell;
      }

      /**
       * Whether @p x lies in the closed box [origin, origin + n_cells h].
       */
      bool
      contains(const dealii::Point<dim> &x) const
      {
        for (unsigned int d = 0; d < dim; ++d)
          if (x[d] < origin[d] || x[d] > origin[d] + n_cells[d] * h[d])
            return false;
        return true;
      }

      unsigned int
      n_nodes_1d(const unsigned int d) const
      {
        return n_cells[d] + 1;
      }

      /**
       * Total number of nodes, prod_d (n_cells[d] + 1).
       */
      unsigned int
      n_nodes() const
      {
        unsigned int n = 1;
        for (unsigned int d = 0; d < dim; ++d)
          n *= n_cells[d] + 1;
        return n;
      }

      /**
       * Lattice-lexicographic number i + (nx+1) (j + (ny+1) k) of the node
       * with multi-index @p index.
       */
      unsigned int
      node_number(const std::array<unsigned int, dim> &index) const
      {
        unsigned int node = index[dim - 1];
        for (int d = dim - 2; d >= 0; --d)
          node = node * (n_cells[d] + 1) + index[d];
        return node;
      }

      /**
       * Multi-index of the node with lattice-lexicographic number @p node.
       */
      std::array<unsigned int, dim>
      node_index(unsigned int node) const
      {
        std::array<unsigned int, dim> index;
        for (unsigned int d = 0; d < dim; ++d)
          {
            index[d] = node % (n_cells[d] + 1);
            node /= (n_cells[d] + 1);
          }
        return index;
      }

      /**
       * Position origin + (h_d i_d) of the node with number @p node.
       */
      dealii::Point<dim>
      node_location(const unsigned int node) const
      {
        const auto         index = node_index(node);
        dealii::Point<dim> p     = origin;
        for (unsigned int d = 0; d < dim; ++d)
          p[d] += h[d] * index[d];
        return p;
      }

    };



    enum class BasisType
    {
      linear,
      cubic_bspline
    };



    /**
     * Linear hat functions. In cell c = floor(xi) (clamped) with
     * t = xi - c: N_c = 1 - t, N_{c+1} = t, dN/dxi = -1, +1.
     */
    struct Linear1D
    {
      static constexpr unsigned int n_support = 2;

      static constexpr unsigned int
      minimum_cells()
      {
        return 1;
      }

      /**
       * Values and xi-derivatives of the two functions nonzero in cell
       * @p cell at local coordinate @p t = xi - cell (normally in [0,1]).
       * Used by evaluate(); exposed so that both one-sided limits at a cell
       * face can be evaluated exactly.
       */
      DEAL_II_ALWAYS_INLINE static inline void
      evaluate_in_cell(const unsigned int cell,
                       const double       t,
                       const unsigned int /*n_cells*/,
                       int &              first,
                       double *           values,
                       double *           derivatives)
      {
        first          = static_cast<int>(cell);
        values[0]      = 1. - t;
        values[1]      = t;
        derivatives[0] = -1.;
        derivatives[1] = 1.;
      }

      /**
       * Support of the lattice coordinate @p xi (clamped into [0, n_cells]):
       * nodes first, first+1 with first the cell index.
       */
      DEAL_II_ALWAYS_INLINE static inline void
      evaluate(double             xi,
               const unsigned int n_cells,
               int &              first,
               double *           values,
               double *           derivatives)
      {
        xi                    = std::min(std::max(xi, 0.), static_cast<double>(n_cells));
        const unsigned int c  = clamped_cell(xi, n_cells);
        evaluate_in_cell(c, xi - c, n_cells, first, values, derivatives);
      }
    };



    /**
     * Uniform cubic B-splines with the boundary modification derived in the
     * file documentation: the support is the four nodes first..first+3, all
     * real nodes of a lattice with at least minimum_cells() = 3 cells.
     */
    struct CubicBSpline1D
    {
      static constexpr unsigned int n_support = 4;

      /**
       * Four consecutive real nodes need n_cells >= 3 in every direction;
       * callers validate their input against this.
       */
      static constexpr unsigned int
      minimum_cells()
      {
        return 3;
      }

      /**
       * Values and xi-derivatives of the (modified) splines nonzero in cell
       * @p cell at local coordinate @p t = xi - cell, on a lattice of
       * @p n_cells cells. Exposed so that both one-sided limits at a cell face
       * can be evaluated exactly.
       */
      DEAL_II_ALWAYS_INLINE static inline void
      evaluate_in_cell(const unsigned int cell,
                       const double       t,
                       const unsigned int n_cells,
                       int &              first,
                       double *           values,
                       double *           derivatives)
      {
        Assert(n_cells >= minimum_cells(),
               dealii::ExcMessage("The cubic B-spline basis needs at least 3 cells per direction."));
        const double t2 = t * t;
        const double t3 = t2 * t;
        if (cell == 0)
          {
            // nodes 0,1,2 (ghost -1 eliminated), node 3 padded with zero
            first          = 0;
            values[0]      = 1. - t + t3 * (1. / 6.);
            values[1]      = t - t3 * (1. / 3.);
            values[2]      = t3 * (1. / 6.);
            values[3]      = 0.;
            derivatives[0] = -1. + 0.5 * t2;
            derivatives[1] = 1. - t2;
            derivatives[2] = 0.5 * t2;
            derivatives[3] = 0.;
          }
        else if (cell + 1 == n_cells)
          {
            // mirror image with u = n - xi = 1 - t; nodes n-2, n-1, n, and
            // node n-3 padded with zero; d/dxi = -d/du
            const double u  = 1. - t;
            const double u2 = u * u;
            const double u3 = u2 * u;
            first           = static_cast<int>(cell) - 2;
            values[0]       = 0.;
            values[1]       = u3 * (1. / 6.);
            values[2]       = u - u3 * (1. / 3.);
            values[3]       = 1. - u + u3 * (1. / 6.);
            derivatives[0]  = 0.;
            derivatives[1]  = -0.5 * u2;
            derivatives[2]  = -(1. - u2);
            derivatives[3]  = 1. - 0.5 * u2;
          }
        else
          {
            // interior: unmodified splines of nodes cell-1 .. cell+2
            const double s = 1. - t;
            first          = static_cast<int>(cell) - 1;
            values[0]      = s * s * s * (1. / 6.);
            values[1]      = 0.5 * t3 - t2 + 2. / 3.;
            values[2]      = (-3. * t3 + 3. * t2 + 3. * t + 1.) * (1. / 6.);
            values[3]      = t3 * (1. / 6.);
            derivatives[0] = -0.5 * s * s;
            derivatives[1] = 1.5 * t2 - 2. * t;
            derivatives[2] = -1.5 * t2 + t + 0.5;
            derivatives[3] = 0.5 * t2;
          }
      }

      /**
       * Support of the lattice coordinate @p xi (clamped into [0, n_cells]).
       */
      DEAL_II_ALWAYS_INLINE static inline void
      evaluate(double             xi,
               const unsigned int n_cells,
               int &              first,
               double *           values,
               double *           derivatives)
      {
        xi                   = std::min(std::max(xi, 0.), static_cast<double>(n_cells));
        const unsigned int c = clamped_cell(xi, n_cells);
        evaluate_in_cell(c, xi - c, n_cells, first, values, derivatives);
      }
    };



    /**
     * Tensor-product shape data of one particle: the n = n_support^dim
     * functions whose support contains the particle, in lexicographic order
     * of their local multi-index (x index fastest), i.e. entry
     * k = a + m (b + m c) belongs to node (first[0]+a, first[1]+b, first[2]+c)
     * with m = n_support. Gradients are in physical units (1/length).
     */
    template <int dim, typename Basis1D>
    struct ShapeData
    {
      static constexpr unsigned int n_1d = Basis1D::n_support;
      static constexpr unsigned int n    = integer_pow(Basis1D::n_support, dim);

      std::array<int, dim>      first;
      double                    values[n];
      dealii::Tensor<1, dim>    gradients[n];

      /**
       * Lattice multi-index of the node of entry @p k.
       */
      std::array<unsigned int, dim>
      node_index(unsigned int k) const
      {
        std::array<unsigned int, dim> index;
        for (unsigned int d = 0; d < dim; ++d)
          {
            index[d] = static_cast<unsigned int>(first[d]) + k % n_1d;
            k /= n_1d;
          }
        return index;
      }

      /**
       * Global (lattice-lexicographic) node number of entry @p k:
       * i + (nx+1) (j + (ny+1) k).
       */
      unsigned int
      node(const Lattice<dim> &lattice, const unsigned int k) const
      {
        return lattice.node_number(node_index(k));
      }
    };



    /**
     * Evaluate the tensor-product basis at @p x into @p out: per direction
     * one 1D kernel call on xi_d = (x_d - o_d)/h_d, then
     * N_k = prod_d N^d_{k_d}, (grad N_k)_d = h^{-1} dN^d_{k_d}/dxi prod_{e!=d} N^e_{k_e}.
     * No allocation, no virtual call.
     */
    template <int dim, typename Basis1D>
    inline void
    evaluate(const Lattice<dim> &          lattice,
             const dealii::Point<dim> &    x,
             ShapeData<dim, Basis1D> &     out)
    {
      static_assert(dim >= 1 && dim <= 3, "dim must be 1, 2 or 3");
      constexpr unsigned int m = Basis1D::n_support;
      double                 v[dim][m];
      double                 dv[dim][m];
      for (unsigned int d = 0; d < dim; ++d)
        {
          const double inv_h = 1. / lattice.h[d];
          Basis1D::evaluate((x[d] - lattice.origin[d]) * inv_h,
                            lattice.n_cells[d],
                            out.first[d],
                            v[d],
                            dv[d]);
          for (unsigned int a = 0; a < m; ++a)
            dv[d][a] *= inv_h;
        }

      if constexpr (dim == 1)
        {
          for (unsigned int a = 0; a < m; ++a)
            {
              out.values[a]       = v[0][a];
              out.gradients[a][0] = dv[0][a];
            }
        }
      else if constexpr (dim == 2)
        {
          unsigned int k = 0;
          for (unsigned int b = 0; b < m; ++b)
            for (unsigned int a = 0; a < m; ++a, ++k)
              {
                out.values[k]       = v[0][a] * v[1][b];
                out.gradients[k][0] = dv[0][a] * v[1][b];
                out.gradients[k][1] = v[0][a] * dv[1][b];
              }
        }
      else
        {
          unsigned int k = 0;
          for (unsigned int c = 0; c < m; ++c)
            for (unsigned int b = 0; b < m; ++b)
              {
                const double v_bc  = v[1][b] * v[2][c];
                const double dv_bc = dv[1][b] * v[2][c];
                const double v_bdc = v[1][b] * dv[2][c];
                for (unsigned int a = 0; a < m; ++a, ++k)
                  {
                    out.values[k]       = v[0][a] * v_bc;
                    out.gradients[k][0] = dv[0][a] * v_bc;
                    out.gradients[k][1] = v[0][a] * dv_bc;
                    out.gradients[k][2] = v[0][a] * v_bdc;
                  }
              }
        }
    }
  } // namespace MPM
} // namespace hysteron

#endif

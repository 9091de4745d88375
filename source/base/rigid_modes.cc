#include <hysteron/base/rigid_modes.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace hysteron
{
  template <int dim>
  RigidModeCheck<dim>::RigidModeCheck(const std::vector<dealii::Point<dim>> &centres,
                                      const std::vector<double>             &sizes)
    : centres(centres)
    , sizes(sizes)
    , gram(centres.size() * n_modes * n_modes, 0.0)
  {}

  template <int dim>
  void
  RigidModeCheck<dim>::add_displacement(const unsigned int        part,
                                        const dealii::Point<dim> &x,
                                        const unsigned int        direction)
  {
    // a_k = r_k(x)_direction: translations e_k, rotations e_i x (x - x_c) / L.
    double                       a[n_modes] = {};
    const dealii::Tensor<1, dim> r          = (x - centres[part]) / sizes[part];
    a[direction]                            = 1;
    if constexpr (dim == 2)
      a[2] = direction == 0 ? -r[1] : r[0]; // (-y, x)
    else
      for (unsigned int i = 0; i < 3; ++i)
        {
          // (e_i x r)_direction = eps_{direction i j} r_j
          const unsigned int j = 3 - i - direction;
          if (i != direction && j < dim && j != i && j != direction)
            a[dim + i] = ((direction + 1) % 3 == i ? 1.0 : -1.0) * r[j];
        }
    double *g = gram.data() + part * n_modes * n_modes;
    for (unsigned int k = 0; k < n_modes; ++k)
      for (unsigned int l = 0; l < n_modes; ++l)
        g[k * n_modes + l] += a[k] * a[l];
  }

  template <int dim>
  void
  RigidModeCheck<dim>::add_rotation(const unsigned int part, const unsigned int axis)
  {
    static_assert(dim == 2 || dim == 3, "");
    // A rotation DoF theta_axis of a rigid cell: the rotation mode about that axis moves
    // it by 1 (per L).
    const unsigned int k = dim + axis;
    double            *g = gram.data() + part * n_modes * n_modes;
    g[k * n_modes + k] += 1;
  }

  template <int dim>
  void
  RigidModeCheck<dim>::sum(const MPI_Comm comm)
  {
    const std::vector<double> local = gram;
    dealii::Utilities::MPI::sum(local, comm, gram);
  }

  template <int dim>
  std::vector<std::string>
  RigidModeCheck<dim>::free_modes(const unsigned int part) const
  {
    // The rank of G by Gaussian elimination with full pivoting, relative to its
    // largest entry; a mode is free on its own when its diagonal entry vanishes.
    std::vector<double> g(gram.begin() + part * n_modes * n_modes,
                          gram.begin() + (part + 1) * n_modes * n_modes);
    const double        scale = *std::max_element(g.begin(), g.end());
    const double        tiny  = 1e-10 * std::max(scale, 1e-300);
    static const char *const names[] = {"translation in x", "translation in y", "translation in z",
                                        "rotation about x", "rotation about y", "rotation about z"};
    std::vector<std::string> out;
    for (unsigned int k = 0; k < n_modes; ++k)
      if (!(g[k * n_modes + k] > tiny))
        out.push_back(dim == 2 ? (k < 2 ? names[k] : "rotation") : names[k]);

    std::vector<unsigned int> rows(n_modes), cols(n_modes);
    std::iota(rows.begin(), rows.end(), 0u);
    std::iota(cols.begin(), cols.end(), 0u);
    unsigned int rank = 0;
    for (; rank < n_modes; ++rank)
      {
        unsigned int pr = rank, pc = rank;
        double       best = 0;
        for (unsigned int i = rank; i < n_modes; ++i)
          for (unsigned int j = rank; j < n_modes; ++j)
            if (std::abs(g[rows[i] * n_modes + cols[j]]) > best)
              {
                best = std::abs(g[rows[i] * n_modes + cols[j]]);
                pr   = i;
                pc   = j;
              }
        if (!(best > tiny))
          break;
        std::swap(rows[rank], rows[pr]);
        std::swap(cols[rank], cols[pc]);
        const double pivot = g[rows[rank] * n_modes + cols[rank]];
        for (unsigned int i = rank + 1; i < n_modes; ++i)
          {
            const double f = g[rows[i] * n_modes + cols[rank]] / pivot;
            for (unsigned int j = rank; j < n_modes; ++j)
              g[rows[i] * n_modes + cols[j]] -= f * g[rows[rank] * n_modes + cols[j]];
          }
      }
    if (n_modes - rank > out.size())
      out.push_back("a combination of translation and rotation");
    return out;
  }

  ConnectedParts::ConnectedParts(const unsigned int n)
    : parent(n)
  {
    std::iota(parent.begin(), parent.end(), 0u);
  }

  unsigned int
  ConnectedParts::root(unsigned int a)
  {
    while (parent[a] != a)
      a = parent[a] = parent[parent[a]];
    return a;
  }

  void
  ConnectedParts::join(const unsigned int a, const unsigned int b)
  {
    const unsigned int ra = root(a), rb = root(b);
    if (ra != rb)
      parent[std::max(ra, rb)] = std::min(ra, rb);
  }

  std::vector<unsigned int>
  ConnectedParts::parts()
  {
    std::vector<unsigned int> number(parent.size(), ~0u), out(parent.size());
    unsigned int              n = 0;
    for (unsigned int i = 0; i < parent.size(); ++i)
      {
        const unsigned int r = root(i);
        if (number[r] == ~0u)
          number[r] = n++;
        out[i] = number[r];
      }
    return out;
  }

  template class RigidModeCheck<2>;
  template class RigidModeCheck<3>;
} // namespace hysteron

// Unit tests of the MPM background-grid bases (source/mpm/basis.h): partition
// of unity and linear completeness of the linear and boundary-modified cubic
// B-spline kernels in 1D and as 2D/3D tensor products, analytic values,
// derivatives against finite differences, C1 continuity of the cubic basis
// across cell faces, nonnegativity, node ranges and the upper boundary.
#include "mpm/basis.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace
{
  using hysteron::MPM::CubicBSpline1D;
  using hysteron::MPM::Lattice;
  using hysteron::MPM::Linear1D;
  using hysteron::MPM::ShapeData;
  using dealii::Point;
  using dealii::Tensor;

  // The uniform cubic B-spline B(r) and its derivative.
  double
  bspline(const double r)
  {
    const double a = std::abs(r);
    if (a <= 1.)
      return 2. / 3. - a * a + 0.5 * a * a * a;
    if (a <= 2.)
      return (2. - a) * (2. - a) * (2. - a) / 6.;
    return 0.;
  }

  double
  bspline_derivative(const double r)
  {
    const double a    = std::abs(r);
    const double sign = r < 0 ? -1. : 1.;
    if (a <= 1.)
      return sign * (-2. * a + 1.5 * a * a);
    if (a <= 2.)
      return -sign * 0.5 * (2. - a) * (2. - a);
    return 0.;
  }

  // Scatter a 1D support (first, values, derivatives) into dense arrays over
  // all n+1 nodes, checking that every entry refers to a real node.
  template <typename Basis>
  void
  scatter_1d(const int                   first,
             const double *              v,
             const double *              dv,
             const unsigned int          n,
             std::vector<double> &       values,
             std::vector<double> &       derivatives)
  {
    values.assign(n + 1, 0.);
    derivatives.assign(n + 1, 0.);
    ASSERT_GE(first, 0);
    ASSERT_LE(first + static_cast<int>(Basis::n_support) - 1, static_cast<int>(n));
    for (unsigned int a = 0; a < Basis::n_support; ++a)
      {
        values[first + a] += v[a];
        derivatives[first + a] += dv[a];
      }
  }

  template <typename Basis>
  void
  dense_1d(const double xi, const unsigned int n, std::vector<double> &values, std::vector<double> &derivatives)
  {
    int    first = -1;
    double v[Basis::n_support], dv[Basis::n_support];
    Basis::evaluate(xi, n, first, v, dv);
    scatter_1d<Basis>(first, v, dv, n, values, derivatives);
  }

  template <typename Basis>
  void
  dense_1d_in_cell(const unsigned int    cell,
                   const double          t,
                   const unsigned int    n,
                   std::vector<double> & values,
                   std::vector<double> & derivatives)
  {
    int    first = -1;
    double v[Basis::n_support], dv[Basis::n_support];
    Basis::evaluate_in_cell(cell, t, n, first, v, dv);
    scatter_1d<Basis>(first, v, dv, n, values, derivatives);
  }

  // Sample lattice coordinates in [0, n]: every multiple of 1/8 (nodes, cell
  // faces, quarter points) plus pseudo-random points.
  std::vector<double>
  sample_points_1d(const unsigned int n)
  {
    std::vector<double> xs;
    for (unsigned int i = 0; i <= 8 * n; ++i)
      xs.push_back(i / 8.);
    std::mt19937                           rng(42 + n);
    std::uniform_real_distribution<double> dist(0., static_cast<double>(n));
    for (unsigned int i = 0; i < 200; ++i)
      xs.push_back(dist(rng));
    xs.push_back(1e-15);
    xs.push_back(n - 1e-15);
    return xs;
  }

  template <typename Basis>
  void
  check_1d_reproduction(const unsigned int n)
  {
    std::vector<double> v, dv;
    for (const double xi : sample_points_1d(n))
      {
        SCOPED_TRACE("n = " + std::to_string(n) + ", xi = " + std::to_string(xi));
        dense_1d<Basis>(xi, n, v, dv);
        double sum = 0, first_moment = 0, sum_d = 0, first_moment_d = 0;
        for (unsigned int i = 0; i <= n; ++i)
          {
            EXPECT_GE(v[i], 0.);
            sum += v[i];
            first_moment += v[i] * i;
            sum_d += dv[i];
            first_moment_d += dv[i] * i;
          }
        EXPECT_NEAR(sum, 1., 1e-13);
        EXPECT_NEAR(first_moment, xi, 1e-13);
        EXPECT_NEAR(sum_d, 0., 1e-13);
        EXPECT_NEAR(first_moment_d, 1., 1e-13);
      }
  }
} // namespace



TEST(MpmBasis1D, LinearPartitionOfUnityAndCompleteness)
{
  for (const unsigned int n : {1u, 2u, 3u, 5u, 8u})
    check_1d_reproduction<Linear1D>(n);
}



TEST(MpmBasis1D, CubicPartitionOfUnityAndCompleteness)
{
  EXPECT_EQ(CubicBSpline1D::minimum_cells(), 3u);
  EXPECT_EQ(Linear1D::minimum_cells(), 1u);
  for (const unsigned int n : {3u, 4u, 5u, 8u, 17u})
    check_1d_reproduction<CubicBSpline1D>(n);
}



TEST(MpmBasis1D, LinearValues)
{
  std::vector<double> v, dv;
  dense_1d<Linear1D>(2.25, 4, v, dv);
  EXPECT_DOUBLE_EQ(v[2], 0.75);
  EXPECT_DOUBLE_EQ(v[3], 0.25);
  EXPECT_DOUBLE_EQ(dv[2], -1.);
  EXPECT_DOUBLE_EQ(dv[3], 1.);
  // upper boundary: last cell, interpolatory
  int    first;
  double w[2], dw[2];
  Linear1D::evaluate(4., 4, first, w, dw);
  EXPECT_EQ(first, 3);
  EXPECT_DOUBLE_EQ(w[0], 0.);
  EXPECT_DOUBLE_EQ(w[1], 1.);
  // n_cells = 1
  Linear1D::evaluate(0.3, 1, first, w, dw);
  EXPECT_EQ(first, 0);
  EXPECT_DOUBLE_EQ(w[0], 0.7);
  EXPECT_DOUBLE_EQ(w[1], 0.3);
}



TEST(MpmBasis1D, CubicInteriorValuesAreTheBSpline)
{
  const unsigned int  n = 7;
  std::vector<double> v, dv;

  // at a node: 1/6, 2/3, 1/6 with slopes -1/2, 0, +1/2 (the function of the
  // node left of xi is decreasing)
  dense_1d<CubicBSpline1D>(3., n, v, dv);
  EXPECT_NEAR(v[2], 1. / 6., 1e-15);
  EXPECT_NEAR(v[3], 2. / 3., 1e-15);
  EXPECT_NEAR(v[4], 1. / 6., 1e-15);
  EXPECT_EQ(v[1], 0.);
  EXPECT_EQ(v[5], 0.);
  EXPECT_NEAR(dv[2], -0.5, 1e-15);
  EXPECT_NEAR(dv[3], 0., 1e-15);
  EXPECT_NEAR(dv[4], 0.5, 1e-15);

  // at a cell midpoint: 1/48, 23/48, 23/48, 1/48
  dense_1d<CubicBSpline1D>(3.5, n, v, dv);
  EXPECT_NEAR(v[2], 1. / 48., 1e-15);
  EXPECT_NEAR(v[3], 23. / 48., 1e-15);
  EXPECT_NEAR(v[4], 23. / 48., 1e-15);
  EXPECT_NEAR(v[5], 1. / 48., 1e-15);

  // the boundary modification only touches cells 0 and n-1: on [1, n-1]
  // every function is the unmodified B(xi - i)
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> dist(1., n - 1.);
  for (unsigned int s = 0; s < 200; ++s)
    {
      const double xi = dist(rng);
      dense_1d<CubicBSpline1D>(xi, n, v, dv);
      for (unsigned int i = 0; i <= n; ++i)
        {
          EXPECT_NEAR(v[i], bspline(xi - i), 1e-15) << "xi = " << xi << ", i = " << i;
          EXPECT_NEAR(dv[i], bspline_derivative(xi - i), 1e-14) << "xi = " << xi << ", i = " << i;
        }
    }
}



TEST(MpmBasis1D, CubicBoundaryModification)
{
  const unsigned int  n = 6;
  std::vector<double> v, dv, vm, dvm;

  // interpolatory at both boundary nodes
  dense_1d<CubicBSpline1D>(0., n, v, dv);
  EXPECT_DOUBLE_EQ(v[0], 1.);
  for (unsigned int i = 1; i <= n; ++i)
    EXPECT_EQ(v[i], 0.);
  EXPECT_DOUBLE_EQ(dv[0], -1.);
  EXPECT_DOUBLE_EQ(dv[1], 1.);
  EXPECT_EQ(dv[2], 0.);

  dense_1d<CubicBSpline1D>(static_cast<double>(n), n, v, dv);
  EXPECT_DOUBLE_EQ(v[n], 1.);
  for (unsigned int i = 0; i < n; ++i)
    EXPECT_EQ(v[i], 0.);

  // cell 0: N_0' = N_0 + 2 N_{-1}, N_1' = N_1 - N_{-1}, N_2 unchanged;
  // upper boundary by mirror symmetry N_i(xi) = N_{n-i}(n - xi)
  std::mt19937                           rng(11);
  std::uniform_real_distribution<double> dist(0., 1.);
  for (unsigned int s = 0; s < 200; ++s)
    {
      const double xi = dist(rng);
      dense_1d<CubicBSpline1D>(xi, n, v, dv);
      EXPECT_NEAR(v[0], bspline(xi) + 2. * bspline(xi + 1.), 1e-15);
      EXPECT_NEAR(v[1], bspline(xi - 1.) - bspline(xi + 1.), 1e-15);
      EXPECT_NEAR(v[2], bspline(xi - 2.), 1e-15);
      EXPECT_NEAR(dv[0], bspline_derivative(xi) + 2. * bspline_derivative(xi + 1.), 1e-14);
      EXPECT_NEAR(dv[1], bspline_derivative(xi - 1.) - bspline_derivative(xi + 1.), 1e-14);
      EXPECT_NEAR(dv[2], bspline_derivative(xi - 2.), 1e-14);
      EXPECT_EQ(v[3], 0.);

      const double x2 = dist(rng) * n;
      dense_1d<CubicBSpline1D>(x2, n, v, dv);
      dense_1d<CubicBSpline1D>(n - x2, n, vm, dvm);
      for (unsigned int i = 0; i <= n; ++i)
        {
          EXPECT_NEAR(v[i], vm[n - i], 1e-14);
          EXPECT_NEAR(dv[i], -dvm[n - i], 1e-14);
        }
    }
}



TEST(MpmBasis1D, SupportAndClamping)
{
  int    first;
  double v[4], dv[4];
  for (const unsigned int n : {3u, 4u, 9u})
    {
      CubicBSpline1D::evaluate(0., n, first, v, dv);
      EXPECT_EQ(first, 0);
      CubicBSpline1D::evaluate(0.5, n, first, v, dv);
      EXPECT_EQ(first, 0);
      EXPECT_EQ(v[3], 0.);
      CubicBSpline1D::evaluate(n, n, first, v, dv);
      EXPECT_EQ(first, static_cast<int>(n) - 3);
      EXPECT_DOUBLE_EQ(v[3], 1.);
      EXPECT_EQ(v[0], 0.);
      // round-off outside the box is projected onto it
      CubicBSpline1D::evaluate(n + 1e-13, n, first, v, dv);
      EXPECT_EQ(first, static_cast<int>(n) - 3);
      EXPECT_DOUBLE_EQ(v[3], 1.);
      CubicBSpline1D::evaluate(-1e-13, n, first, v, dv);
      EXPECT_EQ(first, 0);
      EXPECT_DOUBLE_EQ(v[0], 1.);
    }
  CubicBSpline1D::evaluate(2.5, 5, first, v, dv);
  EXPECT_EQ(first, 1);
  Linear1D::evaluate(-1e-13, 3, first, v, dv);
  EXPECT_EQ(first, 0);
  EXPECT_DOUBLE_EQ(v[0], 1.);
}



namespace
{
  template <typename Basis>
  void
  check_finite_differences_1d(const unsigned int n, const bool avoid_faces)
  {
    const double        delta = 1e-6;
    std::vector<double> v, dv, vp, dvp, vm, dvm;
    for (double xi : sample_points_1d(n))
      {
        if (avoid_faces)
          {
            const double t = xi - std::floor(xi);
            if (t < 10 * delta || t > 1. - 10 * delta)
              continue;
          }
        xi = std::min(std::max(xi, delta), n - delta);
        dense_1d<Basis>(xi, n, v, dv);
        dense_1d<Basis>(xi + delta, n, vp, dvp);
        dense_1d<Basis>(xi - delta, n, vm, dvm);
        for (unsigned int i = 0; i <= n; ++i)
          EXPECT_NEAR(dv[i], (vp[i] - vm[i]) / (2. * delta), 1e-7) << "xi = " << xi << ", i = " << i;
      }
  }
} // namespace



TEST(MpmBasis1D, DerivativesMatchFiniteDifferences)
{
  for (const unsigned int n : {3u, 4u, 7u})
    {
      check_finite_differences_1d<CubicBSpline1D>(n, false);
      check_finite_differences_1d<Linear1D>(n, true);
    }
}



TEST(MpmBasis1D, CubicIsC1AcrossCellFaces)
{
  std::vector<double> vl, dvl, vr, dvr;
  for (const unsigned int n : {3u, 4u, 5u, 8u})
    for (unsigned int c = 1; c < n; ++c)
      {
        // both one-sided limits at the face xi = c, evaluated exactly
        dense_1d_in_cell<CubicBSpline1D>(c - 1, 1., n, vl, dvl);
        dense_1d_in_cell<CubicBSpline1D>(c, 0., n, vr, dvr);
        for (unsigned int i = 0; i <= n; ++i)
          {
            EXPECT_NEAR(vl[i], vr[i], 1e-12) << "n = " << n << ", face " << c << ", node " << i;
            EXPECT_NEAR(dvl[i], dvr[i], 1e-12) << "n = " << n << ", face " << c << ", node " << i;
          }
      }

  // the same check detects the gradient jump of the (C0) linear basis
  dense_1d_in_cell<Linear1D>(1, 1., 4, vl, dvl);
  dense_1d_in_cell<Linear1D>(2, 0., 4, vr, dvr);
  double max_value_jump = 0, max_derivative_jump = 0;
  for (unsigned int i = 0; i <= 4; ++i)
    {
      max_value_jump      = std::max(max_value_jump, std::abs(vl[i] - vr[i]));
      max_derivative_jump = std::max(max_derivative_jump, std::abs(dvl[i] - dvr[i]));
    }
  EXPECT_LT(max_value_jump, 1e-15);
  // the hat of node 2 has slope +1 on the left and -1 on the right of its node
  EXPECT_DOUBLE_EQ(max_derivative_jump, 2.);
}



TEST(MpmBasisLattice, CellsNodesAndContainment)
{
  Lattice<3> lattice;
  lattice.origin  = Point<3>(0.5, -1., 2.);
  lattice.h       = hysteron::MPM::uniform_h<3>(0.25);
  lattice.n_cells = {{4, 3, 5}};

  EXPECT_EQ(lattice.n_nodes_1d(0), 5u);
  EXPECT_EQ(lattice.n_nodes_1d(2), 6u);
  EXPECT_EQ(lattice.n_nodes(), 5u * 4u * 6u);

  const Point<3> upper(0.5 + 4 * 0.25, -1. + 3 * 0.25, 2. + 5 * 0.25);
  EXPECT_TRUE(lattice.contains(lattice.origin));
  EXPECT_TRUE(lattice.contains(upper));
  EXPECT_FALSE(lattice.contains(Point<3>(0.49, -0.5, 2.5)));
  EXPECT_FALSE(lattice.contains(Point<3>(1.0, -0.5, 3.26)));

  auto c = lattice.cell_of(upper);
  EXPECT_EQ(c[0], 3u);
  EXPECT_EQ(c[1], 2u);
  EXPECT_EQ(c[2], 4u);
  c = lattice.cell_of(lattice.origin);
  EXPECT_EQ(c[0] + c[1] + c[2], 0u);
  c = lattice.cell_of(Point<3>(0.5 + 0.3, -1. + 0.5, 2. + 0.74));
  EXPECT_EQ(c[0], 1u);
  EXPECT_EQ(c[1], 2u);
  EXPECT_EQ(c[2], 2u);

  for (unsigned int node = 0; node < lattice.n_nodes(); ++node)
    EXPECT_EQ(lattice.node_number(lattice.node_index(node)), node);
  EXPECT_EQ(lattice.node_number({{1, 2, 3}}), 1u + 5u * (2u + 4u * 3u));
  const Point<3> p = lattice.node_location(lattice.node_number({{1, 2, 3}}));
  EXPECT_NEAR(p.distance(Point<3>(0.75, -0.5, 2.75)), 0., 1e-15);
}



namespace
{
  template <int dim_, typename Basis_>
  struct Config
  {
    static constexpr int dim = dim_;
    using Basis              = Basis_;
  };

  template <typename C>
  class MpmBasisTensorProduct : public ::testing::Test
  {
  protected:
    static constexpr int dim = C::dim;
    using Basis              = typename C::Basis;
    using Data               = ShapeData<dim, Basis>;

    MpmBasisTensorProduct()
    {
      // Cells of a different size in each direction: the lattice of a grid that
      // moved and stretched (MPM/Grid/Motion); the basis is the same in xi_d.
      const double origin[3] = {0.3, -0.7, 0.1};
      const double h[3]      = {0.25, 0.4, 0.15};
      const unsigned int n[3] = {4, 3, 5};
      for (unsigned int d = 0; d < dim; ++d)
        {
          lattice.origin[d]  = origin[d];
          lattice.n_cells[d] = n[d];
          lattice.h[d]       = h[d];
        }
    }

    // Nodes and cell faces and midpoints in every direction (all their
    // combinations), plus pseudo-random points.
    std::vector<Point<dim>>
    sample_points() const
    {
      std::vector<Point<dim>> points;
      unsigned int            n_special = 1;
      for (unsigned int d = 0; d < dim; ++d)
        n_special *= 2 * lattice.n_cells[d] + 1;
      for (unsigned int s = 0; s < n_special; ++s)
        {
          Point<dim>   p;
          unsigned int r = s;
          for (unsigned int d = 0; d < dim; ++d)
            {
              const unsigned int m = 2 * lattice.n_cells[d] + 1;
              p[d]                 = lattice.origin[d] + 0.5 * lattice.h[d] * (r % m);
              r /= m;
            }
          points.push_back(p);
        }
      std::mt19937                           rng(3 + dim);
      std::uniform_real_distribution<double> unit(0., 1.);
      for (unsigned int s = 0; s < 300; ++s)
        {
          Point<dim> p;
          for (unsigned int d = 0; d < dim; ++d)
            p[d] = lattice.origin[d] + unit(rng) * lattice.n_cells[d] * lattice.h[d];
          points.push_back(p);
        }
      return points;
    }

    void
    dense(const Point<dim> &x, std::vector<double> &values, std::vector<Tensor<1, dim>> &gradients) const
    {
      Data data;
      hysteron::MPM::evaluate(lattice, x, data);
      values.assign(lattice.n_nodes(), 0.);
      gradients.assign(lattice.n_nodes(), Tensor<1, dim>());
      for (unsigned int k = 0; k < Data::n; ++k)
        {
          const unsigned int node = data.node(lattice, k);
          ASSERT_LT(node, lattice.n_nodes());
          values[node] += data.values[k];
          gradients[node] += data.gradients[k];
        }
    }

    Lattice<dim> lattice;
  };

  using Configs = ::testing::Types<Config<1, Linear1D>,
                                   Config<2, Linear1D>,
                                   Config<3, Linear1D>,
                                   Config<1, CubicBSpline1D>,
                                   Config<2, CubicBSpline1D>,
                                   Config<3, CubicBSpline1D>>;
} // namespace

TYPED_TEST_SUITE(MpmBasisTensorProduct, Configs);



TYPED_TEST(MpmBasisTensorProduct, PartitionOfUnityAndLinearCompleteness)
{
  constexpr int dim = TestFixture::dim;
  using Data        = typename TestFixture::Data;
  static_assert(Data::n == hysteron::MPM::integer_pow(TestFixture::Basis::n_support, dim));

  const auto &lattice = this->lattice;
  for (const auto &x : this->sample_points())
    {
      SCOPED_TRACE(::testing::Message() << "x = " << x);
      Data data;
      hysteron::MPM::evaluate(lattice, x, data);
      double         sum = 0;
      Point<dim>     first_moment;
      Tensor<1, dim> sum_gradients;
      Tensor<2, dim> moment_gradients;
      for (unsigned int k = 0; k < Data::n; ++k)
        {
          const auto index = data.node_index(k);
          for (unsigned int d = 0; d < dim; ++d)
            ASSERT_LE(index[d], lattice.n_cells[d]);
          const unsigned int node = data.node(lattice, k);
          ASSERT_LT(node, lattice.n_nodes());
          const Point<dim> x_i = lattice.node_location(node);
          EXPECT_GE(data.values[k], 0.);
          sum += data.values[k];
          first_moment += data.values[k] * x_i;
          sum_gradients += data.gradients[k];
          moment_gradients += outer_product(Tensor<1, dim>(x_i), data.gradients[k]);
        }
      EXPECT_NEAR(sum, 1., 1e-13);
      for (unsigned int d = 0; d < dim; ++d)
        {
          EXPECT_NEAR(first_moment[d], x[d], 1e-13);
          EXPECT_NEAR(sum_gradients[d], 0., 1e-13);
          for (unsigned int e = 0; e < dim; ++e)
            EXPECT_NEAR(moment_gradients[d][e], d == e ? 1. : 0., 1e-13);
        }
    }
}



TYPED_TEST(MpmBasisTensorProduct, IsProductOfOneDimensionalKernels)
{
  constexpr int dim = TestFixture::dim;
  using Basis       = typename TestFixture::Basis;
  using Data        = typename TestFixture::Data;
  constexpr unsigned int m = Basis::n_support;

  const auto &lattice = this->lattice;
  for (const auto &x : this->sample_points())
    {
      Data data;
      hysteron::MPM::evaluate(lattice, x, data);
      double v[dim][m], dv[dim][m];
      for (unsigned int d = 0; d < dim; ++d)
        {
          int first;
          Basis::evaluate((x[d] - lattice.origin[d]) / lattice.h[d], lattice.n_cells[d], first, v[d], dv[d]);
          EXPECT_EQ(first, data.first[d]);
        }
      for (unsigned int k = 0; k < Data::n; ++k)
        {
          double         value = 1;
          Tensor<1, dim> gradient;
          for (unsigned int d = 0; d < dim; ++d)
            gradient[d] = 1. / lattice.h[d];
          unsigned int r = k;
          for (unsigned int d = 0; d < dim; ++d, r /= m)
            {
              value *= v[d][r % m];
              for (unsigned int e = 0; e < dim; ++e)
                gradient[e] *= (e == d ? dv[d][r % m] : v[d][r % m]);
            }
          EXPECT_NEAR(data.values[k], value, 1e-15);
          for (unsigned int e = 0; e < dim; ++e)
            EXPECT_NEAR(data.gradients[k][e], gradient[e], 1e-14);
        }
    }
}



TYPED_TEST(MpmBasisTensorProduct, GradientsMatchFiniteDifferences)
{
  constexpr int dim        = TestFixture::dim;
  const bool    is_linear  = std::is_same_v<typename TestFixture::Basis, Linear1D>;
  const auto &  lattice    = this->lattice;
  const double  delta      = 1e-6 * lattice.min_h();

  std::vector<double>         v, vp, vm;
  std::vector<Tensor<1, dim>> g, gp, gm;
  unsigned int                n_checked = 0;
  for (auto x : this->sample_points())
    {
      bool skip = false;
      for (unsigned int d = 0; d < dim; ++d)
        {
          const double xi = (x[d] - lattice.origin[d]) / lattice.h[d];
          const double t  = xi - std::floor(xi);
          // the linear basis has kinks at every face, the cubic one only at
          // the ends of the box where the FD stencil would leave it
          if ((is_linear && (t < 1e-4 || t > 1. - 1e-4)) || xi < 1e-4 || xi > lattice.n_cells[d] - 1e-4)
            skip = true;
        }
      if (skip)
        continue;
      ++n_checked;
      this->dense(x, v, g);
      for (unsigned int d = 0; d < dim; ++d)
        {
          Point<dim> xp = x, xm = x;
          xp[d] += delta;
          xm[d] -= delta;
          this->dense(xp, vp, gp);
          this->dense(xm, vm, gm);
          for (unsigned int i = 0; i < v.size(); ++i)
            EXPECT_NEAR(g[i][d] * lattice.h[d], (vp[i] - vm[i]) / (2. * delta) * lattice.h[d], 1e-7)
              << "x = " << x << ", node " << i << ", direction " << d;
        }
    }
  EXPECT_GT(n_checked, 100u);
}



namespace
{
  template <typename C>
  class MpmBasisCubicTensorProduct : public MpmBasisTensorProduct<C>
  {};

  using CubicConfigs =
    ::testing::Types<Config<1, CubicBSpline1D>, Config<2, CubicBSpline1D>, Config<3, CubicBSpline1D>>;
} // namespace

TYPED_TEST_SUITE(MpmBasisCubicTensorProduct, CubicConfigs);



TYPED_TEST(MpmBasisCubicTensorProduct, IsC1AcrossCellFaces)
{
  constexpr int dim = TestFixture::dim;

  const auto &                lattice = this->lattice;
  std::vector<double>         vl, vr;
  std::vector<Tensor<1, dim>> gl, gr;
  // points on interior faces (including those next to the boundary cells),
  // approached from both sides by 1e-13 h
  for (auto x : this->sample_points())
    for (unsigned int d = 0; d < dim; ++d)
      {
        const double xi = (x[d] - lattice.origin[d]) / lattice.h[d];
        const double c  = std::round(xi);
        if (std::abs(xi - c) > 1e-12 || c < 1 || c > lattice.n_cells[d] - 1)
          continue;
        Point<dim> xl = x, xr = x;
        xl[d] = lattice.origin[d] + (c - 1e-13) * lattice.h[d];
        xr[d] = lattice.origin[d] + (c + 1e-13) * lattice.h[d];
        this->dense(xl, vl, gl);
        this->dense(xr, vr, gr);
        for (unsigned int i = 0; i < vl.size(); ++i)
          {
            EXPECT_NEAR(vl[i], vr[i], 1e-12) << "x = " << x << ", node " << i;
            for (unsigned int e = 0; e < dim; ++e)
              EXPECT_NEAR(gl[i][e] * lattice.h[e], gr[i][e] * lattice.h[e], 1e-12) << "x = " << x << ", node " << i;
          }
      }
}



TYPED_TEST(MpmBasisTensorProduct, UpperCornerIsInterpolatory)
{
  constexpr int dim     = TestFixture::dim;
  using Data            = typename TestFixture::Data;
  const auto &  lattice = this->lattice;

  Point<dim>                    x;
  std::array<unsigned int, dim> corner;
  for (unsigned int d = 0; d < dim; ++d)
    {
      x[d]      = lattice.origin[d] + lattice.n_cells[d] * lattice.h[d];
      corner[d] = lattice.n_cells[d];
    }
  ASSERT_TRUE(lattice.contains(x));
  Data data;
  hysteron::MPM::evaluate(lattice, x, data);
  const unsigned int corner_node = lattice.node_number(corner);
  EXPECT_EQ(corner_node, lattice.n_nodes() - 1);
  bool found = false;
  for (unsigned int k = 0; k < Data::n; ++k)
    {
      ASSERT_LT(data.node(lattice, k), lattice.n_nodes());
      if (data.node(lattice, k) == corner_node)
        {
          found = true;
          EXPECT_NEAR(data.values[k], 1., 1e-15);
        }
      else
        EXPECT_NEAR(data.values[k], 0., 1e-15);
    }
  EXPECT_TRUE(found);
}

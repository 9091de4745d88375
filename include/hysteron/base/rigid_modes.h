#ifndef hysteron_base_rigid_modes_h
#define hysteron_base_rigid_modes_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/point.h>

#include <string>
#include <vector>

namespace hysteron
{
  /**
   * Does a set of supports prevent every rigid-body motion of a structure?
   *
   * A connected elastic structure has zero-energy modes only in its rigid-body
   * motions r(x) = a + omega x (x - x_c) (dim translations, 1 rotation in 2D, 3 in
   * 3D). A prescribed value of displacement component d at x (or of a rotation
   * DoF) removes the modes a_k with r_k(x)_d != 0; all are removed exactly when
   * the Gram matrix G = sum over the supports of a a^T, a_k = r_k(x)_d, is
   * regular. Without that, the static stiffness matrix is singular and Newton
   * drifts. The modes are scaled by the structure's size L (rotations as
   * L omega), so that G is dimensionless and its rank is decided with a relative
   * tolerance.
   *
   * One check holds any number of independent structures (connected parts of a
   * mesh or a network). G is a sum, so ranks add their supports and sum().
   */
  template <int dim>
  class RigidModeCheck
  {
  public:
    /// Number of rigid-body modes: dim translations and the rotations.
    static constexpr unsigned int n_modes = dim == 2 ? 3 : 6;

    /// @p n_parts independent structures, each with its centre and size.
    RigidModeCheck(const std::vector<dealii::Point<dim>> &centres, const std::vector<double> &sizes);

    /// A prescribed displacement component @p direction (< dim) of part @p part at @p x.
    void
    add_displacement(const unsigned int part, const dealii::Point<dim> &x, const unsigned int direction);

    /// A prescribed rotation DoF of a rigid-body-spring cell about the axis @p axis (2D:
    /// theta about z, axis 0; 3D: 0, 1, 2 for x, y, z).
    void
    add_rotation(const unsigned int part, const unsigned int axis = 0);

    /// Add the other ranks' supports.
    void
    sum(const MPI_Comm comm);

    /// The rigid-body motions the supports leave free in @p part ("translation in x",
    /// "rotation", or "a combination of translation and rotation"); empty if none.
    std::vector<std::string>
    free_modes(const unsigned int part) const;

  private:
    std::vector<dealii::Point<dim>> centres;
    std::vector<double>             sizes;
    std::vector<double>             gram; ///< n_modes^2 per part
  };

  /// Union-find: the connected parts of a graph whose nodes are 0..n-1.
  class ConnectedParts
  {
  public:
    explicit ConnectedParts(const unsigned int n);

    void
    join(const unsigned int a, const unsigned int b);

    /// The part of every node, numbered 0, 1, ... in the order of their first node.
    std::vector<unsigned int>
    parts();

  private:
    unsigned int
    root(unsigned int a);

    std::vector<unsigned int> parent;
  };
} // namespace hysteron

#endif

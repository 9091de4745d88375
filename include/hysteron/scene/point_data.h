#ifndef hysteron_scene_point_data_h
#define hysteron_scene_point_data_h

#include <deal.II/base/array_view.h>
#include <deal.II/base/point.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <hysteron/material/interface.h>
#include <hysteron/scene/output_column.h>

#include <array>
#include <string>
#include <vector>

namespace hysteron
{
  template <int dim>
  class Scene;

  /**
   * The tables every field method writes in the same layout, so that runs of
   * one scene by different methods (MPM material points, FEM quadrature points)
   * can be compared column by column (`hysteron --compare`):
   *
   *  - a point (probe_<i>.csv, average_<i>.csv, particles.csv, quadrature
   *    point tables): x_*, u_*, v_*, s_* (SymmetricTensor's unrolled order,
   *    tensor shear components), von_mises (with sigma_zz in 2D), eps_*, then
   *    the material's state variables;
   *  - energy.csv: kinetic, strain_energy, internal_work, dissipated,
   *    external_work, boundary_work, balance;
   *  - reactions.csv: <boundary>_x, <boundary>_y (, _z) per boundary condition,
   *    then per rigid body.
   */
  namespace PointData
  {
    /// "x", "y", "z".
    extern const char *const component_names[3];

    /// The columns of a point, without `time`: the fixed ones, the state variables, then
    /// the scene's @p additional columns (`Output/Additional columns`, output_column.h).
    template <int dim>
    std::vector<std::string>
    columns(const std::vector<std::string> &state_names, const ColumnSelection<dim> &additional);

    /// The von Mises stress sqrt(3/2 dev(s):dev(s)) of @p stress with the out-of-plane @p sigma_zz (2D).
    template <int dim>
    double
    von_mises(const dealii::SymmetricTensor<2, dim> &stress, const double sigma_zz);

    /**
     * The values of a point in the order of columns(): position @p x,
     * displacement @p u, velocity @p v, stress, von Mises, strain and the first
     * @p n_state_columns state variables (missing ones are 0; a null @p material
     * is a rigid point without stress state), then the scene's @p additional
     * columns (output_column.h).
     */
    template <int dim>
    void
    values(const dealii::Point<dim>               &x,
           const dealii::Tensor<1, dim>           &u,
           const dealii::Tensor<1, dim>           &v,
           const dealii::SymmetricTensor<2, dim>  &stress,
           const dealii::SymmetricTensor<2, dim>  &strain,
           const Material::Interface<dim>         *material,
           const dealii::ArrayView<const double>  &state,
           const unsigned int                      n_state_columns,
           double                                 *out,
           const ColumnSelection<dim>             &additional);

    /**
     * The elastic strain energy density [J/m^3] of @p stress,
     * w = ((1 + nu) s:s - nu tr(s)^2) / (2 E), with sigma_zz in 2D (from the
     * material's out_of_plane()).
     */
    template <int dim>
    double
    strain_energy_density(const Material::Interface<dim>        &material,
                          const dealii::SymmetricTensor<2, dim> &stress,
                          const dealii::SymmetricTensor<2, dim> &strain,
                          const dealii::ArrayView<const double> &state);

    /// The columns of energy.csv, with `time`; with @p damping_work a damping_work
    /// column before `balance`.
    std::vector<std::string>
    energy_columns(bool damping_work = false);

    /**
     * One row of energy.csv from the sums over the whole model at time t:
     * dissipated = internal work - (strain energy - initial strain energy),
     * balance = kinetic - initial kinetic + internal work - external work -
     * boundary work + damping work (zero for an exact scheme; the damping work is
     * that of a method's damping forces, 0 without). The first row sets the initial values.
     */
    class EnergyLog
    {
    public:
      std::vector<double>
      row(double t,
          double kinetic,
          double strain_energy,
          double internal_work,
          double external_work,
          double boundary_work,
          double damping_work = 0);

      /// The reference state (t = 0), for a checkpoint.
      std::array<double, 3>
      state() const
      {
        return {{started ? 1.0 : 0.0, initial_kinetic, initial_strain}};
      }

      void
      restore(const std::array<double, 3> &s)
      {
        started         = s[0] != 0;
        initial_kinetic = s[1];
        initial_strain  = s[2];
      }

    private:
      bool   started         = false;
      double initial_kinetic = 0, initial_strain = 0;
    };

    /// The columns of reactions.csv, with `time`: per boundary condition, then per rigid body.
    template <int dim>
    std::vector<std::string>
    reaction_columns(const Scene<dim> &scene);
  } // namespace PointData
} // namespace hysteron

#endif

#ifndef hysteron_material_interface_h
#define hysteron_material_interface_h

#include <deal.II/base/array_view.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/symmetric_tensor.h>

#include <hysteron/base/parameters.h>
#include <hysteron/base/registry.h>
#include <hysteron/material/elasticity.h>
#include <hysteron/material/uniaxial_spring_law.h>

#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace Material
  {
    /**
     * The terms of an axisymmetric tangent besides the in-plane d sigma / d eps:
     * the coupling with the hoop strain eps_tt (d sigma_tt = hoop_by_strain : d eps +
     * hoop_by_hoop d eps_tt, d sigma = C : d eps + stress_by_hoop d eps_tt).
     */
    template <int dim>
    struct HoopTangent
    {
      dealii::SymmetricTensor<2, dim> stress_by_hoop; ///< d sigma_ij / d eps_tt
      dealii::SymmetricTensor<2, dim> hoop_by_strain; ///< d sigma_tt / d eps_kl
      double                          hoop_by_hoop = 0; ///< d sigma_tt / d eps_tt
    };

    /**
     * The interface of every constitutive model (deal.II style: a class
     * templated on dim; SymmetricTensor at the interface).
     *
     * A model is a map (strain increment, stress, state) -> (stress, state,
     * tangent). The per-point state is a flat, fixed-size array of doubles
     * (n_state_variables() of them, each with a name), so that it packs into
     * particle properties, quadrature-point history and spring arrays alike.
     *
     * update() works on a batch of points: one virtual call per batch, and the
     * model's own loop inside, so that hot loops (MPM particles, FEM quadrature
     * points) pay no virtual call per point.
     *
     * Writing a new model: derive from this class, implement update() (and the
     * state description if the model has internal variables), give it a static
     * declare_parameters(ParameterHandler &) that declares its entries inside
     * `subsection Material`, override parse_parameters(), and register it with
     * HYSTERON_REGISTER_MATERIAL(ClassName, "name", "description").
     */
    template <int dim>
    class Interface
    {
    public:
      virtual ~Interface() = default;

      /// The entries every model shares are declared by the scene; a model adds its own.
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /**
       * Store the elastic constants (read by the scene) and let the model read
       * its own parameters from @p section (the `Material` subsection).
       */
      void
      initialize(const Elasticity &elasticity, const Section &section);

      const Elasticity &
      elasticity() const
      {
        return elastic;
      }

      double
      density() const
      {
        return elastic.density;
      }

      /// Number of doubles of per-point state.
      virtual unsigned int
      n_state_variables() const
      {
        return 0;
      }

      /// One name per state slot (CSV columns, particle output).
      virtual std::vector<std::string>
      state_variable_names() const
      {
        return {};
      }

      /// The state of a virgin point (default: zeros).
      virtual void
      initialize_state(const dealii::ArrayView<double> &state) const;

      /**
       * Advance n points by their strain increments.
       * @param strain_increments n tensors (tensor shear components).
       * @param stresses n tensors: in, the stress at the start; out, at the end.
       * @param states n * n_state_variables() doubles, point after point.
       * @param tangents empty, or n tensors receiving d(stress)/d(strain) of the
       *        update (the algorithmic tangent where the model has one).
       */
      virtual void
      update(const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
             const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
             const dealii::ArrayView<double>                                &states,
             const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents) const = 0;

      /// Whether update_axisymmetric() is implemented (default: no; create() then
      /// refuses `Stress state = axisymmetric` with the model's name).
      virtual bool
      supports_axisymmetry() const
      {
        return false;
      }

      /**
       * Axisymmetric 2D (`Stress state = axisymmetric`: x the radius, y the axis, z
       * the hoop direction): update() with the hoop strain increments d eps_tt
       * (u_r / r) besides the in-plane ones. The hoop stress sigma_tt is part of the
       * state and read with out_of_plane() (as sigma_zz). @p hoop_tangents is empty
       * or receives, with @p tangents, the terms that couple eps_tt.
       */
      virtual void
      update_axisymmetric(
        const dealii::ArrayView<const dealii::SymmetricTensor<2, dim>> &strain_increments,
        const dealii::ArrayView<const double>                          &hoop_increments,
        const dealii::ArrayView<dealii::SymmetricTensor<2, dim>>       &stresses,
        const dealii::ArrayView<double>                                &states,
        const dealii::ArrayView<dealii::SymmetricTensor<4, dim>>       &tangents,
        const dealii::ArrayView<HoopTangent<dim>>                      &hoop_tangents) const;

      /**
       * Finite-strain (updated-Lagrangian, Jaumann) analyses: turn the tensor parts of
       * one point's @p state (e.g. a plastic strain or a back stress) with the increment's
       * rotation @p R, T <- R T R^T, as the stress is turned before update(), so that the
       * model stays objective. In 2D @p R turns the plane and leaves zz. Default: the
       * model has no tensor state.
       */
      virtual void
      rotate_state(const dealii::Tensor<2, dim> &R, const dealii::ArrayView<double> &state) const
      {
        (void)R;
        (void)state;
      }

      /// update() for one point.
      void
      update_point(const dealii::SymmetricTensor<2, dim> &strain_increment,
                   dealii::SymmetricTensor<2, dim>       &stress,
                   const dealii::ArrayView<double>       &state,
                   dealii::SymmetricTensor<4, dim>       *tangent = nullptr) const;

      /**
       * In 2D: the out-of-plane strain eps_zz (plane stress) or stress sigma_zz
       * (plane strain) of a point with in-plane @p strain, @p stress and @p state;
       * the other one is zero. The default is the elastic relation
       * eps_zz = -nu/E (s_xx + s_yy), resp. sigma_zz = nu (s_xx + s_yy);
       * inelastic models override it. Axisymmetric models return the hoop stress
       * as sigma_zz and eps_zz = 0 (the hoop strain is known to the caller).
       */
      virtual void
      out_of_plane(const dealii::SymmetricTensor<2, dim> &strain,
                   const dealii::SymmetricTensor<2, dim> &stress,
                   const dealii::ArrayView<const double> &state,
                   double                                &eps_zz,
                   double                                &sigma_zz) const;

      /**
       * Whether the tangents of update() are the consistent (algorithmic)
       * derivatives of the updated stress, so that a Newton solver converges
       * quadratically (default: true; Bouc-Wen only with `backward euler`).
       */
      virtual bool
      has_consistent_tangent() const
      {
        return true;
      }

      /**
       * Whether the tangents of update() are symmetric, so that CG may solve with them
       * (default: a model without state (Hooke's law) or with the continuum Bouc-Wen
       * tangent; the algorithmic tangent of a general local Newton need not be).
       */
      virtual bool
      has_symmetric_tangent() const
      {
        return n_state_variables() == 0 || !has_consistent_tangent();
      }

      /// A new uniaxial law for the springs of a spring network between cells of this
      /// material (UniaxialSpringLaw), or null (the default): the material then cannot be
      /// a spring network's body.
      virtual std::unique_ptr<UniaxialSpringLaw>
      uniaxial_spring_law() const
      {
        return nullptr;
      }

      /// Empty if the model can be a continuum's material (update() of strain tensors),
      /// else why not (a material whose parameters select a law for springs only); the
      /// scene refuses it for the methods that take continuum materials.
      virtual std::string
      continuum_unsupported() const
      {
        return "";
      }

      /// Warnings found while reading the parameters (printed by the scene on rank 0).
      const std::vector<std::string> &
      warnings() const
      {
        return parse_warnings;
      }

    protected:
      /// Read the model's own parameters (inside `subsection Material`).
      virtual void
      parse_parameters(const Section &section);

      /// Record a warning ("Material/Bouc-Wen/Beta: ...") for the user.
      void
      add_warning(const std::string &warning)
      {
        parse_warnings.push_back(warning);
      }

    private:
      Elasticity               elastic;
      std::vector<std::string> parse_warnings;
    };

    template <int dim>
    using Registry = Plugins::Registry<Interface<dim>>;

    /// Declare `Model`, the elastic constants and every model's entries (inside `Material`).
    void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Read the entries declared by declare_parameters() and create the model.
    template <int dim>
    std::unique_ptr<Interface<dim>>
    create(const Section &section);
  } // namespace Material
} // namespace hysteron

/// Register a material model class template (dim = 2, 3) under @p name.
#define HYSTERON_REGISTER_MATERIAL(classname, name, description) \
  HYSTERON_REGISTER_DIM_PLUGIN(::hysteron::Material::Interface, classname, name, description)

#endif

#ifndef hysteron_rbsn_spring_law_h
#define hysteron_rbsn_spring_law_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/tensor.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/parameters.h>
#include <hysteron/base/registry.h>
#include <hysteron/material/bouc_wen_parameters.h>
#include <hysteron/material/bouc_wen_uniaxial.h>
#include <hysteron/material/interface.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    /**
     * The three springs of one facet as a spring law sees them when it sets the
     * facet up: the elastic stiffnesses (Voronoi scaling, eq. 3.9), the facet's
     * thickness and length, and `RBSN/Moment yield factor`.
     */
    struct FacetSprings
    {
      std::array<double, 3> k{};                   ///< k_n, k_t [N/m], k_phi [N m]
      double                thickness           = 1; ///< t [m]
      double                length              = 1; ///< l [m]
      double                moment_yield_factor = 0.25;

      /**
       * The yield values of the three springs for the yield stress @p sigma_y [Pa]:
       * F_y,n = sigma_y t l, F_y,t = sigma_y t l / sqrt(3) (von Mises in shear) and
       * M_y = factor sigma_y t l^2 (factor 1/4: the plastic moment of the section).
       */
      std::array<double, 3>
      yield_values(const double sigma_y) const
      {
        return {{sigma_y * thickness * length,
                 sigma_y * thickness * length / std::sqrt(3.0),
                 moment_yield_factor * sigma_y * thickness * length * length}};
      }
    };

    /**
     * What SpringLaw::update() throws when it cannot integrate an increment (the step
     * is cut): the cause, and which springs of the facet failed ("the normal spring",
     * "the coupled springs"); the network adds where the facet is.
     */
    class SpringFailure : public RuntimeError
    {
    public:
      SpringFailure(const std::string &cause, const std::string &springs)
        : RuntimeError(cause)
        , springs(springs)
      {}

      std::string springs;
    };

    /**
     * What a law precomputes per facet, indexed by the facet number and grown as
     * SpringLaw::setup_facet() visits the facets.
     */
    template <typename T>
    class PerFacet
    {
    public:
      /// The entry of facet @p e (default-constructed when new), to set it up.
      T &
      operator()(const unsigned int e)
      {
        if (e >= data.size())
          data.resize(e + 1);
        return data[e];
      }

      const T &
      operator[](const unsigned int e) const
      {
        return data[e];
      }

    private:
      std::vector<T> data;
    };

    /**
     * A facet spring law: the forces F = (F_n, F_t, M) of a facet's normal,
     * tangential and rotational springs as a function of their deformations
     * delta = (delta_n, delta_t, phi) and of a per-facet state (a flat array of
     * n_state_variables() doubles, which the network stores, commits and
     * checkpoints). Laws register by name and are chosen by `RBSN/Spring law`.
     *
     * One object serves the whole network: setup_facet() is called for every
     * facet in order and the law keeps what it precomputes per facet (indexed by
     * the facet number); update() is called once per facet and evaluation (one
     * virtual call, the law's own loop over the three springs inside).
     *
     * Facets whose springs the law declares linear (setup_facet() returns false)
     * are F = k delta, handled by the network without calling the law; so are all
     * facets with `Analysis = static`.
     *
     * What a law takes from the cells' materials comes through
     * Material::Interface::spring_behaviour() (no downcasts).
     *
     * Writing a new law: derive from this class, implement the pure virtual
     * functions, optionally a static declare_parameters(ParameterHandler &)
     * (entries inside `subsection RBSN`) and parse_parameters(), and register it
     * with HYSTERON_REGISTER_SPRING_LAW(ClassName, "name", "description").
     */
    class SpringLaw
    {
    public:
      using Vector = std::array<double, 3>; ///< (delta_n, delta_t, phi) or (F_n, F_t, M)
      using Matrix = dealii::Tensor<2, 3>;  ///< D = dF / d delta

      virtual ~SpringLaw() = default;

      /// The law's own entries (inside `subsection RBSN`; names must not clash).
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /// Read the law's own entries from @p rbsn (the `RBSN` section).
      virtual void
      parse_parameters(const Section &rbsn)
      {
        (void)rbsn;
      }

      /// The number of doubles of state per facet.
      virtual unsigned int
      n_state_variables() const = 0;

      /// Why the law cannot join cells of material @p material ("" if it can); an error
      /// at `RBSN/Spring law` when a body has such a material.
      virtual std::string
      unsupported(const Material::Interface<2> &material) const
      {
        (void)material;
        return "";
      }

      /**
       * Set up facet @p e (called for e = 0, 1, ... in order) between cells of the
       * materials @p a and @p b: return false if its springs are linear (F = k delta;
       * the law is not asked about this facet again), else initialise @p state
       * (n_state_variables() doubles) and return true.
       */
      virtual bool
      setup_facet(unsigned int                  e,
                  const FacetSprings           &springs,
                  const Material::Interface<2> &a,
                  const Material::Interface<2> &b,
                  double                       *state) = 0;

      /// Whether the tangents of update() are the consistent derivatives of its forces for
      /// cells of @p material (else Newton converges linearly and the user is warned); the
      /// default asks the material.
      virtual bool
      has_consistent_tangent(const Material::Interface<2> &material) const
      {
        return material.has_consistent_tangent();
      }

      /// Whether the tangents of update() are diagonal (independent springs): the
      /// assembly then skips the off-diagonal products.
      virtual bool
      diagonal_tangent() const
      {
        return false;
      }

      /**
       * Advance facet @p e by the deformation increment @p increment: on entry
       * @p force and @p state hold the converged forces and state, on exit the
       * trial ones; @p tangent (if not null) receives D = dF / d delta of the
       * update. Throws SpringFailure when the integration fails (the step is cut).
       */
      virtual void
      update(unsigned int  e,
             const Vector &increment,
             Vector       &force,
             double       *state,
             Matrix       *tangent) const = 0;

      /// The H1 output of spring @p i (0 elastic ... 1 yielding) at @p state.
      virtual double
      h1(unsigned int e, unsigned int i, const double *state) const = 0;

      /// The recoverable energy of spring @p i at deformation @p delta and @p state.
      virtual double
      strain_energy(unsigned int e, unsigned int i, double delta, const double *state) const = 0;

      /**
       * `Analysis = variable order` integrates the springs' states as rates of
       * uniaxial Bouc-Wen laws: a law that supports it returns "" here and, for
       * every hysteretic facet, the uniaxial law of each spring with the offset of
       * its state in the facet's state. Otherwise the reason (an error at
       * `RBSN/Spring law`).
       */
      virtual std::string
      variable_order_unsupported() const
      {
        return "the variable-order analysis integrates the state rates of uniaxial Bouc-Wen "
               "springs, which this spring law does not provide; use Analysis = implicit "
               "dynamics";
      }

      struct UniaxialSpring
      {
        const Material::BoucWenUniaxial *law    = nullptr;
        unsigned int                     offset = 0; ///< of its state in the facet's state
      };

      virtual UniaxialSpring
      uniaxial_spring(unsigned int e, unsigned int i) const
      {
        (void)e;
        (void)i;
        return {};
      }
    };

    using SpringLawRegistry = Plugins::Registry<SpringLaw>;

    /// The Bouc-Wen parameters of the springs between cells of materials @p a and @p b
    /// (those of @p a), or null unless both materials give Bouc-Wen springs.
    inline const Material::BoucWenParameters *
    bouc_wen_springs(const Material::Interface<2> &a, const Material::Interface<2> &b)
    {
      return b.spring_behaviour().bouc_wen ? a.spring_behaviour().bouc_wen : nullptr;
    }

    /// The yield stress sigma_y [Pa] of a facet between two Bouc-Wen materials: the smaller one.
    inline double
    facet_yield_stress(const Material::Interface<2> &a, const Material::Interface<2> &b)
    {
      return std::min(a.spring_behaviour().bouc_wen->yield_stress,
                      b.spring_behaviour().bouc_wen->yield_stress);
    }

    /// The recoverable energy 1/2 a k delta^2 + 1/2 (1 - a) k z^2 of a Bouc-Wen spring
    /// with post-yield ratio @p a, stiffness @p k, deformation @p delta and state @p z.
    inline double
    bouc_wen_strain_energy(const double a, const double k, const double delta, const double z)
    {
      return 0.5 * a * k * delta * delta + 0.5 * (1 - a) * k * z * z;
    }
  } // namespace RBSN
} // namespace hysteron

/// Register the spring law class @p classname under @p name (a value of `RBSN/Spring law`).
#define HYSTERON_REGISTER_SPRING_LAW(classname, name, description)                            \
  namespace                                                                                  \
  {                                                                                          \
    const ::hysteron::Plugins::Registration<::hysteron::RBSN::SpringLaw, classname>           \
      HYSTERON_PLUGIN_CONCAT(hysteron_spring_law_registration_, __LINE__)(name, description); \
  }

#endif

#ifndef hysteron_rbsn_spring_law_h
#define hysteron_rbsn_spring_law_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/tensor.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/parameters.h>
#include <hysteron/base/registry.h>
#include <hysteron/material/interface.h>
#include <hysteron/material/uniaxial_spring_law.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    /// The number of springs of a facet: (normal, tangential, rotational) in 2D;
    /// (normal, two shear, two bending, torsion) in 3D. Also the DoFs of a cell.
    template <int dim>
    inline constexpr unsigned int n_springs = dim == 2 ? 3 : 6;

    /// The name of spring @p i of a facet ("normal", "tangential", "rotational" in 2D;
    /// "normal", "first shear", "second shear", "first bending", "second bending",
    /// "torsion" in 3D), for messages.
    template <int dim>
    inline const char *
    spring_name(const unsigned int i)
    {
      static const char *const names_2d[] = {"normal", "tangential", "rotational"};
      static const char *const names_3d[] = {"normal", "first shear", "second shear", "first bending",
                                             "second bending", "torsion"};
      return dim == 2 ? names_2d[i] : names_3d[i];
    }

    /**
     * The springs of one facet as a spring law sees them when it sets the facet up:
     * the elastic stiffnesses (Voronoi scaling, eq. 3.9 and its 3D form in
     * doc/rbsn3d.md), the facet's section (area and second moments) and
     * `RBSN/Moment yield factor`.
     *
     * The springs, in the order of SpringLaw<dim>::Vector:
     * - 2D: normal, tangential, rotational (delta_n, delta_t, phi; F_n, F_t, M);
     * - 3D: in the facet's axes (n, s_1, s_2), the normal spring, the shear springs along
     *   s_1 and s_2, the bending springs about s_1 and s_2 and the torsion spring about n
     *   (delta_n, delta_1, delta_2, phi_1, phi_2, phi_n; N, V_1, V_2, M_1, M_2, T).
     */
    template <int dim>
    struct FacetSprings
    {
      std::array<double, n_springs<dim>> k{}; ///< [N/m] translations, [N m] rotations
      /// The facet's area A [m^2] (2D: thickness t times length l).
      double area = 1;
      /// Second moments of the facet's area about its centroidal axes [m^4]: 2D, t l^3 / 12
      /// (bending in the plane); 3D, I_1 about s_1 (int (x . s_2)^2 dA) and I_2 about s_2.
      std::array<double, dim - 1> second_moments{};
      double thickness = 1; ///< 2D: t [m]; 3D: not used (1)
      double length    = 1; ///< 2D: l [m]; 3D: sqrt(A)
      double moment_yield_factor = 0.25;

      /**
       * The yield values of the springs for the yield stress @p sigma_y [Pa]: the normal
       * force sigma_y A, the shear forces sigma_y A / sqrt(3) (von Mises in shear), the
       * bending moments f sigma_y A sqrt(12 I / A) and (3D) the torque
       * f (sigma_y / sqrt(3)) A sqrt(12 J / A), J = I_1 + I_2, with f = `Moment yield
       * factor`. For a rectangular section b x h bent about its b side, sqrt(12 I / A) = h
       * and f = 1/4 gives the plastic moment sigma_y b h^2 / 4; in 2D this is
       * f sigma_y t l^2. With f = 1/4 the torque is 1.061 times the plastic torque of a square
       * and 0.919 times that of a circle (derivation: doc/rbsn_coupled_springs.md).
       */
      std::array<double, n_springs<dim>>
      yield_values(const double sigma_y) const
      {
        if constexpr (dim == 2)
          return {{sigma_y * thickness * length,
                   sigma_y * thickness * length / std::sqrt(3.0),
                   moment_yield_factor * sigma_y * thickness * length * length}};
        const double                       shear = sigma_y / std::sqrt(3.0);
        std::array<double, n_springs<dim>> y{};
        y[0] = sigma_y * area;
        for (unsigned int i = 1; i < dim; ++i)
          y[i] = shear * area;
        for (unsigned int i = 0; i + 1 < dim; ++i)
          y[dim + i] = moment_yield_factor * sigma_y * area * std::sqrt(12 * second_moments[i] / area);
        if constexpr (dim == 3)
          y[5] = moment_yield_factor * shear * area *
                 std::sqrt(12 * (second_moments[0] + second_moments[1]) / area);
        return y;
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
     * A facet spring law: the forces F of a facet's springs (2D: F_n, F_t, M of the
     * normal, tangential and rotational springs; 3D: N, V_1, V_2, M_1, M_2, T, see
     * FacetSprings) as a function of their deformations delta (2D: delta_n, delta_t,
     * phi; 3D: delta_n, delta_1, delta_2, phi_1, phi_2, phi_n) and of a per-facet state
     * (a flat array of n_state_variables() doubles, which the network stores, commits
     * and checkpoints). Laws register by name and are chosen by `RBSN/Spring law`.
     *
     * One object serves the whole network: setup_facet() is called for every
     * facet in order and the law keeps what it precomputes per facet (indexed by
     * the facet number); update() is called once per facet and evaluation (one
     * virtual call, the law's own loop over the springs inside).
     *
     * Facets whose springs the law declares linear (setup_facet() returns false)
     * are F = k delta, handled by the network without calling the law; so are all
     * facets with `Analysis = static`.
     *
     * What a law takes from the cells' materials comes through their uniaxial spring
     * laws, Material::Interface::uniaxial_spring_law() (no downcasts, no list of
     * models): the `uncoupled` law drives every spring with it, so any material that
     * offers one can be a body; laws that are Bouc-Wen by nature ask it for its
     * Bouc-Wen parameters (Material::UniaxialSpringLaw::bouc_wen_parameters()).
     *
     * Writing a new law: derive from this class, implement the pure virtual
     * functions, optionally a static declare_parameters(ParameterHandler &)
     * (entries inside `subsection RBSN`) and parse_parameters(), and register it
     * with HYSTERON_REGISTER_SPRING_LAW(ClassName, "name", "description"), where
     * ClassName is a class template on dim (registered for 2D and 3D networks).
     */
    template <int dim>
    class SpringLaw
    {
    public:
      static constexpr unsigned int n = n_springs<dim>;
      using Vector = std::array<double, n>; ///< deformations delta or forces F
      using Matrix = dealii::Tensor<2, n>;  ///< D = dF / d delta

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
      /// at `RBSN/Spring law` when a body has such a material. The network asks about
      /// every body's material before initialize().
      virtual std::string
      unsupported(const Material::Interface<dim> &material) const
      {
        (void)material;
        return "";
      }

      /// The materials of the network's bodies (each once, every one accepted by
      /// unsupported()), before n_state_variables() and setup_facet().
      virtual void
      initialize(const std::vector<const Material::Interface<dim> *> &materials)
      {
        (void)materials;
      }

      /**
       * Set up facet @p e (called for e = 0, 1, ... in order) between cells of the
       * materials @p a and @p b: return false if its springs are linear (F = k delta;
       * the law is not asked about this facet again), else initialise @p state
       * (n_state_variables() doubles) and return true.
       */
      virtual bool
      setup_facet(unsigned int                    e,
                  const FacetSprings<dim>        &springs,
                  const Material::Interface<dim> &a,
                  const Material::Interface<dim> &b,
                  double                         *state) = 0;

      /// Whether the tangents of update() are the consistent derivatives of its forces for
      /// cells of @p material (else Newton converges linearly and the user is warned); the
      /// default asks the material.
      virtual bool
      has_consistent_tangent(const Material::Interface<dim> &material) const
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
       * `RBSN/Analysis`).
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

    template <int dim>
    using SpringLawRegistry = Plugins::Registry<SpringLaw<dim>>;

    /**
     * The uniaxial spring laws of the cells' materials (Material::Interface::
     * uniaxial_spring_law()), one per material, created when first asked for.
     */
    template <int dim>
    class MaterialSpringLaws
    {
    public:
      /// The law of @p material, null if it offers none.
      Material::UniaxialSpringLaw *
      operator()(const Material::Interface<dim> &material)
      {
        for (auto &law : laws)
          if (law.first == &material)
            return law.second.get();
        laws.emplace_back(&material, material.uniaxial_spring_law());
        return laws.back().second.get();
      }

      /// The largest n_state_variables() of the laws so far.
      unsigned int
      max_n_state_variables() const
      {
        unsigned int n = 0;
        for (const auto &law : laws)
          n = std::max(n, law.second ? law.second->n_state_variables() : 0u);
        return n;
      }

      /**
       * The springs of a facet between cells of materials @p a and @p b: null if they are
       * linear (either material's law is, F = k delta), else @p a's law; @p yield_stress
       * receives the smaller yield stress of the two.
       */
      Material::UniaxialSpringLaw *
      facet(const Material::Interface<dim> &a, const Material::Interface<dim> &b, double &yield_stress)
      {
        Material::UniaxialSpringLaw *la = (*this)(a), *lb = (*this)(b);
        if (la == nullptr || lb == nullptr || la->linear() || lb->linear())
          return nullptr;
        yield_stress = std::min(la->yield_stress(), lb->yield_stress());
        return la;
      }

    private:
      std::vector<std::pair<const Material::Interface<dim> *, std::unique_ptr<Material::UniaxialSpringLaw>>> laws;
    };
  } // namespace RBSN
} // namespace hysteron

/// Register the spring law class template @p classname (on dim) under @p name (a value of
/// `RBSN/Spring law`) for 2D and 3D networks.
#define HYSTERON_REGISTER_SPRING_LAW(classname, name, description) \
  HYSTERON_REGISTER_DIM_PLUGIN(::hysteron::RBSN::SpringLaw, classname, name, description)

#endif

// A no-tension facet spring law as a hysteron plugin: the whole of what a user writes to add
// an RBSN spring law. Build it against the installed package (CMakeLists.txt beside this file)
// and load it with `set Additional shared libraries = ./build/libcustom_spring_law.so`, then
// choose it with `set Spring law = no tension` in `subsection RBSN`.
//
// Model (a masonry-like joint): the normal spring carries compression only,
// F_n = k_n min(delta_n, 0), the other springs are linear, F_i = k_i delta_i (2D: the
// tangential and rotational springs; 3D: the two shear, two bending and the torsion springs).
// The law works on the total deformations, which it keeps as its state (the interface passes
// increments); it applies to every material (linear elastic ones too), so every facet is the
// law's. The tangent is diagonal: k_n in compression, 0 in tension.
#include <hysteron/rbsn/spring_law.h>

#include <algorithm>

namespace custom
{
  using hysteron::RBSN::FacetSprings;
  using hysteron::RBSN::SpringLaw;

  /// For 2D and 3D networks: the first spring is the normal one in both (the others are
  /// the tangential and rotational springs in 2D; two shear, two bending and the torsion
  /// spring in 3D).
  template <int dim>
  class NoTension : public SpringLaw<dim>
  {
  public:
    using typename SpringLaw<dim>::Vector;
    using typename SpringLaw<dim>::Matrix;
    static constexpr unsigned int n = SpringLaw<dim>::n;

    /// The total deformations (2D: delta_n, delta_t, phi; 3D: delta_n, delta_1, delta_2,
    /// phi_1, phi_2, phi_n).
    unsigned int
    n_state_variables() const override
    {
      return n;
    }

    bool
    setup_facet(const unsigned int e,
                const FacetSprings<dim> &springs,
                const hysteron::Material::Interface<dim> &,
                const hysteron::Material::Interface<dim> &,
                double *state) override
    {
      k(e) = springs.k;
      std::fill(state, state + n, 0.0);
      return true;
    }

    /// The tangent is exact (the material's own integrator plays no part).
    bool
    has_consistent_tangent(const hysteron::Material::Interface<dim> &) const override
    {
      return true;
    }

    bool
    diagonal_tangent() const override
    {
      return true;
    }

    void
    update(const unsigned int e,
           const Vector      &increment,
           Vector            &force,
           double            *delta,
           Matrix            *tangent) const override
    {
      for (unsigned int i = 0; i < n; ++i)
        delta[i] += increment[i];
      const bool open = delta[0] > 0;
      for (unsigned int i = 0; i < n; ++i)
        force[i] = i == 0 && open ? 0.0 : k[e][i] * delta[i];
      if (tangent)
        for (unsigned int i = 0; i < n; ++i)
          (*tangent)[i][i] = i == 0 && open ? 0.0 : k[e][i];
    }

    /// No yielding: H1 = 0.
    double
    h1(const unsigned int, const unsigned int, const double *) const override
    {
      return 0;
    }

    /// 1/2 k delta^2 (the normal spring in compression only).
    double
    strain_energy(const unsigned int e,
                  const unsigned int i,
                  const double       delta,
                  const double *) const override
    {
      const double d = i == 0 ? std::min(delta, 0.0) : delta;
      return 0.5 * k[e][i] * d * d;
    }

  private:
    hysteron::RBSN::PerFacet<Vector> k; ///< per facet
  };
} // namespace custom

HYSTERON_REGISTER_SPRING_LAW(custom::NoTension,
                             "no tension",
                             "example plugin: the normal spring carries compression only, "
                             "F_n = k_n min(delta_n, 0); the other springs linear")

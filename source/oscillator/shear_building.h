#ifndef hysteron_oscillator_shear_building_h
#define hysteron_oscillator_shear_building_h

#include <hysteron/material/uniaxial_spring_law.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace Oscillator
  {
    /**
     * A shear building of N storeys under a ground acceleration a_g(t) (N = 1: the
     * single-degree-of-freedom oscillator). Floor i (0 ... N-1, ground up) has the
     * mass m_i and moves by u_i relative to the ground; storey i is a spring between
     * floor i - 1 (the ground for i = 0) and floor i, with the drift
     * d_i = u_i - u_{i-1}, the elastic stiffness k_i and the yield force F_y,i, which
     * follows a Material::UniaxialSpringLaw (null: linear, F = k d). With Rayleigh
     * damping C = alpha M + beta K_0,
     *
     *   M u'' + C u' + R(u) = -M 1 a_g(t),   R_i = F_i - F_{i+1},
     *
     * integrated by Newmark's average acceleration (unconditionally stable, second
     * order) with Newton on R and the storeys' tangents: the systems are tridiagonal,
     * a step costs O(N). A step whose Newton iteration or spring fails is cut in
     * halves, down to 1/1024 of it. The energies of the relative motion balance,
     *
     *   input = kinetic + damped + elastic + hysteretic,
     *   input = -int u'^T M 1 a_g dt,  damped = int u'^T C u' dt,
     *   elastic + hysteretic = int F^T d' dt,
     *
     * with each step's works by the trapezoidal rule: for the average acceleration
     * the kinetic energy's change is then exactly the step's net work, so the
     * balance closes to Newton's tolerance.
     */
    class ShearBuilding
    {
    public:
      /// @p law: the storeys' law, with no springs yet (null: linear storeys);
      /// @p yield_force is read only with a law.
      ShearBuilding(std::vector<double>                          mass,
                    std::vector<double>                          stiffness,
                    std::vector<double>                          yield_force,
                    double                                       damping_ratio,
                    std::unique_ptr<Material::UniaxialSpringLaw> law);

      /// The building's state at a time.
      struct State
      {
        std::vector<double> u, v, a;      ///< floors, relative to the ground (a: relative too)
        std::vector<double> drift, force; ///< storeys
        std::vector<double> spring_state; ///< the law's, n_state_variables() doubles per storey
      };

      /// The works since the start [J].
      struct Energies
      {
        double input = 0, kinetic = 0, damped = 0, elastic = 0, hysteretic = 0;
        /// input - kinetic - damped - elastic - hysteretic.
        double
        balance() const
        {
          return input - kinetic - damped - elastic - hysteretic;
        }
      };

      /// Called at t = 0 and at the end of every step of integrate() (ground: a_g(t)).
      using Observer = std::function<void(double t, double ground, const State &, const Energies &)>;

      /**
       * Integrate from rest at t = 0 to @p duration in steps of @p time_step (the
       * last one shorter if needed), calling @p observer (may be empty). Throws
       * RuntimeError if a step fails after 10 cuts.
       */
      void
      integrate(const std::function<double(double)> &ground, double time_step, double duration, const Observer &observer);

      unsigned int
      n_storeys() const
      {
        return mass.size();
      }

      /// The periods 2 pi / omega_j of the elastic building, longest first.
      const std::vector<double> &
      periods() const
      {
        return mode_periods;
      }

      /// The modal damping ratios alpha / (2 omega_j) + beta omega_j / 2 of Rayleigh damping.
      std::vector<double>
      modal_damping_ratios() const;

      /// Whether the storeys follow a hysteretic law (else they are linear).
      bool
      hysteretic() const
      {
        return law != nullptr;
      }

      /// The storeys' hysteretic variable z [m] of a Bouc-Wen law (0 for other laws).
      double
      hysteretic_variable(const State &s, unsigned int storey) const;

      const std::vector<double> &
      yield_forces() const
      {
        return yield_force;
      }

      const std::vector<double> &
      stiffnesses() const
      {
        return stiffness;
      }

      /// Steps taken, Newton iterations and cut steps since construction.
      unsigned long n_steps = 0, n_newton = 0, n_cuts = 0;

    private:
      /// Advance @p s (into trial, then swapped) by @p dt to the ground acceleration
      /// @p ground at the step's end; false if it failed.
      bool
      step(State &s, double dt, double ground, std::string &failure);
      /// The storeys' forces and tangents at the drifts of trial from s.
      bool
      storey_forces(const State &s, std::string &failure);
      /// (C v)_i.
      double
      damping_force(const std::vector<double> &v, unsigned int i) const;
      /// The recoverable energy of the storeys of @p s.
      double
      elastic_energy(const State &s) const;

      std::vector<double>                          mass, stiffness, yield_force;
      std::unique_ptr<Material::UniaxialSpringLaw> law;
      unsigned int                                 n_state = 0;
      std::vector<double>                          virgin_state; ///< of every storey, from add_spring()
      double                                       alpha = 0, beta = 0;
      std::vector<double>                          mode_periods;
      // Work arrays of step() (no allocation per step).
      State               trial;
      std::vector<double> tangent, residual, diagonal, off_diagonal, increment;
    };
  } // namespace Oscillator
} // namespace hysteron

#endif

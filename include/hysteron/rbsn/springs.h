// The RBSN's analyses, its fracture and variable-order parameters, and a facet's springs.
#ifndef hysteron_rbsn_springs_h
#define hysteron_rbsn_springs_h

#include <hysteron/rbsn/spring_law.h>

#include <array>
#include <vector>

namespace hysteron
{
  namespace RBSN
  {
    enum class Analysis
    {
      linear_static,     ///< elastic springs, one solve per step
      quasi_static,      ///< Bouc-Wen springs, load stepping with Newton
      implicit_dynamics, ///< Newmark / HHT-alpha with Newton
      variable_order     ///< SUNDIALS IDA (variable-order BDF) on u, v and the spring states
    };

    /// Brittle fracture of the facets (eq. 3.49-3.51).
    struct FractureParameters
    {
      bool   enabled          = false;
      double tensile_strength = 0; ///< f_t [Pa]: the tension cut-off of the normal stress
      double cohesion         = 0; ///< c [Pa]: the shear strength at zero normal stress
      double friction         = 0; ///< tan of the friction angle
      unsigned int max_cycles = 1000; ///< breaks within one step before the run stops
    };

    /// `subsection RBSN/Variable order`: SUNDIALS IDA (variable_order.cc).
    struct VariableOrderParameters
    {
      double       relative_tolerance = 1e-6;
      double       absolute_tolerance = 0; ///< [m] on the displacements; 0: automatic
      unsigned int maximum_order      = 5; ///< of the BDF, 1..5
      double       maximum_step       = 0; ///< [s]; 0: unlimited
      double       initial_step       = 0; ///< [s]; 0: IDA's estimate
    };

    /**
     * One facet's springs (2D: normal, tangential, rotational; 3D: normal, two shear,
     * two bending, torsion; see FacetSprings): stiffness, the converged and trial
     * deformations, forces and state of the spring law (see SpringLaw), and the tangent
     * D = dF / d delta of the last evaluation. The deformations are delta = B U_e with
     * U_e the two cells' DoFs (a's, then b's).
     */
    template <int dim>
    struct Springs
    {
      static constexpr unsigned int n = n_springs<dim>; ///< springs (and DoFs per cell)
      using Vector                    = typename SpringLaw<dim>::Vector;

      Vector                          k{};
      Vector                          delta{}, force{}, trial_delta{}, trial_force{};
      typename SpringLaw<dim>::Matrix tangent; ///< diag(k) for linear springs
      std::vector<double>             state, trial_state; ///< the law's (hysteretic springs only)
      /// B: row i (spring), column k of U_e (a's n DoFs, then b's).
      std::array<std::array<double, 2 * n>, n> B{};
      double                                   thickness  = 1; ///< 2D: t [m]; 3D: 1
      double                                   area       = 1; ///< the facet's area (2D: t l) [m^2]
      bool                                     hysteretic = false; ///< the spring law's (else linear springs)
      bool                                     broken     = false;

      /// The deformation (or its rate) B_i U of spring i for the facet's DoF values @p U.
      template <typename VectorType>
      double
      deformation(const unsigned int i, const VectorType &U) const
      {
        double s = 0;
        for (unsigned int k = 0; k < 2 * n; ++k)
          s += B[i][k] * U[k];
        return s;
      }
    };
  } // namespace RBSN
} // namespace hysteron

#endif

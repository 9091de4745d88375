#ifndef hysteron_source_mpm_particles_h
#define hysteron_source_mpm_particles_h

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>
#include <deal.II/particles/particle_handler.h>

#include <hysteron/material/interface.h>

#include <string>
#include <vector>

namespace hysteron
{
  namespace MPM
  {
    /// An ArrayView of @p n elements from @p data (make_array_view has no pointer form in 9.4).
    template <typename T>
    inline dealii::ArrayView<T>
    view(T *data, const std::size_t n)
    {
      return dealii::ArrayView<T>(data, n);
    }

    /**
     * The layout of a material point's properties in the ParticleHandler
     * (Lethe style): every slot has a name, and the same names label the
     * particle output. The packed material state (n_state doubles, the largest
     * state of the scene's materials) follows the fixed slots.
     *
     * Stress and strain are stored in SymmetricTensor's unrolled order
     * (xx, yy, xy in 2D; xx, yy, zz, xy, xz, yz in 3D), tensor shear components.
     */
    template <int dim>
    struct PropertiesIndex
    {
      static constexpr unsigned int n_sym = dim * (dim + 1) / 2;
      enum : unsigned int
      {
        mass = 0,          ///< [kg] (2D: including the thickness)
        volume0,           ///< initial volume [m^3]
        volume,            ///< current volume [m^3]
        thickness,         ///< out-of-plane thickness [m] (2D; 1 in 3D)
        body,              ///< index of the body in `Body names`
        load,              ///< 1 + index of the load acting on the point, 0 for none
        velocity,          ///< dim components [m/s]
        displacement = velocity + dim,             ///< dim components [m]
        stress       = displacement + dim,         ///< n_sym components [Pa]
        von_mises    = stress + n_sym,             ///< [Pa] (with sigma_zz in 2D)
        strain       = von_mises + 1,              ///< small-strain sum of increments
        deformation_gradient = strain + n_sym,     ///< dim x dim, row major
        n_fixed              = deformation_gradient + dim * dim
      };

      /// Names of all n_fixed + n_state slots (state names from the material).
      static std::vector<std::string>
      names(const std::vector<std::string> &state_names);

      /// vector / scalar interpretation for Particles::DataOut.
      static std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation>
      interpretations(const unsigned int n_state);
    };

    /**
     * The material points of one rank as contiguous arrays (structure of
     * arrays), sorted by group (one group per material or rigid body) and, in
     * a group, by grid cell. The kernels run over these arrays; the
     * ParticleHandler owns identity, MPI migration and output, and is brought up
     * to date only when needed (to_handler() / from_handler()).
     *
     * The quantities a step changes exist twice (`current` and `next`): a step
     * computes `next` from `current` and commit() swaps them, so that a step
     * that fails (a NaN, a point leaving the grid) leaves the last good state
     * intact for the final output.
     */
    template <int dim>
    struct ParticleStore
    {
      struct State
      {
        std::vector<dealii::Point<dim>>              x;
        std::vector<dealii::Tensor<1, dim>>          v;
        std::vector<dealii::SymmetricTensor<2, dim>> stress;
        std::vector<dealii::SymmetricTensor<2, dim>> strain;
        std::vector<dealii::Tensor<2, dim>>          F;
        std::vector<double>                          volume;
        std::vector<double>                          material_state;

        void
        resize(const std::size_t n, const std::size_t n_material_state);
      };

      /// A range [begin, end) of points that share a material (or a rigid body).
      struct Group
      {
        unsigned int                     begin = 0, end = 0;
        const Material::Interface<dim> *material = nullptr; ///< null: rigid
        unsigned int                     rigid_body = 0;     ///< body index of a rigid group
        unsigned int                     n_state    = 0;
        std::size_t                      state_offset = 0;   ///< into material_state
        double                           wave_speed   = 0;   ///< P-wave speed [m/s]
      };

      // Constant per point.
      std::vector<dealii::types::particle_index> id;
      std::vector<unsigned int>                  body;
      std::vector<unsigned int>                  load;
      std::vector<double>                        mass, volume0, thickness;
      /// Multiplies the load vector of the point's load: 1 / (points of the
      /// load) for a total force, the point's surface area for a traction.
      std::vector<double> load_factor;
      std::vector<dealii::Point<dim>>            x0;
      /// Lattice cell of current.x (updated when a point moves).
      std::vector<unsigned int> cell;
      /// Position of the point in the ParticleHandler's iteration order.
      std::vector<unsigned int> handler_index;

      State              current, next;
      std::vector<Group> groups;
      unsigned int       n_state_slots = 0; ///< material state slots in the handler

      std::size_t
      size() const
      {
        return id.size();
      }

      void
      commit()
      {
        std::swap(current, next);
      }
    };
  } // namespace MPM
} // namespace hysteron

#endif

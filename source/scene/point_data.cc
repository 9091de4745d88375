#include <hysteron/scene/output_column.h>
#include <hysteron/scene/point_data.h>
#include <hysteron/scene/scene.h>

#include <algorithm>
#include <cmath>

namespace hysteron
{
  namespace PointData
  {
    const char *const component_names[3] = {"x", "y", "z"};

    template <int dim>
    std::vector<std::string>
    columns(const std::vector<std::string> &state_names, const ColumnSelection<dim> &additional)
    {
      constexpr unsigned int   n_sym = dealii::SymmetricTensor<2, dim>::n_independent_components;
      std::vector<std::string> c;
      for (const std::string prefix : {"x_", "u_", "v_"})
        for (unsigned int d = 0; d < dim; ++d)
          c.push_back(prefix + component_names[d]);
      for (const std::string prefix : {"s_", "eps_"})
        {
          for (unsigned int k = 0; k < n_sym; ++k)
            {
              const auto ij = dealii::SymmetricTensor<2, dim>::unrolled_to_component_indices(k);
              c.push_back(prefix + component_names[ij[0]] + component_names[ij[1]]);
            }
          if (prefix == "s_")
            c.push_back("von_mises");
        }
      c.insert(c.end(), state_names.begin(), state_names.end());
      const auto more = additional.names();
      c.insert(c.end(), more.begin(), more.end());
      return c;
    }



    template <int dim>
    double
    von_mises(const dealii::SymmetricTensor<2, dim> &s, const double sigma_zz)
    {
      const double tr = dealii::trace(s) + sigma_zz;
      return std::sqrt(std::max(0.0, 1.5 * ((s * s) + sigma_zz * sigma_zz - tr * tr / 3.0)));
    }



    template <int dim>
    void
    values(const dealii::Point<dim>              &x,
           const dealii::Tensor<1, dim>          &u,
           const dealii::Tensor<1, dim>          &v,
           const dealii::SymmetricTensor<2, dim> &stress,
           const dealii::SymmetricTensor<2, dim> &strain,
           const Material::Interface<dim>        *material,
           const dealii::ArrayView<const double> &state,
           const unsigned int                     n_state_columns,
           double                                *out,
           const ColumnSelection<dim>            &additional)
    {
      constexpr unsigned int n_sym = dealii::SymmetricTensor<2, dim>::n_independent_components;
      unsigned int           c     = 0;
      for (unsigned int d = 0; d < dim; ++d)
        out[c++] = x[d];
      for (unsigned int d = 0; d < dim; ++d)
        out[c++] = u[d];
      for (unsigned int d = 0; d < dim; ++d)
        out[c++] = v[d];
      for (unsigned int k = 0; k < n_sym; ++k)
        out[c++] = stress[dealii::SymmetricTensor<2, dim>::unrolled_to_component_indices(k)];
      double sigma_zz = 0, eps_zz = 0;
      if (dim == 2 && material != nullptr)
        material->out_of_plane(strain, stress, state, eps_zz, sigma_zz);
      out[c++] = von_mises(stress, sigma_zz);
      for (unsigned int k = 0; k < n_sym; ++k)
        out[c++] = strain[dealii::SymmetricTensor<2, dim>::unrolled_to_component_indices(k)];
      for (unsigned int k = 0; k < n_state_columns; ++k)
        out[c++] = (material != nullptr && k < state.size()) ? state[k] : 0.0;
      // The plugins of `Output/Additional columns`.
      if (!additional.empty())
        additional.evaluate({x, u, v, stress, strain, material, state, sigma_zz}, out + c);
    }



    template <int dim>
    double
    strain_energy_density(const Material::Interface<dim>        &material,
                          const dealii::SymmetricTensor<2, dim> &stress,
                          const dealii::SymmetricTensor<2, dim> &strain,
                          const dealii::ArrayView<const double> &state)
    {
      const auto &e        = material.elasticity();
      double      sigma_zz = 0, eps_zz = 0;
      if (dim == 2)
        material.out_of_plane(strain, stress, state, eps_zz, sigma_zz);
      const double tr = dealii::trace(stress) + sigma_zz;
      return ((1 + e.poissons_ratio) * ((stress * stress) + sigma_zz * sigma_zz) -
              e.poissons_ratio * tr * tr) /
             (2 * e.youngs_modulus);
    }



    std::vector<std::string>
    energy_columns(const bool damping_work)
    {
      std::vector<std::string> c{"time",
                                 "kinetic",
                                 "strain_energy",
                                 "internal_work",
                                 "dissipated",
                                 "external_work",
                                 "boundary_work",
                                 "balance"};
      if (damping_work)
        c.insert(c.end() - 1, "damping_work");
      return c;
    }



    std::vector<double>
    EnergyLog::row(const double t,
                   const double kinetic,
                   const double strain_energy,
                   const double internal_work,
                   const double external_work,
                   const double boundary_work,
                   const double damping_work)
    {
      if (!started)
        {
          initial_kinetic = kinetic;
          initial_strain  = strain_energy;
          started         = true;
        }
      return {t,
              kinetic,
              strain_energy,
              internal_work,
              internal_work - strain_energy + initial_strain,
              external_work,
              boundary_work,
              kinetic - initial_kinetic + internal_work - external_work - boundary_work + damping_work};
    }



    template <int dim>
    std::vector<std::string>
    reaction_columns(const Scene<dim> &scene)
    {
      std::vector<std::string> c{"time"};
      for (const auto &b : scene.boundary_descriptions())
        for (unsigned int d = 0; d < dim; ++d)
          c.push_back(b.name + "_" + component_names[d]);
      for (const auto &b : scene.body_descriptions())
        if (b.rigid)
          for (unsigned int d = 0; d < dim; ++d)
            c.push_back(b.name + "_" + component_names[d]);
      return c;
    }



#define HYSTERON_INSTANTIATE(dim)                                                              \
  template std::vector<std::string> columns<dim>(const std::vector<std::string> &,             \
                                                 const ColumnSelection<dim> &);                \
  template double von_mises<dim>(const dealii::SymmetricTensor<2, dim> &, double);            \
  template void   values<dim>(const dealii::Point<dim> &,                                      \
                            const dealii::Tensor<1, dim> &,                                    \
                            const dealii::Tensor<1, dim> &,                                    \
                            const dealii::SymmetricTensor<2, dim> &,                           \
                            const dealii::SymmetricTensor<2, dim> &,                           \
                            const Material::Interface<dim> *,                                  \
                            const dealii::ArrayView<const double> &,                           \
                            unsigned int,                                                      \
                            double *,                                                          \
                            const ColumnSelection<dim> &);                                     \
  template double strain_energy_density<dim>(const Material::Interface<dim> &,                 \
                                             const dealii::SymmetricTensor<2, dim> &,          \
                                             const dealii::SymmetricTensor<2, dim> &,          \
                                             const dealii::ArrayView<const double> &);         \
  template std::vector<std::string> reaction_columns<dim>(const Scene<dim> &);

    HYSTERON_INSTANTIATE(2)
    HYSTERON_INSTANTIATE(3)
#undef HYSTERON_INSTANTIATE
  } // namespace PointData
} // namespace hysteron

// Damping in the explicit MPM (`MPM/Damping`, doc/mpm.md "Damping"): Rayleigh damping
// C = a0 M + a1 K0 as in the FEM, and Cundall's local damping for quasi-static runs. The
// viscous stress of a1 is formed in the force kernels (step.h), the nodal terms here.
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/parameters.h>
#include "mpm/mpm.h"

#include <cmath>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    void
    Solver<dim>::declare_damping_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Damping");
      {
        prm.declare_entry("Rayleigh mass coefficient",
                          "0",
                          Patterns::Double(),
                          "Rayleigh damping C = a0 M + a1 K0 as FEM/Dynamics (K0: the initial "
                          "elastic stiffness): a0 [1/s], >= 0, the nodal force -a0 m_i v_i. Damping "
                          "ratio xi(omega) = a0 / (2 omega) + a1 omega / 2.");
        prm.declare_entry("Rayleigh stiffness coefficient",
                          "0",
                          Patterns::Double(),
                          "Rayleigh damping: a1 [s], >= 0, the viscous stress a1 C0 : d of every "
                          "material point (C0 its material's elastic stiffness, d the strain rate), "
                          "in the forces only. Shortens the critical step by the factor "
                          "sqrt(1 + xi^2) - xi, xi = a1 max_p(c_p + |v_p|) / h.");
        prm.declare_entry("Local damping",
                          "0",
                          Patterns::Double(),
                          "Cundall's local (non-viscous) damping alpha in [0, 1): every nodal "
                          "force component f_i gets -alpha |f_i| sgn(v_i). For quasi-static runs "
                          "(settling under gravity, slow loading) only: it is not a physical "
                          "damping of dynamics.");
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Solver<dim>::parse_damping(dealii::ParameterHandler &prm)
    {
      Section s(prm, {"MPM", "Damping"});
      nodal_damping.mass  = s.get_non_negative("Rayleigh mass coefficient");
      stiffness_damping   = s.get_non_negative("Rayleigh stiffness coefficient");
      nodal_damping.local = s.get_non_negative("Local damping");
      require(nodal_damping.local < 1,
              s.where("Local damping"),
              "must be in [0, 1) (got " + s.get("Local damping") + "; 1 would remove every force "
              "that accelerates a node)");
      require(stiffness_damping == 0 || !this->get_scene().axisymmetric(),
              s.where("Rayleigh stiffness coefficient"),
              "is not implemented for axisymmetric scenes (Material/Stress state = axisymmetric: "
              "the viscous hoop stress is missing); use Rayleigh mass coefficient or Local damping");
    }



    template <int dim>
    void
    Solver<dim>::mark_boundary_nodes()
    {
      // Bit c: a condition sets component c (a wall's normal one too, though it may let go).
      using Type = typename BoundaryDescription<dim>::Type;
      boundary_node.reset(grid->n_local_nodes(), grid->sparse_box());
      for (const auto &b : boundaries)
        for (unsigned int k = 0; k < b.nodes.size(); ++k)
          for (unsigned int c = 0; c < dim; ++c)
            {
              const Type type = static_cast<Type>(b.type);
              if (type == Type::absorbing) // sets no component
                continue;
              if (type == Type::fixed || (type != Type::velocity && type != Type::displacement ?
                                            c == b.normal_direction[k] :
                                            bool(b.components[c])))
                boundary_node[b.nodes[k]] |= 1u << c;
            }
    }



    template <int dim>
    double
    Solver<dim>::critical_time_step() const
    {
      const double speed = grid->is_parallel() ?
                             dealii::Utilities::MPI::max(max_speed, grid->mpi_communicator()) :
                             max_speed;
      if (!(speed > 0))
        return std::numeric_limits<double>::max();
      // Undamped: dt <= 2 / omega_max = h / c with omega_max = 2 c / h. With the viscous
      // stress, u'' + 2 xi omega u' + omega^2 u = 0 by central differences needs
      // dt <= 2 / omega (sqrt(1 + xi^2) - xi), xi = a1 omega_max / 2 (doc/mpm.md).
      const double h = grid->lattice().min_h();
      if (stiffness_damping == 0)
        return h / speed;
      const double xi = stiffness_damping * speed / h;
      return h / speed / (std::sqrt(1.0 + xi * xi) + xi);
    }



    template <int dim>
    void
    Solver<dim>::update_damped_nodal_velocities(const double dt)
    {
      // As update_nodal_velocities(), with NodalDamping::velocity_change(); the damping
      // work of the owned nodes (each shared node once), of the components no boundary
      // condition or rigid body sets (there the reaction takes the damping force), and the
      // same for the dashpots' reactions and work (absorbing.cc).
      constexpr unsigned int C    = 1 + 2 * dim;
      double *const          node = grid->data().data();
      const double           tiny = small_mass;
      double                 work = 0;
      for (const unsigned int n : active_nodes)
        {
          double *const r = node + std::size_t(n) * C;
          if (!(r[0] > tiny))
            {
              for (unsigned int c = 1; c < C; ++c)
                r[c] = 0.0;
              continue;
            }
          const double inv_m = 1.0 / r[0];
          const unsigned int held = grid->is_owned(n) && rigid_node_body[n] == 0 ? boundary_node[n] : ~0u;
          // Absorbing boundaries: the node's dashpots c (summed over its faces), as c / m.
          const unsigned int     first = dashpots.empty() ? 0 : dashpot_first[n];
          dealii::Tensor<1, dim> c;
          for (std::size_t k = first; k > 0 && k <= dashpots.size() && dashpots[k - 1].node == n; ++k)
            c += dashpots[k - 1].c;
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double v  = nodes_hold_momenta ? r[1 + d] * inv_m : r[1 + d];
              const double f  = r[1 + dim + d];
              const double dv = nodal_damping.velocity_change(inv_m, v, f, dt, c[d] * inv_m);
              if (!(held & (1u << d)))
                {
                  work += nodal_damping.work(r[0], v, f, dv, dt);
                  if (first > 0)
                    record_dashpots(first, d, v + 0.5 * dv, dt);
                }
              r[1 + dim + d] = dv;
              r[1 + d]       = v + dv;
            }
        }
      damping_work += work;
      nodes_hold_momenta = false;
    }



    template void Solver<2>::declare_damping_parameters(dealii::ParameterHandler &);
    template void Solver<3>::declare_damping_parameters(dealii::ParameterHandler &);
    template void Solver<2>::parse_damping(dealii::ParameterHandler &);
    template void Solver<3>::parse_damping(dealii::ParameterHandler &);
    template double Solver<2>::critical_time_step() const;
    template double Solver<3>::critical_time_step() const;
    template void Solver<2>::mark_boundary_nodes();
    template void Solver<3>::mark_boundary_nodes();
    template void Solver<2>::update_damped_nodal_velocities(double);
    template void Solver<3>::update_damped_nodal_velocities(double);
  } // namespace MPM
} // namespace hysteron

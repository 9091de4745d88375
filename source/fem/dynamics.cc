#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <hysteron/base/energy_check.h>
#include "fem/fem.h"

#include <array>
#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    double
    Solver<dim>::prescribed_increment(const unsigned int k, const double t0, const double t1) const
    {
      const Scene<dim>  &scene = this->get_scene();
      const auto        &s     = dirichlet[constrained_set[k]];
      const unsigned int c     = constrained_component[k];
      if (s.rigid >= 0)
        return scene.body_descriptions()[s.rigid].rigid_displacement(t0, t1)[c];
      const auto &d = scene.boundary_descriptions()[s.boundary];
      if (d.velocity || d.displacement)
        return d.displacement_increment(t0, t1, constrained_point[k])[c];
      return 0; // fixed, roller
    }



    template <int dim>
    double
    Solver<dim>::prescribed_velocity(const unsigned int k, const double t, const double dt) const
    {
      const Scene<dim>  &scene = this->get_scene();
      const auto        &s     = dirichlet[constrained_set[k]];
      const unsigned int c     = constrained_component[k];
      if (s.rigid >= 0)
        return scene.body_descriptions()[s.rigid].rigid_velocity_at(t)[c];
      const auto &d = scene.boundary_descriptions()[s.boundary];
      if (d.velocity)
        return d.velocity_at(t)[c];
      if (d.displacement && dt > 0)
        return d.step_velocity(t, dt, constrained_point[k])[c];
      return 0;
    }



    template <int dim>
    void
    Solver<dim>::damping_force(const Vector &velocity, Vector &force, const double factor) const
    {
      // force += factor C v, C = a0 M_L + a1 K0 (matrix-free) + the lumped C_b of the
      // absorbing boundaries.
      if (dynamics.rayleigh_mass > 0)
        for (const auto i : owned_dofs)
          force(i) += factor * dynamics.rayleigh_mass * lumped_mass(i) * velocity(i);
      if (!absorbers.empty())
        for (const auto i : owned_dofs)
          force(i) += factor * absorbing_lumped(i) * velocity(i);
      if (dynamics.rayleigh_stiffness > 0)
        {
          Vector ghost(owned_dofs, relevant_dofs, this->get_scene().mpi_communicator());
          ghost = velocity;
          Vector Kv(owned_dofs, this->get_scene().mpi_communicator());
          elastic_stiffness_product(ghost, Kv);
          force.add(factor * dynamics.rayleigh_stiffness, Kv);
        }
      force.compress(dealii::VectorOperation::add);
    }



    template <int dim>
    typename Solver<dim>::Vector
    Solver<dim>::rayleigh_force(const Vector &velocity) const
    {
      // y = a0 M v + a1 K0 v with the consistent M = sum_q rho N_i N_j w_q (per component),
      // as Newmark's residual has it (cell_kernels_dynamics.cc).
      using namespace dealii;
      Vector y(owned_dofs, this->get_scene().mpi_communicator());
      if (dynamics.rayleigh_stiffness > 0)
        {
          elastic_stiffness_product(velocity, y);
          y *= dynamics.rayleigh_stiffness;
        }
      const unsigned int n   = fe->n_dofs_per_cell();
      const unsigned int n_q = quadrature->size();
      FEValues<dim>      fv(*mapping, *fe, *quadrature, update_values);
      std::vector<types::global_dof_index> dofs(n);
      dealii::Vector<double>               ve(n), ye(n);
      if (dynamics.rayleigh_mass > 0)
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              fv.reinit(cell);
              cell->get_dof_indices(dofs);
              const CellHistory<dim> &h = *cell_history[cell->active_cell_index()];
              for (unsigned int i = 0; i < n; ++i)
                ve[i] = velocity(dofs[i]);
              ye = 0;
              for (unsigned int q = 0; q < n_q; ++q)
                for (unsigned int c = 0; c < dim; ++c)
                  {
                    double vq = 0; // component c of v at the point
                    for (unsigned int j = 0; j < n; ++j)
                      if (fe->system_to_component_index(j).first == c)
                        vq += fv.shape_value(j, q) * ve[j];
                    for (unsigned int i = 0; i < n; ++i)
                      if (fe->system_to_component_index(i).first == c)
                        ye[i] += dynamics.rayleigh_mass * h.material->density() * fv.shape_value(i, q) * vq *
                                 h.weight[q];
                  }
              y.add(dofs, ye);
            }
      y.compress(VectorOperation::add);
      return y;
    }



    template <int dim>
    double
    Solver<dim>::critical_time_step()
    {
      // Central differences are stable for dt <= 2 / omega_max, omega_max^2 the
      // largest eigenvalue of M_L^-1 K0 on the free DoFs (undamped). Power
      // iteration on the mass-scaled operator from a start vector that depends
      // only on the geometry (the same on any number of ranks), with the
      // Rayleigh quotient as the estimate.
      MPI_Comm comm = this->get_scene().mpi_communicator();
      Vector   x(owned_dofs, comm), y(owned_dofs, comm), ghost(owned_dofs, relevant_dofs, comm);
      std::vector<bool> constrained_owned(owned_dofs.n_elements(), false);
      for (const auto dof : constrained_list)
        if (owned_dofs.is_element(dof))
          constrained_owned[owned_dofs.index_within_set(dof)] = true;
      // A pseudo-random start vector that is a function of the DoFs' support
      // points and components (a hash of the coordinates), so that it has
      // components on every mode and is the same on any number of ranks.
      for (const auto i : owned_dofs)
        {
          const unsigned int k = owned_dofs.index_within_set(i);
          double             h = 0.37 * owned_component[k];
          const double       c[3] = {12.9898, 78.233, 37.719};
          for (unsigned int d = 0; d < dim; ++d)
            h += c[d] * owned_support[k][d] / u_scale;
          const double r = std::sin(h) * 43758.5453;
          x(i)           = constrained_owned[k] ? 0.0 : r - std::floor(r) - 0.5;
        }
      x.compress(dealii::VectorOperation::insert);

      double lambda = 0;
      for (unsigned int it = 0; it < 500; ++it)
        {
          // Normalise in the mass norm.
          double xmx = 0;
          for (const auto i : owned_dofs)
            xmx += x(i) * x(i) * lumped_mass(i);
          xmx = dealii::Utilities::MPI::sum(xmx, comm);
          x *= 1.0 / std::sqrt(xmx);
          ghost = x;
          elastic_stiffness_product(ghost, y);
          double xkx = 0;
          for (const auto i : owned_dofs)
            if (!constrained_owned[owned_dofs.index_within_set(i)])
              xkx += x(i) * y(i);
          xkx                 = dealii::Utilities::MPI::sum(xkx, comm);
          const double change = std::abs(xkx - lambda) / std::max(xkx, 1e-300);
          lambda              = xkx;
          for (const auto i : owned_dofs)
            x(i) = constrained_owned[owned_dofs.index_within_set(i)] ? 0.0 : y(i) / lumped_mass(i);
          x.compress(dealii::VectorOperation::insert);
          if (it > 20 && change < 1e-7)
            break;
        }
      if (!(lambda > 0))
        return std::numeric_limits<double>::max();
      // Dashpots c_i (lumped C_b) act on the velocity of the half step before, which lowers
      // the limit: for one DoF, m a + c v + k u = 0 with c = 2 xi m omega, the recursion
      // z^2 - (2 - W^2 - 2 xi W) z + 1 - 2 xi W = 0 (W = omega dt) has its roots in the unit
      // disc for W <= 2 (sqrt(1 + xi^2) - xi). Taken with omega_max and the largest c_i / m_i
      // (a bound: a 1D bar with a dashpot at its end, h / c_p without it, is stable up to
      // 0.707 h / c_p, the bound gives 0.618 h / c_p).
      double c_over_m = 0;
      if (!absorbers.empty())
        for (const auto i : owned_dofs)
          c_over_m = std::max(c_over_m, absorbing_lumped(i) / lumped_mass(i));
      const double omega = std::sqrt(lambda);
      const double xi    = dealii::Utilities::MPI::max(c_over_m, comm) / (2 * omega);
      return 2.0 / omega * (std::sqrt(1 + xi * xi) - xi);
    }



    template <int dim>
    void
    Solver<dim>::setup_dynamics()
    {
      using namespace dealii;
      const Scene<dim> &scene  = this->get_scene();
      const auto       &bodies = scene.body_descriptions();
      MPI_Comm          comm   = scene.mpi_communicator();
      reaction_old.reinit(owned_dofs, comm);
      v = 0;
      a = 0;
      Vector ghost(owned_dofs, relevant_dofs, comm);
      ghost = u;

      // The forces of the initial state (external work, HHT and the first explicit step).
      if (analysis != Analysis::explicit_dynamics)
        make_constraints(0.0, false);
      assemble(ghost, 0.0, 0.0, Assemble::forces);
      f_int_old    = f_int;
      f_ext_old    = f_ext;
      reaction_old = f_int;
      reaction_old -= f_ext;
      if (analysis == Analysis::quasi_static)
        return;

      // Initial velocities at the DoFs' support points (the body of the cell);
      // lumped (row-sum) masses.
      const unsigned int n   = fe->n_dofs_per_cell();
      const unsigned int n_q = quadrature->size();
      FEValues<dim>      fv(*mapping, *fe, *quadrature, update_values);
      std::vector<types::global_dof_index> dofs(n);
      const auto &unit_points = fe->get_unit_support_points();
      lumped_mass.reinit(owned_dofs, comm);
      Vector velocity(owned_dofs, comm);
      dealii::Vector<double> m(n);
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            fv.reinit(cell);
            cell->get_dof_indices(dofs);
            const CellHistory<dim> &h   = *cell_history[cell->active_cell_index()];
            const double            rho = h.material->density();
            m                           = 0;
            if (simplex)
              {
                // The row sums of quadratic triangles and tetrahedra vanish or turn negative
                // at the vertices: the diagonal scaled to the cell's mass instead (Hinton,
                // Rock and Zienkiewicz), m_i = M_ii rho V / sum_j M_jj over one component.
                double diagonal = 0, mass = 0;
                for (unsigned int q = 0; q < n_q; ++q)
                  {
                    mass += rho * h.weight[q];
                    for (unsigned int i = 0; i < n; ++i)
                      m[i] += rho * fv.shape_value(i, q) * fv.shape_value(i, q) * h.weight[q];
                  }
                for (unsigned int i = 0; i < n; ++i)
                  if (fe->system_to_component_index(i).first == 0)
                    diagonal += m[i];
                m *= mass / diagonal;
              }
            else
              for (unsigned int q = 0; q < n_q; ++q)
                for (unsigned int i = 0; i < n; ++i)
                  for (unsigned int j = 0; j < n; ++j)
                    if (fe->system_to_component_index(i).first == fe->system_to_component_index(j).first)
                      m[i] += rho * fv.shape_value(i, q) * fv.shape_value(j, q) * h.weight[q];
            lumped_mass.add(dofs, m);
            for (unsigned int i = 0; i < n; ++i)
              if (owned_dofs.is_element(dofs[i]))
                {
                  const Point<dim> p = mapping->transform_unit_to_real_cell(cell, unit_points[i]);
                  velocity(dofs[i]) =
                    bodies[h.body].velocity_at(p)[fe->system_to_component_index(i).first];
                }
          }
      lumped_mass.compress(VectorOperation::add);
      velocity.compress(VectorOperation::insert);
      v = velocity;
      // Prescribed DoFs move with their prescribed velocity.
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        if (owned_dofs.is_element(constrained_list[k]))
          v(constrained_list[k]) = prescribed_velocity(k, 0.0, 0.0);
      v.compress(VectorOperation::insert);
      v_ghost = v;

      // a0 from M a0 = f_ext(0) - f_int(0) - C v0 on the free DoFs (prescribed: 0).
      if (analysis == Analysis::explicit_dynamics)
        {
          if (!absorbers.empty())
            {
              Vector one(owned_dofs, comm), ones(owned_dofs, relevant_dofs, comm);
              one              = 1.0;
              ones             = one;
              absorbing_lumped = absorbing_force(ones, true); // the diagonal c_i
            }
          critical_step = critical_time_step();
          Vector force  = f_ext;
          force -= f_int;
          damping_force(v, force, -1.0);
          for (const auto i : owned_dofs)
            a(i) = force(i) / lumped_mass(i);
          for (unsigned int k = 0; k < constrained_list.size(); ++k)
            if (owned_dofs.is_element(constrained_list[k]))
              a(constrained_list[k]) = 0;
          a.compress(VectorOperation::insert);
        }
      else
        {
          assemble_mass_system();
          Vector x(owned_dofs, comm);
          solve_linear(x);
          constraints.distribute(x);
          a = x;
        }
      a_ghost = a;
    }



    template <int dim>
    void
    Solver<dim>::assemble_mass_system()
    {
      // The consistent mass matrix (condensed) and the right-hand side
      // f_ext(0) - f_int(0) - (C + C_b) v0 of the initial acceleration.
      using namespace dealii;
      system_matrix = 0;
      system_rhs    = 0;
      const unsigned int n   = fe->n_dofs_per_cell();
      const unsigned int n_q = quadrature->size();
      FEValues<dim>      fv(*mapping, *fe, *quadrature, update_values);
      FullMatrix<double>     M(n, n);
      dealii::Vector<double> rhs(n), ve(n);
      std::vector<types::global_dof_index> dofs(n);
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            fv.reinit(cell);
            cell->get_dof_indices(dofs);
            const CellHistory<dim> &h   = *cell_history[cell->active_cell_index()];
            const double            rho = h.material->density();
            M                           = 0;
            for (unsigned int q = 0; q < n_q; ++q)
              for (unsigned int i = 0; i < n; ++i)
                for (unsigned int j = 0; j < n; ++j)
                  if (fe->system_to_component_index(i).first == fe->system_to_component_index(j).first)
                    M(i, j) += rho * fv.shape_value(i, q) * fv.shape_value(j, q) * h.weight[q];
            for (unsigned int i = 0; i < n; ++i)
              ve[i] = v_ghost(dofs[i]);
            M.vmult(rhs, ve);
            rhs *= -dynamics.rayleigh_mass;
            constraints.distribute_local_to_global(M, rhs, dofs, system_matrix, system_rhs);
          }
      system_matrix.compress(VectorOperation::add);
      system_rhs.compress(VectorOperation::add);
      Vector force = f_ext;
      force -= f_int;
      if (dynamics.rayleigh_stiffness > 0)
        {
          Vector Kv(owned_dofs, this->get_scene().mpi_communicator());
          elastic_stiffness_product(v_ghost, Kv);
          force.add(-dynamics.rayleigh_stiffness, Kv);
        }
      if (!absorbers.empty())
        force.add(-1.0, absorbing_force(v_ghost));
      for (const auto i : owned_dofs)
        if (!constraints.is_constrained(i))
          system_rhs(i) += force(i);
      system_rhs.compress(VectorOperation::insert);
    }



    template <int dim>
    double
    Solver<dim>::project_on_walls(const double dt, Vector &v_half, std::vector<dealii::Tensor<1, dim>> &contact)
    {
      // Walls: x = X + u may not cross the wall plane. The impulse m dv of the
      // projection is the wall's force times dt; a fixed wall does the work F . du with
      // the node's displacement of the step (zero for a node that stays on it). The
      // kinetic energy the projection removes (a perfectly inelastic contact of the node)
      // is a loss that shows in the energy balance.
      double wall_work = 0;
      for (unsigned int k = 0; k < wall_dofs.size(); ++k)
        {
          const auto   dof  = wall_dofs[k];
          const Wall  &w    = walls[wall_of_dof[k]];
          const double x    = wall_reference[k] + u_trial(dof);
          if (w.lower ? x < w.position : x > w.position)
            {
              const double corrected = w.position - wall_reference[k];
              const double dv        = (corrected - u_trial(dof)) / dt;
              u_trial(dof)           = corrected;
              wall_work += lumped_mass(dof) * dv / dt * (corrected - u(dof));
              v_half(dof) += dv;
              contact[w.set][w.direction] += lumped_mass(dof) * dv / dt;
            }
        }
      return wall_work;
    }



    template <int dim>
    void
    Solver<dim>::explicit_step(const double t, const double dt)
    {
      // Velocity Verlet (central differences with velocities at whole steps):
      //   v_1/2 = v0 + dt/2 a0,  u1 = u0 + dt v_1/2,
      //   a1 = M_L^-1 (f_ext(t1) - f_int(u1) - C v_1/2),  v1 = v_1/2 + dt/2 a1.
      // Prescribed DoFs follow their motion exactly; a wall projects the nodes
      // that would cross it back onto it (the change of momentum is its force).
      using namespace dealii;
      const Scene<dim> &scene = this->get_scene();
      MPI_Comm          comm  = scene.mpi_communicator();
      const double      t1    = t + dt;
      double            k0    = 0; // this rank's initial kinetic energy (first step only)
      if (initial_kinetic < 0)
        for (const auto i : owned_dofs)
          k0 += 0.5 * lumped_mass(i) * v(i) * v(i);
      Vector            v_half = v;
      v_half.add(0.5 * dt, a);
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        if (owned_dofs.is_element(constrained_list[k]))
          v_half(constrained_list[k]) = prescribed_increment(k, t, t1) / dt;
      v_half.compress(VectorOperation::insert);
      u_trial = u;
      u_trial.add(dt, v_half);

      // The boundaries' work of the step: the walls', then the dashpots'.
      std::vector<Tensor<1, dim>> contact(dirichlet.size());
      double                      step_work = project_on_walls(dt, v_half, contact);
      u_trial.compress(VectorOperation::insert);
      v_half.compress(VectorOperation::insert);
      // The dashpots of absorbing boundaries do the work -c_i v_1/2 du_i on the body (their
      // force -c_i v_1/2 acts over the step): a boundary work, with the walls'.
      if (!absorbers.empty())
        for (const auto i : owned_dofs)
          step_work -= absorbing_lumped(i) * v_half(i) * (u_trial(i) - u(i));

      // The members keep the state of t until the step has passed its checks: a failing
      // step writes the tables of t (StepFailure), not a mixture with the failed step (its
      // velocity and acceleration are not yet assigned; the reactions are the converged
      // reaction_old, not the f_int and f_ext that assemble() overwrites).
      const auto fail_step = [&](const std::string &what) { throw Run::StepFailure(what); };
      Vector ghost(owned_dofs, relevant_dofs, comm);
      ghost = u_trial;
      if (!assemble(ghost, t1, dt, Assemble::forces))
        fail_step("fem: " + (material_failure.empty() ? std::string("non-finite forces") : material_failure) +
                  " in the explicit step to t = " + std::to_string(t1) + " s.");
      Vector force = f_ext;
      force -= f_int;
      Vector damping(owned_dofs, comm);
      damping_force(v_half, damping, 1.0);
      force -= damping;
      // The Rayleigh forces (C v_1/2 less the dashpots', which are boundary work) act over
      // the step: their work C v_1/2 . du is dissipated.
      double step_damping = 0;
      if (has_rayleigh_damping())
        for (const auto i : owned_dofs)
          step_damping += (damping(i) - (absorbers.empty() ? 0.0 : absorbing_lumped(i) * v_half(i))) *
                          (u_trial(i) - u(i));
      Vector a_new(owned_dofs, comm);
      for (const auto i : owned_dofs)
        a_new(i) = force(i) / lumped_mass(i);
      // Prescribed DoFs: the acceleration that ends the step at the prescribed velocity.
      for (unsigned int k = 0; k < constrained_list.size(); ++k)
        if (owned_dofs.is_element(constrained_list[k]))
          {
            const auto dof = constrained_list[k];
            a_new(dof) = 2 * (prescribed_velocity(k, t1, dt) - v_half(dof)) / dt;
          }
      a_new.compress(VectorOperation::insert);
      Vector v_new = v_half;
      v_new.add(0.5 * dt, a_new);

      const double check = u_trial.linfty_norm() + v_new.linfty_norm();
      if (!std::isfinite(check))
        fail_step("fem: a non-finite displacement or velocity in the explicit step to t = " +
                  std::to_string(t1) + " s (time step " + std::to_string(dt) + " s, critical " +
                  std::to_string(critical_step) + " s).");

      // Divergence (energy_diverged(); a step above the stability limit, allowed by a large
      // FEM/Maximum CFL number; stable runs of the vibrating bar stay within 0.2 % of the
      // input), long before the values overflow: the unstable mode grows by
      // a factor of 1.9 per step at 1.05 times the critical step (3.5 at 1.2 times), and the
      // strain energy reaches inf while u is still finite. (The internal work is the one up
      // to t: commit() adds this step's. The external work has this step's, which a load
      // that rises from 0 needs: its work up to t can be less than half the kinetic energy at
      // t + dt in the first steps.)
      {
        double kinetic = 0, external = external_work;
        for (const auto i : owned_dofs)
          {
            kinetic += 0.5 * lumped_mass(i) * v_new(i) * v_new(i);
            external += 0.5 * (f_ext_old(i) + f_ext(i)) * (u_trial(i) - u(i));
          }
        std::array<double, 5> sums{{kinetic, external, boundary_work + step_work, k0, internal_work}};
        if (dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
          dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(sums.data(), sums.size()),
                                      comm,
                                      dealii::ArrayView<double>(sums.data(), sums.size()));
        if (initial_kinetic < 0)
          initial_kinetic = sums[3];
        // Boundary work that takes energy out (walls, the dashpots of absorbing boundaries) is
        // no input: the dashpots of an unstable run would otherwise absorb ever more of it.
        const double input = initial_kinetic + std::abs(sums[1]) + std::max(0.0, sums[2]);
        if (energy_diverged(sums[0] + sums[4], input))
          {
            std::ostringstream m;
            m << "fem: the explicit scheme diverged in the step to t = " << t1
              << " s: the kinetic energy plus the internal work " << sums[0] + sums[4]
              << " J is more than twice the energy put in ("
              << input << " J: initial kinetic energy, external and boundary work). The time step "
              << dt << " s is " << dt / critical_step << " times the critical step " << critical_step
              << " s = 2 / omega_max" << (absorbers.empty() ? "" : ", lowered by the absorbing boundaries' dashpots")
              << " (FEM/Maximum CFL number = " << maximum_cfl
              << "); use a time step <= " << critical_step << " s.";
            fail_step(m.str());
          }
      }

      v = v_new;
      a = a_new;
      // The inertia and damping forces (reactions = M a + C v + f_int - f_ext on prescribed DoFs).
      for (const auto i : owned_dofs)
        inertia(i) = lumped_mass(i) * a_new(i) + damping(i);
      inertia.compress(VectorOperation::insert);
      wall_forces = contact;      // this rank's part, like every table value
      boundary_work += step_work;
      damping_work += step_damping;
      commit(t1, dt);
      v_ghost = v;
      a_ghost = a;
    }

    template class Solver<2>;
    template class Solver<3>;
  } // namespace FEM
} // namespace hysteron

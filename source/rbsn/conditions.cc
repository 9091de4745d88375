// The RBSN's conditions: history sets, supports (Dirichlet sets), loads and the constraints.
#include <deal.II/base/mpi.h>

#include "rbsn/model.h"

#include "base/implicit_step.h"

#include <cmath>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    void
    Model<dim>::setup_conditions()
    {
      setup_history_sets();
      setup_dirichlet();
      setup_loads();
    }



    template <int dim>
    void
    Model<dim>::setup_history_sets()
    {
      // A set's cells are those whose nucleus is on its faces of the nuclei's box or in its
      // region (the rule of the boundary conditions).
      const auto  &lo = nuclei_box[0], &hi = nuclei_box[1];
      const double tolerance = selection_tolerance();
      history_cells.clear();
      history_size.clear();
      for (const unsigned int k : scene().output_control().history_sets)
        {
          const SetDescription<dim> &d = scene().set_descriptions()[k];
          std::vector<unsigned int>  cells;
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            {
              const auto &x  = local_nuclei[c];
              bool        in = d.has_region && d.region.contains(x, tolerance);
              for (const unsigned int face : d.faces)
                in = in || std::abs(x[face / 2] - (face % 2 == 0 ? lo[face / 2] : hi[face / 2])) <= tolerance;
              if (in)
                cells.push_back(c);
            }
          const unsigned long n = global_count(cells.size());
          require(n > 0,
                  d.where(),
                  "selects no cell of the network (a cell is selected by its nucleus: on the face "
                  "of the nuclei's bounding box, or in the region)");
          history_cells.push_back(std::move(cells));
          history_size.push_back(n);
        }
    }



    template <int dim>
    void
    Model<dim>::setup_dirichlet()
    {
      using Type                 = typename BoundaryDescription<dim>::Type;
      const auto        &bodies  = scene().body_descriptions();
      const auto        &lo      = nuclei_box[0], &hi = nuclei_box[1];
      const double       tolerance = selection_tolerance();
      const MPI_Comm     comm    = network_communicator();
      const unsigned int n_local = cell_id.size();
      dof_set.assign(n_dofs * n_local, -1);
      dirichlet.clear();
      // A DoF that two conditions select belongs to the first (its reaction); the two must
      // prescribe the same motion there (ConditionOverlaps), else the scene is refused.
      ConditionOverlaps<dim> overlaps(scene().boundary_descriptions(), scene().time_control().end_time, "cell of the network (its nucleus)");
      bool selects_owned = false; // the current condition selects an owned cell
      const auto take = [&](Dirichlet &set, const unsigned int dof) {
        selects_owned = selects_owned || dof < n_dofs * n_owned_cells;
        if (dof_set[dof] < 0)
          {
            dof_set[dof] = dirichlet.size();
            set.dofs.push_back(dof);
          }
        else if (const Dirichlet &first = dirichlet[dof_set[dof]]; first.boundary >= 0 && set.boundary >= 0)
          {
            // The same DoF's history under either condition (prescribed_increment() reads
            // only the set's boundary), translations and rotations alike.
            const unsigned int k = dof % n_dofs;
            static const char *const axes[3] = {"x", "y", "z"};
            const std::string  name = k < dim ? std::string(axes[k]) :
                                      dim == 2 ? std::string("rotation") :
                                                 "rotation about " + std::string(axes[k - dim]);
            overlaps.check(first.boundary,
                           set.boundary,
                           name,
                           local_nuclei[dof / n_dofs],
                           [&](const double t) { return prescribed_increment(first, dof, 0, t); },
                           [&](const double t) { return prescribed_increment(set, dof, 0, t); });
          }
      };
      // The translations by the boundary's rule; the rotations with all of them (fixed,
      // or velocity / displacement of every component: the rigid motion the field gives
      // the nucleus), not for a roller. Every local cell, ghosts included.
      for (unsigned int b = 0; b < scene().boundary_descriptions().size(); ++b)
        {
          const auto &d = scene().boundary_descriptions()[b];
          Dirichlet   set;
          set.name      = d.name;
          set.boundary  = b;
          selects_owned = false;
          for (unsigned int c = 0; c < n_local; ++c)
            {
              const auto &x   = local_nuclei[c];
              bool        all = d.type != Type::roller;
              for (unsigned int k = 0; k < dim; ++k)
                if (d.prescribes(x, k, lo, hi, tolerance))
                  take(set, n_dofs * c + k);
                else
                  all = false;
              if (all)
                for (unsigned int k = dim; k < n_dofs; ++k)
                  take(set, n_dofs * c + k);
            }
          require(global_count(selects_owned ? 1 : 0) > 0,
                  d.where(),
                  "selects no cell of the network (a cell is selected by its nucleus: on the face "
                  "of the nuclei's bounding box, or in the region)");
          dirichlet.push_back(std::move(set));
        }
      overlaps.throw_if_any(comm);
      for (unsigned int b = 0; b < bodies.size(); ++b)
        if (bodies[b].rigid)
          {
            Dirichlet set;
            set.name      = bodies[b].name;
            set.rigid     = b;
            selects_owned = false;
            for (unsigned int c = 0; c < n_local; ++c)
              if (bodies[b].shape.contains(local_nuclei[c], tolerance))
                for (unsigned int k = 0; k < n_dofs; ++k)
                  take(set, n_dofs * c + k);
            require(global_count(selects_owned ? 1 : 0) > 0,
                    "Body " + bodies[b].name + "/Shape",
                    "the rigid body holds no nucleus of the network (it moves the cells whose "
                    "nuclei lie in its shape)");
            dirichlet.push_back(std::move(set));
          }
    }



    template <int dim>
    void
    Model<dim>::setup_loads()
    {
      // A total force is shared evenly by the cells whose nucleus is in the region; a
      // traction acts on the boundary pieces of the cells in the region.
      const auto  &bodies    = scene().body_descriptions();
      const double tolerance = selection_tolerance();
      load_sets.clear();
      const auto &loads = scene().load_descriptions();
      for (unsigned int l = 0; l < loads.size(); ++l)
        {
          LoadSet set;
          set.load = l;
          if (loads[l].type == LoadDescription<dim>::Type::force)
            {
              for (unsigned int c = 0; c < n_owned_cells; ++c)
                if (loads[l].region.contains(local_nuclei[c], tolerance))
                  {
                    set.cells.push_back(c);
                    set.arm.emplace_back();
                  }
              const unsigned long n = global_count(set.cells.size());
              for (unsigned int k = 0; k < set.cells.size(); ++k)
                set.weight.push_back(1.0 / n);
            }
          else
            for (unsigned int c = 0; c < n_owned_cells; ++c)
              for (const auto &piece : network.cells[c].boundary)
                {
                  // The piece's centroid and area (a segment times the thickness in 2D).
                  dealii::Point<dim> mid;
                  double             weight = 0;
                  if constexpr (dim == 2)
                    {
                      mid    = 0.5 * (piece[0] + piece[1]);
                      weight = piece[0].distance(piece[1]) * bodies[cell_body[c]].thickness_at(mid);
                    }
                  else
                    {
                      // A planar polygon: fan triangles from its first vertex.
                      dealii::Tensor<1, 3> moment;
                      for (unsigned int k = 1; k + 1 < piece.size(); ++k)
                        {
                          const double a = 0.5 * dealii::cross_product_3d(piece[k] - piece[0], piece[k + 1] - piece[0]).norm();
                          weight += a;
                          moment += a / 3 * (piece[0] + piece[k] + piece[k + 1]);
                        }
                      if (weight <= 0)
                        continue;
                      mid = dealii::Point<3>(moment / weight);
                    }
                  if (!loads[l].region.contains(mid, tolerance))
                    continue;
                  set.cells.push_back(c);
                  set.arm.push_back(mid - local_nuclei[c]);
                  set.weight.push_back(weight);
                }
          require(global_count(set.cells.size()) > 0,
                  "Load " + loads[l].name + "/Region",
                  loads[l].type == LoadDescription<dim>::Type::force ?
                    "contains no nucleus of the network" :
                    "contains no boundary piece of the network");
          load_sets.push_back(std::move(set));
        }
    }



    template <int dim>
    void
    Model<dim>::make_constraints(const double t0, const double t1, const bool predictor)
    {
      // The prescribed DoFs set by set; released cells (a fragment nothing holds) keep
      // their displacements.
      std::vector<dof_index>    prescribed, held;
      std::vector<unsigned int> set_of, local_of;
      for (unsigned int s = 0; s < dirichlet.size(); ++s)
        for (const unsigned int dof : dirichlet[s].dofs)
          {
            prescribed.push_back(global_dof(dof));
            set_of.push_back(s);
            local_of.push_back(dof);
          }
      if (n_released > 0)
        for (unsigned int c = 0; c < released.size(); ++c)
          if (released[c])
            for (unsigned int k = 0; k < n_dofs; ++k)
              held.push_back(global_dof(n_dofs * c + k));
      const auto increment = [&](const unsigned int k) {
        return prescribed_increment(dirichlet[set_of[k]], local_of[k], t0, t1);
      };
      constrain_prescribed(constraints,
                           relevant_dofs,
                           prescribed,
                           predictor ? std::function<double(unsigned int)>(increment) : nullptr,
                           held);
    }



    template <int dim>
    double
    Model<dim>::prescribed_increment(const Dirichlet &set, const unsigned int dof, const double t0, const double t1) const
    {
      const unsigned int c = dof / n_dofs, k = dof % n_dofs;
      if (set.rigid >= 0)
        return k < dim ? scene().body_descriptions()[set.rigid].rigid_displacement(t0, t1)[k] : 0.0;
      const auto &d = scene().boundary_descriptions()[set.boundary];
      const auto &x = local_nuclei[c];
      if (k < dim && (d.velocity || d.displacement))
        return d.displacement_increment(t0, t1, x)[k];
      if (k >= dim && d.displacement)
        {
          // The rotation 1/2 curl u of the field, by central differences: in 2D
          // 1/2 (du_y/dx - du_x/dy); in 3D component i is 1/2 (du_k/dx_j - du_j/dx_k) for
          // (i, j, k) cyclic.
          const double e  = 1e-4 * scale;
          const auto   du = [&](const unsigned int direction, const double h) {
            dealii::Tensor<1, dim> shift;
            shift[direction] = h;
            return d.displacement_increment(t0, t1, x + shift);
          };
          if constexpr (dim == 2)
            return 0.25 / e * ((du(0, e)[1] - du(0, -e)[1]) - (du(1, e)[0] - du(1, -e)[0]));
          else
            {
              const unsigned int i = k - dim, j = (i + 1) % 3, l = (i + 2) % 3;
              return 0.25 / e * ((du(j, e)[l] - du(j, -e)[l]) - (du(l, e)[j] - du(l, -e)[j]));
            }
        }
      return 0;
    }



    template <int dim>
    double
    Model<dim>::prescribed_velocity(const Dirichlet &set, const unsigned int dof, const double t, const double dt) const
    {
      const unsigned int k = dof % n_dofs;
      if (set.rigid >= 0)
        return k < dim ? scene().body_descriptions()[set.rigid].rigid_velocity_at(t)[k] : 0.0;
      const auto &d = scene().boundary_descriptions()[set.boundary];
      if (d.velocity)
        return k < dim ? d.velocity_at(t)[k] : 0.0;
      if (!d.displacement || dt <= 0)
        return 0; // fixed, roller; a displacement without a step
      // The step's mean velocity, for the rotations as well.
      return k < dim ? d.step_velocity(t + dt, dt, local_nuclei[dof / n_dofs])[k] :
                       prescribed_increment(set, dof, t, t + dt) / dt;
    }



    template <int dim>
    void
    Model<dim>::external_forces(const double t, Vector &f) const
    {
      // Loads, and the body force at the centroids (a force and its moment about the
      // nucleus), on the owned cells. The body force per unit mass is gravity minus the
      // ground's acceleration a_g(t) d (Scene::body_acceleration()): with a ground motion
      // the network moves relative to the ground, so its supports move with it.
      f                 = 0;
      const auto &loads = scene().load_descriptions();
      const auto  add   = [&](const unsigned int c, const dealii::Tensor<1, dim> &arm, const dealii::Tensor<1, dim> &F) {
        for (unsigned int d = 0; d < dim; ++d)
          f.local_element(n_dofs * c + d) += F[d];
        if constexpr (dim == 2)
          f.local_element(n_dofs * c + 2) += arm[0] * F[1] - arm[1] * F[0];
        else
          {
            const dealii::Tensor<1, 3> m = dealii::cross_product_3d(arm, F);
            for (unsigned int d = 0; d < 3; ++d)
              f.local_element(n_dofs * c + 3 + d) += m[d];
          }
      };
      for (const auto &set : load_sets)
        {
          const dealii::Tensor<1, dim> value = loads[set.load].value_at(t);
          for (unsigned int k = 0; k < set.cells.size(); ++k)
            add(set.cells[k], set.arm[k], set.weight[k] * value);
        }
      const dealii::Tensor<1, dim> g = scene().body_acceleration(t);
      if (g.norm() > 0)
        for (unsigned int c = 0; c < n_owned_cells; ++c)
          add(c, cell_offset[c], cell_mass[c] * g);
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

// The moving background grid (`MPM/Grid/Motion`): after every step the lattice is
// moved to where it follows the bodies (the affine part of their motion, fitted to the
// points' displacements of the step) or to a prescribed motion, so that the points stay
// in their cells. The lattice stays Cartesian: each direction d has its own lower
// corner o_d and cell size h_d, and every node moves with x_d -> x_d + a_d + B_d (x_d - o_d).
// Derivation and limits: doc/mpm.md, "Moving grid".
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/parameters.h>
#include "mpm/mpm.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    void
    Solver<dim>::declare_grid_motion_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Motion");
      {
        prm.declare_entry("Type",
                          "fixed",
                          Patterns::Selection("fixed|follow|prescribed"),
                          "How the background grid moves (doc/mpm.md, 'Moving grid'). fixed: it "
                          "stays where it is. follow: after every step the grid moves with the "
                          "affine part of the motion of the `Bodies` (a translation and, with "
                          "`Stretch`, a stretch of each direction, fitted to the displacements "
                          "of their points in the step by least squares), so that points stay "
                          "in their cells (no grid-crossing error); a face of the grid that a "
                          "fixed, roller or wall condition holds stays where it is, and a face "
                          "with a prescribed velocity or displacement moves with it. "
                          "prescribed: the lower corner moves with `Velocity` and the cells "
                          "stretch with `Stretch rate`. The grid stays Cartesian; grid.csv "
                          "records its lower corner and cell sizes.");
        prm.declare_entry("Bodies",
                          "",
                          Patterns::Anything(),
                          "follow: the deformable bodies whose motion the grid follows, "
                          "separated by commas (empty: every deformable body).");
        prm.declare_entry("Stretch",
                          "true",
                          Patterns::Bool(),
                          "follow: whether the cells stretch with the bodies (true) or the grid "
                          "only translates with their mean displacement (false).");
        prm.declare_entry("Velocity",
                          "",
                          Patterns::Anything(),
                          "prescribed: the velocity of the grid's lower corner [m/s], functions "
                          "of t separated by ';' ('0.001; 0'); empty: at rest.");
        prm.declare_entry("Stretch rate",
                          "",
                          Patterns::Anything(),
                          "prescribed: the rate d ln h_d / dt at which the cells of each "
                          "direction stretch [1/s], functions of t separated by ';' (about the "
                          "lower corner: node x moves with Velocity + rate (x - lower corner)); "
                          "empty: no stretch.");
      }
      prm.leave_subsection();
    }



    template <int dim>
    void
    Solver<dim>::parse_grid_motion(dealii::ParameterHandler &prm)
    {
      const Scene<dim> &scene  = this->get_scene();
      const auto       &bodies = scene.body_descriptions();
      Section           s(prm, {"MPM", "Grid", "Motion"});
      const std::string type     = s.get("Type");
      const auto        followed = s.get_list("Bodies");
      const std::string velocity = dealii::Utilities::trim(s.get("Velocity"));
      const std::string rate     = dealii::Utilities::trim(s.get("Stretch rate"));
      grid_motion      = type == "follow"     ? GridMotion::follow :
                         type == "prescribed" ? GridMotion::prescribed :
                                                GridMotion::fixed;
      grid_moves       = grid_motion != GridMotion::fixed;
      motion_stretches = s.get_bool("Stretch");

      // Entries of the other types would act on nothing.
      if (grid_motion != GridMotion::follow)
        for (const auto &[entry, unset] : {std::make_pair("Bodies", followed.empty()), std::make_pair("Stretch", motion_stretches)})
          require(unset, s.where(entry), "is set but the grid does not follow bodies (Type = " + type + ")");
      if (grid_motion != GridMotion::prescribed)
        for (const auto &[entry, text] : {std::make_pair("Velocity", velocity), std::make_pair("Stretch rate", rate)})
          require(text.empty(), s.where(entry), "is set but the grid motion is not prescribed (Type = " + type + ")");

      if (grid_motion == GridMotion::follow)
        {
          motion_follows_body.assign(bodies.size(), followed.empty());
          for (const auto &name : followed)
            {
              unsigned int b = 0;
              while (b < bodies.size() && bodies[b].name != name)
                ++b;
              require(b < bodies.size(), s.where("Bodies"), "'" + name + "' is not a body (Body names)");
              require(!bodies[b].rigid,
                      s.where("Bodies"),
                      "'" + name + "' is rigid: the grid follows the points of deformable bodies "
                      "(use Type = prescribed for a motion of your own)");
              motion_follows_body[b] = true;
            }
          for (unsigned int b = 0; b < bodies.size(); ++b)
            if (bodies[b].rigid)
              motion_follows_body[b] = false;
        }
      else if (grid_motion == GridMotion::prescribed)
        {
          const double end = scene.time_control().end_time;
          const auto   zero = [](const unsigned int n) {
            std::string z = "0";
            for (unsigned int d = 1; d < n; ++d)
              z += "; 0";
            return z;
          };
          motion_velocity =
            parse_vector_function<1>(velocity.empty() ? zero(dim) : velocity, dim, "t", false, s.where("Velocity"));
          motion_stretch_rate =
            parse_vector_function<1>(rate.empty() ? zero(dim) : rate, dim, "t", false, s.where("Stretch rate"));
          check_finite_in_time(*motion_velocity, end);
          check_finite_in_time(*motion_stretch_rate, end);
          if (scene.axisymmetric() && lower[0] == 0)
            // The nodes on the axis must stay there (the axis roller, r >= 0).
            for (unsigned int k = 0; k <= 1000; ++k)
              {
                const dealii::Point<1> time(end * k / 1000.);
                require(motion_velocity->value(time, 0) == 0,
                        s.where("Velocity"),
                        "moves the grid off the axis (x velocity " +
                          std::to_string(motion_velocity->value(time, 0)) + " m/s at t = " +
                          std::to_string(time[0]) + " s): an axisymmetric grid that starts at r = 0 "
                          "must keep its lower corner there; stretch it with `Stretch rate` instead");
              }
        }
    }



    template <int dim>
    void
    Solver<dim>::setup_grid_motion()
    {
      using Type = typename BoundaryDescription<dim>::Type;
      held_face.fill(-1);
      if (grid_motion != GridMotion::follow)
        return;
      // A condition on a face that prescribes its normal component holds that face.
      const auto &descriptions = this->get_scene().boundary_descriptions();
      for (unsigned int b = 0; b < descriptions.size(); ++b)
        for (const unsigned int face : descriptions[b].faces)
          {
            const unsigned int d    = face / 2;
            const Type         type = descriptions[b].type;
            const bool         holds =
              type == Type::fixed || type == Type::roller || type == Type::wall ||
              ((type == Type::velocity || type == Type::displacement) && descriptions[b].components[d]);
            if (holds && held_face[face] < 0)
              held_face[face] = static_cast<int>(b);
          }
    }



    template <int dim>
    std::string
    Solver<dim>::moved_lattice(const double t, const double dt, Lattice<dim> &moved)
    {
      using Type                  = typename BoundaryDescription<dim>::Type;
      const Lattice<dim> &lattice = grid->lattice();
      const auto         &P       = particles;
      moved                       = lattice;
      // a_d: the displacement of the lower corner; B_d: the stretch h_d' / h_d - 1.
      std::array<double, dim> a{}, B{};

      if (grid_motion == GridMotion::prescribed)
        {
          const auto shift = integrate_in_time<dim>(*motion_velocity, t, t + dt, nullptr);
          const auto rate  = integrate_in_time<dim>(*motion_stretch_rate, t, t + dt, nullptr);
          for (unsigned int d = 0; d < dim; ++d)
            {
              a[d] = shift[d];
              B[d] = std::expm1(rate[d]);
            }
        }
      else
        {
          // Least squares over the followed points p (mass m_p) of their displacement
          // Delta_p = x_p' - x_p in each direction against xi_p = x_p - o_d:
          // Delta(xi) = a + B xi. The sums: the failed points (this rank), M, then per
          // direction S1 = sum m xi, S2 = sum m xi^2, D1 = sum m Delta, X1 = sum m xi Delta.
          std::array<double, 2 + 4 * dim> sums{};
          sums[0] = failed_point >= 0 ? 1 : 0;
          for (const auto &group : P.groups)
            if (group.material != nullptr)
              for (unsigned int p = group.begin; p < group.end; ++p)
                if (motion_follows_body[P.body[p]])
                  {
                    const double m = P.mass[p];
                    sums[1] += m;
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        const double xi    = P.current.x[p][d] - lattice.origin[d];
                        const double delta = P.next.x[p][d] - P.current.x[p][d];
                        double      *s     = sums.data() + 2 + 4 * d;
                        s[0] += m * xi;
                        s[1] += m * xi * xi;
                        s[2] += m * delta;
                        s[3] += m * xi * delta;
                      }
                  }
          if (grid->is_parallel())
            dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(sums.data(), sums.size()),
                                        grid->mpi_communicator(),
                                        dealii::ArrayView<double>(sums.data(), sums.size()));
          // A failed step is reported as such (describe_failure()), on every rank.
          if (sums[0] > 0)
            return "";
          const double M = sums[1];
          const auto  &descriptions = this->get_scene().boundary_descriptions();
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double  length = lattice.n_cells[d] * lattice.h[d];
              const double *s      = sums.data() + 2 + 4 * d;
              // The faces held in d: where (xi) and by how much they move in the step.
              std::array<bool, 2>   held{{false, false}};
              std::array<double, 2> at{{0.0, length}}, by{{0.0, 0.0}};
              for (unsigned int side = 0; side < 2; ++side)
                if (const int b = held_face[2 * d + side]; b >= 0)
                  {
                    held[side] = true;
                    const auto &condition = descriptions[b];
                    if (condition.type == Type::velocity || condition.type == Type::displacement)
                      {
                        // The face's centre: where a displacement u(x, t) is read.
                        dealii::Point<dim> centre = lattice.origin;
                        for (unsigned int e = 0; e < dim; ++e)
                          centre[e] += e == d ? at[side] : 0.5 * lattice.n_cells[e] * lattice.h[e];
                        by[side] = condition.displacement_increment(t, t + dt, centre)[d];
                      }
                  }
              // The axis of an axisymmetric scene holds the radius when no face does.
              if (axisymmetric && d == 0 && !held[0] && !held[1])
                {
                  held[0] = true;
                  at[0]   = -lattice.origin[0];
                }
              if (held[0] && held[1])
                {
                  B[d] = (by[1] - by[0]) / length;
                  a[d] = by[0];
                }
              else if (held[0] || held[1])
                {
                  // Through the held face f: Delta(xi) = delta_f + B (xi - xi_f).
                  const unsigned int side = held[0] ? 0 : 1;
                  const double       f = at[side], delta_f = by[side];
                  const double       den = s[1] - 2 * f * s[0] + f * f * M;
                  const double       num = s[3] - f * s[2] - delta_f * s[0] + delta_f * f * M;
                  B[d] = motion_stretches && den > 1e-20 * M * length * length ? num / den : 0.0;
                  a[d] = delta_f - B[d] * f;
                }
              else if (M > 0)
                {
                  const double var = s[1] - s[0] * s[0] / M;
                  const double cov = s[3] - s[0] * s[2] / M;
                  B[d] = motion_stretches && var > 1e-20 * M * length * length ? cov / var : 0.0;
                  a[d] = (s[2] - B[d] * s[0]) / M;
                }
            }
        }

      for (unsigned int d = 0; d < dim; ++d)
        {
          moved.origin[d] = lattice.origin[d] + a[d];
          moved.h[d]      = lattice.h[d] * (1.0 + B[d]);
          // A cell that halves or doubles in one step: the fitted motion is not a
          // deformation the grid can follow (the points are not moving as a body).
          if (!(std::isfinite(moved.origin[d]) && moved.h[d] > 0.5 * lattice.h[d] &&
                moved.h[d] < 2.0 * lattice.h[d]))
            {
              std::ostringstream m;
              m.precision(6);
              m << "mpm: the moving grid (MPM/Grid/Motion) would change its cell size in "
                << PointData::component_names[d] << " from " << lattice.h[d] << " m to " << moved.h[d]
                << " m and move its lower corner by " << a[d] << " m in the step from t = " << t
                << " s (step " << this->n_steps() + 1
                << "): more than a factor 2 in one step, which no body deforms by. "
                << (grid_motion == GridMotion::follow ?
                      "The followed points do not move as one body (check MPM/Grid/Motion/Bodies)." :
                      "Check MPM/Grid/Motion/Velocity and Stretch rate.");
              return m.str();
            }
          if (axisymmetric && d == 0 && !(moved.origin[0] >= 0))
            {
              std::ostringstream m;
              m << "mpm: the moving grid's lower corner would reach r = " << moved.origin[0]
                << " < 0 in the step from t = " << t << " s (x is the radius of an axisymmetric "
                << "scene; check MPM/Grid/Motion)";
              return m.str();
            }
        }

      // Every point must lie in the moved grid.
      last_moved_lattice = moved;
      if (failed_point < 0)
        for (unsigned int p = 0; p < P.size(); ++p)
          if (!moved.contains(P.next.x[p]))
            {
              failed_point = p;
              failure      = "a material point left the moving grid";
              break;
            }
      return "";
    }



    template <int dim>
    void
    Solver<dim>::move_grid(const Lattice<dim> &moved)
    {
      grid->move(moved);
      // The points' cells in the moved grid (the step found them in the old one).
      const auto &P = particles;
      left_subdomain = false;
      for (unsigned int p = 0; p < P.size(); ++p)
        {
          const auto         cell = moved.cell_of(P.current.x[p]);
          const unsigned int id   = grid->cell_id(cell);
          if (id != particles.cell[p])
            {
              particles.cell[p] = id;
              ++n_changed_cells;
            }
          left_subdomain = left_subdomain || !grid->owns_cell(cell);
        }
    }



    template <int dim>
    void
    Solver<dim>::write_grid_row(const double t)
    {
      if (!grid_table || t == grid_table_time)
        return;
      const Lattice<dim> &lattice = grid->lattice();
      std::vector<double> row{t};
      for (unsigned int d = 0; d < dim; ++d)
        row.push_back(lattice.origin[d]);
      for (unsigned int d = 0; d < dim; ++d)
        row.push_back(lattice.h[d]);
      grid_table->add_row(row);
      grid_table_time = t;
    }



    template void Solver<2>::declare_grid_motion_parameters(dealii::ParameterHandler &);
    template void Solver<3>::declare_grid_motion_parameters(dealii::ParameterHandler &);
    template void Solver<2>::parse_grid_motion(dealii::ParameterHandler &);
    template void Solver<3>::parse_grid_motion(dealii::ParameterHandler &);
    template void Solver<2>::setup_grid_motion();
    template void Solver<3>::setup_grid_motion();
    template std::string Solver<2>::moved_lattice(double, double, Lattice<2> &);
    template std::string Solver<3>::moved_lattice(double, double, Lattice<3> &);
    template void Solver<2>::move_grid(const Lattice<2> &);
    template void Solver<3>::move_grid(const Lattice<3> &);
    template void Solver<2>::write_grid_row(double);
    template void Solver<3>::write_grid_row(double);
  } // namespace MPM
} // namespace hysteron

// Brittle fracture of the facets: the fracture ratio, the facet to break, the breaks of an increment.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include "rbsn/model.h"
#include <hysteron/run/stepping_method.h>

#include <iostream>
#include <limits>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /// "(x, y)" or "(x, y, z)".
      template <int dim>
      std::string
      xyz(const dealii::Point<dim> &p)
      {
        std::ostringstream s;
        s << "(" << p[0];
        for (unsigned int d = 1; d < dim; ++d)
          s << ", " << p[d];
        s << ")";
        return s.str();
      }
    } // namespace



    template <int dim>
    std::array<double, 3>
    Model<dim>::fracture_ratio(const unsigned int e) const
    {
      // R = max(s_n / f_t, (|s_t| + tan(phi) s_n) / c): the distance to the Mohr-Coulomb
      // surface with a tension cut-off along the ray from the origin (eq. 3.50-3.51), on
      // the facet's normal stress and (3D) its resultant shear stress.
      const Springs<dim> &sp   = springs[e];
      const double        area = sp.area;
      const double        s_n  = sp.trial_force[0] / area;
      const double s_t = dim == 2 ? sp.trial_force[1] / area : std::hypot(sp.trial_force[1], sp.trial_force[dim - 1]) / area;
      const double R   = std::max(s_n / fracture.tensile_strength, (std::abs(s_t) + fracture.friction * s_n) / fracture.cohesion);
      return {{R, s_n, s_t}};
    }



    template <int dim>
    typename Model<dim>::Break
    Model<dim>::facet_to_break() const
    {
      Break  mine;
      double R_max = 1;
      for (unsigned int e = 0; e < springs.size(); ++e)
        {
          if (springs[e].broken)
            continue;
          const double R = fracture_ratio(e)[0];
          if (R > R_max)
            {
              R_max       = R;
              mine.local  = e;
              mine.facet  = facet_id[e];
            }
        }
      mine.R = R_max;
      if (!distributed())
        return mine;
      // The largest R over the ranks (MAXLOC: the lowest facet number among equal R,
      // as one rank's loop over the facets in their order would take), and its owner.
      const MPI_Comm comm = network_communicator();
      struct
      {
        double R;
        int    facet;
      } local{R_max, mine.facet < 0 ? std::numeric_limits<int>::max() : static_cast<int>(mine.facet)}, all{};
      int ierr = MPI_Allreduce(&local, &all, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm);
      AssertThrowMPI(ierr);
      Break result;
      if (!(all.R > 1))
        return result;
      result.R     = all.R;
      result.facet = all.facet;
      const int owner = dealii::Utilities::MPI::max(mine.facet == all.facet ? int(part) : -1, comm);
      result.owner    = owner;
      result.local    = owner == int(part) ? mine.local : -1;
      return result;
    }



    template <int dim>
    bool
    Model<dim>::fracture_cycles(const double t, const double dt, Breaks &breaks)
    {
      // Break the facet with the largest R > 1, solve the step again.
      bool converged = true;
      for (unsigned int cycle = 0; converged; ++cycle)
        {
          const Break broken = facet_to_break();
          if (broken.facet < 0)
            break;
          if (cycle >= fracture.max_cycles)
            fail_at_t(breaks,
                      "rbsn: more than " + std::to_string(fracture.max_cycles) +
                        " facets break in the step to t = " + std::to_string(t + dt) +
                        " s: the network falls apart.");
          const dealii::Point<dim> midpoint = break_facet(broken, t + dt, breaks);
          try
            {
              converged = solve_step(t, dt);
            }
          catch (const RuntimeError &error)
            {
              fail_at_t(breaks,
                        std::string(error.what()) + " after the facet at " + xyz(midpoint) +
                          " broke at t = " + std::to_string(t + dt) + " s: the structure has fallen apart.");
            }
        }
      return converged;
    }



    template <int dim>
    dealii::Point<dim>
    Model<dim>::break_facet(const Break &broken, const double t1, Breaks &breaks)
    {
      const MPI_Comm comm = network_communicator();
      // The facet's owner: its midpoint, stresses and cells for every rank.
      std::array<double, dim + 5> facet{};
      if (broken.local >= 0)
        {
          const unsigned int e     = broken.local;
          const auto         ratio = fracture_ratio(e);
          for (unsigned int d = 0; d < dim; ++d)
            facet[d] = network.facets[e].midpoint[d];
          facet[dim]     = ratio[1];
          facet[dim + 1] = ratio[2];
          facet[dim + 2] = ratio[0];
          facet[dim + 3] = cell_id[network.facets[e].a];
          facet[dim + 4] = cell_id[network.facets[e].b];
          springs[e].broken = true;
          breaks.local.push_back(e);
        }
      if (distributed())
        {
          dealii::Utilities::MPI::broadcast(facet.data(), facet.size(), broken.owner, comm);
        }
      ++n_broken;
      ++breaks.n;
      dealii::Point<dim> midpoint;
      for (unsigned int d = 0; d < dim; ++d)
        midpoint[d] = facet[d];
      const std::vector<bool> released_before = released;
      update_fragments();
      const Separation separated = separation(facet[dim + 3], facet[dim + 4], released_before);
      {
        // The fracture.csv row: time, facet, midpoint, s_n, s_t, R, fragments, the
        // separated piece's cells and centroid, the released cells.
        std::vector<double> row{t1, double(broken.facet)};
        row.insert(row.end(), facet.begin(), facet.begin() + dim + 3);
        row.push_back(n_fragments);
        row.push_back(separated.cells);
        for (unsigned int d = 0; d < dim; ++d)
          row.push_back(separated.centroid[d]);
        row.push_back(separated.released);
        breaks.rows.push_back(row);
      }
      if (separated.released > 0)
        {
          const bool         one = separated.released == 1;
          std::ostringstream m;
          m << "rbsn: t = " << t1 << " s: the facet at " << xyz(midpoint) << " broke and cut off "
            << separated.released << (one ? " cell" : " cells") << " around "
            << xyz(separated.released_centroid) << " that nothing holds: "
            << (one ? "it keeps its last state and leaves" : "they keep their last state and leave")
            << " the static system";
          if (separated.load.norm() > 1e-12 * std::max(force_scale, last_force_level))
            m << "; the load on " << (one ? "it" : "them") << ", "
              << xyz(dealii::Point<dim>(separated.load)) << " N, is no longer carried";
          breaks.messages.push_back(m.str() + ".");
        }
      return midpoint;
    }



    template <int dim>
    void
    Model<dim>::undo_breaks(Breaks &breaks)
    {
      for (const unsigned int e : breaks.local)
        springs[e].broken = false;
      n_broken -= breaks.n;
      if (breaks.n > 0)
        update_fragments();
      breaks.local.clear();
      breaks.n = 0;
      breaks.messages.clear();
    }



    template <int dim>
    void
    Model<dim>::write_breaks(Breaks &breaks)
    {
      if (fracture_table)
        for (const auto &row : breaks.rows)
          fracture_table->add_row(row);
      breaks.rows.clear();
      if (scene().is_root())
        for (const auto &m : breaks.messages)
          std::cerr << "hysteron: warning: " << m << std::endl;
      breaks.messages.clear();
    }



    template <int dim>
    void
    Model<dim>::fail_at_t(Breaks &breaks, const std::string &what)
    {
      undo_breaks(breaks);
      write_breaks(breaks);
      throw Run::StepFailure(what);
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

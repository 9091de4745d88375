// Are the network's supports enough for a static analysis? Each connected part of
// the network (cells joined by facet springs) must have its rigid-body motions
// prevented by the prescribed DoFs, or its stiffness matrix is singular.
#include <hysteron/base/rigid_modes.h>
#include <hysteron/rbsn/model.h>

#include <algorithm>
#include <set>

namespace hysteron
{
  namespace RBSN
  {
    void
    Model::check_supports() const
    {
      if (analysis != Analysis::linear_static && analysis != Analysis::quasi_static)
        return; // the mass matrix makes the dynamic system regular
      const unsigned int n_cells = network.cells.size();
      ConnectedParts     connected(n_cells);
      for (const auto &f : network.facets)
        connected.join(f.a, f.b);
      const std::vector<unsigned int> part    = connected.parts();
      const unsigned int              n_parts = n_cells == 0 ? 0 : *std::max_element(part.begin(), part.end()) + 1;

      // The centre and size of each part, from its nuclei.
      std::vector<dealii::Point<2>> lo(n_parts, dealii::Point<2>(1e300, 1e300)), hi(n_parts, dealii::Point<2>(-1e300, -1e300));
      for (unsigned int c = 0; c < n_cells; ++c)
        for (unsigned int d = 0; d < 2; ++d)
          {
            lo[part[c]][d] = std::min(lo[part[c]][d], network.cells[c].nucleus[d]);
            hi[part[c]][d] = std::max(hi[part[c]][d], network.cells[c].nucleus[d]);
          }
      std::vector<dealii::Point<2>> centres(n_parts);
      std::vector<double>           sizes(n_parts);
      for (unsigned int p = 0; p < n_parts; ++p)
        {
          centres[p] = 0.5 * (lo[p] + hi[p]);
          sizes[p]   = std::max(lo[p].distance(hi[p]), 1e-300);
        }

      RigidModeCheck<2> check(centres, sizes);
      for (const auto &set : dirichlet)
        for (const unsigned int dof : set.dofs)
          {
            const unsigned int c = dof / 3, k = dof % 3;
            if (k == 2)
              check.add_rotation(part[c]);
            else
              check.add_displacement(part[c], network.cells[c].nucleus, k);
          }

      const auto &bodies = scene.body_descriptions();
      for (unsigned int p = 0; p < n_parts; ++p)
        {
          const auto free = check.free_modes(p);
          if (free.empty())
            continue;
          std::set<std::string> names;
          for (unsigned int c = 0; c < n_cells; ++c)
            if (part[c] == p)
              names.insert(bodies[cell_body[c]].name);
          std::string where, modes;
          for (const auto &n : names)
            where += (where.empty() ? "Body " : ", Body ") + n;
          for (const auto &m : free)
            modes += (modes.empty() ? "" : ", ") + m;
          throw InputError(where,
                           "unsupported structure: its supports leave a rigid-body motion free (" + modes +
                             "), so the stiffness matrix of a static analysis is singular. Add a "
                             "fixed, roller, velocity or displacement boundary that prevents it, or "
                             "use RBSN/Analysis = implicit dynamics");
        }
    }
  } // namespace RBSN
} // namespace hysteron

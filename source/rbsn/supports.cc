// Supports and fragments. Each connected part of the network (cells joined by
// facet springs) must have its rigid-body motions prevented by the prescribed
// DoFs, or its static stiffness matrix is singular: at set-up that is an input
// error; when fracture cuts a part loose during a static analysis, the part is
// released (its cells keep their last state and leave the system of equations).
#include <hysteron/base/rigid_modes.h>
#include <hysteron/rbsn/model.h>

#include <algorithm>
#include <set>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    std::vector<std::vector<std::string>>
    Model::network_parts(const bool intact_only, std::vector<unsigned int> &part) const
    {
      const unsigned int n_cells = network.cells.size();
      ConnectedParts     connected(n_cells);
      for (unsigned int e = 0; e < network.facets.size(); ++e)
        if (!intact_only || !springs[e].broken)
          connected.join(network.facets[e].a, network.facets[e].b);
      part                       = connected.parts();
      const unsigned int n_parts = n_cells == 0 ? 0 : *std::max_element(part.begin(), part.end()) + 1;

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
          // A single cell: its size from its area (the nuclei span nothing).
          sizes[p] = std::max(lo[p].distance(hi[p]), 1e-300);
        }
      for (unsigned int c = 0; c < n_cells; ++c)
        if (sizes[part[c]] == 1e-300)
          sizes[part[c]] = std::sqrt(network.cells[c].area);

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
      std::vector<std::vector<std::string>> free(n_parts);
      for (unsigned int p = 0; p < n_parts; ++p)
        free[p] = check.free_modes(p);
      return free;
    }



    void
    Model::check_supports() const
    {
      if (analysis != Analysis::linear_static && analysis != Analysis::quasi_static)
        return; // the mass matrix makes the dynamic system regular
      std::vector<unsigned int> part;
      const auto                free = network_parts(false, part);

      const auto &bodies = scene.body_descriptions();
      for (unsigned int p = 0; p < free.size(); ++p)
        {
          if (free[p].empty())
            continue;
          std::set<std::string> names;
          for (unsigned int c = 0; c < part.size(); ++c)
            if (part[c] == p)
              names.insert(bodies[cell_body[c]].name);
          std::string where, modes;
          for (const auto &n : names)
            where += (where.empty() ? "Body " : ", Body ") + n;
          for (const auto &m : free[p])
            modes += (modes.empty() ? "" : ", ") + m;
          throw InputError(where,
                           "unsupported structure: its supports leave a rigid-body motion free (" + modes +
                             "), so the stiffness matrix of a static analysis is singular. Add a "
                             "fixed, roller, velocity or displacement boundary that prevents it, or "
                             "use RBSN/Analysis = implicit dynamics");
        }
    }



    void
    Model::update_fragments()
    {
      // A change of the released or lone cells (their DoFs' constraints) rebuilds the matrix.
      const std::vector<bool>         released_before = released;
      const std::vector<unsigned int> lone_before     = lone_cells;
      const auto free = network_parts(true, fragment);
      n_fragments     = free.size();
      // Dynamics: a loose fragment moves under its inertia; nothing is released.
      const bool release = analysis == Analysis::linear_static || analysis == Analysis::quasi_static;
      released.assign(network.cells.size(), false);
      n_released = 0;
      std::vector<unsigned int> size(n_fragments, 0);
      for (const unsigned int p : fragment)
        ++size[p];
      lone_cells.clear();
      for (unsigned int c = 0; c < fragment.size(); ++c)
        if (size[fragment[c]] == 1)
          lone_cells.push_back(c);
      for (unsigned int c = 0; c < fragment.size(); ++c)
        if (release && !free[fragment[c]].empty())
          {
            released[c] = true;
            ++n_released;
          }
      if (released != released_before || lone_cells != lone_before)
        matrix_current = false;
    }



    Model::Separation
    Model::separation(const unsigned int e, const std::vector<bool> &released_before) const
    {
      // The facet's cells in different fragments: the smaller one separated.
      Separation   s;
      const Facet<2> &f = network.facets[e];
      if (fragment[f.a] != fragment[f.b])
        {
          std::array<unsigned int, 2> size{{0, 0}};
          for (const unsigned int p : fragment)
            size[0] += p == fragment[f.a], size[1] += p == fragment[f.b];
          const unsigned int piece = size[0] <= size[1] ? fragment[f.a] : fragment[f.b];
          double             area  = 0;
          dealii::Point<2>   centroid;
          for (unsigned int c = 0; c < fragment.size(); ++c)
            if (fragment[c] == piece)
              {
                ++s.cells;
                area += network.cells[c].area;
                centroid += network.cells[c].area * network.cells[c].centroid;
              }
          s.centroid = centroid / area;
        }
      // Cells released by this break (a break can release the larger piece, or both).
      dealii::Point<2> centroid;
      double           area = 0;
      for (unsigned int c = 0; c < released.size(); ++c)
        if (released[c] && !released_before[c])
          {
            ++s.released;
            area += network.cells[c].area;
            centroid += network.cells[c].area * network.cells[c].centroid;
            for (unsigned int k = 0; k < 2; ++k)
              s.load[k] += f_ext(3 * c + k);
          }
      if (s.released > 0)
        s.released_centroid = centroid / area;
      return s;
    }
  } // namespace RBSN
} // namespace hysteron

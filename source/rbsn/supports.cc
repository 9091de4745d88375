// Supports and fragments. Each connected part of the network (cells joined by
// facet springs) must have its rigid-body motions prevented by the prescribed
// DoFs, or its static stiffness matrix is singular: at set-up that is an input
// error; when fracture cuts a part loose during a static analysis, the part is
// released (its cells keep their last state and leave the system of equations).
//
// On several ranks the parts are found in two stages: each rank joins its cells
// (and ghost cells) over its own facets (union-find), labels each of its parts with
// the lowest global cell number in it, and the ranks then exchange the labels of the
// cells they share (the owner keeps the lowest) until no label changes. A part's label
// is then the lowest cell number in it on every rank, and the parts are numbered in
// the order of their labels, as one rank numbers them.
#include <deal.II/base/mpi.h>

#include <hysteron/base/rigid_modes.h>
#include "rbsn/model.h"

#include "rbsn/collective.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <type_traits>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    std::vector<std::vector<std::string>>
    Model<dim>::network_parts(const bool                  intact_only,
                              std::vector<unsigned int>  &part_of,
                              std::vector<unsigned long> &sizes) const
    {
      const unsigned int n_local = cell_id.size();
      const MPI_Comm     comm    = network_communicator();
      ConnectedParts     connected(n_local);
      for (unsigned int e = 0; e < network.facets.size(); ++e)
        if (!intact_only || !springs[e].broken)
          connected.join(network.facets[e].a, network.facets[e].b);
      part_of = connected.parts();
      unsigned int n_parts_here = n_local == 0 ? 0 : *std::max_element(part_of.begin(), part_of.end()) + 1;
      if (distributed())
        {
          // The lowest global cell number of every local part, exchanged over the cells
          // that two ranks share until no label changes.
          std::vector<double> label(n_parts_here, std::numeric_limits<double>::max());
          for (unsigned int c = 0; c < n_local; ++c)
            label[part_of[c]] = std::min(label[part_of[c]], double(cell_id[c]));
          dealii::IndexSet owned(n_cells), relevant(n_cells);
          if (n_owned_cells > 0)
            owned.add_range(cell_block[0], cell_block[0] + n_owned_cells);
          relevant = owned;
          for (unsigned int c = n_owned_cells; c < n_local; ++c)
            relevant.add_index(cell_block[c]);
          owned.compress();
          relevant.compress();
          Vector labels(owned, relevant, comm);
          for (bool changed = true; changed;)
            {
              for (unsigned int c = 0; c < n_local; ++c)
                labels.local_element(c) = label[part_of[c]];
              labels.compress(dealii::VectorOperation::min);
              labels.update_ghost_values();
              bool lower = false;
              for (unsigned int c = 0; c < n_local; ++c)
                if (labels.local_element(c) < label[part_of[c]])
                  {
                    label[part_of[c]] = labels.local_element(c);
                    lower             = true;
                  }
              changed = dealii::Utilities::MPI::logical_or(lower, comm);
              labels.zero_out_ghost_values();
            }
          // The parts in the order of their labels: the lowest cells of the parts are owned
          // by exactly one rank each.
          std::vector<unsigned int> roots;
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            if (label[part_of[c]] == double(cell_id[c]))
              roots.push_back(cell_id[c]);
          std::vector<unsigned int> all_roots = Collective::gather(roots, comm);
          std::sort(all_roots.begin(), all_roots.end());
          std::vector<unsigned int> global_part(n_parts_here);
          for (unsigned int p = 0; p < n_parts_here; ++p)
            global_part[p] = std::lower_bound(all_roots.begin(), all_roots.end(), static_cast<unsigned int>(label[p])) -
                             all_roots.begin();
          for (auto &p : part_of)
            p = global_part[p];
          n_parts_here = all_roots.size();
        }

      // The cells, centre and size of each part, from its (owned) nuclei.
      const unsigned int  n = n_parts_here;
      sizes.assign(n, 0);
      std::vector<double> lo(n * dim, std::numeric_limits<double>::max()), hi(n * dim, -std::numeric_limits<double>::max()),
        measure(n, 0);
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          const unsigned int p = part_of[c];
          ++sizes[p];
          measure[p] += cell_measure(c);
          for (unsigned int d = 0; d < dim; ++d)
            {
              lo[p * dim + d] = std::min(lo[p * dim + d], local_nuclei[c][d]);
              hi[p * dim + d] = std::max(hi[p * dim + d], local_nuclei[c][d]);
            }
        }
      if (distributed())
        {
          dealii::Utilities::MPI::sum(sizes, comm, sizes);
          dealii::Utilities::MPI::sum(measure, comm, measure);
          dealii::Utilities::MPI::min(lo, comm, lo);
          dealii::Utilities::MPI::max(hi, comm, hi);
        }
      std::vector<dealii::Point<dim>> centres(n);
      std::vector<double>             extents(n);
      for (unsigned int p = 0; p < n; ++p)
        {
          dealii::Point<dim> a, b;
          for (unsigned int d = 0; d < dim; ++d)
            {
              a[d] = lo[p * dim + d];
              b[d] = hi[p * dim + d];
            }
          centres[p] = 0.5 * (a + b);
          // A single cell: its size from its measure (the nuclei span nothing).
          extents[p] = std::max(a.distance(b), 1e-300);
          if (extents[p] == 1e-300)
            extents[p] = dim == 2 ? std::sqrt(measure[p]) : std::cbrt(measure[p]);
        }

      RigidModeCheck<dim> check(centres, extents);
      for (const auto &set : dirichlet)
        for (const unsigned int dof : set.dofs)
          {
            const unsigned int c = dof / n_dofs, k = dof % n_dofs;
            if (c >= n_owned_cells)
              continue; // its owner counts it
            if (k >= dim)
              check.add_rotation(part_of[c], k - dim);
            else
              check.add_displacement(part_of[c], local_nuclei[c], k);
          }
      if (distributed())
        check.sum(comm);
      std::vector<std::vector<std::string>> free(n);
      for (unsigned int p = 0; p < n; ++p)
        free[p] = check.free_modes(p);
      return free;
    }



    template <int dim>
    void
    Model<dim>::check_supports() const
    {
      if (analysis != Analysis::linear_static && analysis != Analysis::quasi_static)
        return; // the mass matrix makes the dynamic system regular
      std::vector<unsigned int>  part_of;
      std::vector<unsigned long> sizes;
      const auto                 free = network_parts(false, part_of, sizes);

      const auto &bodies = scene().body_descriptions();
      for (unsigned int p = 0; p < free.size(); ++p)
        {
          if (free[p].empty())
            continue;
          std::set<std::string> names;
          for (unsigned int c = 0; c < n_owned_cells; ++c)
            if (part_of[c] == p)
              names.insert(bodies[cell_body[c]].name);
          std::string mine;
          for (const auto &n : names)
            mine += n + "\n";
          names.clear();
          for (const auto &text : dealii::Utilities::MPI::all_gather(network_communicator(), mine))
            {
              std::istringstream lines(text);
              for (std::string n; std::getline(lines, n);)
                names.insert(n);
            }
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



    template <int dim>
    void
    Model<dim>::update_fragments()
    {
      // A change of the released or lone cells (their DoFs' constraints) rebuilds the matrix.
      const std::vector<bool>         released_before = released;
      const std::vector<unsigned int> lone_before     = lone_cells;
      const auto free = network_parts(true, fragment, fragment_size);
      n_fragments     = free.size();
      // Dynamics: a loose fragment moves under its inertia; nothing is released.
      const bool release = analysis == Analysis::linear_static || analysis == Analysis::quasi_static;
      released.assign(cell_id.size(), false);
      lone_cells.clear();
      unsigned long n_owned_released = 0;
      for (unsigned int c = 0; c < fragment.size(); ++c)
        {
          if (fragment_size[fragment[c]] == 1)
            lone_cells.push_back(c);
          if (release && !free[fragment[c]].empty())
            {
              released[c] = true;
              n_owned_released += c < n_owned_cells;
            }
        }
      n_released = dealii::Utilities::MPI::sum(n_owned_released, network_communicator());
      const bool changed = released != released_before || lone_cells != lone_before;
      if (dealii::Utilities::MPI::logical_or(changed, network_communicator()))
        matrix_current = false;
    }



    template <int dim>
    typename Model<dim>::Separation
    Model<dim>::separation(const unsigned int a, const unsigned int b, const std::vector<bool> &released_before) const
    {
      const MPI_Comm comm = network_communicator();
      // The fragments of the facet's cells (known where they are local).
      int pa = -1, pb = -1;
      for (unsigned int c = 0; c < cell_id.size(); ++c)
        {
          if (cell_id[c] == a)
            pa = fragment[c];
          if (cell_id[c] == b)
            pb = fragment[c];
        }
      pa = dealii::Utilities::MPI::max(pa, comm);
      pb = dealii::Utilities::MPI::max(pb, comm);
      // The cells in different fragments: the smaller one separated.
      Separation          s;
      std::vector<double> sums(2 * (dim + 1) + dim, 0.0); // piece: measure, moment; released: the same; load
      const unsigned int  piece = pa == pb ? n_fragments :
                                  fragment_size[pa] <= fragment_size[pb] ? pa : pb;
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          const double measure = cell_measure(c);
          if (fragment[c] == piece)
            {
              sums[0] += measure;
              for (unsigned int d = 0; d < dim; ++d)
                sums[1 + d] += measure * network.cells[c].centroid[d];
            }
          // Cells released by this break (a break can release the larger piece, or both).
          if (released[c] && !released_before[c])
            {
              ++s.released;
              sums[dim + 1] += measure;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  sums[dim + 2 + d] += measure * network.cells[c].centroid[d];
                  sums[2 * dim + 2 + d] += f_ext.local_element(n_dofs * c + d);
                }
            }
        }
      if (distributed())
        {
          dealii::Utilities::MPI::sum(sums, comm, sums);
          s.released = dealii::Utilities::MPI::sum(s.released, comm);
        }
      if (piece < n_fragments)
        {
          s.cells = fragment_size[piece];
          for (unsigned int d = 0; d < dim; ++d)
            s.centroid[d] = sums[1 + d] / sums[0];
        }
      if (s.released > 0)
        for (unsigned int d = 0; d < dim; ++d)
          {
            s.released_centroid[d] = sums[dim + 2 + d] / sums[dim + 1];
            s.load[d]              = sums[2 * dim + 2 + d];
          }
      return s;
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

// The network: the nuclei (every rank), their partition over the ranks, and each
// rank's own cells, ghost cells and facets with their mass properties.
//
// Every rank samples the same nuclei from the same seed: they are the one thing it
// holds for the whole network (2 or 3 doubles and a rank per cell). The nuclei are
// split into parts of equal size by recursive coordinate bisection (each cut across
// the longest side of the part's box), which needs no graph and gives compact parts.
// A rank builds the Voronoi cells of its own nuclei from them and the nuclei within
// a halo of width H around them. A cell's geometry depends only on the nuclei near
// it: the clipped cell V_i lies within its reach rho_i of the nucleus, and a nucleus q
// farther than 2 rho_i from it cannot cut it (for x in V_i, |x - q| >= |q - x_i| -
// |x - x_i| > rho_i >= |x - x_i|). So the cells are exact when 2 rho_i <= H for each;
// a saturated Poisson-disk set has rho <= d_max, and H starts at 2.5 d_max (and is
// doubled for a cell that needs more).
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/rbsn/model.h>

#include "rbsn/polyhedron.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>

namespace hysteron
{
  namespace RBSN
  {
    namespace
    {
      /// The same error on every rank of @p comm if @p f throws on any (the first
      /// rank's message): the ranks of a distributed set-up never diverge.
      template <typename Function>
      void
      collectively(const MPI_Comm comm, Function f)
      {
        std::string input_where, input_problem, runtime;
        try
          {
            f();
          }
        catch (const InputError &e)
          {
            input_where   = e.where();
            input_problem = e.problem();
          }
        catch (const RuntimeError &e)
          {
            runtime = e.what();
          }
        if (dealii::Utilities::MPI::n_mpi_processes(comm) == 1)
          {
            if (!input_problem.empty())
              throw InputError(input_where, input_problem);
            if (!runtime.empty())
              throw RuntimeError(runtime);
            return;
          }
        const auto wheres   = dealii::Utilities::MPI::all_gather(comm, input_where);
        const auto problems = dealii::Utilities::MPI::all_gather(comm, input_problem);
        const auto runtimes = dealii::Utilities::MPI::all_gather(comm, runtime);
        for (unsigned int r = 0; r < problems.size(); ++r)
          {
            if (!problems[r].empty())
              throw InputError(wheres[r], problems[r]);
            if (!runtimes[r].empty())
              throw RuntimeError(runtimes[r]);
          }
      }
    } // namespace



    template <int dim>
    std::vector<unsigned int>
    Model<dim>::partition_nuclei(const unsigned int n) const
    {
      // Parts [first, first + count) of the ranks for the cells in ids: a cut across the
      // longest side of their box, with as many cells on each side as parts (the lower
      // coordinate, then the lower number, first: deterministic).
      std::vector<unsigned int> result(nuclei.size(), 0);
      std::vector<unsigned int> ids(nuclei.size());
      std::iota(ids.begin(), ids.end(), 0u);
      struct Range
      {
        std::size_t  begin, end;
        unsigned int first, count;
      };
      std::vector<Range> todo{{0, ids.size(), 0, n}};
      while (!todo.empty())
        {
          const Range r = todo.back();
          todo.pop_back();
          if (r.count == 1)
            {
              for (std::size_t k = r.begin; k < r.end; ++k)
                result[ids[k]] = r.first;
              continue;
            }
          dealii::Point<dim> lo = nuclei[ids[r.begin]], hi = lo;
          for (std::size_t k = r.begin; k < r.end; ++k)
            for (unsigned int d = 0; d < dim; ++d)
              {
                lo[d] = std::min(lo[d], nuclei[ids[k]][d]);
                hi[d] = std::max(hi[d], nuclei[ids[k]][d]);
              }
          unsigned int axis = 0;
          for (unsigned int d = 1; d < dim; ++d)
            if (hi[d] - lo[d] > hi[axis] - lo[axis])
              axis = d;
          const unsigned int left_parts = r.count / 2;
          const std::size_t  middle =
            r.begin + static_cast<std::size_t>(std::llround(double(r.end - r.begin) * left_parts / r.count));
          std::nth_element(ids.begin() + r.begin, ids.begin() + middle, ids.begin() + r.end,
                           [&](const unsigned int a, const unsigned int b) {
                             return nuclei[a][axis] < nuclei[b][axis] ||
                                    (nuclei[a][axis] == nuclei[b][axis] && a < b);
                           });
          todo.push_back({r.begin, middle, r.first, left_parts});
          todo.push_back({middle, r.end, r.first + left_parts, r.count - left_parts});
        }
      return result;
    }



    template <int dim>
    void
    Model<dim>::build_network()
    {
      const auto &bodies = scene.body_descriptions();
      // d over the bodies: its smallest value (d_m for the messages and the default
      // resolution of curved boundaries) and the predicted number of points,
      // 0.68 int 1/d^2 dA (0.70 int 1/d^3 dV in 3D), which guards the memory and
      // announces a long set-up.
      spacing.sample(body_shapes);
      d_m = spacing.min;
      if (boundary_h == 0)
        boundary_h = 0.25 * d_m;
      std::ostringstream range;
      if (spacing.is_constant())
        range << "d_m = " << d_m;
      else
        range << "d = " << spacing.min << " ... " << spacing.max;
      const std::string distance = range.str();
      const std::string integral = dim == 2 ? "0.68 int 1/d^2 dA" : "0.70 int 1/d^3 dV";
      require(spacing.predicted_points <= 5e6,
              "RBSN/Minimum distance",
              "about " + std::to_string(static_cast<long>(spacing.predicted_points)) +
                " points predicted at this minimum distance (" + integral + " over the bodies; at most 5e6)");
      StageReport stage(scene.console(), spacing.predicted_points > (dim == 2 ? 5e4 : 1e4));
      if (stage.enabled())
        scene.console() << "rbsn: about " << StageReport::count(static_cast<std::size_t>(spacing.predicted_points))
                        << " cells predicted (" << integral << ", " << distance << " m)" << std::endl;

      // The nuclei: the user's points, points along every body's boundary, then
      // random points (one set for all bodies; each point belongs to the body
      // that contains it).
      std::vector<dealii::Point<dim>> fixed = extra_points;
      for (const auto &p : extra_points)
        {
          bool inside = false;
          for (const auto *shape : body_shapes)
            inside = inside || shape->contains(p, 1e-9 * d_m);
          std::ostringstream point;
          point << p;
          require(inside, "RBSN/Additional points", "the point (" + point.str() + ") lies in no deformable body");
        }
      if (points_on_boundary)
        for (unsigned int s = 0; s < body_shapes.size(); ++s)
          {
            std::vector<dealii::Point<dim>> p;
            if constexpr (dim == 2)
              p = boundary_points(*body_shapes[s], spacing, boundary_h);
            else
              p = boundary_points(*body_shapes[s], spacing, boundary_h, scene.random_seed() + 104729 * s);
            fixed.insert(fixed.end(), p.begin(), p.end());
          }
      // Merge points closer than 1e-6 d_m (corners shared by touching bodies), the
      // first kept: each point is compared with the kept ones in its and the
      // neighbouring cells of a hash grid of that size.
      std::vector<dealii::Point<dim>> points;
      {
        const double tolerance = 1e-6 * d_m;
        using Key              = std::array<long long, dim>;
        std::map<Key, std::vector<unsigned int>> kept;
        const auto key = [&](const dealii::Point<dim> &p, const std::array<int, dim> &shift) {
          Key k;
          for (unsigned int d = 0; d < dim; ++d)
            k[d] = static_cast<long long>(std::floor(p[d] / tolerance)) + shift[d];
          return k;
        };
        for (const auto &p : fixed)
          {
            bool seen = false;
            // The 3^dim neighbouring keys, the last coordinate slowest.
            for (unsigned int m = 0; m < (dim == 2 ? 9u : 27u) && !seen; ++m)
              {
                std::array<int, dim> shift;
                unsigned int         r = m;
                for (unsigned int d = 0; d < dim; ++d, r /= 3)
                  shift[d] = static_cast<int>(r % 3) - 1;
                if (const auto k = kept.find(key(p, shift)); k != kept.end())
                  for (const unsigned int q : k->second)
                    seen = seen || p.distance(points[q]) < tolerance;
              }
            if (!seen)
              {
                kept[key(p, std::array<int, dim>{})].push_back(points.size());
                points.push_back(p);
              }
          }
      }
      for (unsigned int s = 0; s < body_shapes.size(); ++s)
        {
          // Each body is filled in turn, keeping the distance from every point so far.
          std::vector<dealii::Point<dim>> filled;
          if constexpr (dim == 2)
            filled = poisson_disk_points(*body_shapes[s], spacing, points, scene.random_seed() + 7919 * s,
                                         "RBSN/Minimum distance");
          else
            filled = poisson_disk_points(*body_shapes[s], spacing, points, scene.random_seed() + 7919 * s,
                                         "RBSN/Minimum distance", boundary_h);
          points.swap(filled);
        }
      require(points.size() >= 2,
              "RBSN/Minimum distance",
              "leaves room for " + std::to_string(points.size()) +
                " nucleus in the bodies, and a network needs at least two cells: the minimum "
                "distance must be well below the size of the bodies (got " + distance + " m)");
      stage(StageReport::count(points.size()) + " nuclei");
      nuclei.swap(points);
      nuclei_box.assign(2, nuclei[0]);
      for (const auto &p : nuclei)
        for (unsigned int d = 0; d < dim; ++d)
          {
            nuclei_box[0][d] = std::min(nuclei_box[0][d], p[d]);
            nuclei_box[1][d] = std::max(nuclei_box[1][d], p[d]);
          }

      // The parts: one per rank, or one for all (every rank runs the whole network) with
      // the variable-order analysis (one SUNDIALS vector) or fewer cells than ranks.
      const MPI_Comm     comm    = scene.mpi_communicator();
      const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      n_parts                    = analysis == Analysis::variable_order || nuclei.size() < 2 * n_ranks ? 1 : n_ranks;
      part                       = n_parts == 1 ? 0 : dealii::Utilities::MPI::this_mpi_process(comm);
      cell_part                  = n_parts == 1 ? std::vector<unsigned int>(nuclei.size(), 0) : partition_nuclei(n_parts);
      std::vector<unsigned int> owned;
      for (unsigned int c = 0; c < nuclei.size(); ++c)
        if (cell_part[c] == part)
          owned.push_back(c);
      collectively(n_parts > 1 ? comm : MPI_COMM_SELF, [&]() { build_local_tessellation(owned); });
      stage("Voronoi cells");

      // The bodies of the local cells, and the rigid-body mass properties of the owned
      // ones about their nuclei (eq. 3.12; in 3D the inertia tensor).
      const unsigned int n_local = cell_id.size();
      cell_body.assign(n_local, 0);
      const auto lo = bodies[mesh_body[0]].shape.bounding_box().get_boundary_points();
      scale         = lo.first.distance(lo.second);
      // In 3D the bodies as the polyhedra the cells are clipped to: a nucleus on the
      // polyhedral surface of a subtracted sphere or cylinder lies inside the exact one.
      std::vector<std::unique_ptr<Polyhedral::Domain>> polyhedra;
      if constexpr (dim == 3)
        for (const auto *shape : body_shapes)
          polyhedra.push_back(std::make_unique<Polyhedral::Domain>(
            std::vector<const Geometry::Region<3> *>{shape}, boundary_h, "Body names"));
      const auto in_body = [&](const unsigned int s, const dealii::Point<dim> &p) {
        if constexpr (dim == 3)
          return polyhedra[s]->contains(p, 1e-9 * scale);
        else
          return body_shapes[s]->contains(p, 1e-9 * scale);
      };
      for (unsigned int c = 0; c < n_local; ++c)
        for (unsigned int s = 0; s < body_shapes.size(); ++s)
          if (in_body(s, nuclei[cell_id[c]]))
            {
              cell_body[c] = mesh_body[s];
              break;
            }
      cell_mass.assign(n_owned_cells, 0);
      cell_offset.assign(n_owned_cells, dealii::Tensor<1, dim>());
      cell_inertia.assign(n_owned_cells, dealii::SymmetricTensor<2, dim>());
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        {
          const auto  &cell = network.cells[c];
          const auto  &body = bodies[cell_body[c]];
          const double rho  = scene.material(body.material, "Body " + body.name + "/Material").density();
          cell_offset[c]    = cell.centroid - cell.nucleus;
          if constexpr (dim == 2)
            {
              // A varying thickness is taken at the cell's centroid (midpoint rule over the cell).
              const double t = body.thickness_at(cell.centroid);
              const double m = rho * t * cell.area;
              cell_mass[c]   = m;
              // I_c + m r^2: the polar moment about the nucleus.
              cell_inertia[c][0][0] = rho * t * cell.polar_moment + m * cell_offset[c].norm_square();
            }
          else
            {
              // J = rho (tr(S) I - S) with S = S_c + V o o^T the second moment about the nucleus.
              cell_mass[c] = rho * cell.volume;
              const dealii::SymmetricTensor<2, 3> S =
                cell.second_moment + cell.volume * dealii::symmetrize(dealii::outer_product(cell_offset[c], cell_offset[c]));
              cell_inertia[c] = rho * (dealii::trace(S) * dealii::unit_symmetric_tensor<3>() - S);
            }
        }
    }



    template <int dim>
    void
    Model<dim>::build_local_tessellation(const std::vector<unsigned int> &owned)
    {
      const unsigned int n_cells = nuclei.size();
      n_owned_cells              = owned.size();
      if (n_parts == 1)
        {
          // The whole network on this rank, in the numbering of the nuclei.
          network = voronoi(nuclei, body_shapes, boundary_h, "Body names");
          cell_id.resize(n_cells);
          std::iota(cell_id.begin(), cell_id.end(), 0u);
          cell_block.resize(n_cells);
          std::iota(cell_block.begin(), cell_block.end(), dof_index(0));
          facet_id.resize(network.facets.size());
          std::iota(facet_id.begin(), facet_id.end(), 0ul);
          n_global_facets = network.facets.size();
          return;
        }

      // The nuclei within H of an owned one (a hash grid of cells H), the owned ones
      // flagged; their cells are exact if 2 reach <= H (see the top of the file).
      double             H        = 2.5 * spacing.max;
      Tessellation<dim>  local;
      std::vector<unsigned int> local_ids;
      for (unsigned int attempt = 0;; ++attempt)
        {
          std::map<std::array<long long, dim>, std::vector<unsigned int>> grid;
          const auto key = [&](const dealii::Point<dim> &p) {
            std::array<long long, dim> k;
            for (unsigned int d = 0; d < dim; ++d)
              k[d] = static_cast<long long>(std::floor(p[d] / H));
            return k;
          };
          for (unsigned int c = 0; c < n_cells; ++c)
            grid[key(nuclei[c])].push_back(c);
          std::vector<bool> in_set(n_cells, false);
          for (const unsigned int c : owned)
            {
              const auto k = key(nuclei[c]);
              for (unsigned int m = 0; m < (dim == 2 ? 9u : 27u); ++m)
                {
                  auto         q = k;
                  unsigned int r = m;
                  for (unsigned int d = 0; d < dim; ++d, r /= 3)
                    q[d] += static_cast<int>(r % 3) - 1;
                  if (const auto g = grid.find(q); g != grid.end())
                    for (const unsigned int p : g->second)
                      if (!in_set[p] && nuclei[p].distance(nuclei[c]) <= H)
                        in_set[p] = true;
                }
            }
          local_ids.clear();
          std::vector<dealii::Point<dim>> points;
          std::vector<bool>               wanted;
          for (unsigned int c = 0; c < n_cells; ++c)
            if (in_set[c] || cell_part[c] == part)
              {
                local_ids.push_back(c);
                points.push_back(nuclei[c]);
                wanted.push_back(cell_part[c] == part);
              }
          if (points.size() >= 2)
            {
              local = voronoi(points, body_shapes, boundary_h, "Body names", wanted);
              bool wide_enough = true;
              for (unsigned int i = 0; i < points.size(); ++i)
                if (wanted[i] && 2 * local.cells[i].reach > H * (1 - 1e-12))
                  wide_enough = false;
              if (wide_enough)
                break;
            }
          if (attempt > 20)
            throw RuntimeError("rbsn: the halo of a rank's cells does not reach the nuclei that "
                               "shape them (a cell wider than " + std::to_string(H) + " m)");
          H *= 2;
        }

      // The DoF blocks: each rank's cells in the order of their numbers, rank by rank.
      std::vector<dof_index> block(n_cells);
      {
        std::vector<dof_index> first(n_parts + 1, 0);
        for (const unsigned int p : cell_part)
          ++first[p + 1];
        std::partial_sum(first.begin(), first.end(), first.begin());
        for (unsigned int c = 0; c < n_cells; ++c)
          block[c] = first[cell_part[c]]++;
      }
      // The owned cells, then the ghost cells (the other cells of the owned facets) in
      // the order of their blocks.
      std::vector<int> local_of(n_cells, -1);
      cell_id = owned;
      for (unsigned int c = 0; c < owned.size(); ++c)
        local_of[owned[c]] = c;
      std::vector<unsigned int> ghosts;
      for (const auto &f : local.facets)
        if (const unsigned int b = local_ids[f.b]; cell_part[b] != part && local_of[b] == -1)
          {
            local_of[b] = -2;
            ghosts.push_back(b);
          }
      std::sort(ghosts.begin(), ghosts.end(), [&](const unsigned int a, const unsigned int b) { return block[a] < block[b]; });
      for (const unsigned int g : ghosts)
        {
          local_of[g] = cell_id.size();
          cell_id.push_back(g);
        }
      cell_block.resize(cell_id.size());
      for (unsigned int c = 0; c < cell_id.size(); ++c)
        cell_block[c] = block[cell_id[c]];

      // The owned cells' geometry and the facets in local numbers.
      network.cells.clear();
      network.facets.clear();
      std::vector<unsigned long> n_up(n_cells, 0); // facets per first cell (owned cells only)
      for (unsigned int i = 0; i < local_ids.size(); ++i)
        if (cell_part[local_ids[i]] == part)
          network.cells.push_back(std::move(local.cells[i]));
      for (auto &f : local.facets)
        {
          ++n_up[local_ids[f.a]];
          f.a = local_of[local_ids[f.a]];
          f.b = local_of[local_ids[f.b]];
          network.facets.push_back(std::move(f));
        }
      // The global numbers of the facets: in the order of (a, b) over the whole network,
      // as one rank numbers them.
      const MPI_Comm comm = scene.mpi_communicator();
      const int      ierr = MPI_Allreduce(MPI_IN_PLACE, n_up.data(), n_cells, MPI_UNSIGNED_LONG, MPI_SUM, comm);
      AssertThrowMPI(ierr);
      std::vector<unsigned long> first_facet(n_cells + 1, 0);
      std::partial_sum(n_up.begin(), n_up.end(), first_facet.begin() + 1);
      n_global_facets = first_facet.back();
      facet_id.resize(network.facets.size());
      for (unsigned int e = 0; e < network.facets.size(); ++e)
        facet_id[e] = first_facet[cell_id[network.facets[e].a]]++;
    }



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

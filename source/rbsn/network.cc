// The network: the nuclei (sampled block by block, blocks.cc), their split over the
// ranks, and each rank's own cells, ghost cells and facets with their mass properties.
//
// A network predicted to be small (at most 20,000 points in 2D, 10,000 in 3D, unless
// `Sampling block size` is given) is one block: every rank samples all its nuclei, as
// a single rank does. A larger one is tiled into blocks that the ranks sample in
// parallel; a rank holds the nuclei of its blocks and of those around its cells only.
// The cells are numbered block by block (a network of one block in the order of its
// nuclei), so the numbers are the same on any number of ranks; each rank owns a
// consecutive share of them along the blocks' Hilbert order, a block two ranks share
// being split by coordinate bisection.
//
// A rank builds the Voronoi cells of its own nuclei from them and the nuclei within a
// halo of width H around them. A cell's geometry depends only on the nuclei near it:
// the clipped cell V_i lies within its reach rho_i of the nucleus, and a nucleus q
// farther than 2 rho_i from it cannot cut it (for x in V_i, |x - q| >= |q - x_i| -
// |x - x_i| > rho_i >= |x - x_i|). So the cells are exact when 2 rho_i <= H for each;
// a saturated Poisson-disk set has rho <= d_max, and H starts at 2.5 d_max (and is
// doubled for a cell that needs more, the nuclei of the blocks farther out fetched).
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/memory.h>
#include "rbsn/model.h"

#include "rbsn/blocks.h"
#include "rbsn/collective.h"
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
    template <int dim>
    std::vector<dealii::Point<dim>>
    Model<dim>::fixed_points() const
    {
      // The user's points, then points along every body's boundary; points closer than
      // 1e-6 d_m (corners shared by touching bodies) merged, the first kept: each point
      // is compared with the kept ones in its and the neighbouring cells of a hash grid
      // of that size.
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
              p = boundary_points(*body_shapes[s], spacing, boundary_h, scene().random_seed() + 104729 * s);
            fixed.insert(fixed.end(), p.begin(), p.end());
          }
      std::vector<dealii::Point<dim>> points;
      const double                    tolerance = 1e-6 * d_m;
      using Key                                 = std::array<long long, dim>;
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
      return points;
    }



    template <int dim>
    double
    Model<dim>::sampling_block_side() const
    {
      // A network predicted above the threshold is tiled into blocks of about 4,096
      // points (2,048 in 3D), at least 4 d_max wide; one below it is one block.
      if (block_size > 0)
        {
          std::ostringstream s;
          s << "must be at least 2 d_max = " << 2 * spacing.max
            << " m (the margin of known points around a block; got " << block_size << " m)";
          require(block_size >= 2 * spacing.max, "RBSN/Sampling block size", s.str());
          return block_size;
        }
      if (spacing.predicted_points <= single_block_points)
        return 0;
      const double per_block = dim == 2 ? 4096 : 2048;
      return std::max(4 * spacing.max, std::pow(per_block * spacing.measure / spacing.predicted_points, 1.0 / dim));
    }



    template <int dim>
    void
    Model<dim>::build_network()
    {
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
      {
        // The memory before the sampling: every rank its share of the cells with their
        // facets (about 3 per cell in 2D, 7 in 3D), the tangent and an iterative solver
        // (ML); the whole network on each rank with variable order. A direct factorization
        // adds its fill where it is made (on one rank but for Mumps): 6.5 kB per cell in 2D,
        // 6 kB n^(1/3) per cell in 3D (nested dissection: n^(4/3)). The constants are
        // slopes of the peak RSS, rounded up: 6.1 kB per cell in 2D (2.7e4 ... 5.6e4 cells),
        // 46 kB in 3D (7.7e3 ... 1.6e4 cells), linear static, CG + ML, measured by
        //   benchmarks/memory_estimate.py --hysteron build/hysteron --only rbsn
        // (each run /usr/bin/time -v hysteron scene().prm); the fill from the UMFPACK and CG
        // runs of doc/benchmarks.md (2D 13.9 against 7.4 kB per cell at 1e5 cells; 3D 203 kB
        // per cell at 2.1e4 cells, 117 kB at 3.8e3: 6 kB n^(1/3) over CG's 48 kB).
        constexpr double   bytes_per_cell[2] = {6.5e3, 48e3};
        const MPI_Comm     comm              = scene().mpi_communicator();
        const unsigned int n_ranks           = dealii::Utilities::MPI::n_mpi_processes(comm);
        const double       n                 = spacing.predicted_points;
        const bool         whole             = analysis == Analysis::variable_order || n_ranks == 1;
        double             bytes = (whole ? n : Memory::largest_share(n, n_ranks, dim)) * bytes_per_cell[dim - 2];
        if (analysis != Analysis::variable_order && linear_solver == "direct")
          {
            const double fill = n * (dim == 2 ? 6.5e3 : 6e3 * std::cbrt(n));
            if (whole || distributed_solver != "Amesos_Mumps")
              bytes += dealii::Utilities::MPI::this_mpi_process(comm) == 0 ? fill : 0.0;
            else
              bytes += fill / n_ranks;
          }
        std::ostringstream what;
        what.precision(3);
        what << "about " << Memory::count(n) << " cells predicted at this minimum distance (" << integral
             << " over the bodies), " << bytes_per_cell[dim - 2] << " B each with their facets"
             << (linear_solver == "direct" && analysis != Analysis::variable_order ?
                   " and the direct solver's fill" :
                   "");
        Memory::require_fits(comm, bytes, "RBSN/Minimum distance", what.str(),
                             "use a larger RBSN/Minimum distance, smaller bodies" +
                               std::string(linear_solver == "direct" ? ", RBSN/Linear solver = cg or gmres" : "") +
                               " or more machines");
      }
      StageReport stage(scene().console(), spacing.predicted_points > (dim == 2 ? 5e4 : 1e4));
      if (stage.enabled())
        scene().console() << "rbsn: about " << StageReport::count(static_cast<std::size_t>(spacing.predicted_points))
                        << " cells predicted (" << integral << ", " << distance << " m)" << std::endl;

      // The nuclei: the user's points, points along every body's boundary, then random
      // points (one set for all bodies; each point belongs to the body that contains
      // it), in one block or block by block.
      const std::vector<dealii::Point<dim>> fixed = fixed_points();
      std::vector<std::pair<dealii::Point<dim>, dealii::Point<dim>>> boxes;
      dealii::Point<dim>                                             lo, hi;
      for (unsigned int s = 0; s < body_shapes.size(); ++s)
        {
          boxes.push_back(body_shapes[s]->bounding_box().get_boundary_points());
          for (unsigned int d = 0; d < dim; ++d)
            {
              lo[d] = s == 0 ? boxes[s].first[d] : std::min(lo[d], boxes[s].first[d]);
              hi[d] = s == 0 ? boxes[s].second[d] : std::max(hi[d], boxes[s].second[d]);
            }
        }
      const MPI_Comm                comm    = scene().mpi_communicator();
      const unsigned int            n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
      const Blocks::Layout<dim>     layout(lo, hi, sampling_block_side(), boxes);
      Blocks::Nuclei<dim>           nuclei(layout, comm);
      if (layout.single())
        nuclei.hold_all(sample_one_block(fixed));
      else
        sample_blocks(fixed, layout, nuclei);
      n_cells  = nuclei.size();
      n_blocks = layout.single() ? 1 : layout.size();
      require(n_cells >= 2,
              "RBSN/Minimum distance",
              "leaves room for " + std::to_string(n_cells) +
                " nucleus in the bodies, and a network needs at least two cells: the minimum "
                "distance must be well below the size of the bodies (got " + distance + " m)");
      std::ostringstream blocks;
      if (!layout.single())
        blocks << " in " << layout.size() << " blocks of " << layout.side << " m";
      stage(StageReport::count(n_cells) + " nuclei" + blocks.str());

      // The parts: one per rank, or one for all (every rank runs the whole network) with
      // the variable-order analysis (one SUNDIALS vector) or fewer cells than ranks.
      n_parts = analysis == Analysis::variable_order || n_cells < 2 * n_ranks ? 1 : n_ranks;
      part    = n_parts == 1 ? 0 : dealii::Utilities::MPI::this_mpi_process(comm);
      require(n_parts == n_ranks || layout.single() || n_ranks == 1,
              "RBSN/Sampling block size",
              "a network of several sampling blocks needs at least two cells per MPI rank (" +
                std::to_string(n_cells) + " cells on " + std::to_string(n_ranks) + " ranks)");
      if (n_parts == 1)
        Collective::collectively(MPI_COMM_SELF, [&]() { build_whole_tessellation(nuclei.all()); });
      else
        build_local_tessellation(nuclei);
      stage("Voronoi cells");
      setup_cells();
    }



    template <int dim>
    std::vector<dealii::Point<dim>>
    Model<dim>::sample_one_block(const std::vector<dealii::Point<dim>> &fixed) const
    {
      // Each body is filled in turn, keeping the distance from every point so far.
      std::vector<dealii::Point<dim>> points = fixed;
      for (unsigned int s = 0; s < body_shapes.size(); ++s)
        {
          std::vector<dealii::Point<dim>> filled;
          if constexpr (dim == 2)
            filled = poisson_disk_points(*body_shapes[s], spacing, points, scene().random_seed() + 7919 * s,
                                         "RBSN/Minimum distance");
          else
            filled = poisson_disk_points(*body_shapes[s], spacing, points, scene().random_seed() + 7919 * s,
                                         "RBSN/Minimum distance", boundary_h);
          points.swap(filled);
        }
      return points;
    }



    template <int dim>
    void
    Model<dim>::sample_blocks(const std::vector<dealii::Point<dim>> &fixed,
                              const Blocks::Layout<dim>             &layout,
                              Blocks::Nuclei<dim>                   &nuclei) const
    {
      const MPI_Comm comm = scene().mpi_communicator();
      require(analysis != Analysis::variable_order || dealii::Utilities::MPI::n_mpi_processes(comm) == 1,
              "RBSN/Analysis",
              "the variable-order analysis integrates the whole network as one SUNDIALS vector on "
              "every rank, so every rank would sample and hold all of its nuclei; on several MPI "
              "ranks it takes networks of one sampling block only (at most " +
                std::to_string(static_cast<long>(single_block_points)) +
                " points predicted, and no Sampling block size), and this one has about " +
                std::to_string(static_cast<long>(spacing.predicted_points)) + " in " +
                std::to_string(layout.size()) + " blocks: run it on one rank");
      typename Blocks::Nuclei<dim>::Sources                      sources;
      std::vector<std::unique_ptr<Sampling::BodySampler<dim>>> samplers;
      Collective::collectively(comm, [&]() {
        for (const auto *shape : body_shapes)
          samplers.push_back(
            std::make_unique<Sampling::BodySampler<dim>>(*shape, spacing, fixed, boundary_h, "RBSN/Minimum distance"));
      });
      sources.fixed = &fixed;
      for (unsigned int s = 0; s < body_shapes.size(); ++s)
        {
          sources.bodies.push_back(samplers[s].get());
          sources.body_boxes.push_back(body_shapes[s]->bounding_box().get_boundary_points());
        }
      sources.seed   = scene().random_seed();
      sources.margin = 2 * spacing.max;
      const std::vector<double> predicted = spacing.predicted_in_blocks(layout.origin, layout.side, layout.n);
      for (unsigned int b = 0; b < layout.size(); ++b)
        sources.predicted.push_back(predicted[layout.linear(b)]);
      nuclei.sample(sources);
    }



    template <int dim>
    void
    Model<dim>::build_whole_tessellation(const std::vector<dealii::Point<dim>> &all)
    {
      // The whole network on this rank, in the numbering of the nuclei.
      network = voronoi(all, body_shapes, boundary_h, "Body names");
      n_owned_cells = all.size();
      local_nuclei  = all;
      cell_id.resize(all.size());
      std::iota(cell_id.begin(), cell_id.end(), 0u);
      cell_block.resize(all.size());
      std::iota(cell_block.begin(), cell_block.end(), dof_index(0));
      facet_id.resize(network.facets.size());
      std::iota(facet_id.begin(), facet_id.end(), 0ul);
      n_global_facets = network.facets.size();
      number_owned_facets();
    }



    template <int dim>
    void
    Model<dim>::build_local_tessellation(Blocks::Nuclei<dim> &nuclei)
    {
      // The nuclei within H of an owned one, the owned ones flagged; their cells are
      // exact if 2 reach <= H (see the top of the file). A rank whose halo is too narrow
      // doubles it; the others wait for it in the fetches.
      const MPI_Comm comm = scene().mpi_communicator();
      nuclei.partition(n_parts);
      double                     H    = 2.5 * spacing.max;
      bool                       done = false;
      Tessellation<dim>               local;
      std::vector<std::uint64_t>      ids;
      std::vector<dealii::Point<dim>> points;
      std::vector<bool>               own;
      for (unsigned int attempt = 0;; ++attempt)
        {
          nuclei.fetch(H);
          Collective::collectively(comm, [&]() {
            if (done)
              return;
            nuclei.near_own(H, ids, points, own);
            if (points.size() < 2)
              return;
            local = voronoi(points, body_shapes, boundary_h, "Body names", own);
            done  = true;
            for (unsigned int i = 0; i < points.size(); ++i)
              if (own[i] && 2 * local.cells[i].reach > H * (1 - 1e-12))
                done = false;
          });
          if (dealii::Utilities::MPI::min(done ? 1 : 0, comm) == 1)
            break;
          if (attempt > 20)
            throw RuntimeError("rbsn: the halo of a rank's cells does not reach the nuclei that "
                               "shape them (a cell wider than " + std::to_string(H) + " m)");
          if (!done)
            H *= 2;
        }

      // The owned cells (ascending numbers), then the ghost cells (the other cells of
      // the owned facets) in the order of their DoFs.
      std::vector<int> local_of(ids.size(), -1);
      cell_id.clear();
      cell_block.clear();
      local_nuclei.clear();
      network.cells.clear();
      network.facets.clear();
      for (unsigned int i = 0; i < ids.size(); ++i)
        if (own[i])
          {
            local_of[i] = cell_id.size();
            cell_id.push_back(ids[i]);
            cell_block.push_back(nuclei.owner(ids[i]).second);
            local_nuclei.push_back(points[i]);
            network.cells.push_back(std::move(local.cells[i]));
          }
      n_owned_cells = cell_id.size();
      std::vector<std::pair<dof_index, unsigned int>> ghosts; // DoF block, index in ids
      for (const auto &f : local.facets)
        if (!own[f.b] && local_of[f.b] == -1)
          {
            local_of[f.b] = -2;
            ghosts.emplace_back(nuclei.owner(ids[f.b]).second, f.b);
          }
      std::sort(ghosts.begin(), ghosts.end());
      for (const auto &[block, i] : ghosts)
        {
          local_of[i] = cell_id.size();
          cell_id.push_back(ids[i]);
          cell_block.push_back(block);
          local_nuclei.push_back(points[i]);
        }
      for (auto &f : local.facets)
        {
          f.a = local_of[f.a];
          f.b = local_of[f.b];
          network.facets.push_back(std::move(f));
        }
      number_owned_facets();

      // The global numbers of the facets: in the order of (a, b) over the whole network,
      // as one rank numbers them.
      std::vector<unsigned int> n_up(n_owned_cells);
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        n_up[c] = owned_facet_start[c + 1] - owned_facet_start[c];
      const std::vector<std::uint64_t> first = nuclei.first_facets(n_up);
      facet_id.resize(network.facets.size());
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        for (unsigned int e = owned_facet_start[c]; e < owned_facet_start[c + 1]; ++e)
          facet_id[e] = first[c] + (e - owned_facet_start[c]);
      n_global_facets = dealii::Utilities::MPI::sum<unsigned long>(network.facets.size(), comm);
    }



    template <int dim>
    void
    Model<dim>::number_owned_facets()
    {
      // The facets are sorted by (a, b): those of owned cell c are a range.
      owned_facet_start.assign(n_owned_cells + 1, 0);
      for (const auto &f : network.facets)
        ++owned_facet_start[f.a + 1];
      std::partial_sum(owned_facet_start.begin(), owned_facet_start.end(), owned_facet_start.begin());
    }



    template <int dim>
    void
    Model<dim>::setup_cells()
    {
      // The box of the nuclei (the faces that select cells), the bodies of the local
      // cells, and the rigid-body mass properties of the owned ones about their nuclei
      // (eq. 3.12; in 3D the inertia tensor).
      const auto &bodies = scene().body_descriptions();
      nuclei_box.assign(2, local_nuclei[0]);
      for (unsigned int c = 0; c < n_owned_cells; ++c)
        for (unsigned int d = 0; d < dim; ++d)
          {
            nuclei_box[0][d] = std::min(nuclei_box[0][d], local_nuclei[c][d]);
            nuclei_box[1][d] = std::max(nuclei_box[1][d], local_nuclei[c][d]);
          }
      if (distributed())
        for (unsigned int d = 0; d < dim; ++d)
          {
            nuclei_box[0][d] = dealii::Utilities::MPI::min(nuclei_box[0][d], network_communicator());
            nuclei_box[1][d] = dealii::Utilities::MPI::max(nuclei_box[1][d], network_communicator());
          }
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
          if (in_body(s, local_nuclei[c]))
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
          const double rho  = scene().material(body.material, "Body " + body.name + "/Material").density();
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



    template class Model<2>;
    template class Model<3>;
  } // namespace RBSN
} // namespace hysteron

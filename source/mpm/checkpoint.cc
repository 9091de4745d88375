// The MPM's part of a checkpoint, readable on any number of ranks:
//  - the grid's triangulation (p4est's files) with every block's material points
//    attached to it, each point as one record (PointRecord::serialize); p4est
//    gives each rank of the resumed run its blocks and their points;
//  - the global state (counters, loads, probes, tables, the moving grid), the same
//    on every rank, and each rank's partial sums (works, reactions).
// On as many ranks as the checkpoint's, every rank gets its own blocks back and its
// arrays in their order at the checkpoint (the order of a step's sums): the resumed
// run is bit for bit the uninterrupted one. On another number of ranks the blocks
// are first balanced again by their points, the arrays sorted afresh and the partial
// sums gathered on rank 0: the run agrees with the uninterrupted one to round-off.
#include "mpm/mpm.h"
#include "run/rank_parts.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <utility>

namespace hysteron
{
  namespace MPM
  {
    namespace
    {
      /// The format of what this file stores: raise it with every change of a description below.
      constexpr std::uint32_t format = 3;

      /**
       * One material point in a checkpoint. Its fields are listed once, in fields():
       * @p f(record's field, the point arrays' field) for each, which serialize(),
       * save() (arrays to record) and restore_points() (record to arrays) all use.
       */
      template <int dim>
      struct PointRecord
      {
        unsigned int                    position = 0; ///< in the rank's arrays
        unsigned int                    group    = 0; ///< index of the group template
        dealii::types::particle_index   id       = 0;
        unsigned int                    body = 0, load = 0, cell = 0;
        double                          mass = 0, volume0 = 0, thickness = 0, load_factor = 0, volume = 0;
        dealii::Point<dim>              x0, x;
        dealii::Tensor<1, dim>          v;
        dealii::SymmetricTensor<2, dim> stress, strain;
        dealii::Tensor<2, dim>          F;
        std::vector<double>             state; ///< the material's state variables

        /// @p f(field, array) for every field held in the point arrays (@p f gets the
        /// array as a function of the arrays: P -> the array).
        template <class Function>
        void
        fields(const Function &f)
        {
          f(id, [](auto &P) -> auto & { return P.id; });
          f(body, [](auto &P) -> auto & { return P.body; });
          f(load, [](auto &P) -> auto & { return P.load; });
          f(cell, [](auto &P) -> auto & { return P.cell; });
          f(mass, [](auto &P) -> auto & { return P.mass; });
          f(volume0, [](auto &P) -> auto & { return P.volume0; });
          f(thickness, [](auto &P) -> auto & { return P.thickness; });
          f(load_factor, [](auto &P) -> auto & { return P.load_factor; });
          f(volume, [](auto &P) -> auto & { return P.current.volume; });
          f(x0, [](auto &P) -> auto & { return P.x0; });
          f(x, [](auto &P) -> auto & { return P.current.x; });
          f(v, [](auto &P) -> auto & { return P.current.v; });
          f(stress, [](auto &P) -> auto & { return P.current.stress; });
          f(strain, [](auto &P) -> auto & { return P.current.strain; });
          f(F, [](auto &P) -> auto & { return P.current.F; });
        }

        template <class Archive>
        void
        serialize(Archive &ar)
        {
          ar &position &group;
          fields([&](auto &value, const auto &) { ar &value; });
          ar &state;
        }
      };

      /// The records of one block's bytes.
      template <int dim>
      std::vector<PointRecord<dim>>
      read_records(const std::vector<char> &bytes)
      {
        std::istringstream            in(std::string(bytes.begin(), bytes.end()));
        CheckpointReader              reader(in, "a block of the MPM grid's checkpoint");
        std::vector<PointRecord<dim>> records;
        reader & records;
        return records;
      }
    } // namespace



    template <int dim>
    template <class Archive>
    void
    Solver<dim>::serialize_global(Archive &ar)
    {
      ar.section("mpm", format);
      ar &n_global_particles &load_count &load_volume &initial_kinetic_energy &n_rebuilds;
      std::uint64_t n_probes = probes.size();
      ar &n_probes;
      if (n_probes != probes.size())
        throw InputError("--resume", "the checkpoint has another number of probe points");
      for (auto &probe : probes)
        ar &probe.id &probe.initial_position;
      tables.serialize(ar);
      if (grid_moves)
        {
          // Where the grid is (a checkpoint of a fixed grid has no such section).
          ar.section("mpm grid motion", format);
          Lattice<dim> moved = grid->lattice();
          ar &moved.origin &moved.h &grid_table_time;
          if constexpr (Archive::is_loading)
            {
              for (unsigned int d = 0; d < dim; ++d)
                if (!(moved.h[d] > 0) || !std::isfinite(moved.origin[d]))
                  throw InputError("--resume", "the moving grid's corner or cell sizes are not valid");
              grid->move(moved);
            }
        }
    }



    template <int dim>
    template <class Archive>
    void
    Solver<dim>::serialize_rank(Archive &ar)
    {
      ar.section("mpm rank", format);
      ar &internal_work &external_work &boundary_work &max_speed &reactions &n_changed_cells;
      if (damped())
        {
          // Only a damped run has this section (undamped checkpoints keep their format).
          ar.section("mpm damping", format);
          ar &damping_work;
        }
      if (!probe_acceleration.empty())
        {
          // With a ground motion: the probes' accelerations of the last step (partial sums).
          ar.section("mpm ground motion", format);
          ar &probe_acceleration;
        }
    }



    template <int dim>
    void
    Solver<dim>::save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const
    {
      auto &self = const_cast<Solver<dim> &>(*this); // serialize() only reads when saving
      self.serialize_global(global);
      self.serialize_rank(rank);

      // Every point into the record list of its block (all in this rank's blocks: a
      // point that left them was migrated at the end of its step).
      const auto &P       = particles;
      const auto &lattice = grid->lattice();
      std::map<std::array<unsigned int, dim>, std::vector<PointRecord<dim>>> blocks;
      for (unsigned int g = 0; g < P.groups.size(); ++g)
        {
          const auto  &group = P.groups[g];
          unsigned int key   = 0;
          for (unsigned int i = 0; i < group_templates.size(); ++i)
            if (group_templates[i].material == group.material &&
                (group.material != nullptr || group_templates[i].rigid_body == group.rigid_body))
              key = i;
          for (unsigned int s = group.begin; s < group.end; ++s)
            {
              PointRecord<dim> r;
              r.position = s;
              r.group    = key;
              r.fields([&](auto &value, const auto &array) { value = array(P)[s]; });
              const auto first = P.current.material_state.begin() + group.state_offset +
                                 std::size_t(s - group.begin) * group.n_state;
              r.state.assign(first, first + group.n_state);
              blocks[grid->block_of(lattice.cell_of(r.x))].push_back(std::move(r));
            }
        }
      grid->save(directory.file("grid"), [&](const std::array<unsigned int, dim> &block) {
        std::ostringstream bytes;
        CheckpointWriter   out(bytes);
        const auto         it = blocks.find(block);
        out & (it == blocks.end() ? std::vector<PointRecord<dim>>() : it->second);
        const std::string text = bytes.str();
        return std::vector<char>(text.begin(), text.end());
      });
    }



    template <int dim>
    void
    Solver<dim>::setup_from_checkpoint()
    {
      const CheckpointDirectory &directory = this->resume_from();
      grid = std::make_unique<BackgroundGrid<dim>>(this->get_scene().mpi_communicator());
      resumed_points.clear();
      const auto keep = [&](const std::array<unsigned int, dim>                              &block,
                            const boost::iterator_range<std::vector<char>::const_iterator> &data) {
        resumed_points[block].assign(data.begin(), data.end());
      };
      grid->load(lower, cell_size, n_cells, basis_name == "linear" ? 0 : 1, directory.file("grid"), directory.same_ranks(), keep);
      if (!directory.same_ranks() && grid->is_parallel())
        {
          // The blocks in equal numbers as loaded: balance their work again (as the
          // set-up does), the points moving with their blocks.
          std::map<std::array<unsigned int, dim>, std::vector<char>> moving;
          moving.swap(resumed_points);
          grid->repartition(
            [&](const std::array<unsigned int, dim> &block) {
              double cells = 1;
              for (unsigned int d = 0; d < dim; ++d)
                cells *= std::min((block[d] + 1) * grid->block_size(), n_cells[d]) - block[d] * grid->block_size();
              const auto   it     = moving.find(block);
              const double points = it == moving.end() ? 0.0 : read_records<dim>(it->second).size();
              return static_cast<unsigned int>(std::llround(100 * (points + cell_weight * cells)));
            },
            [&](const std::array<unsigned int, dim> &block) {
              const auto it = moving.find(block);
              return it == moving.end() ? std::vector<char>() : it->second;
            },
            keep);
        }
      grid->setup_nodes(1 + 2 * dim);
      node_stamp.reset(grid->n_local_nodes(), grid->sparse_box());
      rigid_node_body.reset(grid->n_local_nodes(), grid->sparse_box());
      grid->track_reached_nodes(node_stamp.data(), &stamp);
      active_nodes.clear();
      rigid_nodes.clear();
      setup_groups();
      // The masses (the smallest sets the nodes' mass threshold at set-up).
      particles.mass.clear();
      unsigned long n = 0;
      for (const auto &[block, bytes] : resumed_points)
        for (const auto &r : read_records<dim>(bytes))
          {
            particles.mass.push_back(r.mass);
            ++n;
          }
      n_global_particles = dealii::Utilities::MPI::sum(n, this->get_scene().mpi_communicator());
    }



    template <int dim>
    void
    Solver<dim>::restore_points(const bool same_order)
    {
      using namespace dealii;
      using PI = PropertiesIndex<dim>;
      std::vector<PointRecord<dim>> records;
      for (const auto &[block, bytes] : resumed_points)
        for (auto &r : read_records<dim>(bytes))
          {
            if (r.group >= group_templates.size() ||
                r.state.size() != group_templates[r.group].n_state)
              throw InputError("--resume", "a material point of the checkpoint has no material of this scene");
            records.push_back(std::move(r));
          }
      resumed_points.clear();
      const std::size_t n = records.size();
      // The arrays' order: as at the checkpoint, or as a fresh sort (group, cell, id).
      std::sort(records.begin(), records.end(), [&](const PointRecord<dim> &a, const PointRecord<dim> &b) {
        return same_order ? a.position < b.position :
                            std::tie(a.group, a.cell, a.id) < std::tie(b.group, b.cell, b.id);
      });
      if (same_order)
        for (std::size_t s = 0; s < n; ++s)
          if (records[s].position != s)
            throw InputError("--resume", "the checkpoint's material points of this rank are not complete");

      auto &P = particles;
      P.groups.clear();
      std::size_t n_state = 0;
      for (std::size_t s = 0; s < n; ++s)
        {
          if (P.groups.empty() || records[s].group != current_group_key)
            {
              auto group         = group_templates[records[s].group];
              group.begin        = s;
              group.end          = s;
              group.state_offset = n_state;
              P.groups.push_back(group);
              current_group_key = records[s].group;
            }
          ++P.groups.back().end;
          n_state += records[s].state.size();
        }
      for (auto *v : {&P.body, &P.load, &P.cell, &P.handler_index})
        v->resize(n);
      P.id.resize(n);
      for (auto *v : {&P.mass, &P.volume0, &P.thickness, &P.load_factor})
        v->resize(n);
      P.x0.resize(n);
      P.current.resize(n, n_state);
      P.next.resize(n, n_state);
      std::size_t offset = 0;
      for (std::size_t s = 0; s < n; ++s)
        {
          auto &r = records[s];
          r.fields([&](const auto &value, const auto &array) { array(P)[s] = value; });
          std::copy(r.state.begin(), r.state.end(), P.current.material_state.begin() + offset);
          offset += r.state.size();
        }

      // The ParticleHandler holds the same points (identity, owner, output): it is
      // filled from the arrays, and handler_index maps its order to theirs.
      handler->clear_particles();
      std::vector<double> properties(n_properties, 0.0);
      for (std::size_t s = 0; s < n; ++s)
        {
          if (!grid->owns_cell(grid->lattice().cell_of(P.current.x[s])))
            throw InputError("--resume", "material point " + std::to_string(P.id[s]) + " lies outside this rank's blocks");
          // The constant slots (to_handler() writes the others below).
          properties[PI::body]      = P.body[s];
          properties[PI::load]      = P.load[s];
          properties[PI::mass]      = P.mass[s];
          properties[PI::volume0]   = P.volume0[s];
          properties[PI::thickness] = P.thickness[s];
          insert_into_handler(P.current.x[s], P.id[s], make_array_view(std::as_const(properties)));
        }
      handler->update_cached_numbers();
      std::vector<std::pair<types::particle_index, unsigned int>> by_id(n);
      for (std::size_t s = 0; s < n; ++s)
        by_id[s] = {P.id[s], static_cast<unsigned int>(s)};
      std::sort(by_id.begin(), by_id.end());
      unsigned int k = 0;
      for (const auto &particle : *handler)
        {
          const auto it = std::lower_bound(by_id.begin(), by_id.end(), std::make_pair(particle.get_id(), 0u));
          P.handler_index[it->second] = k++;
        }
      to_handler();

      for (auto &probe : probes)
        probe.local = -1;
      for (std::size_t s = 0; s < n; ++s)
        for (auto &probe : probes)
          if (P.id[s] == probe.id)
            probe.local = s;
      left_subdomain = false;
      failed_point   = -1;
    }



    template <int dim>
    void
    Solver<dim>::load(CheckpointReader                &global,
                      std::vector<CheckpointReader>  &rank_parts,
                      const CheckpointDirectory       &directory)
    {
      // What the conditions did before the checkpoint is not stored: no idle warning.
      boundary_acted.assign(boundaries.size(), true);
      serialize_global(global);
      if (directory.same_ranks())
        serialize_rank(rank_parts[0]);
      else
        {
          Run::sum_rank_parts(rank_parts, this->get_scene().is_root(),
                              [this](CheckpointReader &part) { serialize_rank(part); },
                              internal_work, external_work, boundary_work, reactions, damping_work,
                              probe_acceleration);
          n_changed_cells = 0;
        }
      restore_points(directory.same_ranks());
      if (!directory.same_ranks())
        {
          // The speed that bounds the next step (eq. 4.47), from this rank's points.
          max_speed = 0;
          for (const auto &group : particles.groups)
            for (unsigned int s = group.begin; s < group.end; ++s)
              max_speed = std::max(max_speed, group.wave_speed + particles.current.v[s].norm());
        }
    }

    template void Solver<2>::save(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &) const;
    template void Solver<3>::save(CheckpointWriter &, CheckpointWriter &, const CheckpointDirectory &) const;
    template void Solver<2>::load(CheckpointReader &, std::vector<CheckpointReader> &, const CheckpointDirectory &);
    template void Solver<3>::load(CheckpointReader &, std::vector<CheckpointReader> &, const CheckpointDirectory &);
    template void Solver<2>::setup_from_checkpoint();
    template void Solver<3>::setup_from_checkpoint();
  } // namespace MPM
} // namespace hysteron

// Contact between bodies on the grid (`MPM/Contact`), after Bardenhagen, Brackbill and
// Sulsky (2000) with the common normal of Huang et al. (2011): every body keeps its own
// nodal mass, momentum, force and mass gradient in the grid's layer; where two or more
// bodies have mass at a node, their velocities are corrected so that they do not
// interpenetrate, may separate and slide with Coulomb friction. The derivation is in
// doc/mpm.md ("Contact between bodies").
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/base/parameters.h>
#include "mpm/mpm.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace hysteron
{
  namespace MPM
  {
    template <int dim>
    void
    Solver<dim>::parse_contact(dealii::ParameterHandler &prm)
    {
      const auto &bodies = this->get_scene().body_descriptions();
      Section     s(prm, {"MPM", "Contact"});
      contact            = s.get_bool("Enable");
      const double mu    = s.get_non_negative("Friction coefficient");
      const auto   pairs = s.get("Pair friction coefficients");
      const bool   given = pairs.find_first_not_of(" \t") != std::string::npos;
      if (!contact)
        {
          // Settings that would act on nothing.
          require(mu == 0 && !given,
                  s.where(mu != 0 ? "Friction coefficient" : "Pair friction coefficients"),
                  "is set but contact is off: set MPM/Contact/Enable = true");
          return;
        }
      require(bodies.size() >= 2,
              s.where("Enable"),
              "contact needs at least two bodies (Body names has " +
                std::to_string(bodies.size()) + ")");
      n_contact_blocks = bodies.size();
      friction.assign(bodies.size() * bodies.size(), mu);

      // "a, b: 0.3; c, d: 0"
      const auto find_body = [&](const std::string &name) {
        for (unsigned int b = 0; b < bodies.size(); ++b)
          if (bodies[b].name == name)
            return b;
        throw InputError(s.where("Pair friction coefficients"),
                         "'" + name + "' is not a body (Body names)");
      };
      std::vector<bool> set(friction.size(), false);
      std::istringstream items(pairs);
      std::string        item;
      while (std::getline(items, item, ';'))
        {
          if (item.find_first_not_of(" \t") == std::string::npos)
            continue;
          const auto colon = item.find(':');
          const auto comma = item.find(',');
          require(colon != std::string::npos && comma != std::string::npos && comma < colon,
                  s.where("Pair friction coefficients"),
                  "'" + item + "' is not of the form 'body, body: coefficient'");
          const auto trim = [](const std::string &t) {
            const auto first = t.find_first_not_of(" \t");
            const auto last  = t.find_last_not_of(" \t");
            return first == std::string::npos ? std::string() : t.substr(first, last - first + 1);
          };
          const unsigned int a = find_body(trim(item.substr(0, comma)));
          const unsigned int b = find_body(trim(item.substr(comma + 1, colon - comma - 1)));
          require(a != b,
                  s.where("Pair friction coefficients"),
                  "'" + item + "' names the same body twice");
          require(!set[a * bodies.size() + b],
                  s.where("Pair friction coefficients"),
                  "the pair in '" + item + "' is given twice");
          const std::string value = trim(item.substr(colon + 1));
          char             *end   = nullptr;
          const double      m     = std::strtod(value.c_str(), &end);
          require(!value.empty() && end != nullptr && *end == '\0' && std::isfinite(m) && m >= 0,
                  s.where("Pair friction coefficients"),
                  "the coefficient in '" + item + "' must be a number >= 0");
          friction[a * bodies.size() + b] = friction[b * bodies.size() + a] = m;
          set[a * bodies.size() + b] = set[b * bodies.size() + a] = true;
        }
    }



    template <int dim>
    void
    Solver<dim>::setup_contact()
    {
      grid->initialize_layer(n_contact_blocks, contact_block);
      mark_boundary_nodes();
      contact_velocity.assign(n_contact_blocks, dealii::Tensor<1, dim>());
      contact_rigid_velocity.assign(n_contact_blocks, dealii::Tensor<1, dim>());
    }



    namespace
    {
      /**
       * The layer of contact at one node: per body b, K = 1 + 4 dim values at q + b K:
       * the mass m_b, the velocity (or momentum) v_b, the force f_b, the mass gradient
       * g_b = sum_p m_p grad N_ip and the velocity projected from the points.
       */
      template <int dim>
      struct NodeLayer
      {
        static constexpr unsigned int K = 1 + 4 * dim;
        double *const                 q;
        const unsigned int            B;

        double *
        body(const unsigned int b) const
        {
          return q + b * K;
        }

        double
        mass(const unsigned int b) const
        {
          return q[b * K];
        }

        /// The mass gradient of body b, component d.
        double
        gradient(const unsigned int b, const unsigned int d) const
        {
          return q[b * K + 1 + 2 * dim + d];
        }
      };



      /// The contact search at a node: how many bodies have mass there, and the first
      /// rigid one among them (invalid_unsigned_int if none).
      template <int dim>
      std::pair<unsigned int, unsigned int>
      bodies_at_node(const NodeLayer<dim>                      &node,
                     const std::vector<BodyDescription<dim>> &bodies,
                     const double                              tiny)
      {
        unsigned int n_bodies = 0, rigid = dealii::numbers::invalid_unsigned_int;
        for (unsigned int b = 0; b < node.B; ++b)
          if (node.mass(b) > tiny)
            {
              ++n_bodies;
              if (bodies[b].rigid && rigid == dealii::numbers::invalid_unsigned_int)
                rigid = b;
            }
        return {n_bodies, rigid};
      }



      /// One body at the node: its field is the common one @p r (after the boundary
      /// conditions), value for value.
      template <int dim>
      void
      copy_common_field(const NodeLayer<dim>                      &node,
                        const double *const                       r,
                        const std::vector<BodyDescription<dim>> &bodies,
                        const bool                                record)
      {
        for (unsigned int b = 0; b < node.B; ++b)
          if (!bodies[b].rigid)
            {
              double *const q = node.body(b);
              for (unsigned int d = 0; d < dim; ++d)
                {
                  q[1 + d] = r[1 + d];
                  if (record)
                    q[1 + dim + d] = r[1 + dim + d];
                }
            }
      }



      /**
       * The outward normal of body b at a node, towards the other bodies (not
       * normalised), from the nodal mass gradients g_c (g_c points out of body c: N_i
       * falls away from node i). Against a rigid body its surface normal, n_b ~ -g_rigid
       * (the material's own gradient turns at its corners and would lift a sliding
       * body); between deformable bodies the average n_b ~ g_b - sum_{c != b} g_c, so that
       * for two bodies n_a = -n_b and the pair's momentum is kept exactly.
       */
      template <int dim>
      dealii::Tensor<1, dim>
      outward_normal(const NodeLayer<dim>         &node,
                     const unsigned int            b,
                     const unsigned int            rigid,
                     const dealii::Tensor<1, dim> &grad_total)
      {
        dealii::Tensor<1, dim> normal;
        if (rigid != dealii::numbers::invalid_unsigned_int)
          for (unsigned int d = 0; d < dim; ++d)
            normal[d] = -node.gradient(rigid, d);
        else
          for (unsigned int d = 0; d < dim; ++d)
            normal[d] = 2.0 * node.gradient(b, d) - grad_total[d];
        return normal;
      }



      /// The heaviest body at the node other than @p b (the partner of its friction).
      template <int dim>
      unsigned int
      heaviest_other(const NodeLayer<dim> &node, const unsigned int b)
      {
        unsigned int other    = dealii::numbers::invalid_unsigned_int;
        double       heaviest = 0;
        for (unsigned int c = 0; c < node.B; ++c)
          if (c != b && node.mass(c) > heaviest)
            {
              heaviest = node.mass(c);
              other    = c;
            }
        return other;
      }



      /**
       * The contact impulse per unit mass of an approaching body (@p approach =
       * relative . normal > 0, @p normal a unit vector): no interpenetration removes the
       * approaching normal velocity; Coulomb reduces the tangential slip by at most
       * mu times that normal change (stick when it suffices).
       */
      template <int dim>
      dealii::Tensor<1, dim>
      contact_correction(const dealii::Tensor<1, dim> &relative,
                         const dealii::Tensor<1, dim> &normal,
                         const double                  approach,
                         const double                  mu)
      {
        const dealii::Tensor<1, dim> slip       = relative - approach * normal;
        const double                 slip_v     = slip.norm();
        dealii::Tensor<1, dim>       correction = approach * normal;
        if (slip_v > 0)
          correction += std::min(mu * approach, slip_v) / slip_v * slip;
        return correction;
      }
      /// What the deformable bodies at a node add up to: their mass and the momentum of
      /// their trial velocities; and the mass gradient of all bodies.
      template <int dim>
      struct NodeTotals
      {
        double                 mass = 0;
        dealii::Tensor<1, dim> momentum, grad;
      };



      /**
       * The trial velocity v_b of each deformable body at a node with two or more bodies:
       * p_b / m_b (or the velocity the layer holds, if not @p holds_momenta), plus
       * dt f_b / m_b after the momentum balance (@p record; with @p damping's nodal
       * terms on the body's own force and velocity). At the first conversion of
       * the layer the velocity projected from the points is kept, for the FLIP increment
       * Delta v_b = v_b' - p_b / m_b (a correction at the step's start, USF, belongs to
       * it too).
       */
      template <int dim>
      NodeTotals<dim>
      trial_velocities(const NodeLayer<dim>                      &node,
                       const std::vector<BodyDescription<dim>> &bodies,
                       const double                              tiny,
                       const bool                                holds_momenta,
                       const bool                                first_conversion,
                       const double                              dt,
                       const bool                                record,
                       const NodalDamping                       &damping,
                       std::vector<dealii::Tensor<1, dim>>      &v)
      {
        NodeTotals<dim> total;
        for (unsigned int b = 0; b < node.B; ++b)
          {
            double *const q = node.body(b);
            for (unsigned int d = 0; d < dim; ++d)
              total.grad[d] += q[1 + 2 * dim + d];
            if (bodies[b].rigid)
              continue;
            if (!(q[0] > tiny))
              {
                for (unsigned int d = 0; d < dim; ++d)
                  q[1 + d] = q[1 + dim + d] = 0;
                continue;
              }
            const double inv_m = 1.0 / q[0];
            for (unsigned int d = 0; d < dim; ++d)
              {
                const double v0 = holds_momenta ? q[1 + d] * inv_m : q[1 + d];
                if (first_conversion)
                  q[1 + 3 * dim + d] = v0;
                if (!record)
                  v[b][d] = v0;
                else if (damping.active()) // the body's own damped momentum balance
                  v[b][d] = v0 + damping.velocity_change(inv_m, v0, q[1 + dim + d], dt);
                else
                  v[b][d] = v0 + dt * q[1 + dim + d] * inv_m;
              }
            total.mass += q[0];
            total.momentum += q[0] * v[b];
          }
        return total;
      }
    } // namespace



    template <int dim>
    void
    Solver<dim>::apply_contact(const double t, const double dt, const bool record)
    {
      using namespace dealii;
      constexpr unsigned int C      = 1 + 2 * dim;
      constexpr unsigned int K      = contact_block;
      const unsigned int     B      = n_contact_blocks;
      const double *const    common = grid->data().data();
      double *const          layer  = grid->layer_data().data();
      const double           tiny   = small_mass;
      const auto            &bodies = this->get_scene().body_descriptions();

      // Rigid bodies' velocities at t, and the reactions' first index.
      std::vector<Tensor<1, dim>> &v_rigid = contact_rigid_velocity;
      for (unsigned int b = 0; b < B; ++b)
        if (bodies[b].rigid)
          v_rigid[b] = bodies[b].rigid_velocity_at(t);
      const unsigned int first_rigid_reaction = boundaries.size();

      std::vector<Tensor<1, dim>> &v                = contact_velocity;
      const bool                   first_conversion = layer_from_points;
      for (const unsigned int n : active_nodes)
        {
          const NodeLayer<dim> node{layer + n * std::size_t(K) * B, B};
          const double *const  r       = common + std::size_t(n) * C;
          const auto [n_bodies, rigid] = bodies_at_node(node, bodies, tiny);
          if (n_bodies < 2)
            {
              copy_common_field(node, r, bodies, record);
              continue;
            }

          // Two or more bodies: each deformable one's trial velocity.
          const NodeTotals<dim> total =
            trial_velocities(node, bodies, tiny, layer_holds_momenta, first_conversion, dt, record, nodal_damping, v);
          if (!(total.mass > tiny))
            continue;

          // Boundary conditions act on the common field, i.e. on the centre of mass of
          // the deformable bodies at the node: on a boundary node every body is shifted
          // by the change they made there.
          Tensor<1, dim> shift;
          if (boundary_node[n] && r[0] > tiny)
            for (unsigned int d = 0; d < dim; ++d)
              shift[d] = r[1 + d] - total.momentum[d] / total.mass;
          // The velocity the bodies are measured against: a rigid body's (it does not
          // give way), else their centre of mass's.
          const Tensor<1, dim> v_ref = rigid != numbers::invalid_unsigned_int ?
                                         v_rigid[rigid] :
                                         total.momentum / total.mass + shift;

          for (unsigned int b = 0; b < B; ++b)
            {
              double *const q = node.body(b);
              if (bodies[b].rigid || !(q[0] > tiny))
                continue;
              v[b] += shift;
              Tensor<1, dim> normal = outward_normal(node, b, rigid, total.grad);
              const double   length = normal.norm();
              Tensor<1, dim> correction;
              if (length > 0)
                {
                  normal /= length;
                  const Tensor<1, dim> relative = v[b] - v_ref;
                  const double         approach = relative * normal;
                  if (approach > 0)
                    {
                      const unsigned int other =
                        rigid != numbers::invalid_unsigned_int ? rigid : heaviest_other(node, b);
                      correction =
                        contact_correction(relative, normal, approach, friction[b * B + other]);
                      v[b] -= correction;
                    }
                }
              for (unsigned int d = 0; d < dim; ++d)
                {
                  if (record)
                    q[1 + dim + d] = v[b][d] - q[1 + 3 * dim + d];
                  q[1 + d] = v[b][d];
                }
              // The force of a rigid body on the material, and its work.
              if (record && rigid != numbers::invalid_unsigned_int && grid->is_owned(n))
                {
                  const Tensor<1, dim> impulse = -q[0] * correction;
                  reactions[first_rigid_reaction + rigid] += impulse / dt;
                  boundary_work += impulse * v_ref;
                }
            }
        }
      layer_holds_momenta = false;
      layer_from_points   = false;
    }



    template void Solver<2>::parse_contact(dealii::ParameterHandler &);
    template void Solver<3>::parse_contact(dealii::ParameterHandler &);
    template void Solver<2>::setup_contact();
    template void Solver<3>::setup_contact();
    template void Solver<2>::apply_contact(double, double, bool);
    template void Solver<3>::apply_contact(double, double, bool);
  } // namespace MPM
} // namespace hysteron

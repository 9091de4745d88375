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
      contact_boundary_node.reset(grid->n_local_nodes(), grid->sparse_box());
      for (const auto &b : boundaries)
        for (const unsigned int n : b.nodes)
          contact_boundary_node[n] = 1;
      contact_velocity.assign(n_contact_blocks, dealii::Tensor<1, dim>());
      contact_rigid_velocity.assign(n_contact_blocks, dealii::Tensor<1, dim>());
    }



    template <int dim>
    void
    Solver<dim>::apply_contact(const double t, const double dt, const bool record)
    {
      using namespace dealii;
      constexpr unsigned int C      = 1 + 2 * dim;
      constexpr unsigned int K      = contact_block;
      const unsigned int     B      = n_contact_blocks;
      const std::size_t      L      = std::size_t(K) * B;
      const double *const    node   = grid->data().data();
      double *const          layer  = grid->layer_data().data();
      const double           tiny   = small_mass;
      const auto            &bodies = this->get_scene().body_descriptions();

      // Rigid bodies' velocities at t, and the reactions' first index.
      std::vector<Tensor<1, dim>> &v_rigid = contact_rigid_velocity;
      for (unsigned int b = 0; b < B; ++b)
        if (bodies[b].rigid)
          v_rigid[b] = bodies[b].rigid_velocity_at(t);
      const unsigned int first_rigid_reaction = boundaries.size();

      // Per node: the trial velocity v_b' of each body with mass there.
      std::vector<Tensor<1, dim>> &v                = contact_velocity;
      const bool                   first_conversion = layer_from_points;
      for (const unsigned int n : active_nodes)
        {
          double *const       q_n = layer + n * L;
          const double *const r   = node + std::size_t(n) * C;

          unsigned int n_bodies = 0, rigid = numbers::invalid_unsigned_int;
          for (unsigned int b = 0; b < B; ++b)
            if (q_n[b * K] > tiny)
              {
                ++n_bodies;
                if (bodies[b].rigid && rigid == numbers::invalid_unsigned_int)
                  rigid = b;
              }

          if (n_bodies < 2)
            {
              // One body at the node: its field is the common one (after the
              // boundary conditions), value for value.
              for (unsigned int b = 0; b < B; ++b)
                if (!bodies[b].rigid)
                  {
                    double *const q = q_n + b * K;
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        q[1 + d] = r[1 + d];
                        if (record)
                          q[1 + dim + d] = r[1 + dim + d];
                      }
                  }
              continue;
            }

          // Two or more bodies. The trial velocity of each deformable body:
          // v_b = p_b / m_b (or the velocity the layer holds), plus dt f_b / m_b
          // after the momentum balance (record).
          double         m_total = 0;
          Tensor<1, dim> p_total, grad_total;
          for (unsigned int b = 0; b < B; ++b)
            {
              double *const q = q_n + b * K;
              for (unsigned int d = 0; d < dim; ++d)
                grad_total[d] += q[1 + 2 * dim + d];
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
                  const double v0 = layer_holds_momenta ? q[1 + d] * inv_m : q[1 + d];
                  // The velocity projected from the points, for the FLIP increment
                  // Delta v_b = v_b' - p_b / m_b (a correction at the step's start, USF,
                  // belongs to it too).
                  if (first_conversion)
                    q[1 + 3 * dim + d] = v0;
                  v[b][d] = record ? v0 + dt * q[1 + dim + d] * inv_m : v0;
                }
              m_total += q[0];
              p_total += q[0] * v[b];
            }
          if (!(m_total > tiny))
            continue;

          // Boundary conditions act on the common field, i.e. on the centre of mass of
          // the deformable bodies at the node: on a boundary node every body is shifted
          // by the change they made there.
          Tensor<1, dim> shift;
          if (contact_boundary_node[n] && r[0] > tiny)
            for (unsigned int d = 0; d < dim; ++d)
              shift[d] = r[1 + d] - p_total[d] / m_total;
          // The velocity the bodies are measured against: a rigid body's (it does not
          // give way), else their centre of mass's.
          const Tensor<1, dim> v_ref =
            rigid != numbers::invalid_unsigned_int ? v_rigid[rigid] : p_total / m_total + shift;

          for (unsigned int b = 0; b < B; ++b)
            {
              double *const q = q_n + b * K;
              if (bodies[b].rigid || !(q[0] > tiny))
                continue;
              v[b] += shift;
              // Outward normal of body b, towards the other bodies, from the nodal
              // mass gradients g_c = sum_p m_p grad N_ip (g_c points out of body c:
              // N_i falls away from node i). Against a rigid body its surface normal,
              // n_b ~ -g_rigid (the material's own gradient turns at its corners and
              // would lift a sliding body); between deformable bodies the average
              // n_b ~ g_b - sum_{c != b} g_c, so that for two bodies n_a = -n_b and the
              // pair's momentum is kept exactly.
              Tensor<1, dim> normal;
              if (rigid != numbers::invalid_unsigned_int)
                for (unsigned int d = 0; d < dim; ++d)
                  normal[d] = -q_n[rigid * K + 1 + 2 * dim + d];
              else
                for (unsigned int d = 0; d < dim; ++d)
                  normal[d] = 2.0 * q[1 + 2 * dim + d] - grad_total[d];
              const double length = normal.norm();
              Tensor<1, dim> correction;
              if (length > 0)
                {
                  normal /= length;
                  const Tensor<1, dim> relative = v[b] - v_ref;
                  const double         approach = relative * normal;
                  if (approach > 0)
                    {
                      // No interpenetration: remove the approaching normal velocity;
                      // Coulomb: the tangential slip is reduced by at most mu times
                      // that normal change (stick when it suffices).
                      unsigned int other = rigid;
                      if (other == numbers::invalid_unsigned_int)
                        {
                          double heaviest = 0;
                          for (unsigned int c = 0; c < B; ++c)
                            if (c != b && q_n[c * K] > heaviest)
                              {
                                heaviest = q_n[c * K];
                                other    = c;
                              }
                        }
                      const double         mu      = friction[b * B + other];
                      const Tensor<1, dim> slip    = relative - approach * normal;
                      const double         slip_v  = slip.norm();
                      correction                   = approach * normal;
                      if (slip_v > 0)
                        correction += std::min(mu * approach, slip_v) / slip_v * slip;
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

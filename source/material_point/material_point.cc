#include <deal.II/base/utilities.h>

#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include "base/progress.h"
#include <hysteron/material_point/material_point.h>

#include <cmath>
#include <sstream>

namespace hysteron
{
  namespace MaterialPoint
  {
    const std::array<const char *, 6> component_names = {{"xx", "yy", "zz", "xy", "yz", "xz"}};

    namespace
    {
      const std::array<std::array<unsigned int, 2>, 6> component_indices = {
        {{{0, 0}}, {{1, 1}}, {{2, 2}}, {{0, 1}}, {{1, 2}}, {{0, 2}}}};

      bool
      exists_in(const unsigned int c, const int dim)
      {
        return dim == 3 || c == 0 || c == 1 || c == 3;
      }

      /// Solve A x = b (n <= 6) by Gaussian elimination with partial pivoting.
      /// Returns false if A is singular relative to its largest entry.
      bool
      solve_small(std::vector<double> A, std::vector<double> b, const unsigned int n,
                  std::vector<double> &x)
      {
        double scale = 0;
        for (const double a : A)
          scale = std::max(scale, std::abs(a));
        for (unsigned int k = 0; k < n; ++k)
          {
            unsigned int p = k;
            for (unsigned int r = k + 1; r < n; ++r)
              if (std::abs(A[r * n + k]) > std::abs(A[p * n + k]))
                p = r;
            if (!(std::abs(A[p * n + k]) > 1e-14 * scale))
              return false;
            if (p != k)
              {
                for (unsigned int c = 0; c < n; ++c)
                  std::swap(A[k * n + c], A[p * n + c]);
                std::swap(b[k], b[p]);
              }
            for (unsigned int r = k + 1; r < n; ++r)
              {
                const double f = A[r * n + k] / A[k * n + k];
                for (unsigned int c = k; c < n; ++c)
                  A[r * n + c] -= f * A[k * n + c];
                b[r] -= f * b[k];
              }
          }
        x.assign(n, 0.0);
        for (int k = n - 1; k >= 0; --k)
          {
            double s = b[k];
            for (unsigned int c = k + 1; c < n; ++c)
              s -= A[k * n + c] * x[c];
            x[k] = s / A[k * n + k];
          }
        return true;
      }
    } // namespace

    template <int dim>
    void
    Method<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Material point");
      {
        for (unsigned int c = 0; c < 6; ++c)
          prm.declare_entry(std::string("Strain ") + component_names[c],
                            "0",
                            Patterns::Anything(),
                            std::string("Prescribed strain eps_") + component_names[c] +
                              " [-] as a function of time t [s] (muParser; pi is known)." +
                              (c >= 3 ? " Tensor shear component: eps_xy = gamma_xy / 2." : "") +
                              (c == 2 || c >= 4 ? " 3D only." : ""));
        prm.declare_entry("Stress-free components",
                          "",
                          Patterns::List(Patterns::Selection("xx|yy|zz|xy|yz|xz")),
                          "Strain components that are unknowns instead of prescribed: they are "
                          "solved at every step so that the matching stress components stay zero "
                          "(mixed control). 'yy, xy' in 2D plane stress, or 'yy, zz, xy, yz, xz' "
                          "in 3D, gives uniaxial stress.");
        prm.declare_entry("End time", "1", Patterns::Double(), "End of the path [s], > 0.");
        prm.declare_entry("Steps",
                          "1000",
                          Patterns::Integer(),
                          "Number of equal strain increments (material updates), 1 to 10^7.");
        prm.declare_entry("Material",
                          "",
                          Patterns::Anything(),
                          "Name of the material (see `Material names`); empty: the default "
                          "`subsection Material`.");
        prm.declare_entry("Mixed control tolerance",
                          "1e-12",
                          Patterns::Double(),
                          "Newton tolerance on the stress-free components, relative to "
                          "E * max(|eps|, 1e-6), > 0.");
      }
      prm.leave_subsection();
    }

    template <int dim>
    void
    Method<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      Section s(prm, {"Material point"});
      end_time = s.get_positive("End time");
      {
        const long steps = s.get_integer("Steps");
        require(steps >= 1 && steps <= 10000000L,
                s.where("Steps"),
                "must be an integer from 1 to 10,000,000 (each step is a row of history.csv, kept "
                "in memory too; got " + s.get("Steps") + ")");
        n_steps = steps;
      }
      tolerance = s.get_positive("Mixed control tolerance");
      material  = &this->get_scene().material(dealii::Utilities::trim(s.get("Material")),
                                             s.where("Material"));
      require(material->elasticity().stress_state != Material::StressState::axisymmetric,
              s.where("Material"),
              "an axisymmetric material needs a solid of revolution (its hoop strain comes from "
              "the radial displacement): drive a single point in 3D (Dimension = 3) instead");

      const auto free_names = s.get_list("Stress-free components");
      for (const auto &name : free_names)
        {
          unsigned int c = 0;
          while (component_names[c] != name)
            ++c;
          require(exists_in(c, dim),
                  s.where("Stress-free components"),
                  "'" + name + "' is not an in-plane component of a 2D scene (the stress state "
                  "of the material decides the out-of-plane direction)");
        }

      for (unsigned int c = 0; c < 6; ++c)
        {
          const std::string entry = std::string("Strain ") + component_names[c];
          const std::string expr  = dealii::Utilities::trim(s.get(entry));
          const bool        free =
            std::find(free_names.begin(), free_names.end(), component_names[c]) != free_names.end();
          if (!exists_in(c, dim))
            {
              require(expr == "0",
                      s.where(entry),
                      "exists only in 3D scenes (got '" + expr + "' with Dimension = 2)");
              continue;
            }
          require(!free || expr == "0",
                  s.where(entry),
                  "is prescribed as '" + expr + "', but '" + component_names[c] +
                    "' is listed in Stress-free components");
          Component comp;
          comp.i    = component_indices[c][0];
          comp.j    = component_indices[c][1];
          comp.name = component_names[c];
          comp.free = free;
          if (!free)
            {
              comp.strain = parse_function<1>(expr, "t", false, s.where(entry));
              check_finite_in_time(*comp.strain, end_time);
            }
          components.push_back(std::move(comp));
        }
      require(std::any_of(components.begin(),
                          components.end(),
                          [](const Component &c) { return !c.free; }),
              s.where("Stress-free components"),
              "every strain component is stress-free; prescribe at least one");
    }

    template <int dim>
    std::vector<std::string>
    Method<dim>::column_names() const
    {
      std::vector<std::string> names{"t"};
      for (const char *c : component_names)
        names.push_back(std::string("eps_") + c);
      for (const char *c : component_names)
        names.push_back(std::string("sig_") + c);
      for (const auto &n : material->state_variable_names())
        names.push_back(n);
      return names;
    }

    template <int dim>
    void
    Method<dim>::run()
    {
      using Tensor2 = dealii::SymmetricTensor<2, dim>;
      const Scene<dim> &scene = this->get_scene();
      const double      E     = material->elasticity().youngs_modulus;
      const unsigned int n_state = material->n_state_variables();

      std::vector<unsigned int> free_index;
      for (unsigned int k = 0; k < components.size(); ++k)
        if (components[k].free)
          free_index.push_back(k);
      const unsigned int n_free = free_index.size();

      std::vector<double> state(n_state), trial_state(n_state);
      material->initialize_state(dealii::make_array_view(state));
      Tensor2 strain, stress, previous_increment;

      std::unique_ptr<Output::TimeTable> csv;
      if (scene.is_root())
        csv = std::make_unique<Output::TimeTable>(scene.output_file("history.csv"),
                                                  column_names(),
                                                  this->run_record());

      // One CSV row: all six components, the out-of-plane ones from the model in 2D.
      const auto write_row = [&](const double t) {
        double eps_zz = 0, sig_zz = 0;
        if (dim == 2)
          material->out_of_plane(strain, stress, dealii::make_array_view(state), eps_zz, sig_zz);
        std::vector<double> row(13 + n_state, 0.0);
        row[0] = t;
        for (unsigned int c = 0; c < 6; ++c)
          {
            const unsigned int i = component_indices[c][0], j = component_indices[c][1];
            if (i < dim && j < dim)
              {
                row[1 + c] = strain[i][j];
                row[7 + c] = stress[i][j];
              }
          }
        if (dim == 2)
          {
            row[3] = eps_zz;
            row[9] = sig_zz;
          }
        std::copy(state.begin(), state.end(), row.begin() + 13);
        rows.push_back(row);
        if (csv)
          csv->add_row(row);
      };

      Progress progress(scene.console(), "material point", end_time, scene.output_control().progress_interval);
      write_row(0.0);

      dealii::SymmetricTensor<4, dim> tangent;
      std::vector<double>             J(n_free * n_free), r(n_free), dx;
      dealii::TimerOutput::Scope timing(scene.timer(), "material updates");
      for (unsigned int step = 1; step <= n_steps; ++step)
        {
          const double t = end_time * step / n_steps;

          // Prescribed components from the path; free ones extrapolated from the last step.
          Tensor2 target = strain + previous_increment;
          for (const auto &c : components)
            if (!c.free)
              target[c.i][c.j] = c.strain->value(dealii::Point<1>(t));

          Tensor2      trial_stress;
          unsigned int it = 0;
          for (;; ++it)
            {
              trial_stress = stress;
              trial_state  = state;
              material->update_point(target - strain,
                                     trial_stress,
                                     dealii::make_array_view(trial_state),
                                     n_free > 0 ? &tangent : nullptr);
              if (n_free == 0)
                break;

              double scale = 1e-6;
              for (unsigned int a = 0; a < dim; ++a)
                for (unsigned int b = 0; b < dim; ++b)
                  scale = std::max(scale, std::abs(target[a][b]));
              double residual = 0;
              for (unsigned int a = 0; a < n_free; ++a)
                {
                  const auto &ca = components[free_index[a]];
                  r[a]           = trial_stress[ca.i][ca.j];
                  residual       = std::max(residual, std::abs(r[a]));
                }
              if (residual <= tolerance * E * scale)
                break;
              if (it == max_iterations || !std::isfinite(residual))
                {
                  std::ostringstream m;
                  m << "Material point: the stress-free components did not converge at step "
                    << step << " (t = " << t << " s): residual " << residual << " Pa after " << it
                    << " Newton iterations (tolerance " << tolerance * E * scale
                    << " Pa = Material point/Mixed control tolerance x E x max |eps|). An adaptive "
                    << "material integrator changes its sub-steps between the iterations, so its "
                    << "response is only piecewise smooth at the level of its Tolerance: raise the "
                    << "Mixed control tolerance towards the material's Tolerance";
                  throw RuntimeError(m.str());
                }
              for (unsigned int a = 0; a < n_free; ++a)
                for (unsigned int b = 0; b < n_free; ++b)
                  {
                    const auto &ca = components[free_index[a]];
                    const auto &cb = components[free_index[b]];
                    J[a * n_free + b] =
                      tangent[ca.i][ca.j][cb.i][cb.j] * (cb.i == cb.j ? 1.0 : 2.0);
                  }
              if (!solve_small(J, r, n_free, dx))
                throw RuntimeError("Material point: the tangent restricted to the stress-free "
                                   "components is singular at step " +
                                   std::to_string(step) + " (t = " + std::to_string(t) + " s)");
              for (unsigned int a = 0; a < n_free; ++a)
                {
                  const auto &ca = components[free_index[a]];
                  target[ca.i][ca.j] -= dx[a];
                }
            }
          total_iterations += it;

          for (unsigned int a = 0; a < dim; ++a)
            for (unsigned int b = a; b < dim; ++b)
              if (!std::isfinite(trial_stress[a][b]) || !std::isfinite(target[a][b]))
                {
                  std::ostringstream m;
                  m << "Material point: the " << (std::isfinite(target[a][b]) ? "stress" : "strain")
                    << " component " << "xyz"[a] << "xyz"[b] << " is not finite at step " << step
                    << " (t = " << t << " s)";
                  throw RuntimeError(m.str());
                }

          previous_increment = target - strain;
          strain             = target;
          stress             = trial_stress;
          state              = trial_state;
          write_row(t);
          progress.update(step, t);
        }
      progress.finish(n_steps, end_time);
      timing.stop();

      // Timer sections synchronise the ranks: every rank enters them.
      dealii::TimerOutput::Scope output_timing(scene.timer(), "output");
      if (csv)
        csv->flush();
    }

    template <int dim>
    std::string
    Method<dim>::summary() const
    {
      std::ostringstream s;
      s << n_steps << " steps";
      if (total_iterations > 0)
        s << ", " << total_iterations << " mixed-control Newton iterations";
      return s.str();
    }

    template class Method<2>;
    template class Method<3>;
  } // namespace MaterialPoint
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::MaterialPoint::Method,
                         "material point",
                         "one material point driven along a strain path with optional "
                         "stress-free components (the constitutive test bench); writes "
                         "history.csv")

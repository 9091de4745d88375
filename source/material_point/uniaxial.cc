#include <deal.II/base/utilities.h>

#include <hysteron/base/output.h>
#include <hysteron/base/parameters.h>
#include "base/progress.h"
#include <hysteron/material_point/uniaxial.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

namespace hysteron
{
  namespace MaterialPoint
  {
    template <int dim>
    void
    Uniaxial<dim>::declare_parameters(dealii::ParameterHandler &prm)
    {
      using namespace dealii;
      prm.enter_subsection("Uniaxial");
      {
        prm.declare_entry("Strain",
                          "0",
                          Patterns::Anything(),
                          "Prescribed strain eps [-] (or deformation, in the units of "
                          "Bouc-Wen/Yield stress divided by Young's modulus) as a function of time "
                          "t [s] (muParser; pi is known).");
        prm.declare_entry("End time", "1", Patterns::Double(), "End of the path [s], > 0.");
        prm.declare_entry("Steps",
                          "1000",
                          Patterns::Integer(),
                          "Number of equal time steps (strain increments, updates of the law), "
                          "1 to 10^7.");
      }
      prm.leave_subsection();

      // The bench reads `Material / Bouc-Wen`; a material model that uses the
      // Bouc-Wen law declares it already (materials are declared first).
      prm.enter_subsection("Material");
      if (!prm.subsection_path_exists({"Bouc-Wen"}))
        Material::BoucWenParameters::declare_parameters(prm);
      prm.leave_subsection();
    }



    template <int dim>
    void
    Uniaxial<dim>::parse_parameters(dealii::ParameterHandler &prm)
    {
      const Scene<dim> &scene = this->get_scene();
      {
        Section s(prm, {"Uniaxial"});
        end_time         = s.get_positive("End time");
        const long steps = s.get_integer("Steps");
        require(steps >= 1 && steps <= 10000000L,
                s.where("Steps"),
                "must be an integer from 1 to 10,000,000 (each step is a row of history.csv, kept "
                "in memory too; got " + s.get("Steps") + ")");
        n_steps = steps;
        strain  = parse_function<1>(dealii::Utilities::trim(s.get("Strain")),
                                   "t",
                                   false,
                                   s.where("Strain"));
        check_finite_in_time(*strain, end_time);
      }

      Section                        material(prm, {"Material"});
      const double                   E = material.get_positive("Young's modulus");
      Material::BoucWenParameters    parameters;
      const std::vector<std::string> warnings = parameters.parse_parameters(material);
      law.reinit(parameters, E, parameters.yield_stress);
      {
        Section                           bouc_wen(material, "Bouc-Wen");
        Material::BoucWenFamilyParameters family;
        family.parse_parameters(bouc_wen, parameters);
        if (family.variant != Material::UniaxialVariant::smooth)
          variant = Material::create_bouc_wen_variant(family, parameters.yield_stress);
      }

      // The scene prints the warnings of its material model; print ours unless
      // that model (a Bouc-Wen model) has printed the same ones already.
      if (scene.is_root())
        {
          const auto &printed = scene.material("", "Material").warnings();
          for (const auto &w : warnings)
            if (std::find(printed.begin(), printed.end(), w) == printed.end())
              std::cerr << "hysteron: warning: " << w << std::endl;
        }
    }



    template <int dim>
    std::vector<std::string>
    Uniaxial<dim>::column_names() const
    {
      std::vector<std::string> names{"t", "eps", "sig", "z"};
      if (variant)
        return {"t", "eps", "sig", "z", "H1"};
      if (law.degradation())
        for (const char *c : {"eta", "e_h", "nu_s"})
          names.push_back(c);
      names.push_back("H1");
      names.push_back("H2");
      return names;
    }



    template <int dim>
    double
    Uniaxial<dim>::strain_at(const unsigned int step) const
    {
      const double t     = end_time * step / n_steps;
      const double value = strain->value(dealii::Point<1>(t));
      if (!std::isfinite(value))
        {
          std::ostringstream m;
          m << "Uniaxial: the strain is not finite at step " << step << " (t = " << t << " s)";
          throw RuntimeError(m.str());
        }
      return value;
    }



    template <int dim>
    void
    Uniaxial<dim>::run_variant()
    {
      const Scene<dim> &scene = this->get_scene();
      std::unique_ptr<Output::TimeTable> csv;
      if (scene.is_root())
        csv = std::make_unique<Output::TimeTable>(scene.output_file("history.csv"),
                                                  column_names(),
                                                  this->run_record());
      const double E = scene.material("", "Material").elasticity().youngs_modulus;
      double       state[3];
      variant->add_spring(E, variant->yield_stress(), state);
      double      eps = 0, stress = 0;
      std::string failure;
      const auto  advance = [&](const unsigned int step) {
        const double next = strain_at(step);
        double       deps = next - eps;
        if (variant->update(0, 1, &deps, &stress, state, nullptr, 1, failure) != 1)
          throw RuntimeError(failure + " [at step " + std::to_string(step) + "]");
        eps = next;
        std::vector<double> row{end_time * step / n_steps, eps, stress,
                                variant->hysteretic_variable(0, state), variant->h1(0, state)};
        if (csv)
          csv->add_row(row);
        rows.push_back(std::move(row));
      };
      Progress progress(scene.console(), "uniaxial", end_time, scene.output_control().progress_interval);
      dealii::TimerOutput::Scope timing(scene.timer(), "material updates");
      // Step 0 loads the path's start from the virgin state in one increment.
      for (unsigned int step = 0; step <= n_steps; ++step)
        {
          advance(step);
          progress.update(step, end_time * step / n_steps);
        }
      progress.finish(n_steps, end_time);
      timing.stop();
      dealii::TimerOutput::Scope output_timing(scene.timer(), "output");
      if (csv)
        csv->flush();
    }



    template <int dim>
    void
    Uniaxial<dim>::run()
    {
      if (variant)
        return run_variant();
      const Scene<dim> &scene = this->get_scene();
      using State             = Material::BoucWenUniaxial;

      std::unique_ptr<Output::TimeTable> csv;
      if (scene.is_root())
        csv = std::make_unique<Output::TimeTable>(scene.output_file("history.csv"),
                                                  column_names(),
                                                  this->run_record());

      double state[State::max_n_state_variables];
      law.initialize_state(state);
      double eps = strain->value(dealii::Point<1>(0.0));
      if (!std::isfinite(eps))
        throw RuntimeError("Uniaxial: the strain is not finite at t = 0 s");
      double stress = law.stress(eps, state);

      const auto write_row = [&](const double t, const double deps) {
        std::vector<double> row{t, eps, stress, state[State::z_index]};
        if (law.degradation())
          {
            row.push_back(state[State::eta_index]);
            row.push_back(state[State::energy_index]);
            row.push_back(law.nu_s(state));
          }
        row.push_back(law.h1(state));
        row.push_back(law.h2(state, deps));
        if (csv)
          csv->add_row(row);
        rows.push_back(std::move(row));
      };

      Progress progress(scene.console(),
                        "uniaxial",
                        end_time,
                        scene.output_control().progress_interval);
      write_row(0.0, 0.0);

      dealii::TimerOutput::Scope timing(scene.timer(), "material updates");
      for (unsigned int step = 1; step <= n_steps; ++step)
        {
          const double t    = end_time * step / n_steps;
          const double next = strain_at(step);
          const double deps = next - eps;
          try
            {
              total_work += law.update(deps, stress, state);
            }
          catch (const RuntimeError &e)
            {
              std::ostringstream m;
              m << e.what() << " [at step " << step << ", t = " << t << " s]";
              throw RuntimeError(m.str());
            }
          eps = next;
          write_row(t, deps);
          progress.update(step, t);
        }
      progress.finish(n_steps, end_time);
      timing.stop();

      {
        // Timer sections are collective: every rank enters it.
        dealii::TimerOutput::Scope output_timing(scene.timer(), "output");
        if (csv)
          csv->flush();
      }
    }



    template <int dim>
    std::string
    Uniaxial<dim>::summary() const
    {
      std::ostringstream s;
      s << n_steps << " steps";
      if (variant)
        return s.str() + ", one implicit update each";
      switch (law.parameters().integrator)
        {
          case Material::BoucWenIntegrator::adaptive:
            s << ", " << total_work << " adaptive sub-steps";
            break;
          case Material::BoucWenIntegrator::backward_euler:
            s << ", " << total_work << " local Newton iterations";
            break;
          default:
            break;
        }
      return s.str();
    }

    template class Uniaxial<2>;
    template class Uniaxial<3>;
  } // namespace MaterialPoint
} // namespace hysteron

HYSTERON_REGISTER_METHOD(hysteron::MaterialPoint::Uniaxial,
                         "uniaxial",
                         "the uniaxial Bouc-Wen law (Material/Young's modulus and "
                         "Material/Bouc-Wen) driven along a strain path eps(t); writes "
                         "history.csv (the 1D test bench)")

#ifndef hysteron_oscillator_oscillator_h
#define hysteron_oscillator_oscillator_h

#include <deal.II/base/function_parser.h>

#include <hysteron/scene/ground_motion.h>
#include <hysteron/scene/method.h>
#include <hysteron/scene/scene.h>
#include "oscillator/shear_building.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace Oscillator
  {
    /**
     * The ground motion of the oscillator and spectrum methods: `Ground motion/File`
     * (a record) or an expression a_g(t) of the method's own section, one of the two.
     */
    class GroundInput
    {
    public:
      /// `Ground acceleration`, `Time step`, `Duration` (in the method's section).
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      /// Read `Ground motion` and the method's section @p section; @p needs_record:
      /// the expression is not offered (the spectrum's record).
      template <int dim>
      void
      parse(dealii::ParameterHandler &prm, const Scene<dim> &scene, const std::string &section, bool needs_record);

      /// a_g(t) [m/s^2].
      double
      operator()(double t) const
      {
        return expression ? expression->value(dealii::Point<1>(t)) : record.acceleration(t);
      }

      /// The record's sampling step [s] (0: an expression).
      double
      record_step() const
      {
        return record.empty() ? 0.0 : record.time_step();
      }

      /// The time step and duration of the analysis [s].
      double time_step = 0, duration = 0;

    private:
      GroundMotion                               record;
      std::unique_ptr<dealii::FunctionParser<1>> expression;
    };

    /**
     * SIGINT and SIGTERM (and the test hook HYSTERON_TEST_SIGNAL) during the oscillator
     * and spectrum methods, which write no checkpoint: the handlers are installed for
     * the object's life; check() after each step of @p label stops the run with
     * Interrupted (exit status 4) when a signal came, the tables written so far whole.
     */
    class SignalGuard
    {
    public:
      SignalGuard(const RunOptions &options, MPI_Comm comm, Output::RunRecord &record, std::string label);
      ~SignalGuard();
      SignalGuard(const SignalGuard &) = delete;
      SignalGuard &
      operator=(const SignalGuard &) = delete;

      /// After step @p step (1, 2, ...; the test hook counts them) at time @p t.
      void
      check(unsigned long step, double t);

    private:
      const RunOptions  &options;
      MPI_Comm           comm;
      unsigned int       n_ranks;
      Output::RunRecord &record;
      std::string        label;
    };

    /// The positive numbers of the list @p entry of @p s: @p n of them, or one for all.
    std::vector<double>
    positive_list(const Section &s, const std::string &entry, unsigned int n);

    /**
     * `set Method = oscillator` (doc/oscillator.md): a ShearBuilding from `subsection
     * Oscillator` and the storeys' law of `Material`, under the ground motion. Writes
     * history.csv (t, u_i, v_i, absolute a_i, F_i, z_i), energy.csv and, at the end,
     * summary.csv (per storey: peak and residual drift, ductility, peak force and
     * absolute acceleration) and modes.csv (periods and damping ratios).
     */
    template <int dim>
    class Method : public Methods::Interface<dim>
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm);

      void
      setup() override;

      std::string
      check_size() override;

      void
      run() override;

      std::string
      summary() const override;

      bool
      takes_ground_motion() const override
      {
        return true;
      }

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override;

    private:
      std::vector<std::string>
      history_columns() const;
      void
      write_summary(const ShearBuilding::State &last) const;

      std::vector<double>            mass, stiffness, yield_force;
      double                         damping_ratio = 0.05;
      GroundInput                    ground;
      std::unique_ptr<ShearBuilding> building;
      // The run's results.
      std::vector<double> peak_drift, peak_force, peak_acceleration;
      double              input = 0, worst_balance = 0;
    };
  } // namespace Oscillator
} // namespace hysteron

#endif

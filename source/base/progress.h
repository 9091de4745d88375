#ifndef hysteron_base_progress_h
#define hysteron_base_progress_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/timer.h>

#include <string>

namespace hysteron
{
  /**
   * Progress of a time-stepping run: "step, time, % done, ETA", printed at most
   * every @p interval seconds of wall time (and once at the end), to a
   * ConditionalOStream that is silent with --quiet and on ranks other than 0.
   */
  class Progress
  {
  public:
    Progress(dealii::ConditionalOStream &out,
             const std::string          &label,
             double                      end_time,
             double                      interval_seconds = 2.0);

    /// Report that @p step has finished at simulated time @p time.
    void
    update(unsigned long step, double time);

    /// The last line, always printed (unless silenced).
    void
    finish(unsigned long step, double time);

  private:
    void
    print(unsigned long step, double time);

    dealii::ConditionalOStream &out;
    std::string                 label;
    double                      end_time;
    double                      interval;
    dealii::Timer               timer;
    double                      last_print = 0;
    bool                        printed    = false;
    unsigned long               last_step  = 0;
  };
} // namespace hysteron

#endif

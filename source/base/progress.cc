#include "base/progress.h"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace hysteron
{
  Progress::Progress(dealii::ConditionalOStream &out,
                     const std::string          &label,
                     const double                end_time,
                     const double                interval_seconds)
    : out(out)
    , label(label)
    , end_time(end_time)
    , interval(interval_seconds)
  {
    timer.start();
  }

  void
  Progress::update(const unsigned long step, const double time)
  {
    if (!out.is_active())
      return;
    const double now = timer.wall_time();
    if (now - last_print < interval)
      return;
    last_print = now;
    print(step, time);
  }

  void
  Progress::finish(const unsigned long step, const double time)
  {
    // Once, unless update() has just printed this very step.
    if (!(printed && step == last_step))
      print(step, time);
  }

  void
  Progress::print(const unsigned long step, const double time)
  {
    const double elapsed  = timer.wall_time();
    const double fraction = end_time > 0 ? std::clamp(time / end_time, 0.0, 1.0) : 1.0;
    std::ostringstream line;
    line << label << ": step " << step << "  t = " << std::setprecision(6) << time << " s  "
         << std::fixed << std::setprecision(1) << 100 * fraction << " %";
    if (fraction > 0 && fraction < 1)
      line << "  ETA " << std::setprecision(1) << elapsed * (1 - fraction) / fraction << " s";
    else
      line << "  wall " << std::setprecision(2) << elapsed << " s";
    out << line.str() << std::endl;
    printed   = true;
    last_step = step;
  }
} // namespace hysteron

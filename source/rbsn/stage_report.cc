// StageReport: the console lines of a large network's set-up, one per stage.
#include "rbsn/tessellation.h"

#include <iomanip>
#include <sstream>
#include <string>

namespace hysteron
{
  namespace RBSN
  {
    StageReport::StageReport(const dealii::ConditionalOStream &console, const bool enabled)
      : console(console)
      , on(enabled)
    {}



    void
    StageReport::operator()(const std::string &what)
    {
      if (on)
        {
          std::ostringstream line;
          line << "rbsn: " << what << " in " << std::fixed << std::setprecision(1) << clock.wall_time() << " s";
          console << line.str() << std::endl;
        }
      clock.restart();
    }



    std::string
    StageReport::count(const std::size_t n)
    {
      std::string digits = std::to_string(n), grouped;
      for (std::size_t k = 0; k < digits.size(); ++k)
        {
          if (k > 0 && (digits.size() - k) % 3 == 0)
            grouped += ',';
          grouped += digits[k];
        }
      return grouped;
    }
  } // namespace RBSN
} // namespace hysteron

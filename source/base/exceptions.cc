#include <hysteron/base/exceptions.h>

namespace hysteron
{
  LocatedError::LocatedError(const std::string &where, const std::string &problem)
    : std::runtime_error(where + ": " + problem)
    , where_(where)
    , problem_(problem)
  {}

  RuntimeError::RuntimeError(const std::string &message)
    : std::runtime_error(message)
  {}
} // namespace hysteron

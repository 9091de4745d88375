#ifndef hysteron_source_material_update_each_spring_h
#define hysteron_source_material_update_each_spring_h

// The loop of the uniaxial spring laws' update(): every spring, even if one fails.

#include <hysteron/base/exceptions.h>

#include <string>

namespace hysteron
{
  namespace Material
  {
    /// For implementations of UniaxialSpringLaw::update(): @p advance(i) for i = 0, ..., n - 1,
    /// each spring even if one fails (RuntimeError); returns n or the last i that failed, its
    /// message in @p failure.
    template <typename Advance>
    unsigned int
    update_each_spring(const unsigned int n, std::string &failure, const Advance &advance)
    {
      unsigned int failed = n;
      for (unsigned int i = 0; i < n; ++i)
        try
          {
            advance(i);
          }
        catch (const RuntimeError &error)
          {
            failure = error.what();
            failed  = i;
          }
      return failed;
    }

  } // namespace Material
} // namespace hysteron

#endif

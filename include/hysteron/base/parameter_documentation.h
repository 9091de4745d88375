#ifndef hysteron_base_parameter_documentation_h
#define hysteron_base_parameter_documentation_h

#include <deal.II/base/parameter_handler.h>

#include <ostream>

namespace hysteron
{
  /**
   * Write every declared parameter with its current value, default, allowed
   * values and documentation (which states the unit).
   * PRM: a parameter file that can be edited and run;
   * Markdown: one section per subsection, a table per section (doc/parameters.md).
   */
  enum class ParameterFormat
  {
    prm,
    markdown
  };

  void
  print_parameter_documentation(const dealii::ParameterHandler &prm,
                                std::ostream                   &out,
                                ParameterFormat                 format);
} // namespace hysteron

#endif

#ifndef hysteron_source_run_parameter_file_h
#define hysteron_source_run_parameter_file_h

#include <hysteron/base/exceptions.h>

#include <string>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace Run
  {
    /**
     * A parameter file read for ParameterHandler, with the checks deal.II does not
     * make (each an InputError naming the file and line):
     *  - `include other.prm` lines are expanded here, relative to the including
     *    file's directory (else to the working directory), at most 16 deep; a file that includes itself (directly or
     *    through others), a missing or non-text include is refused;
     *  - a UTF-8 byte-order mark is dropped and CR LF line ends are read as LF;
     *  - a file with a NUL byte (not text), larger than 16 MiB, or without a single
     *    `set` or `subsection` (an empty scene would silently run the defaults) is
     *    refused;
     *  - an entry set twice in the same subsection is refused with both lines (the
     *    second would silently win).
     * origin[k] is the file and line of line k + 1 of text, so that deal.II's
     * messages ("Line <n> of file <f>") can name the real place (locate()).
     */
    struct ParameterFile
    {
      std::string                                       name;
      std::string                                       text;
      std::vector<std::pair<std::string, unsigned int>> origin;

      static ParameterFile
      read(const std::string &filename);

      /// An InputError for deal.II's parse error @p message, at the file and line its
      /// "Line <n> of file <name>" refers to.
      InputError
      error(const std::string &message) const;
    };
  } // namespace Run
} // namespace hysteron

#endif

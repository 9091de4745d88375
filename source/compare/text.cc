#include <hysteron/base/exceptions.h>

#include "compare/text.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <iomanip>
#include <sstream>

namespace hysteron
{
  namespace Compare
  {
    namespace internal
    {
      std::string
      number(const double value, const int digits)
      {
        std::ostringstream s;
        s << std::setprecision(digits) << value + 0.0;
        return s.str();
      }

      std::string
      trim(const std::string &s)
      {
        const auto begin = s.find_first_not_of(" \t\r");
        if (begin == std::string::npos)
          return "";
        const auto end = s.find_last_not_of(" \t\r");
        return s.substr(begin, end - begin + 1);
      }

      std::vector<std::string>
      split(const std::string &line)
      {
        std::vector<std::string> fields;
        std::size_t              begin = 0;
        while (true)
          {
            const auto comma = line.find(',', begin);
            fields.push_back(trim(line.substr(begin, comma - begin)));
            if (comma == std::string::npos)
              return fields;
            begin = comma + 1;
          }
      }



      std::string
      format(const char *spec, const double value)
      {
        char buffer[64];
        std::snprintf(buffer, sizeof(buffer), spec, value + 0.0);
        return buffer;
      }



      void
      check_labels(const std::string &label_a, const std::string &label_b)
      {
        for (const std::string &label : {label_a, label_b})
          {
            require(!label.empty() && label != "diff" &&
                      std::all_of(label.begin(),
                                  label.end(),
                                  [](const char c) {
                                    return std::isalnum(static_cast<unsigned char>(c)) ||
                                           c == '_' || c == '-' || c == '.' || c == '+';
                                  }),
                    "comparison label '" + label + "'",
                    "must be a non-empty word of letters, digits and _-.+ (and not 'diff')");
          }
        require(label_a != label_b,
                "comparison labels",
                "the two runs need different labels (both are '" + label_a + "')");
      }
    } // namespace internal

  } // namespace Compare
} // namespace hysteron

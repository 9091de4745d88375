#ifndef hysteron_source_compare_text_h
#define hysteron_source_compare_text_h

#include <string>
#include <vector>

namespace hysteron
{
  namespace Compare
  {
    /// Text helpers shared by the files of the module.
    namespace internal
    {
      /// 15 significant digits (or @p digits), -0 printed as 0: the format of CsvWriter.
      std::string
      number(double value, int digits = 15);

      /// @p value printed with the printf conversion @p spec ("%.4g"), -0 as 0.
      std::string
      format(const char *spec, double value);

      /// @p s without leading and trailing blanks (spaces, tabs, CR).
      std::string
      trim(const std::string &s);

      /// The trimmed comma-separated fields of a CSV line.
      std::vector<std::string>
      split(const std::string &line);

      /// Labels become column names and plot titles: refuse all but two distinct short words.
      void
      check_labels(const std::string &label_a, const std::string &label_b);
    } // namespace internal

  } // namespace Compare
} // namespace hysteron

#endif

#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>

#include "run/parameter_file.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

namespace hysteron
{
  namespace Run
  {
    namespace fs = std::filesystem;

    namespace
    {
      /**
       * The position of the first byte that cannot be in a UTF-8 text file: a control
       * character other than tab, line feed, carriage return and form feed, or a byte
       * sequence that is not UTF-8 (a stray continuation byte, a truncated or overlong
       * sequence); npos for a text file.
       */
      std::size_t
      first_non_text(const std::string &s)
      {
        for (std::size_t i = 0; i < s.size();)
          {
            const unsigned char c = s[i];
            if (c < 0x80)
              {
                if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f') || c == 0x7f)
                  return i;
                ++i;
                continue;
              }
            // The lead byte gives the length; C0, C1 and F5..FF never occur.
            const std::size_t n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
            if (n == 0 || i + n > s.size())
              return i;
            for (std::size_t k = 1; k < n; ++k)
              if ((static_cast<unsigned char>(s[i + k]) & 0xc0) != 0x80)
                return i;
            i += n;
          }
        return std::string::npos;
      }

      constexpr std::size_t max_size  = 16u << 20;
      constexpr unsigned    max_depth = 16;

      std::string
      where(const std::string &file, const unsigned int line)
      {
        return file + ":" + std::to_string(line);
      }

      /// The words of a line without its comment (deal.II: '#' starts a comment).
      std::string
      strip(const std::string &line)
      {
        return dealii::Utilities::trim(line.substr(0, line.find('#')));
      }

      /// The files being read: canonical path and the name as written.
      using Stack = std::vector<std::pair<std::string, std::string>>;

      void
      append(ParameterFile &out, const std::string &file, Stack &stack)
      {
        std::error_code ec;
        const std::string canonical = fs::weakly_canonical(file, ec).string();
        for (std::size_t i = 0; i < stack.size(); ++i)
          if (stack[i].first == canonical)
            {
              std::string chain;
              for (std::size_t k = i; k < stack.size(); ++k)
                chain += stack[k].second + " -> ";
              throw InputError(file, "the parameter file includes itself (" + chain + file + ")");
            }
        require(stack.size() < max_depth,
                file,
                "includes are nested more than " + std::to_string(max_depth) + " deep");
        require(fs::is_regular_file(file, ec), file, "cannot include it: no such file");
        require(fs::file_size(file, ec) <= max_size,
                file,
                "the parameter file is larger than 16 MiB: not a scene");
        std::ifstream in(file, std::ios::binary);
        require(static_cast<bool>(in), file, "cannot open the parameter file for reading");
        std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (content.compare(0, 3, "\xEF\xBB\xBF") == 0)
          content.erase(0, 3); // a UTF-8 byte-order mark
        if (const auto nul = content.find('\0'); nul != std::string::npos)
          throw InputError(where(file, 1 + std::count(content.begin(), content.begin() + nul, '\n')),
                           "not a text file (a NUL byte): not a parameter file");
        if (const auto bad = first_non_text(content); bad != std::string::npos)
          {
            std::ostringstream byte;
            byte << "0x" << std::hex << std::uppercase
                 << static_cast<unsigned int>(static_cast<unsigned char>(content[bad]));
            throw InputError(where(file, 1 + std::count(content.begin(), content.begin() + bad, '\n')),
                             "not UTF-8 text (byte " + byte.str() +
                               "): not a parameter file, or one saved in another encoding (save it "
                               "as UTF-8)");
          }

        stack.emplace_back(canonical, file);
        std::istringstream lines(content);
        std::string        line;
        unsigned int       number = 0;
        while (std::getline(lines, line))
          {
            ++number;
            if (!line.empty() && line.back() == '\r')
              line.pop_back();
            const std::string words = strip(line);
            if (words.rfind("include", 0) == 0 &&
                (words.size() == 7 || words[7] == ' ' || words[7] == '\t'))
              {
                const std::string name = dealii::Utilities::trim(words.substr(7));
                require(!name.empty(), where(file, number), "`include` names no file");
                // Relative to the including file; else as given (the working directory).
                fs::path        path(name);
                std::error_code ec;
                if (path.is_relative() &&
                    (fs::exists(fs::path(file).parent_path() / path, ec) || !fs::exists(path, ec)))
                  path = fs::path(file).parent_path() / path;
                try
                  {
                    append(out, path.string(), stack);
                  }
                catch (const InputError &e)
                  {
                    throw InputError(where(file, number),
                                     "include " + name + ": " + e.where() + ": " + e.problem());
                  }
                continue;
              }
            out.text += line + '\n';
            out.origin.emplace_back(file, number);
            require(out.text.size() <= max_size,
                    file,
                    "the parameter file (with its includes) is larger than 16 MiB: not a scene");
          }
        stack.pop_back();
      }
    } // namespace

    ParameterFile
    ParameterFile::read(const std::string &filename)
    {
      ParameterFile file;
      Stack         stack;
      file.name = filename;
      append(file, filename, stack);

      // What deal.II accepts silently: no entry at all, an entry set twice.
      std::vector<std::string>                                       path;
      std::vector<std::pair<std::string, unsigned int>>              opened; // where each path entry began
      std::map<std::string, std::pair<std::string, unsigned int>> seen;
      bool                                                           any = false;
      std::istringstream                                             lines(file.text);
      std::string                                                    line, logical;
      unsigned int                                                   k = 0, first = 0;
      while (std::getline(lines, line))
        {
          ++k;
          // A trailing backslash continues the line (deal.II's rule).
          if (logical.empty())
            first = k;
          const std::string trimmed = dealii::Utilities::trim(line);
          if (!trimmed.empty() && trimmed.back() == '\\')
            {
              logical += trimmed.substr(0, trimmed.size() - 1) + ' ';
              continue;
            }
          logical += line;
          const std::string words = strip(logical);
          logical.clear();
          if (words.rfind("subsection", 0) == 0)
            {
              any = true;
              path.push_back(dealii::Utilities::trim(words.substr(10)));
              opened.push_back(file.origin[first - 1]);
            }
          else if (words == "end")
            {
              const auto &at = file.origin[first - 1];
              require(!path.empty(),
                      where(at.first, at.second),
                      "`end` without an open subsection (one `end` too many)");
              path.pop_back();
              opened.pop_back();
            }
          else if (words.rfind("set", 0) == 0 && words.size() > 3 &&
                   (words[3] == ' ' || words[3] == '\t') && words.find('=') != std::string::npos)
            {
              any = true;
              std::string entry = dealii::Utilities::trim(words.substr(3, words.find('=') - 3));
              // ParameterHandler treats runs of spaces in a name as one.
              entry = std::regex_replace(entry, std::regex("[ \t]+"), " ");
              std::string key;
              for (const auto &p : path)
                key += p + "/";
              key += entry;
              const auto &at = file.origin[first - 1];
              const auto  it = seen.find(key);
              if (it != seen.end())
                throw InputError(where(at.first, at.second),
                                 "'" + key + "' is set twice (first at " +
                                   where(it->second.first, it->second.second) +
                                   "); the second would silently replace the first: remove one");
              seen.emplace(key, at);
            }
        }
      if (!path.empty())
        throw InputError(where(opened.back().first, opened.back().second),
                         "`subsection " + path.back() + "` is never closed: an `end` is missing "
                         "inside it or after it");
      require(any,
              filename,
              "the parameter file sets nothing (no `set` and no `subsection`): an empty scene would "
              "run the defaults; see build/hysteron --print-parameters and prm/default.prm");
      return file;
    }

    InputError
    ParameterFile::error(const std::string &message) const
    {
      // deal.II: "Line <12> of file <scene.prm>: ..." (its count is of our expanded text;
      // one message lacks the closing '>').
      static const std::regex line_of_file(R"(Line <(\d+)> of file <[^>:]*>?:?\s*)");
      // A named subsection (Body, Boundary, Load, Material) whose name is not declared.
      static const std::regex undeclared(
        R"(no such subsection to be entered: (Body|Boundary|Load|Material) (.+)$)");
      std::string problem = message;
      std::smatch named;
      if (std::regex_search(message, named, undeclared))
        problem += " (a `subsection " + named[1].str() + " " + named[2].str() +
                   "` needs its name in the list: set " + named[1].str() + " names = " +
                   named[2].str() + ")";
      std::smatch m;
      if (!std::regex_search(problem, m, line_of_file))
        return InputError(name, problem);
      const unsigned long n = std::stoul(m[1].str());
      const std::string   place =
        n >= 1 && n <= origin.size() ? where(origin[n - 1].first, origin[n - 1].second) : name;
      return InputError(place, m.prefix().str() + m.suffix().str());
    }
  } // namespace Run
} // namespace hysteron

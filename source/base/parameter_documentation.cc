// property_tree pulls in boost/bind.hpp, which otherwise prints a deprecation note.
#define BOOST_BIND_GLOBAL_PLACEHOLDERS
#include <deal.II/base/utilities.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <hysteron/base/parameter_documentation.h>

#include <sstream>
#include <string>

namespace hysteron
{
  namespace
  {
    using Tree = boost::property_tree::ptree;

    bool
    is_entry(const Tree &node)
    {
      return node.get_child_optional("value") && node.get_child_optional("documentation");
    }

    /// deal.II's pattern description without the surrounding brackets.
    std::string
    allowed(const Tree &entry)
    {
      std::string p = entry.get<std::string>("pattern_description", "");
      if (p.size() >= 2 && p.front() == '[' && p.back() == ']')
        p = p.substr(1, p.size() - 2);
      return dealii::Utilities::trim(p);
    }

    std::string
    wrap_comment(const std::string &text, const std::string &indent)
    {
      std::string out;
      for (const auto &paragraph : dealii::Utilities::split_string_list(text, '\n'))
        for (const auto &line : dealii::Utilities::break_text_into_lines(paragraph, 76))
          out += indent + "# " + line + "\n";
      return out;
    }

    void
    print_prm(const Tree &node, std::ostream &out, const std::string &indent)
    {
      for (const auto &child : node)
        if (is_entry(child.second))
          {
            const Tree &e = child.second;
            out << wrap_comment(e.get<std::string>("documentation"), indent);
            out << indent << "#   default: " << e.get<std::string>("default_value")
                << "   allowed: " << allowed(e) << "\n";
            out << indent << "set " << child.first << " = " << e.get<std::string>("value")
                << "\n\n";
          }
      for (const auto &child : node)
        if (!is_entry(child.second))
          {
            out << indent << "subsection " << child.first << "\n";
            print_prm(child.second, out, indent + "  ");
            out << indent << "end\n\n";
          }
    }

    std::string
    escape_markdown(std::string s)
    {
      std::string out;
      for (const char c : s)
        {
          if (c == '|')
            out += "\\|";
          else if (c == '\n')
            out += "<br>";
          else
            out += c;
        }
      return out;
    }

    void
    print_markdown(const Tree &node, std::ostream &out, const std::string &path)
    {
      bool has_entries = false;
      for (const auto &child : node)
        has_entries = has_entries || is_entry(child.second);
      if (has_entries)
        {
          out << "\n## " << (path.empty() ? std::string("Top level") : "`" + path + "`") << "\n\n";
          out << "| Parameter | Default | Allowed values | Description |\n";
          out << "|---|---|---|---|\n";
          for (const auto &child : node)
            if (is_entry(child.second))
              {
                const Tree &e = child.second;
                out << "| `" << child.first << "` | `" << e.get<std::string>("default_value")
                    << "` | " << escape_markdown(allowed(e)) << " | "
                    << escape_markdown(e.get<std::string>("documentation")) << " |\n";
              }
        }
      for (const auto &child : node)
        if (!is_entry(child.second))
          print_markdown(child.second, out, path.empty() ? child.first : path + "/" + child.first);
    }
  } // namespace

  void
  print_parameter_documentation(const dealii::ParameterHandler &prm,
                                std::ostream                   &out,
                                const ParameterFormat           format)
  {
    std::stringstream json;
    prm.print_parameters(json, dealii::ParameterHandler::JSON);
    Tree tree;
    boost::property_tree::read_json(json, tree);
    if (format == ParameterFormat::prm)
      {
        out << "# hysteron parameters: every entry with its documentation (units in brackets),\n"
            << "# default and allowed values. Methods read only their own subsection.\n\n";
        print_prm(tree, out, "");
      }
    else
      print_markdown(tree, out, "");
  }
} // namespace hysteron

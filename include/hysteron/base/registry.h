#ifndef hysteron_base_registry_h
#define hysteron_base_registry_h

#include <deal.II/base/parameter_handler.h>

#include <hysteron/base/exceptions.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hysteron
{
  namespace Plugins
  {
    /**
     * A name -> factory map for one plugin interface (ASPECT style). Plugins
     * register themselves from a static object in their own translation unit
     * (see the HYSTERON_REGISTER_* macros), so adding a model means writing one
     * class and one registration line. The registry also provides the
     * Patterns::Selection string and the documentation used by
     * `hysteron --print-parameters`.
     */
    template <typename InterfaceType>
    class Registry
    {
    public:
      using Factory = std::function<std::unique_ptr<InterfaceType>()>;
      using Declare = std::function<void(dealii::ParameterHandler &)>;

      struct Entry
      {
        std::string name;
        std::string description;
        Declare     declare_parameters;
        Factory     factory;
      };

      /// Add a plugin. A second plugin with the same name is a programming error.
      static void
      register_plugin(const std::string &name,
                      const std::string &description,
                      const Declare     &declare_parameters,
                      const Factory     &factory)
      {
        auto &list = entries_storage();
        if (std::any_of(list.begin(), list.end(), [&](const Entry &e) { return e.name == name; }))
          throw std::logic_error("hysteron: two plugins registered under the name '" + name +
                                 "'");
        list.push_back(Entry{name, description, declare_parameters, factory});
        // Sorted by name: the order of static initialisation across translation
        // units is unspecified, the parameter documentation should not be.
        std::sort(list.begin(), list.end(), [](const Entry &a, const Entry &b) {
          return a.name < b.name;
        });
      }

      static const std::vector<Entry> &
      entries()
      {
        return entries_storage();
      }

      static bool
      has(const std::string &name)
      {
        const auto &list = entries_storage();
        return std::any_of(list.begin(), list.end(), [&](const Entry &e) { return e.name == name; });
      }

      /// "a|b|c", for Patterns::Selection.
      static std::string
      pattern_string()
      {
        std::string s;
        for (const auto &e : entries_storage())
          s += (s.empty() ? "" : "|") + e.name;
        return s;
      }

      /// A bullet list "name: description" for parameter documentation.
      static std::string
      documentation()
      {
        std::string s;
        for (const auto &e : entries_storage())
          s += "\n  '" + e.name + "': " + e.description;
        return s;
      }

      /// Every plugin declares its parameters (into the current subsection).
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        for (const auto &e : entries_storage())
          if (e.declare_parameters)
            e.declare_parameters(prm);
      }

      /// Create the plugin @p name; @p where is the parameter path for the error.
      static std::unique_ptr<InterfaceType>
      create(const std::string &name, const std::string &where)
      {
        for (const auto &e : entries_storage())
          if (e.name == name)
            return e.factory();
        throw InputError(where,
                         "no plugin named '" + name + "'; registered: " +
                           (pattern_string().empty() ? std::string("none") : pattern_string()));
      }

    private:
      static std::vector<Entry> &
      entries_storage()
      {
        static std::vector<Entry> list;
        return list;
      }
    };

    /// The object whose construction registers a plugin (used by the macros).
    template <typename InterfaceType, typename PluginType>
    struct Registration
    {
      Registration(const std::string &name, const std::string &description)
      {
        Registry<InterfaceType>::register_plugin(
          name,
          description,
          [](dealii::ParameterHandler &prm) { PluginType::declare_parameters(prm); },
          []() -> std::unique_ptr<InterfaceType> { return std::make_unique<PluginType>(); });
      }
    };
  } // namespace Plugins
} // namespace hysteron

#define HYSTERON_PLUGIN_CONCAT_IMPL(a, b) a##b
#define HYSTERON_PLUGIN_CONCAT(a, b) HYSTERON_PLUGIN_CONCAT_IMPL(a, b)

/**
 * Register the class template @p classname (templated on dim) under @p name in
 * the registry of interface template @p interface, for dim = 2 and 3.
 */
#define HYSTERON_REGISTER_DIM_PLUGIN(interface, classname, name, description)               \
  namespace                                                                                \
  {                                                                                        \
    const ::hysteron::Plugins::Registration<interface<2>, classname<2>>                     \
      HYSTERON_PLUGIN_CONCAT(hysteron_registration_2d_, __LINE__)(name, description);      \
    const ::hysteron::Plugins::Registration<interface<3>, classname<3>>                     \
      HYSTERON_PLUGIN_CONCAT(hysteron_registration_3d_, __LINE__)(name, description);      \
  }

#endif

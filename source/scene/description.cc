#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/scene/description.h>

#include <cmath>
#include <limits>
#include <sstream>

namespace hysteron
{
  SceneNames
  SceneNames::read(const dealii::ParameterHandler &prm)
  {
    SceneNames names;
    names.materials  = parse_names(prm.get("Material names"), "Material names");
    names.bodies     = parse_names(prm.get("Body names"), "Body names");
    names.boundaries = parse_names(prm.get("Boundary names"), "Boundary names");
    names.loads      = parse_names(prm.get("Load names"), "Load names");
    names.amplitudes = parse_names(prm.get("Amplitude names"), "Amplitude names");
    names.sets       = parse_names(prm.get("Set names"), "Set names");
    return names;
  }

  namespace
  {
    const char *coordinate_names[3] = {"x", "y", "z"};

    /// "x,y" or "x,y,z": the space variables of a function of position.
    template <int dim>
    std::string
    space_variables()
    {
      return dim == 2 ? "x,y" : "x,y,z";
    }

    /// The faces of the domain box listed in entry @p entry (`Faces`).
    template <int dim>
    std::vector<unsigned int>
    parse_faces(const Section &s, const std::string &entry)
    {
      std::vector<unsigned int> faces;
      for (const auto &f : s.get_list(entry))
        {
          bool found = false;
          for (unsigned int face = 0; face < 2 * dim; ++face)
            if (f == BoundaryDescription<dim>::face_name(face))
              {
                faces.push_back(face);
                found = true;
              }
          require(found,
                  s.where(entry),
                  "unknown face '" + f + "' (a " + std::to_string(dim) + "D box has " +
                    (dim == 2 ? "x-, x+, y-, y+" : "x-, x+, y-, y+, z-, z+") + ")");
        }
      return faces;
    }

    /// The set named in entry `Set` of @p s, or null if the entry is empty.
    template <int dim>
    const SetDescription<dim> *
    find_set(const Section &s, const std::vector<SetDescription<dim>> &sets)
    {
      const std::string name = dealii::Utilities::trim(s.get("Set"));
      if (name.empty())
        return nullptr;
      std::string known;
      for (const auto &set : sets)
        {
          if (set.name == name)
            return &set;
          known += (known.empty() ? "" : ", ") + set.name;
        }
      throw InputError(s.where("Set"),
                       "no set named '" + name + "' (`Set names` lists " +
                         (known.empty() ? std::string("none") : known) + ")");
    }
  } // namespace

  template <int dim>
  dealii::Tensor<1, dim>
  evaluate_in_time(const dealii::FunctionParser<1> &f, const double t)
  {
    dealii::Tensor<1, dim> v;
    const dealii::Point<1> time(t);
    for (unsigned int d = 0; d < dim; ++d)
      v[d] = f.value(time, d);
    return v;
  }

  template <int dim>
  dealii::Tensor<1, dim>
  integrate_in_time(const dealii::FunctionParser<1> &f,
                    const double                     t0,
                    const double                     t1,
                    const Amplitude                 *amplitude)
  {
    // f(t) a(t) on [s0, s1], 3-point Gauss-Legendre.
    const auto piece = [&](const double s0, const double s1) {
      const double           m = 0.5 * (s0 + s1), r = 0.5 * (s1 - s0), g = std::sqrt(0.6);
      dealii::Tensor<1, dim> sum;
      for (const auto &[x, w] : {std::make_pair(m - g * r, 5.0 / 9.0),
                                 std::make_pair(m, 8.0 / 9.0),
                                 std::make_pair(m + g * r, 5.0 / 9.0)})
        sum += (w * (amplitude ? amplitude->value(x) : 1.0)) * evaluate_in_time<dim>(f, x);
      return r * sum;
    };
    if (!amplitude)
      return piece(t0, t1);
    dealii::Tensor<1, dim> sum;
    double                 s0 = t0;
    for (const double s1 : amplitude->breakpoints(t0, t1))
      {
        sum += piece(s0, s1);
        s0 = s1;
      }
    return sum + piece(s0, t1);
  }

  namespace
  {
    /// f(t) a(t) (a = 1 without an amplitude): every amplified history of t.
    template <int dim>
    dealii::Tensor<1, dim>
    amplified(const dealii::FunctionParser<1> &f, const Amplitude *amplitude, const double t)
    {
      return evaluate_in_time<dim>(f, t) * (amplitude ? amplitude->value(t) : 1.0);
    }
  } // namespace

  template <int dim>
  dealii::Tensor<1, dim>
  BodyDescription<dim>::rigid_velocity_at(const double t) const
  {
    return amplified<dim>(*rigid_velocity, amplitude.get(), t);
  }

  template <int dim>
  dealii::Tensor<1, dim>
  BodyDescription<dim>::rigid_displacement(const double t0, const double t1) const
  {
    return integrate_in_time<dim>(*rigid_velocity, t0, t1, amplitude.get());
  }

  template <int dim>
  dealii::Tensor<1, dim>
  BoundaryDescription<dim>::velocity_at(const double t) const
  {
    return amplified<dim>(*velocity, amplitude.get(), t);
  }



  template <int dim>
  dealii::Tensor<1, dim>
  BodyDescription<dim>::velocity_at(const dealii::Point<dim> &p) const
  {
    dealii::Tensor<1, dim> v;
    if (initial_velocity)
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = initial_velocity->value(p, d);
    return v;
  }

  template <int dim>
  double
  BodyDescription<dim>::thickness_at(const dealii::Point<dim> &p) const
  {
    if (dim != 2)
      return 1.0;
    if (!thickness_function)
      return thickness;
    const double t = thickness_function->value(p);
    if (!(t > 0) || !std::isfinite(t))
      {
        std::ostringstream s;
        s.precision(6);
        s << "the expression '" << thickness_expression << "' evaluates to " << t << " at x = " << p[0]
          << ", y = " << p[1] << " in body '" << name << "': the thickness must be > 0 wherever the body has material";
        throw InputError(thickness_where, s.str());
      }
    return t;
  }

  template <int dim>
  std::string
  BoundaryDescription<dim>::face_name(const unsigned int face)
  {
    return std::string(coordinate_names[face / 2]) + (face % 2 == 0 ? "-" : "+");
  }

  template <int dim>
  bool
  BoundaryDescription<dim>::prescribes(const dealii::Point<dim> &x,
                                       const unsigned int        c,
                                       const dealii::Point<dim> &lower,
                                       const dealii::Point<dim> &upper,
                                       const double              tolerance) const
  {
    if (type == Type::wall || type == Type::absorbing)
      return false; // no kinematic constraint
    for (const unsigned int face : faces)
      {
        const unsigned int d = face / 2;
        if (std::abs(x[d] - (face % 2 == 0 ? lower[d] : upper[d])) <= tolerance &&
            (type == Type::fixed || (type == Type::roller ? c == d : bool(components[c]))))
          return true;
      }
    return has_region && region.contains(x, tolerance) && (type == Type::fixed || components[c]);
  }

  template <int dim>
  dealii::Tensor<1, dim>
  BoundaryDescription<dim>::displacement_increment(const double              t0,
                                                   const double              t1,
                                                   const dealii::Point<dim> &x) const
  {
    if (!displacement)
      return integrate_in_time<dim>(*velocity, t0, t1, amplitude.get());
    // u(x, t1) a(t1) - u(x, t0) a(t0).
    const double           a1 = amplitude ? amplitude->value(t1) : 1.0;
    const double           a0 = amplitude ? amplitude->value(t0) : 1.0;
    dealii::Tensor<1, dim> u;
    displacement->set_time(t1);
    for (unsigned int d = 0; d < dim; ++d)
      u[d] = a1 * displacement->value(x, d);
    displacement->set_time(t0);
    for (unsigned int d = 0; d < dim; ++d)
      u[d] -= a0 * displacement->value(x, d);
    return u;
  }



  template <int dim>
  dealii::Tensor<1, dim>
  BoundaryDescription<dim>::step_velocity(const double              t,
                                          const double              dt,
                                          const dealii::Point<dim> &x) const
  {
    if (velocity)
      return velocity_at(t);
    Assert(dt > 0, dealii::ExcMessage("a displacement needs the step length"));
    return displacement_increment(std::max(t - dt, 0.0), t, x) / dt;
  }



  template <int dim>
  dealii::Tensor<1, dim>
  LoadDescription<dim>::value_at(const double t) const
  {
    return amplified<dim>(*value, amplitude.get(), t);
  }

  template <int dim>
  dealii::Tensor<1, dim>
  parse_vector(const std::string &text, const std::string &where)
  {
    dealii::Tensor<1, dim> v;
    if (dealii::Utilities::trim(text).empty())
      return v;
    const auto items = dealii::Utilities::split_string_list(text, ',');
    require(items.size() == dim,
            where,
            "'" + text + "' has " + std::to_string(items.size()) + " components; a " +
              std::to_string(dim) + "D scene needs " + std::to_string(dim));
    for (unsigned int d = 0; d < dim; ++d)
      {
        try
          {
            v[d] = dealii::Utilities::string_to_double(items[d]);
          }
        catch (const dealii::ExceptionBase &)
          {
            throw InputError(where, "cannot read the number '" + items[d] + "'");
          }
        require(std::isfinite(v[d]), where, "'" + items[d] + "' is not finite");
      }
    return v;
  }

  template <int dim>
  std::vector<BodyDescription<dim>>
  parse_bodies(dealii::ParameterHandler &prm, const SceneNames &names, const AmplitudeMap &amplitudes)
  {
    std::vector<BodyDescription<dim>> bodies;
    for (const auto &name : names.bodies)
      {
        Section             s(prm, {"Body " + name});
        BodyDescription<dim> b;
        b.name     = name;
        b.material = dealii::Utilities::trim(s.get("Material"));
        require(!dealii::Utilities::trim(s.get("Shape")).empty(),
                s.where("Shape"),
                "a body needs a shape, e.g. 'rectangle(0, 0, 1, 1)'");
        b.shape              = Geometry::Region<dim>::parse(s.get("Shape"), s.where("Shape"));
        b.particles_per_cell = s.get_integer("Particles per cell");
        // A number is a constant thickness; anything else an expression in x, y.
        const std::string thickness = dealii::Utilities::trim(s.get("Thickness"));
        char             *end       = nullptr;
        std::strtod(thickness.c_str(), &end);
        if (!thickness.empty() && end == thickness.c_str() + thickness.size())
          b.thickness = s.get_positive("Thickness");
        else
          {
            require(!thickness.empty(), s.where("Thickness"), "the thickness is empty: give a number or a function of x, y");
            b.thickness_function =
              parse_function<dim>(thickness, space_variables<dim>(), false, s.where("Thickness"));
            b.thickness_expression = thickness;
            b.thickness_where      = s.where("Thickness");
            b.thickness            = std::numeric_limits<double>::quiet_NaN(); // read thickness_at()
          }
        if (!dealii::Utilities::trim(s.get("Initial velocity")).empty())
          b.initial_velocity = parse_vector_function<dim>(s.get("Initial velocity"),
                                                          dim,
                                                          space_variables<dim>(),
                                                          false,
                                                          s.where("Initial velocity"));
        b.rigid = s.get_bool("Rigid");
        if (b.rigid)
          {
            b.rigid_velocity =
              parse_vector_function<1>(s.get("Velocity"), dim, "t", false, s.where("Velocity"));
            b.amplitude = find_amplitude(s, "Amplitude", amplitudes);
          }
        else
          {
            require(dealii::Utilities::trim(s.get("Velocity")).empty(),
                    s.where("Velocity"),
                    "only rigid bodies have a prescribed velocity (set Rigid = true, or use "
                    "`Initial velocity`)");
            require(dealii::Utilities::trim(s.get("Amplitude")).empty(),
                    s.where("Amplitude"),
                    "an amplitude multiplies the `Velocity` of a rigid body; this body is not rigid");
          }
        bodies.push_back(std::move(b));
      }
    return bodies;
  }

  template <int dim>
  std::vector<SetDescription<dim>>
  parse_sets(dealii::ParameterHandler &prm, const SceneNames &names)
  {
    std::vector<SetDescription<dim>> sets;
    for (const auto &name : names.sets)
      {
        Section             s(prm, {"Set " + name});
        SetDescription<dim> set;
        set.name       = name;
        set.faces      = parse_faces<dim>(s, "Faces");
        set.has_region = !dealii::Utilities::trim(s.get("Region")).empty();
        if (set.has_region)
          set.region = Geometry::Region<dim>::parse(s.get("Region"), s.where("Region"));
        set.physical_group = dealii::Utilities::trim(s.get("Physical group"));
        require(set.physical_group.empty() || (set.faces.empty() && !set.has_region),
                s.where("Physical group"),
                "a set is a Gmsh physical group or faces and a region, not both");
        require(!set.physical_group.empty() || !set.faces.empty() || set.has_region,
                s.where("Region"),
                "the set is empty: give `Faces`, a `Region` or a `Physical group`");
        sets.push_back(std::move(set));
      }
    return sets;
  }

  template <int dim>
  std::vector<BoundaryDescription<dim>>
  parse_boundaries(dealii::ParameterHandler               &prm,
                   const SceneNames                       &names,
                   const AmplitudeMap                     &amplitudes,
                   const std::vector<SetDescription<dim>> &sets)
  {
    using Description = BoundaryDescription<dim>;
    std::vector<Description> boundaries;
    for (const auto &name : names.boundaries)
      {
        Section     s(prm, {"Boundary " + name});
        Description b;
        b.name                 = name;
        const std::string type = s.get("Type");
        b.type                 = type == "fixed"    ? Description::Type::fixed :
                                 type == "roller"   ? Description::Type::roller :
                                 type == "wall"     ? Description::Type::wall :
                                 type == "velocity" ? Description::Type::velocity :
                                 type == "absorbing" ? Description::Type::absorbing :
                                                      Description::Type::displacement;
        b.faces      = parse_faces<dim>(s, "Faces");
        b.has_region = !dealii::Utilities::trim(s.get("Region")).empty();
        if (b.has_region)
          b.region = Geometry::Region<dim>::parse(s.get("Region"), s.where("Region"));
        if (const auto *set = find_set<dim>(s, sets))
          {
            require(b.faces.empty() && !b.has_region,
                    s.where("Set"),
                    "give either a `Set` or `Faces`/`Region`, not both");
            b.set            = set->name;
            b.faces          = set->faces;
            b.region         = set->region;
            b.has_region     = set->has_region;
            b.physical_group = set->physical_group;
          }
        require(!b.faces.empty() || b.has_region || !b.physical_group.empty(),
                s.where("Faces"),
                "a boundary condition needs `Faces`, a `Region` or a `Set`");
        if (b.type == Description::Type::roller || b.type == Description::Type::wall)
          require(!b.has_region && !b.faces.empty(),
                  s.where(b.set.empty() ? "Region" : "Set"),
                  "roller and wall conditions act on `Faces` (the face gives the normal), "
                  "not on a region or a physical group");
        if (b.type == Description::Type::absorbing)
          require(!b.has_region && (!b.faces.empty() || !b.physical_group.empty()),
                  s.where(b.set.empty() ? "Region" : "Set"),
                  "an absorbing boundary acts on boundary faces, whose normal it needs: give "
                  "`Faces` or a `Set` of boundary faces (a Gmsh physical group), not a region");
        b.components.assign(dim, true);
        if (b.type == Description::Type::velocity || b.type == Description::Type::displacement)
          {
            const auto list = s.get_list("Components");
            if (!(list.size() == 1 && list[0] == "all"))
              {
                b.components.assign(dim, false);
                for (const auto &c : list)
                  {
                    bool found = false;
                    for (unsigned int d = 0; d < dim; ++d)
                      if (c == coordinate_names[d])
                        b.components[d] = found = true;
                    require(found,
                            s.where("Components"),
                            "unknown component '" + c + "' (use " +
                              (dim == 2 ? "x, y" : "x, y, z") + " or all)");
                  }
              }
            if (b.type == Description::Type::velocity)
              b.velocity =
                parse_vector_function<1>(s.get("Velocity"), dim, "t", false, s.where("Velocity"));
            else
              b.displacement = parse_vector_function<dim>(s.get("Displacement"),
                                                          dim,
                                                          space_variables<dim>() + ",t",
                                                          true,
                                                          s.where("Displacement"));
            b.amplitude = find_amplitude(s, "Amplitude", amplitudes);
          }
        else
          require(dealii::Utilities::trim(s.get("Amplitude")).empty(),
                  s.where("Amplitude"),
                  "an amplitude multiplies a `Velocity` or a `Displacement`; a " + type +
                    " condition has neither");
        boundaries.push_back(std::move(b));
      }
    return boundaries;
  }

  template <int dim>
  std::vector<LoadDescription<dim>>
  parse_loads(dealii::ParameterHandler               &prm,
              const SceneNames                       &names,
              const AmplitudeMap                     &amplitudes,
              const std::vector<SetDescription<dim>> &sets)
  {
    std::vector<LoadDescription<dim>> loads;
    for (const auto &name : names.loads)
      {
        Section              s(prm, {"Load " + name});
        LoadDescription<dim> l;
        l.name = name;
        l.type = s.get("Type") == "force" ? LoadDescription<dim>::Type::force :
                                            LoadDescription<dim>::Type::traction;
        const bool has_region = !dealii::Utilities::trim(s.get("Region")).empty();
        if (const auto *set = find_set<dim>(s, sets))
          {
            require(!has_region, s.where("Set"), "give either a `Set` or a `Region`, not both");
            require(set->has_region || !set->physical_group.empty(),
                    s.where("Set"),
                    "set '" + set->name +
                      "' has only box faces; a load needs a set with a Region or a physical group");
            l.set            = set->name;
            l.region         = set->region;
            l.physical_group = set->physical_group;
          }
        else
          {
            require(has_region, s.where("Region"), "a load needs the region of the points it acts on (or a `Set`)");
            l.region = Geometry::Region<dim>::parse(s.get("Region"), s.where("Region"));
          }
        l.value     = parse_vector_function<1>(s.get("Value"), dim, "t", false, s.where("Value"));
        l.amplitude = find_amplitude(s, "Amplitude", amplitudes);
        loads.push_back(std::move(l));
      }
    return loads;
  }

#define HYSTERON_INSTANTIATE(dim)                                                              \
  template struct BodyDescription<dim>;                                                         \
  template struct BoundaryDescription<dim>;                                                     \
  template struct LoadDescription<dim>;                                                         \
  template std::vector<SetDescription<dim>> parse_sets<dim>(dealii::ParameterHandler &,         \
                                                            const SceneNames &);                \
  template std::vector<BodyDescription<dim>> parse_bodies<dim>(dealii::ParameterHandler &,      \
                                                               const SceneNames &,              \
                                                               const AmplitudeMap &);           \
  template std::vector<BoundaryDescription<dim>> parse_boundaries<dim>(                         \
    dealii::ParameterHandler &, const SceneNames &, const AmplitudeMap &,                       \
    const std::vector<SetDescription<dim>> &);                                                  \
  template std::vector<LoadDescription<dim>> parse_loads<dim>(                                  \
    dealii::ParameterHandler &, const SceneNames &, const AmplitudeMap &,                       \
    const std::vector<SetDescription<dim>> &);                                                  \
  template dealii::Tensor<1, dim> parse_vector<dim>(const std::string &, const std::string &);  \
  template dealii::Tensor<1, dim> evaluate_in_time<dim>(const dealii::FunctionParser<1> &,      \
                                                        double);                               \
  template dealii::Tensor<1, dim> integrate_in_time<dim>(const dealii::FunctionParser<1> &,     \
                                                         double,                               \
                                                         double,                               \
                                                         const Amplitude *);

  HYSTERON_INSTANTIATE(2)
  HYSTERON_INSTANTIATE(3)
#undef HYSTERON_INSTANTIATE
} // namespace hysteron

// Conditions that meet: two boundary conditions on one node and component must prescribe the
// same motion there (one rule for the FEM, the RBSN and the MPM).
#include <deal.II/base/mpi.h>

#include <hysteron/base/exceptions.h>
#include <hysteron/scene/description.h>

#include <cmath>
#include <sstream>

namespace hysteron
{
  template <int dim>
  std::string
  BoundaryDescription<dim>::where() const
  {
    return "Boundary " + name + (!set.empty() ? "/Set" : has_region ? "/Region" : "/Faces");
  }



  template <int dim>
  std::string
  BoundaryDescription<dim>::type_name() const
  {
    switch (type)
      {
        case Type::fixed:
          return "fixed";
        case Type::roller:
          return "roller";
        case Type::wall:
          return "wall";
        case Type::velocity:
          return "velocity";
        case Type::absorbing:
          return "absorbing";
        default:
          return "displacement";
      }
  }



  template <int dim>
  ConditionOverlaps<dim>::ConditionOverlaps(const std::vector<BoundaryDescription<dim>> &conditions,
                                            const double                                 end_time,
                                            const std::string                           &node)
    : conditions(conditions)
    , end_time(end_time)
    , node(node)
  {}



  template <int dim>
  void
  ConditionOverlaps<dim>::check(const unsigned int                   a,
                                const unsigned int                   b,
                                const std::string                   &component,
                                const dealii::Point<dim>            &x,
                                const std::function<double(double)> &g_a,
                                const std::function<double(double)> &g_b)
  {
    using Type = typename BoundaryDescription<dim>::Type;
    if (a == b || !problem.empty())
      return;
    const auto &A = conditions[a], &B = conditions[b];
    // Fixed and roller hold the component at zero: they always agree.
    const auto zero = [](const BoundaryDescription<dim> &d) { return d.type == Type::fixed || d.type == Type::roller; };
    if (zero(A) && zero(B))
      return;
    const bool anywhere = A.type != Type::displacement && B.type != Type::displacement;
    const auto key      = std::make_tuple(a, b, component);
    if (anywhere)
      if (const auto known = compared.find(key); known != compared.end() && known->second)
        return;
    // The displacements since t = 0 at t_k = k T / 100: equal to 1e-9 of their size (a
    // velocity's integral and the same motion given as a displacement agree to round-off).
    constexpr unsigned int n = 100;
    std::vector<double>    u_a(n), u_b(n);
    double                 size = 0;
    for (unsigned int k = 0; k < n; ++k)
      {
        const double t = (k + 1) * end_time / n;
        u_a[k]         = g_a(t);
        u_b[k]         = g_b(t);
        size           = std::max({size, std::abs(u_a[k]), std::abs(u_b[k])});
      }
    for (unsigned int k = 0; k < n; ++k)
      if (!(std::abs(u_a[k] - u_b[k]) <= 1e-9 * size))
        {
          std::ostringstream m;
          m.precision(6);
          m << "prescribes the " << component << " displacement of the " << node << " at (";
          for (unsigned int d = 0; d < dim; ++d)
            m << (d > 0 ? ", " : "") << x[d];
          m << ") differently from " << A.where() << ", which selects it too (" << A.type_name()
            << " condition '" << A.name << "': " << u_a[k] << ", " << B.type_name() << " condition '"
            << B.name << "': " << u_b[k] << " at t = " << (k + 1) * end_time / n
            << " s). A node follows one prescription: two conditions may share nodes only "
               "where they prescribe the same motion (e.g. two fixed faces). Make the faces or "
               "regions of Boundary "
            << A.name << " and Boundary " << B.name << " disjoint, or drop the component from one of them";
          where   = B.where();
          problem = m.str();
          return;
        }
    if (anywhere)
      compared[key] = true;
  }



  template <int dim>
  void
  ConditionOverlaps<dim>::check(const unsigned int        a,
                                const unsigned int        b,
                                const unsigned int        c,
                                const dealii::Point<dim> &x)
  {
    static const char *const names[3] = {"x", "y", "z"};
    const auto         history  = [&](const unsigned int i) {
      return [&, i](const double t) {
        const auto &d = conditions[i];
        return d.velocity || d.displacement ? d.displacement_increment(0, t, x)[c] : 0.0;
      };
    };
    check(a, b, names[c], x, history(a), history(b));
  }



  template <int dim>
  void
  ConditionOverlaps<dim>::throw_if_any(const MPI_Comm comm) const
  {
    const auto wheres   = dealii::Utilities::MPI::all_gather(comm, where);
    const auto problems = dealii::Utilities::MPI::all_gather(comm, problem);
    for (unsigned int r = 0; r < problems.size(); ++r)
      if (!problems[r].empty())
        throw InputError(wheres[r], problems[r]);
  }



  template std::string BoundaryDescription<2>::where() const;
  template std::string BoundaryDescription<3>::where() const;
  template std::string BoundaryDescription<2>::type_name() const;
  template std::string BoundaryDescription<3>::type_name() const;
  template class ConditionOverlaps<2>;
  template class ConditionOverlaps<3>;
} // namespace hysteron

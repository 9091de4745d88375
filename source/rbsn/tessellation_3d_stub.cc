// Temporary: the 3D tessellation is being built on its own branch.
#include <hysteron/base/exceptions.h>
#include <hysteron/rbsn/tessellation.h>

namespace hysteron
{
  namespace RBSN
  {
    std::vector<dealii::Point<3>>
    poisson_disk_points(const Geometry::Region<3> &, const Spacing<3> &, const std::vector<dealii::Point<3>> &,
                        const std::uint64_t, const std::string &where)
    {
      throw InputError(where, "3D networks are not available yet");
    }

    std::vector<dealii::Point<3>>
    boundary_points(const Geometry::Region<3> &, const Spacing<3> &, const double, const std::uint64_t)
    {
      throw InputError("Dimension", "3D networks are not available yet");
    }

    Tessellation<3>
    voronoi(const std::vector<dealii::Point<3>> &, const std::vector<const Geometry::Region<3> *> &, const double,
            const std::string &where, const std::vector<bool> &)
    {
      throw InputError(where, "3D networks are not available yet");
    }
  } // namespace RBSN
} // namespace hysteron

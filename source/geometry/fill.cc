// Material points filling a region: the centres of the sub-cells of a lattice that lie in
// it, over the whole lattice or a box of its cells.
#include <deal.II/base/exceptions.h>

#include <hysteron/geometry/region.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace hysteron
{
  namespace Geometry
  {
    template <int dim>
    double
    fill_particle_volume(const FillLattice<dim> &lattice, const unsigned int k)
    {
      AssertThrow(k >= 1, dealii::ExcMessage("fill: k must be >= 1"));
      return std::pow(lattice.h / k, dim);
    }



    template <int dim>
    std::vector<dealii::Point<dim>>
    fill(const Region<dim>                                                    &region,
         const FillLattice<dim>                                               &lattice,
         const unsigned int                                                    k,
         const std::array<unsigned int, dim>                                  &range_first,
         const std::array<unsigned int, dim>                                  &range_last,
         const std::function<bool(const std::array<unsigned int, dim> &cell)> &keep_cell)
    {
      AssertThrow(lattice.h > 0 && std::isfinite(lattice.h),
                  dealii::ExcMessage("fill: the lattice spacing h must be > 0"));
      AssertThrow(k >= 1, dealii::ExcMessage("fill: k must be >= 1"));
      std::vector<dealii::Point<dim>> points;
      if (region.is_empty())
        return points;

      const double h         = lattice.h;
      const double tolerance = 1e-12 * h;
      const double margin    = 1e-9 * h; // visiting one cell too many is harmless

      // The range of cells [first, last] whose box intersects the bounding box.
      const auto                    corners = region.bounding_box().get_boundary_points();
      std::array<unsigned int, dim> first, last;
      for (unsigned int d = 0; d < dim; ++d)
        {
          if (lattice.n_cells[d] == 0)
            return points;
          const double n  = lattice.n_cells[d];
          const double lo = (corners.first[d] - margin - lattice.origin[d]) / h - 1;
          const double hi = (corners.second[d] + margin - lattice.origin[d]) / h;
          const double f  = std::max<double>(range_first[d], std::ceil(std::min(lo, n)));
          const double l  = std::min<double>(std::min<double>(n - 1, range_last[d]),
                                             std::floor(std::max(hi, -1.0)));
          if (l < f)
            return points;
          first[d] = static_cast<unsigned int>(f);
          last[d]  = static_cast<unsigned int>(l);
        }

      const double                  sub_h = h / k;
      std::array<unsigned int, dim> cell  = first;
      std::array<unsigned int, dim> sub{};
      while (true)
        {
          if (!keep_cell || keep_cell(cell))
            {
              sub.fill(0);
              while (true)
                {
                  dealii::Point<dim> p;
                  for (unsigned int d = 0; d < dim; ++d)
                    p[d] = lattice.origin[d] + cell[d] * h + (sub[d] + 0.5) * sub_h;
                  if (region.contains(p, tolerance))
                    points.push_back(p);
                  unsigned int d = 0;
                  for (; d < dim; ++d)
                    if (++sub[d] < k)
                      break;
                    else
                      sub[d] = 0;
                  if (d == dim)
                    break;
                }
            }
          unsigned int d = 0;
          for (; d < dim; ++d)
            if (++cell[d] <= last[d])
              break;
            else
              cell[d] = first[d];
          if (d == dim)
            break;
        }
      return points;
    }



    template <int dim>
    std::vector<dealii::Point<dim>>
    fill(const Region<dim> &region, const FillLattice<dim> &lattice, const unsigned int k)
    {
      std::array<unsigned int, dim> first{}, last;
      for (unsigned int d = 0; d < dim; ++d)
        last[d] = lattice.n_cells[d] > 0 ? lattice.n_cells[d] - 1 : 0;
      return fill<dim>(region, lattice, k, first, last);
    }



#define HYSTERON_INSTANTIATE(dim)                                                               \
  template struct FillLattice<dim>;                                                             \
  template std::vector<dealii::Point<dim>> fill(const Region<dim> &,                            \
                                                const FillLattice<dim> &,                       \
                                                unsigned int);                                  \
  template std::vector<dealii::Point<dim>> fill<dim>(                                           \
    const Region<dim> &,                                                                        \
    const FillLattice<dim> &,                                                                   \
    unsigned int,                                                                               \
    const std::array<unsigned int, dim> &,                                                      \
    const std::array<unsigned int, dim> &,                                                      \
    const std::function<bool(const std::array<unsigned int, dim> &)> &);                        \
  template double fill_particle_volume(const FillLattice<dim> &, unsigned int);

    HYSTERON_INSTANTIATE(2)
    HYSTERON_INSTANTIATE(3)
#undef HYSTERON_INSTANTIATE
  } // namespace Geometry
} // namespace hysteron

#include "cell_kernels.h"

namespace hysteron
{
  namespace FEM
  {
    template <int dim>
    void
    CellKernels<dim>::external_forces(const CellIterator                        &cell,
                                      const CellHistory<dim>                    &h,
                                      const dealii::Tensor<1, dim>              &g,
                                      const std::vector<dealii::Tensor<1, dim>> &value,
                                      dealii::Vector<double>                    &f,
                                      CellScratch<dim>                          &scratch) const
    {
      // Volume loads act at the points in their region, tractions on the boundary faces
      // whose centre lies in it (load values already scaled); in 2D the face weights take
      // the thickness of the body there (the cell weights hold it already).
      using LoadSet                    = typename Solver<dim>::LoadSet;
      const dealii::FEValues<dim> &fv  = scratch.fv;
      dealii::FEFaceValues<dim>   &ffv = scratch.ffv;
      const unsigned int n_loads       = solver.load_sets.size();
      const std::size_t  first         = cell->active_cell_index() * n_loads;
      f                                = 0;
      for (unsigned int q = 0; q < n_q; ++q)
        {
          dealii::Tensor<1, dim> b = h.material->density() * g;
          for (unsigned int l = 0; l < n_loads; ++l)
            if (solver.cell_in_load[first + l] && solver.load_sets[l].kind == LoadSet::Kind::volume &&
                solver.in_region(l, h.point[q]))
              b += value[l];
          for (unsigned int i = 0; i < n; ++i)
            f[i] += fv.shape_value(i, q) * b[comp[i]] * h.weight[q];
        }
      const auto &body = scene.body_descriptions()[h.body];
      for (unsigned int l = 0; l < n_loads; ++l)
        if (solver.cell_in_load[first + l] && solver.load_sets[l].kind == LoadSet::Kind::traction)
          for (const unsigned int face : cell->face_indices())
            if (solver.loads_face(l, cell, face))
              {
                ffv.reinit(cell, face);
                for (unsigned int q = 0; q < ffv.n_quadrature_points; ++q)
                  for (unsigned int i = 0; i < n; ++i)
                    f[i] += ffv.shape_value(i, q) * value[l][comp[i]] * ffv.JxW(q) *
                            scene.thickness_at(body, ffv.quadrature_point(q));
              }
    }



    template class CellKernels<2>;
    template class CellKernels<3>;
  } // namespace FEM
} // namespace hysteron

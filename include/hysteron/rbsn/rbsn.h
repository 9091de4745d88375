#ifndef hysteron_rbsn_rbsn_h
#define hysteron_rbsn_rbsn_h

#include <hysteron/run/stepping_method.h>

#include <memory>
#include <string>

namespace hysteron
{
  namespace RBSN
  {
    template <int dim>
    class Model;

    /**
     * The Rigid-Body-Spring Network (`set Method = rbsn`, dissertation chapter
     * 3; doc/rbsn.md, doc/rbsn3d.md): the scene's bodies are cut into Voronoi cells
     * around seeded random points; every cell is a rigid body with the DoFs of its
     * nucleus (2D: u, v, theta; 3D: three translations and three rotations), and
     * every common facet of two cells carries zero-length springs (2D: normal,
     * tangential, rotational; 3D: normal, two shear, two bending, torsion) with the
     * Voronoi scaled stiffnesses of eq. 3.9 and Bouc-Wen laws (eq. 3.32-3.42).
     * Static, quasi-static (Newton) and dynamic (Newmark / HHT with Newton, or
     * SUNDIALS' variable-order IDA) analyses, and brittle fracture of the facets
     * (Mohr-Coulomb with a tension cut-off, eq. 3.49-3.51).
     *
     * The work is done by Model<dim>, distributed over the MPI ranks.
     */
    template <int dim>
    class Solver : public Run::SteppingMethod<dim>
    {
    public:
      Solver();
      ~Solver() override;

      static void
      declare_parameters(dealii::ParameterHandler &prm);

      void
      setup() override;

      std::string
      summary() const override;

      std::string
      checkpoint_unsupported() const override;

    protected:
      void
      parse_parameters(dealii::ParameterHandler &prm) override;

      // The driver's hooks, forwarded to the Model.
      std::string
      label() const override
      {
        return "rbsn";
      }
      double
      size_of_state() const override;
      std::string
      field_name() const override
      {
        return "rbsn";
      }
      void
      open_outputs() override;
      void
      initialize() override;
      double
      propose_step(double t) override;
      bool
      advance(double &t, double dt) override;
      void
      write_rows(double t) override;
      void
      write_fields(double t, Output::FieldWriter &writer) override;
      void
      finish(double t) override;
      void
      save(CheckpointWriter &global, CheckpointWriter &rank, const CheckpointDirectory &directory) const override;
      void
      load(CheckpointReader &global, std::vector<CheckpointReader> &rank_parts, const CheckpointDirectory &directory) override;

    private:
      std::unique_ptr<Model<dim>> model;
    };
  } // namespace RBSN
} // namespace hysteron

#endif

#ifndef hysteron_scene_description_h
#define hysteron_scene_description_h

#include <deal.II/base/function_parser.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <hysteron/base/parameters.h>
#include <hysteron/geometry/region.h>
#include <hysteron/scene/amplitude.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

namespace hysteron
{
  /**
   * The names of the named subsections of a scene, read in the pre-pass:
   * `Material names`, `Body names`, `Boundary names`, `Load names`, `Amplitude names`,
   * `Set names`. Each name N gets `subsection Material N` (resp. `Body N`, `Boundary N`,
   * `Load N`, `Amplitude N`, `Set N`).
   */
  struct SceneNames
  {
    std::vector<std::string> materials;
    std::vector<std::string> bodies;
    std::vector<std::string> boundaries;
    std::vector<std::string> loads;
    std::vector<std::string> amplitudes;
    std::vector<std::string> sets;

    /// Read the six lists (declared by declare_preamble()) from @p prm.
    static SceneNames
    read(const dealii::ParameterHandler &prm);
  };

  /**
   * `subsection Body <name>`: a solid of one material, its shape, its initial
   * velocity and (in 2D) its out-of-plane thickness. A rigid body moves with a
   * prescribed velocity and carries no stress (MPM: it imposes its velocity on
   * the grid nodes it touches).
   */
  template <int dim>
  struct BodyDescription
  {
    std::string                                   name;
    std::string                                   material; ///< "" is the default material
    Geometry::Region<dim>                         shape;
    unsigned int                                  particles_per_cell = 2;
    /// 2D: the out-of-plane thickness, a constant, or (thickness_function) a function of
    /// x, y read through thickness_at(); 3D: 1.
    double                                        thickness          = 1.0;
    std::shared_ptr<dealii::FunctionParser<dim>>  thickness_function; ///< null: constant
    std::string                                   thickness_expression, thickness_where;
    std::shared_ptr<dealii::FunctionParser<dim>>  initial_velocity; ///< of x; null: at rest
    bool                                          rigid = false;
    std::shared_ptr<dealii::FunctionParser<1>>    rigid_velocity; ///< of t (rigid bodies)
    std::shared_ptr<const Amplitude>              amplitude; ///< multiplies rigid_velocity; null: 1

    /// A rigid body's velocity at @p t (`Velocity` times the amplitude).
    dealii::Tensor<1, dim>
    rigid_velocity_at(const double t) const;

    /// A rigid body's displacement from @p t0 to @p t1.
    dealii::Tensor<1, dim>
    rigid_displacement(const double t0, const double t1) const;

    dealii::Tensor<1, dim>
    velocity_at(const dealii::Point<dim> &p) const;

    /// The thickness at @p p [m] (1 in 3D); an InputError naming the expression and the
    /// point unless it is > 0 and finite there.
    double
    thickness_at(const dealii::Point<dim> &p) const;

    /// Whether the thickness varies (an expression, 2D).
    bool
    varying_thickness() const
    {
      return dim == 2 && thickness_function != nullptr;
    }
  };

  /**
   * `subsection Set <name>`: a named selection of nodes, points or cells that
   * conditions, loads and history tables refer to by name: faces of the domain
   * box and/or a region (every method), or a physical group of a Gmsh mesh file
   * (the FEM with `Generator = file`), given by its name or number.
   */
  template <int dim>
  struct SetDescription
  {
    std::string               name;
    std::vector<unsigned int> faces; ///< as BoundaryDescription::faces
    Geometry::Region<dim>     region; ///< used if has_region
    bool                      has_region = false;
    std::string               physical_group; ///< "" : none

    /// Where the set is defined, for messages: "Set <name>".
    std::string
    where() const
    {
      return "Set " + name;
    }
  };

  /**
   * `subsection Boundary <name>`: a kinematic condition on the grid (MPM) or
   * mesh (FEM) nodes on faces of the domain box and/or inside a region, or on
   * a named set (which gives those, or a Gmsh physical group).
   */
  template <int dim>
  struct BoundaryDescription
  {
    enum class Type
    {
      fixed,    ///< every velocity component zero
      roller,   ///< the normal component zero (faces only)
      wall,         ///< rigid frictionless wall: the normal component may not point into the wall
      velocity,     ///< the selected components of the velocity follow functions of t
      displacement, ///< the selected components of the displacement follow functions of t
      absorbing     ///< viscous (Lysmer-Kuhlemeyer) dashpots on boundary faces (FEM dynamics, MPM)
    };
    std::string                                name;
    Type                                       type = Type::fixed;
    /// Faces of the domain box: 2 d + (0 for the lower, 1 for the upper face of direction d).
    std::vector<unsigned int>                  faces;
    Geometry::Region<dim>                      region; ///< used if has_region
    bool                                       has_region = false;
    std::vector<bool> components; ///< velocity/displacement types: prescribed components
    std::shared_ptr<dealii::FunctionParser<1>> velocity;     ///< velocity type: of t
    /// displacement type: of x, y (, z), t; u(x, t) - u(x, 0) is prescribed
    std::shared_ptr<dealii::FunctionParser<dim>> displacement;
    /// Multiplies the velocity or the displacement (u(x, t) a(t)); null: 1.
    std::shared_ptr<const Amplitude> amplitude;
    /// `Set`: the named set the condition acts on ("": its own Faces and Region), and
    /// the set's Gmsh physical group ("": none; then prescribes() selects nothing and
    /// the FEM selects the group's nodes).
    std::string set, physical_group;

    /// velocity type: the velocity at @p t (times the amplitude).
    dealii::Tensor<1, dim>
    velocity_at(const double t) const;

    /**
     * velocity and displacement types, for explicit steps: the velocity v(t)
     * of a velocity type; for a displacement type the mean velocity of the step
     * that ends at t at the node @p x, (u(x, t) - u(x, max(t - dt, 0))) / dt, so that
     * x += dt v moves the node exactly along u.
     */
    dealii::Tensor<1, dim>
    step_velocity(const double t, const double dt, const dealii::Point<dim> &x) const;

    /// velocity and displacement types: u(x, t1) - u(x, t0) (a velocity is integrated by
    /// 3-point Gauss and does not depend on x).
    dealii::Tensor<1, dim>
    displacement_increment(const double t0, const double t1, const dealii::Point<dim> &x) const;

    /**
     * Does this condition prescribe displacement component @p c at the node @p x of
     * a model whose nodes span the box [@p lower, @p upper]? Through a face of the
     * box (x within @p tolerance of it): every component (fixed), the face normal
     * (roller), the `Components` (velocity, displacement); through the Region:
     * every component (fixed) or the `Components`. Walls prescribe nothing (they
     * are unilateral). The FEM (nodes) and the RBSN (cell nuclei) select their
     * Dirichlet DoFs with this one rule.
     */
    bool
    prescribes(const dealii::Point<dim> &x,
               const unsigned int        c,
               const dealii::Point<dim> &lower,
               const dealii::Point<dim> &upper,
               const double              tolerance) const;

    /// "x-", "y+", ... for face f.
    static std::string
    face_name(const unsigned int face);

    /// The entry that selects the condition's nodes, for messages: "Boundary <name>/Set",
    /// ".../Region" or ".../Faces".
    std::string
    where() const;

    /// "fixed", "roller", "wall", "velocity" or "displacement".
    std::string
    type_name() const;
  };

  /**
   * Conditions that meet, one rule for every method: two boundary conditions may prescribe
   * the same component at the same node (a DoF of the FEM mesh, a cell of the RBSN, a node
   * of the MPM grid) only if they prescribe the same motion there -- the same displacement
   * since t = 0 at 100 times of the run (t_k = k T / 100), to 1e-9 of its size -- such as
   * two fixed conditions that share an edge. Otherwise the scene is refused (an InputError
   * at the later condition's entry, naming both conditions, the node, the component and
   * what each prescribes), never resolved by the order of the subsections. A method
   * records each pair that meets with check() and calls throw_if_any() (collective) once.
   */
  template <int dim>
  class ConditionOverlaps
  {
  public:
    /// @p node: what the method's nodes are called in messages ("node of the fem mesh").
    ConditionOverlaps(const std::vector<BoundaryDescription<dim>> &conditions,
                      const double                                 end_time,
                      const std::string                           &node);

    /**
     * Condition @p a (listed before @p b) and condition @p b both prescribe @p component
     * ("x", "rotation", ...) of the node at @p x; @p g_a and @p g_b give each one's
     * displacement from 0 to t. Two conditions whose motions do not depend on the
     * position (fixed, roller, velocity) are compared once per component.
     */
    void
    check(const unsigned int                  a,
          const unsigned int                  b,
          const std::string                  &component,
          const dealii::Point<dim>           &x,
          const std::function<double(double)> &g_a,
          const std::function<double(double)> &g_b);

    /// check() of the translation @p c, the histories from displacement_increment().
    void
    check(const unsigned int a, const unsigned int b, const unsigned int c, const dealii::Point<dim> &x);

    /// Collective: throw the InputError of the first disagreement (the lowest rank's)
    /// on every rank; nothing if the conditions agree wherever they meet.
    void
    throw_if_any(const MPI_Comm comm) const;

  private:
    const std::vector<BoundaryDescription<dim>> &conditions;
    double                                       end_time;
    std::string                                  node;
    /// (a, b, component) of position-independent pairs already compared.
    std::map<std::tuple<unsigned int, unsigned int, std::string>, bool> compared;
    std::string                                                        where, problem;
  };

  /**
   * `subsection Load <name>`: a force on the particles (MPM) or nodes (FEM) of
   * a region: a total force split evenly, or a traction per unit of surface.
   */
  template <int dim>
  struct LoadDescription
  {
    enum class Type
    {
      force,   ///< the total force [N] is shared evenly by the selected points
      traction ///< force per unit area [Pa] on the selected (surface) points
    };
    std::string                                name;
    Type                                       type = Type::force;
    Geometry::Region<dim>                      region;
    std::shared_ptr<dealii::FunctionParser<1>> value; ///< of t, dim components
    std::shared_ptr<const Amplitude>           amplitude; ///< multiplies value; null: 1
    /// `Set`: the named set that gives the region ("": `Region`), and its Gmsh physical
    /// group ("": none; the FEM loads the group's faces or cells).
    std::string set, physical_group;

    /// `Value` at @p t times the amplitude.
    dealii::Tensor<1, dim>
    value_at(const double t) const;
  };

  /// Declare the entries of the named body, boundary and load subsections.
  void
  declare_scene_descriptions(dealii::ParameterHandler &prm, const SceneNames &names);

  /// The scene's amplitudes by name (Amplitude::parse_all()).
  using AmplitudeMap = std::map<std::string, std::shared_ptr<const Amplitude>>;

  template <int dim>
  std::vector<BodyDescription<dim>>
  parse_bodies(dealii::ParameterHandler &prm, const SceneNames &names, const AmplitudeMap &amplitudes);

  template <int dim>
  std::vector<SetDescription<dim>>
  parse_sets(dealii::ParameterHandler &prm, const SceneNames &names);

  template <int dim>
  std::vector<BoundaryDescription<dim>>
  parse_boundaries(dealii::ParameterHandler &prm,
                   const SceneNames &names,
                   const AmplitudeMap &amplitudes,
                   const std::vector<SetDescription<dim>> &sets);

  template <int dim>
  std::vector<LoadDescription<dim>>
  parse_loads(dealii::ParameterHandler &prm,
              const SceneNames &names,
              const AmplitudeMap &amplitudes,
              const std::vector<SetDescription<dim>> &sets);

  /// `Gravity` (top level): a vector of dim components [m/s^2]; "" is zero.
  template <int dim>
  dealii::Tensor<1, dim>
  parse_vector(const std::string &text, const std::string &where);

  /// Evaluate a vector function of t (a FunctionParser<1> in the variable t).
  template <int dim>
  dealii::Tensor<1, dim>
  evaluate_in_time(const dealii::FunctionParser<1> &f, const double t);

  /// The integral of a vector function of t (times @p amplitude, if given) over [t0, t1] by
  /// 3-point Gauss-Legendre on each piece between the amplitude's points (exact for
  /// polynomials of degree 5 times a piecewise linear amplitude; a velocity's displacement
  /// increment).
  template <int dim>
  dealii::Tensor<1, dim>
  integrate_in_time(const dealii::FunctionParser<1> &f,
                    const double                     t0,
                    const double                     t1,
                    const Amplitude                 *amplitude = nullptr);
} // namespace hysteron

#endif

#ifndef hysteron_base_exceptions_h
#define hysteron_base_exceptions_h

#include <stdexcept>
#include <string>

namespace hysteron
{
  /**
   * An error that names its place: `where` is the parameter path ("Material/Young's
   * modulus") or the file, `problem` says what is wrong there; what() is
   * "<where>: <problem>".
   */
  class LocatedError : public std::runtime_error
  {
  public:
    LocatedError(const std::string &where, const std::string &problem);

    const std::string &
    where() const
    {
      return where_;
    }

    const std::string &
    problem() const
    {
      return problem_;
    }

  private:
    std::string where_;
    std::string problem_;
  };

  /**
   * An error in what the user gave us: a parameter value, an expression, a file.
   * The `hysteron` executable prints "error: <where>: <problem>" and exits with
   * status 1.
   */
  class InputError : public LocatedError
  {
  public:
    using LocatedError::LocatedError;
  };

  /**
   * A failure while running a valid scene: a NaN, a non-converging local Newton
   * iteration, an unstable time step. The message says what, where and when; the
   * executable prints it and exits with status 2.
   */
  class RuntimeError : public std::runtime_error
  {
  public:
    explicit RuntimeError(const std::string &message);
  };

  /**
   * A user's expression evaluated to NaN or infinity during a run (a division by
   * zero, log(0), the root of a negative number). Deliberately not a RuntimeError:
   * the methods cut a step on a RuntimeError (a material that failed to
   * converge), and a smaller step does not cure a wrong expression. The
   * executable ends the run with exit status 2 and this message, which names the
   * entry, the expression, the value and the point and time of the evaluation.
   */
  class NonFiniteExpression : public LocatedError
  {
  public:
    using LocatedError::LocatedError;
  };

  /**
   * The run was stopped by SIGINT or SIGTERM after it wrote its state (tables,
   * a VTU, a checkpoint); the executable prints the message and exits with
   * status 4. `hysteron --resume` continues it.
   */
  class Interrupted : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  /// Throw InputError(where, problem) unless @p condition holds.
  inline void
  require(const bool condition, const std::string &where, const std::string &problem)
  {
    if (!condition)
      throw InputError(where, problem);
  }
} // namespace hysteron

#endif

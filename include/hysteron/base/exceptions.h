#ifndef hysteron_base_exceptions_h
#define hysteron_base_exceptions_h

#include <stdexcept>
#include <string>

namespace hysteron
{
  /**
   * An error in what the user gave us: a parameter value, an expression, a file.
   * `where` names the parameter path ("Material/Young's modulus") or the file;
   * `problem` says what is wrong with it. The `hysteron` executable prints
   * "error: <where>: <problem>" and exits with status 1.
   */
  class InputError : public std::runtime_error
  {
  public:
    InputError(const std::string &where, const std::string &problem);

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

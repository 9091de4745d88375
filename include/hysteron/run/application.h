#ifndef hysteron_run_application_h
#define hysteron_run_application_h

namespace hysteron
{
  /**
   * The `hysteron` command line (MPI must already be initialised):
   *   hysteron [--quiet] [--compare] [--resume] scene.prm
   *   hysteron --print-parameters [prm|json|markdown] [scene.prm]
   *   hysteron --help | --version
   * Returns the exit status: 0 success, 1 bad input (parameters, files,
   * command line), 2 a run-time failure (NaN, non-convergence, instability),
   * 3 an internal error, 4 stopped by SIGINT or SIGTERM (resumable). Messages go to stderr as "hysteron: error: ...".
   */
  int
  run_application(int argc, char **argv);
} // namespace hysteron

#endif

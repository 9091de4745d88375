#ifndef hysteron_base_plotter_h
#define hysteron_base_plotter_h

#include <string>
#include <vector>

namespace hysteron
{
  namespace Output
  {
    class RunRecord;
  }

  /// External plotters (gnuplot) run without a shell, with a timeout, drawing a PNG
  /// under a temporary name that is renamed once the plotter has succeeded.
  namespace Plot
  {
    /// An external plotter that draws one PNG: what run_plotter() runs.
    struct PlotCommand
    {
      /// The program (looked up on PATH unless it names a directory) and its arguments.
      std::vector<std::string> arguments;

      /// The directory it runs in ("" for the current one).
      std::string directory;

      /// The PNG it draws, relative to @p directory; the plotter writes "<png_file>.tmp".
      std::string png_file;

      /// What it draws from, for messages (the script: "out/compare/probe_0.gp").
      std::string subject;

      /// Seconds it may run (> 0).
      double timeout = 60;

      /// The run whose file the PNG is (null: outside a run).
      Output::RunRecord *record = nullptr;
    };

    /**
     * Run a plotter without a shell (posix_spawn with an argument vector, stdin
     * from /dev/null, stdout and stderr captured, a process group of its own)
     * and rename its "<png_file>.tmp" to @p png_file once it has exited with
     * status 0. A plotter still running after the timeout is killed with its
     * process group. Returns an empty string if the PNG was drawn and the
     * plotter printed nothing, else a warning: the plotter could not be
     * started, failed, timed out or drew nothing (then neither the PNG of an
     * earlier run nor the temporary file is left), or what it printed. Never
     * throws because of the plotter.
     */
    std::string
    run_plotter(const PlotCommand &command);

    /// Whether an executable `gnuplot` is on PATH.
    bool
    gnuplot_available();

    /**
     * Run gnuplot on @p script_file (written by write_gnuplot_script()) in the
     * script's directory with run_plotter(), the PNG it draws being @p png_file
     * (relative to that directory), for at most @p timeout seconds. Returns an
     * empty string if the PNG was drawn and gnuplot printed nothing, else a
     * warning: gnuplot not on PATH, failed or timed out (then neither the PNG of
     * an earlier run nor a temporary file is left under @p png_file), or what
     * gnuplot printed. Never throws because of gnuplot. The PNG is a file of the
     * run of @p record (null: outside a run).
     */
    std::string
    run_gnuplot(const std::string &script_file,
                const std::string &png_file,
                double             timeout = 60,
                Output::RunRecord *record  = nullptr);
  } // namespace Plot
} // namespace hysteron

#endif

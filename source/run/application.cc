#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/utilities.h>

#include <hysteron/base/config.h>
#include <hysteron/base/exceptions.h>
#include <hysteron/base/parameter_documentation.h>
#include <hysteron/base/parameters.h>
#include <hysteron/run/application.h>
#include "run/run_scene.h"
#include <hysteron/scene/scene.h>

#include "run/output_directory.h"
#include "run/parameter_file.h"
#include "run/signals.h"

#include <algorithm>
#include <chrono>
#include <dlfcn.h>
#include <filesystem>
#include <memory>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

namespace hysteron
{
  namespace
  {
    const char *usage_text =
      "Usage: hysteron [--quiet] [--compare] [--resume] SCENE.prm\n"
      "       hysteron --print-parameters [prm|json|markdown] [SCENE.prm]\n"
      "       hysteron --status DIRECTORY\n"
      "       hysteron --help | --version\n"
      "\n"
      "Runs the scene described by the parameter file SCENE.prm: its `Dimension` (2 or 3) and\n"
      "`Method` (material point, ...) choose what runs; results go to `Output/Directory`.\n"
      "\n"
      "Options:\n"
      "  --quiet              no progress, summary or timer table on stdout\n"
      "  --compare            run the scene with two methods (Compare/Methods, default mpm\n"
      "                       and fem) and compare their tables (= set Method = compare)\n"
      "  --resume             continue the run of SCENE.prm from the newest checkpoint in\n"
      "                       its output directory (subsection Checkpoint; a run stopped by\n"
      "                       SIGINT or SIGTERM writes one), on any number of MPI ranks\n"
      "  --print-parameters   write every parameter with its default, allowed values and\n"
      "                       documentation (PRM, JSON or Markdown) and exit; with SCENE.prm,\n"
      "                       the values of that file and its named materials\n"
      "  --status DIRECTORY   the state of the run in the output directory DIRECTORY:\n"
      "                       running (and by which process), finished, failed or\n"
      "                       interrupted (also a run that was killed: its manifest still\n"
      "                       says running, but no process holds the directory's lock)\n"
      "  --help               this text\n"
      "  --version            the version\n"
      "\n"
      "Exit status: 0 success, 1 bad input (nothing written), 2 run-time failure (the last\n"
      "good state written), 3 internal error, 4 stopped by SIGINT or SIGTERM (state and a\n"
      "checkpoint written; continue with --resume).\n"
      "Documentation: README.md, doc/parameters.md, doc/architecture.md.\n";

    /// A deal.II exception's own message, on one line, without the source location banner.
    std::string
    one_line(const dealii::ExceptionBase &e)
    {
      std::ostringstream info;
      e.print_info(info);
      std::string text = info.str();
      std::string out;
      bool        space = false;
      for (const char c : text)
        if (c == '\n' || c == ' ' || c == '\t')
          space = !out.empty();
        else
          {
            if (space)
              out += ' ';
            out += c;
            space = false;
          }
      return out;
    }

    struct Preamble
    {
      unsigned int             dimension = 2;
      SceneNames               names;
      std::vector<std::string> inputs; ///< the parameter file, its includes, libraries
    };

    /// Parse @p file into @p prm (deal.II's errors at the file and line they concern).
    void
    parse(dealii::ParameterHandler &prm, const Run::ParameterFile &file, const bool skip_undefined)
    {
      std::istringstream in(file.text);
      try
        {
          prm.parse_input(in, file.name, "", skip_undefined);
        }
      catch (const dealii::ExceptionBase &e)
        {
          throw file.error(one_line(e));
        }
    }

    /// Read Dimension, Material names and libraries, skipping everything else.
    Preamble
    read_preamble(const Run::ParameterFile &file)
    {
      dealii::ParameterHandler prm;
      declare_preamble(prm);
      parse(prm, file, /*skip_undefined=*/true);

      Preamble p;
      p.dimension      = prm.get_integer("Dimension");
      p.names     = SceneNames::read(prm);
      // The parameter file and its includes: inputs of the run.
      for (const auto &origin : file.origin)
        if (std::find(p.inputs.begin(), p.inputs.end(), origin.first) == p.inputs.end())
          p.inputs.push_back(origin.first);
      for (const auto &library : dealii::Utilities::split_string_list(
             prm.get("Additional shared libraries"), ','))
        if (!library.empty())
          {
            // RTLD_GLOBAL: the plugin's registration objects run now and register into
            // the registries of this executable's library.
            if (dlopen(library.c_str(), RTLD_NOW | RTLD_GLOBAL) == nullptr)
              throw InputError("Additional shared libraries",
                               "cannot load '" + library + "': " + dlerror());
            p.inputs.push_back(library);
          }
      return p;
    }

    void
    check_readable(const std::string &file)
    {
      std::error_code ec;
      require(std::filesystem::exists(file, ec), file, "cannot open the parameter file: no such file");
      require(std::filesystem::is_regular_file(file, ec),
              file,
              "cannot open the parameter file: not a regular file");
      std::ifstream in(file);
      require(static_cast<bool>(in), file, "cannot open the parameter file for reading");
    }

    template <int dim>
    void
    run_scene(dealii::ParameterHandler &prm, const RunOptions &options)
    {
      // The record of the run's files outlives the scene, whose tables it knows.
      Output::RunRecord record;
      auto              scene = std::make_unique<Scene<dim>>(prm, options);
      try
        {
          Run::run_scene(*scene, record);
        }
      catch (...)
        {
          // Destroy the scene (and its TimerOutput) while the exception is
          // caught: every rank fails together, so its clean-up may communicate.
          scene.reset();
          throw;
        }
    }

    int
    run(int argc, char **argv)
    {
      RunOptions  options;
      for (int i = 0; i < argc; ++i)
        options.command_line += (i ? " " : "") + std::string(argv[i]);
      options.test_signal = Run::test_signal_from_environment();
      bool        print_parameters = false;
      bool        compare          = false;
      std::string format           = "prm";
      std::vector<std::string> files;
      for (int i = 1; i < argc; ++i)
        {
          const std::string arg = argv[i];
          if (arg == "--help" || arg == "-h")
            {
              if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
                std::cout << usage_text;
              return 0;
            }
          else if (arg == "--version")
            {
              if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
                std::cout << "hysteron " HYSTERON_VERSION " (deal.II " DEAL_II_PACKAGE_VERSION ")\n";
              return 0;
            }
          else if (arg == "--status")
            {
              if (i + 1 >= argc)
                throw InputError("command line", "--status needs the output directory of a run");
              const std::string state = Run::OutputDirectory::describe(argv[i + 1]);
              if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
                std::cout << state << std::endl;
              return 0;
            }
          else if (arg == "--quiet" || arg == "-q")
            options.quiet = true;
          else if (arg == "--compare")
            compare = true;
          else if (arg == "--resume")
            options.resume = true;
          else if (arg == "--print-parameters")
            {
              print_parameters = true;
              if (i + 1 < argc && (std::string(argv[i + 1]) == "prm" ||
                                   std::string(argv[i + 1]) == "json" ||
                                   std::string(argv[i + 1]) == "markdown"))
                format = argv[++i];
            }
          else if (!arg.empty() && arg[0] == '-')
            throw InputError("command line", "unknown option '" + arg + "' (see hysteron --help)");
          else
            files.push_back(arg);
        }
      if (files.size() > 1)
        throw InputError("command line", "more than one parameter file given (see hysteron --help)");

      Preamble          preamble;
      Run::ParameterFile file;
      if (!files.empty())
        {
          options.parameter_file = files[0];
          check_readable(files[0]);
          file     = Run::ParameterFile::read(files[0]);
          preamble = read_preamble(file);
          options.input_files = preamble.inputs;
        }
      else if (!print_parameters)
        throw InputError("command line", "no parameter file given\n" + std::string(usage_text));
      else
        {
          // Without a scene, document one instance of each named subsection.
          preamble.names.bodies     = {"<name>"};
          preamble.names.boundaries = {"<name>"};
          preamble.names.loads      = {"<name>"};
        }

      dealii::ParameterHandler prm;
      if (preamble.dimension == 2)
        Scene<2>::declare_parameters(prm, preamble.names);
      else
        Scene<3>::declare_parameters(prm, preamble.names);

      if (!files.empty())
        parse(prm, file, /*skip_undefined=*/false);

      if (compare)
        prm.set("Method", "compare");

      if (print_parameters)
        {
          if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
            {
              if (format == "json")
                prm.print_parameters(std::cout, dealii::ParameterHandler::JSON);
              else
                print_parameter_documentation(prm,
                                              std::cout,
                                              format == "markdown" ? ParameterFormat::markdown :
                                                                     ParameterFormat::prm);
            }
          return 0;
        }

      if (preamble.dimension == 2)
        run_scene<2>(prm, options);
      else
        run_scene<3>(prm, options);
      return 0;
    }

    /// Whether every rank ended with an error within @p seconds: a non-blocking barrier
    /// on a communicator of its own, which no other operation uses. An error found
    /// collectively (bad input, a failure shared by collectively()) reaches every rank at
    /// about the same time; one that only some ranks found (a table the root cannot
    /// write) leaves the others in their next collective operation, where they would wait
    /// forever.
    bool
    every_rank_failed(const MPI_Comm comm, const double seconds)
    {
      MPI_Request request;
      MPI_Ibarrier(comm, &request);
      const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
      int        done  = 0;
      while (MPI_Test(&request, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && done == 0)
        {
          if (std::chrono::steady_clock::now() > until)
            return false;
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
      return done != 0;
    }

    /// The end of a run with an error: the message once, and @p status. On several ranks,
    /// an error of some ranks only stops all of them (MPI_Abort with @p status) with the
    /// message of the rank that found it, instead of leaving the others waiting.
    int
    fail(const MPI_Comm errors, const int status, const std::string &kind, const std::string &message)
    {
      const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(errors);
      const unsigned int rank    = dealii::Utilities::MPI::this_mpi_process(errors);
      if (n_ranks == 1 || every_rank_failed(errors, 10))
        {
          // Every rank has the same message; one is enough.
          if (rank == 0)
            std::cerr << "hysteron: " << kind << ": " << message << std::endl;
          return status;
        }
      std::cerr << "hysteron: " << kind << " on MPI rank " << rank << " of " << n_ranks << ": " << message
                << " (the other ranks did not meet this error and are stopped)" << std::endl;
      MPI_Abort(MPI_COMM_WORLD, status);
      return status;
    }
  } // namespace

  int
  run_application(int argc, char **argv)
  {
    // The communicator of the error handshake (fail()), made while every rank is here.
    MPI_Comm errors;
    MPI_Comm_dup(MPI_COMM_WORLD, &errors);
    int status = 0;
    try
      {
        status = run(argc, argv);
      }
    catch (const InputError &e)
      {
        return fail(errors, 1, "error", e.what());
      }
    catch (const RuntimeError &e)
      {
        return fail(errors, 2, "run-time error", e.what());
      }
    catch (const NonFiniteExpression &e)
      {
        // Found during the run (between the times checked up front): the tables
        // hold every step before it.
        return fail(errors, 2, "run-time error", e.what());
      }
    catch (const Interrupted &e)
      {
        return fail(errors, 4, "interrupted", e.what());
      }
    catch (const dealii::ExceptionBase &e)
      {
        return fail(errors, 3, "internal error", one_line(e));
      }
    catch (const std::exception &e)
      {
        return fail(errors, 3, "internal error", e.what());
      }
    MPI_Comm_free(&errors);
    return status;
  }
} // namespace hysteron

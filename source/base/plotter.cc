#include "base/plotter.h"
#include "base/run_record.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <iomanip>
#include <poll.h>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char **environ;

namespace hysteron
{
  namespace Plot
  {
    namespace
    {
      namespace fs = std::filesystem;

      /// At most this much of what a plotter prints goes into its warning.
      constexpr std::size_t max_message_length = 2000;

      /// Remove the PNG @p png and its temporary file: a PNG of an earlier run would not show
      /// these data.
      void
      remove_plot(const fs::path &png)
      {
        std::error_code ec;
        fs::remove(png.string() + ".tmp", ec);
        fs::remove(png, ec);
      }

      /// What a plotter printed, on one line.
      std::string
      one_line(std::string text)
      {
        if (text.size() > max_message_length)
          text = text.substr(0, max_message_length) + " ...";
        std::replace(text.begin(), text.end(), '\n', ' ');
        const auto first = text.find_first_not_of(" \t\r");
        if (first == std::string::npos)
          return "";
        return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
      }

      /// @p t with 6 significant digits ("0.5", "60").
      std::string
      seconds(const double t)
      {
        std::ostringstream s;
        s << std::setprecision(6) << t;
        return s.str();
      }

      /// Whether the child @p pid has exited; it is not reaped (its process group stays).
      bool
      has_exited(const pid_t pid)
      {
        siginfo_t info{};
        if (::waitid(P_PID, pid, &info, WEXITED | WNOHANG | WNOWAIT) != 0)
          return errno == ECHILD; // reaped elsewhere
        return info.si_pid == pid;
      }

      /**
       * Start @p arguments in @p directory without a shell, stdin from /dev/null,
       * stdout and stderr into the pipe @p output, in a process group of its own
       * (to be killed as a whole) with the default signal actions. Returns 0 or
       * an error number.
       */
      int
      spawn(const std::vector<std::string> &arguments,
            const std::string              &directory,
            const int                       output,
            pid_t                          &pid)
      {
        std::vector<char *> argv;
        for (const auto &a : arguments)
          argv.push_back(const_cast<char *>(a.c_str()));
        argv.push_back(nullptr);

        posix_spawn_file_actions_t actions;
        posix_spawnattr_t          attributes;
        sigset_t                   no_signals, all_signals;
        sigemptyset(&no_signals);
        sigfillset(&all_signals);
        posix_spawn_file_actions_init(&actions);
        posix_spawnattr_init(&attributes);
        int error = posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
        if (error == 0)
          error = posix_spawn_file_actions_adddup2(&actions, output, 1);
        if (error == 0)
          error = posix_spawn_file_actions_adddup2(&actions, output, 2);
        if (error == 0 && !directory.empty())
          error = posix_spawn_file_actions_addchdir_np(&actions, directory.c_str());
        if (error == 0)
          error = posix_spawnattr_setflags(&attributes,
                                           POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK |
                                             POSIX_SPAWN_SETSIGDEF);
        if (error == 0)
          error = posix_spawnattr_setpgroup(&attributes, 0);
        if (error == 0)
          error = posix_spawnattr_setsigmask(&attributes, &no_signals);
        if (error == 0)
          error = posix_spawnattr_setsigdefault(&attributes, &all_signals);
        if (error == 0)
          error = posix_spawnp(&pid, argv[0], &actions, &attributes, argv.data(), environ);
        posix_spawnattr_destroy(&attributes);
        posix_spawn_file_actions_destroy(&actions);
        return error;
      }
    } // namespace



    std::string
    run_plotter(const PlotCommand &command)
    {
      const std::string program   = fs::path(command.arguments.at(0)).filename().string();
      const fs::path    directory = command.directory.empty() ? "." : command.directory;
      const fs::path    png       = directory / command.png_file;
      const fs::path    temporary = directory / (command.png_file + ".tmp");
      const std::string no_png    = "; no PNG written";
      remove_plot(png);

      int pipe_ends[2];
      if (::pipe2(pipe_ends, O_CLOEXEC) != 0)
        return "cannot run " + program + " on " + command.subject + ": " + std::strerror(errno) +
               no_png;
      pid_t     pid   = 0;
      const int error = spawn(command.arguments, command.directory, pipe_ends[1], pid);
      ::close(pipe_ends[1]);
      if (error != 0)
        {
          ::close(pipe_ends[0]);
          return "cannot run " + program + " on " + command.subject + ": " + std::strerror(error) +
                 no_png;
        }

      // Read what it prints until it exits or its time is up. Once it has exited, whatever it
      // started may still hold the pipe: stop reading when nothing is left to read.
      const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(command.timeout);
      std::string output;
      bool        open = true, timed_out = false;
      while (true)
        {
          const bool exited = has_exited(pid);
          const auto left   = std::chrono::ceil<std::chrono::milliseconds>(
                              deadline - std::chrono::steady_clock::now())
                              .count();
          if (!exited && left <= 0)
            {
              timed_out = true;
              break;
            }
          if (!open)
            {
              if (exited)
                break;
              std::this_thread::sleep_for(std::chrono::milliseconds(1));
              continue;
            }
          pollfd    ready{pipe_ends[0], POLLIN, 0};
          const int n_ready =
            ::poll(&ready, 1, exited ? 0 : static_cast<int>(std::min<decltype(left)>(left, 50)));
          if (n_ready > 0)
            {
              char          buffer[4096];
              const ssize_t n = ::read(pipe_ends[0], buffer, sizeof(buffer));
              if (n > 0 && output.size() <= max_message_length)
                output.append(buffer, n);
              else if (n == 0 || (n < 0 && errno != EINTR))
                open = false;
            }
          else if (n_ready == 0 && exited)
            break;
        }
      ::close(pipe_ends[0]);
      // The process group: a plotter out of time, and anything a plotter left running.
      ::kill(-pid, SIGKILL);
      // Reaped elsewhere (SIGCHLD ignored), its status is unknown: the temporary PNG decides.
      int  status = 0;
      bool reaped = false;
      do
        reaped = ::waitpid(pid, &status, 0) == pid;
      while (!reaped && errno == EINTR);

      const std::string messages = one_line(output);
      const std::string printed  = messages.empty() ? "" : ": " + messages;
      std::error_code   ec;
      std::string       failure;
      if (timed_out)
        failure = "still running after " + seconds(command.timeout) + " s: killed";
      else if (reaped && !WIFEXITED(status))
        failure = "killed by signal " + std::to_string(WTERMSIG(status));
      else if (reaped && WEXITSTATUS(status) != 0)
        failure = "exit status " + std::to_string(WEXITSTATUS(status));
      else if (!fs::is_regular_file(temporary, ec))
        failure = "it drew no " + command.png_file + ".tmp";
      else
        {
          fs::rename(temporary, png, ec);
          if (ec)
            failure = "cannot rename " + command.png_file + ".tmp: " + ec.message();
        }
      if (!failure.empty())
        {
          remove_plot(png);
          return program + " failed on " + command.subject + " (" + failure + ")" + printed +
                 no_png;
        }
      if (command.record != nullptr)
        command.record->add_file(png.string());
      return messages.empty() ? "" : program + " on " + command.subject + printed;
    }



    bool
    gnuplot_available()
    {
      const char *path = std::getenv("PATH");
      if (path == nullptr)
        return false;
      std::istringstream directories(path);
      std::string        directory;
      while (std::getline(directories, directory, ':'))
        {
          const std::string candidate = (directory.empty() ? "." : directory) + "/gnuplot";
          if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate))
            return true;
        }
      return false;
    }



    std::string
    run_gnuplot(const std::string       &script_file,
                const std::string       &png_file,
                const double             timeout,
                Output::RunRecord *const record)
    {
      const fs::path script(script_file);
      if (!gnuplot_available())
        {
          remove_plot(script.parent_path() / png_file);
          return "gnuplot is not on PATH: wrote " + script_file + " but not its PNG";
        }
      PlotCommand command;
      command.arguments = {"gnuplot", script.filename().string()};
      command.directory = script.parent_path().string();
      command.png_file  = png_file;
      command.subject   = script_file;
      command.timeout   = timeout;
      command.record    = record;
      return run_plotter(command);
    }
  } // namespace Plot
} // namespace hysteron

#include "run/signals.h"

#include "base/run_record.h"

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <string>

namespace hysteron
{
  namespace Run
  {
    namespace
    {
      // Static storage, the one exception to the run's objects (doc/architecture.md): a
      // signal handler can reach no object and may only store to a volatile sig_atomic_t.
      // The driver reads it after each step.
      volatile std::sig_atomic_t signal_received = 0;

      extern "C" void
      record_signal(const int signal)
      {
        signal_received = signal;
      }
    } // namespace

    void
    install_signal_handlers()
    {
      signal_received = 0;
      struct sigaction action;
      std::memset(&action, 0, sizeof(action));
      action.sa_handler = record_signal;
      action.sa_flags   = SA_RESETHAND; // a second signal takes the default action
      sigemptyset(&action.sa_mask);
      sigaction(SIGINT, &action, nullptr);
      sigaction(SIGTERM, &action, nullptr);
    }

    void
    restore_signal_handlers()
    {
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
    }

    int
    received_signal(MPI_Comm comm, const unsigned int n_ranks, bool &due_on_root)
    {
      if (n_ranks == 1)
        return signal_received;
      // One reduction per step: the signal (any rank) and the root's wall-clock decision.
      int values[2] = {static_cast<int>(signal_received), due_on_root ? 1 : 0};
      MPI_Allreduce(MPI_IN_PLACE, values, 2, MPI_INT, MPI_MAX, comm);
      due_on_root = values[1] != 0;
      return values[0];
    }

    RunOptions::TestSignal
    test_signal_from_environment()
    {
      RunOptions::TestSignal hook;
      const char            *spec = std::getenv("HYSTERON_TEST_SIGNAL");
      if (spec == nullptr)
        return hook;
      const std::string text(spec);
      const auto        at = text.find('@');
      if (at == std::string::npos)
        return hook;
      const std::string name = text.substr(0, at);
      hook.signal = name == "SIGKILL" ? SIGKILL : name == "SIGTERM" ? SIGTERM : SIGINT;
      hook.step   = std::stoul(text.substr(at + 1));
      return hook;
    }

    void
    test_signal_after_step(const RunOptions::TestSignal &hook, const unsigned long step, Output::RunRecord &record)
    {
      if (hook.signal == 0 || hook.step != step)
        return;
      if (hook.signal == SIGKILL)
        // What a crash leaves: the rows written so far reach the files, then nothing.
        record.flush_tables();
      std::raise(hook.signal);
    }
  } // namespace Run
} // namespace hysteron

#ifndef hysteron_source_run_signals_h
#define hysteron_source_run_signals_h

#include <mpi.h>

#include "base/run_record.h"
#include <hysteron/scene/scene.h>

namespace hysteron
{
  namespace Run
  {
    /**
     * SIGINT and SIGTERM during a run: the handler only records the signal (and
     * restores the default action, so that a second Ctrl-C stops the program at
     * once); the driver sees it after the current step, writes the state and
     * stops with exit status 4.
     */
    void
    install_signal_handlers();

    /// The default actions again (after the run).
    void
    restore_signal_handlers();

    /// The signal received on any rank of @p comm (0: none). Collective when
    /// @p n_ranks > 1, so that every rank stops after the same step.
    int
    received_signal(MPI_Comm comm, unsigned int n_ranks, bool &any_due_on_root);

    /// The test hook of the environment variable HYSTERON_TEST_SIGNAL
    /// (<SIGINT|SIGTERM|SIGKILL>@<step>; unset: none), read once at start-up.
    RunOptions::TestSignal
    test_signal_from_environment();

    /// The test hook: raise @p hook's signal in this process if @p step is its step
    /// (see tests/run/). Before a SIGKILL the rows of the tables of @p record reach
    /// their files, as after a crash.
    void
    test_signal_after_step(const RunOptions::TestSignal &hook, unsigned long step, Output::RunRecord &record);
  } // namespace Run
} // namespace hysteron

#endif

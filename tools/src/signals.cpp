#include "signals.hpp"

#include <csignal>

#include "dualgrid/core/input_file.hpp"

namespace dualgrid::tools {
namespace {

volatile std::sig_atomic_t g_stop = 0;

extern "C" void OnStop(int sig) {
  if (g_stop != 0) {  // asked twice: stop now
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  g_stop = sig;
}

}  // namespace

void InstallStopHandlers() {
  struct sigaction sa {};
  sa.sa_handler = OnStop;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: experiment's wait() must wake up to forward the signal
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  SetInputStopFlag(&g_stop);  // a long read of an input ends at the signal too
}

int StopSignal() { return static_cast<int>(g_stop); }

int StopExitCode() { return 128 + StopSignal(); }

}  // namespace dualgrid::tools

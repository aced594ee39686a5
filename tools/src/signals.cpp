#include "signals.hpp"

#include <csignal>

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
}

int StopSignal() { return static_cast<int>(g_stop); }

int StopExitCode() { return 128 + StopSignal(); }

}  // namespace dualgrid::tools

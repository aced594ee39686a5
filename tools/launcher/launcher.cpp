// `dualgrid`, the command users run: sets libgomp's wait policy and executes the program itself
// (dualgrid-bin), so that its ~220 shared libraries are loaded once.
//
// libgomp reads OMP_WAIT_POLICY and GOMP_SPINCOUNT once, when it is loaded, before main(): a
// program can only choose them for itself by executing itself again with them set, which loads
// and relocates every library twice (~0.09 s of CPU per start, docs/performance.md). This
// launcher links the C library alone, sets the two variables (unless the user chose either) and
// executes dualgrid-bin with the same arguments, in the same process (same PID, same signals,
// same exit status). It also puts its own path into DUALGRID_COMMAND, which dualgrid-bin names
// when it starts child runs (experiment, sweep, regress, the lines of a sweep's runs.txt).
//
// dualgrid-bin is looked for beside the launcher (the build tree) and then in the installed
// tree's libexec folder (DUALGRID_LIBEXEC: its path relative to the launcher's folder, e.g.
// PREFIX/bin/dualgrid and PREFIX/libexec/dualgrid-bin). Exit status 1 with one line on stderr
// when it cannot be found or executed. Uses no C++ library (no exceptions, no allocation beyond
// the environment's).
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

constexpr const char* kProgram = "dualgrid-bin";
// Where dualgrid-bin lies relative to the launcher's folder, in the order tried.
constexpr const char* kPlaces[] = {"", DUALGRID_LIBEXEC};

// Wait policy for OpenMP's idle threads: passive after a short spin (docs/performance.md: spinning
// threads steal the working threads' time slices when another process is busy on the cores).
void ChooseOpenMpWaiting() {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  setenv("OMP_WAIT_POLICY", "PASSIVE", 1);
  setenv("GOMP_SPINCOUNT", "300", 1);
}

int Fail(const char* what, const char* path, int error) {
  std::fprintf(stderr, "dualgrid: error: %s %s: %s\n", what, path, std::strerror(error));
  return 1;
}

}  // namespace

int main(int /*argc*/, char** argv) {
  char self[PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0 && argv[0] != nullptr && std::strchr(argv[0], '/') != nullptr)  // no /proc
    n = static_cast<ssize_t>(std::snprintf(self, sizeof self, "%s", argv[0]));
  if (n <= 0 || n >= static_cast<ssize_t>(sizeof self))
    return Fail("cannot read", "/proc/self/exe (the launcher's own path)", errno);
  self[n] = '\0';
  char dir[PATH_MAX];
  std::memcpy(dir, self, static_cast<std::size_t>(n) + 1);
  if (char* slash = std::strrchr(dir, '/')) *slash = '\0';
  ChooseOpenMpWaiting();
  setenv("DUALGRID_COMMAND", self, 1);
  char program[PATH_MAX];
  int error = ENOENT;
  for (const char* place : kPlaces) {
    const int length =
        *place ? std::snprintf(program, sizeof program, "%s/%s/%s", dir, place, kProgram)
               : std::snprintf(program, sizeof program, "%s/%s", dir, kProgram);
    if (length >= static_cast<int>(sizeof program)) continue;
    execv(program, argv);  // returns only on failure
    error = errno;
    if (error != ENOENT && error != ENOTDIR) return Fail("cannot execute", program, error);
  }
  std::fprintf(stderr,
               "dualgrid: error: cannot find %s in %s or in %s/%s (the launcher's folder and the "
               "installed libexec folder): %s\n",
               kProgram, dir, dir, DUALGRID_LIBEXEC, std::strerror(error));
  return 1;
}

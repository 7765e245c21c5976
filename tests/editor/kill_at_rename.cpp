// Preloaded (LD_PRELOAD) into the editor fault tests' worker process: counts rename(2)
// calls and SIGKILLs the process at the N-th one, so a test can stop a save exactly
// between two of its file-system steps, which no timed kill reliably hits.
//   SSLPV_KILL_AT_RENAME=N     the rename to stop at (1-based; unset: never)
//   SSLPV_KILL_BEFORE_RENAME   set: die before that rename happens, else right after it
//   SSLPV_RENAME_LOG=<file>    append every rename's target to this file (one per line)
#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace {
using RenameFn = int (*)(const char*, const char*);
std::atomic<int> gRenames{0};

void logTarget(const char* to) {
  const char* log = std::getenv("SSLPV_RENAME_LOG");
  if (!log) return;
  const int fd = ::open(log, O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) return;
  const std::size_t n = std::strlen(to);
  if (::write(fd, to, n) == ssize_t(n)) (void)!::write(fd, "\n", 1);
  ::close(fd);
}
}  // namespace

extern "C" int rename(const char* from, const char* to) {
  static const RenameFn real = reinterpret_cast<RenameFn>(::dlsym(RTLD_NEXT, "rename"));
  const int n = ++gRenames;
  const char* at = std::getenv("SSLPV_KILL_AT_RENAME");
  const bool stop = at && std::atoi(at) == n;
  if (stop && std::getenv("SSLPV_KILL_BEFORE_RENAME")) ::raise(SIGKILL);
  const int result = real(from, to);
  logTarget(to);
  if (stop) ::raise(SIGKILL);
  return result;
}

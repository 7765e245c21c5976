#include "volume/core/isolated_child.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <new>
#include <vector>

#include "volume/core/error.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
#include <sanitizer/common_interface_defs.h>
#define SSLPV_CHILD_UNDER_SANITIZER 1
#endif
#endif

namespace sslpv {
namespace {

std::size_t currentAddressSpaceBytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  return pages * std::size_t(sysconf(_SC_PAGE_SIZE));
}

std::size_t physicalMemoryBytes() {
  long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return std::size_t(8) << 30;
  return std::size_t(pages) * std::size_t(pageSize);
}

/// Only async-signal-safe-in-practice work: the child of a multi-threaded parent has one
/// thread, so `body` must not wait for locks other threads may have held at fork time.
[[noreturn]] void runChild(int fd, std::size_t addressLimit, const std::function<int(int)>& body) {
  // SIGINT, SIGTERM and SIGHUP too: the parent's handlers would remove the parent's temporaries.
  for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL, SIGPIPE, SIGINT, SIGTERM, SIGHUP}) ::signal(sig, SIG_DFL);
#ifdef SSLPV_CHILD_UNDER_SANITIZER
  // A parser that dies on a corrupt file is why this child exists: the parent reports its
  // death as the file's error. Under ASan it dies more often (its operator new aborts on
  // the absurd sizes OpenVDB's Blosc reader asks for, where the release build throws
  // bad_alloc), and each death would call the callback a fuzzer set in the parent, which
  // saves the input as a crash of the parent's (docs/design.md §1, Fuzzing).
  __sanitizer_set_death_callback(nullptr);
#endif
  // glibc's "malloc(): corrupted ...", assertion texts and the parser's own log would reach
  // the user's terminal before the one-line error the parent reports; a flush of the
  // parent's inherited stdout buffer would duplicate its output.
  int devNull = ::open("/dev/null", O_WRONLY);
  if (devNull >= 0) {
    ::dup2(devNull, STDOUT_FILENO);
    ::dup2(devNull, STDERR_FILENO);
  }
  struct rlimit limit {};
  if (getrlimit(RLIMIT_AS, &limit) == 0) {
    limit.rlim_cur = limit.rlim_max == RLIM_INFINITY ? addressLimit : std::min<rlim_t>(addressLimit, limit.rlim_max);
    setrlimit(RLIMIT_AS, &limit);
  }
  int code = kChildWriteError;
  try {
    code = body(fd);
  } catch (const std::bad_alloc&) {
    code = kChildOutOfMemory;
  } catch (...) {
    code = kChildWriteError;
  }
  ::_exit(code);
}

}  // namespace

bool writeFully(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    ssize_t written = ::write(fd, data, size);
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) return false;
    data += written;
    size -= std::size_t(written);
  }
  return true;
}

std::size_t isolatedMemoryBudget(std::size_t inputBytes, std::size_t perInputByte) {
  const std::size_t wanted = (std::size_t(1) << 30) + perInputByte * inputBytes;
  return std::min(wanted, physicalMemoryBytes() / 4 * 3);
}

std::chrono::seconds isolatedTimeout(std::size_t inputBytes) {
  return std::chrono::seconds(120 + inputBytes / (2u << 20));
}

ChildOutput runIsolated(const std::string& name, const IsolatedParser& parser, std::size_t memoryBudget,
                        std::chrono::seconds timeout, const std::function<int(int fd)>& body) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw ResourceError(name + ": cannot create a pipe to read the file: " + std::strerror(errno));
  const std::size_t addressLimit = currentAddressSpaceBytes() + memoryBudget;
  const pid_t pid = ::fork();
  if (pid < 0) {
    int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw ResourceError(name + ": cannot start a reader process: " + std::strerror(err));
  }
  if (pid == 0) {
    ::close(fds[0]);
    runChild(fds[1], addressLimit, body);
  }
  ::close(fds[1]);

  const auto deadline = std::chrono::steady_clock::now() + timeout;
  ChildOutput output;
  std::vector<char> chunk(1 << 16);
  bool timedOut = false;
  for (;;) {
    auto remaining = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (remaining.count() <= 0) {
      timedOut = true;
      break;
    }
    struct pollfd waitFor {
      fds[0], POLLIN, 0
    };
    int ready = ::poll(&waitFor, 1, int(std::min<long long>(remaining.count(), 1000000)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;  // the loop re-checks the deadline
    ssize_t n = ::read(fds[0], chunk.data(), chunk.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    output.bytes.append(chunk.data(), std::size_t(n));
  }
  ::close(fds[0]);
  if (timedOut) ::kill(pid, SIGKILL);
  int status = 0;
  pid_t waited;
  do waited = ::waitpid(pid, &status, 0);
  while (waited < 0 && errno == EINTR);

  if (timedOut)
    throw InputError(name + ": reading did not finish within " + std::to_string(timeout.count()) +
                     " s; the file looks corrupt");
  if (waited < 0)  // SIGCHLD ignored by the application: the caller's own checks decide
    return output;
  if (WIFSIGNALED(status))
    throw InputError(name + ": corrupt " + parser.fileKind + " (" + parser.parser + " crashed with signal " +
                     std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status)) + ")");
  switch (WEXITSTATUS(status)) {
    case kChildOk:
      return output;
    case kChildParseError:
      output.parseError = true;
      return output;
    case kChildOutOfMemory:
      throw InputError(name + ": corrupt " + parser.fileKind + ": reading it needs more than " +
                       std::to_string(memoryBudget >> 20) + " MiB of memory");
    default:
      throw InputError(name + ": " + parser.process + " failed (exit code " + std::to_string(WEXITSTATUS(status)) +
                       ")");
  }
}

}  // namespace sslpv

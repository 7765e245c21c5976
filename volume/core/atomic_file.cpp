#include "volume/core/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <string>
#include <system_error>

#include "volume/core/error.h"

namespace sslpv {
namespace fs = std::filesystem;

namespace {

/// Temporaries being written, for the signal handler: fixed slots of plain characters,
/// since a handler may neither allocate nor take a lock. A slot is claimed (Claimed),
/// filled, then published (Live); the handler only reads Live slots.
enum SlotState : int { Free = 0, Claimed = 1, Live = 2 };
constexpr int kSlots = 32;
struct TempSlot {
  std::atomic<int> state{Free};
  char path[PATH_MAX];
};
TempSlot gSlots[kSlots];
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the slots' state");

/// The slot now naming `temp`, or -1 when all are taken (the file is then merely not
/// cleaned up on a signal; the next run's stale-temporary sweep still removes it).
int registerTemporary(const fs::path& temp) {
  const std::string& text = temp.native();
  if (text.size() >= PATH_MAX) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = Free;
    if (!gSlots[i].state.compare_exchange_strong(expected, Claimed)) continue;
    std::memcpy(gSlots[i].path, text.c_str(), text.size() + 1);
    gSlots[i].state.store(Live);
    return i;
  }
  return -1;
}

void unregisterTemporary(int slot) {
  if (slot >= 0) gSlots[slot].state.store(Free);
}

extern "C" void removeTemporariesAndReraise(int sig) {
  const int savedErrno = errno;
  for (TempSlot& slot : gSlots)
    if (slot.state.load() == Live) ::unlink(slot.path);
  errno = savedErrno;
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

const std::string kTempMarker = ".tmp-";

fs::path temporaryFor(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  // Same directory as the target, so the rename never crosses file systems.
  fs::path temp = target;
  temp += kTempMarker + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return temp;
}

}  // namespace

void requireWritableOutput(const fs::path& target) {
  if (target.empty()) throw InputError("output path is empty");
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(target.string() + ": output directory '" + dir.string() + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(target.string() + ": output directory '" + dir.string() + "' is not writable");
  if (fs::is_directory(target, ec))
    throw InputError(target.string() + ": output path is a directory");
}

// Only when process <pid> no longer exists, so a concurrent run writing the same output
// keeps its temporary. A writer that writes its temporary atomically in turn (the editor's
// first save) leaves "<target>.tmp-<pid>-<n>.tmp-<pid>-<m>": removed when every pid named
// is gone.
void removeStaleTemporaries(const fs::path& target) {
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  const std::string prefix = target.filename().string() + kTempMarker;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    bool stale = true;
    std::string rest = name.substr(prefix.size());
    while (stale) {
      const std::size_t next = rest.find(kTempMarker);
      const std::string part = rest.substr(0, next);
      const std::size_t dash = part.find('-');
      if (dash == 0 || dash == std::string::npos || dash > 9 || dash + 1 == part.size() ||
          part.find_first_not_of("0123456789-") != std::string::npos || part.find('-', dash + 1) != std::string::npos) {
        stale = false;
        break;
      }
      const pid_t pid = pid_t(std::stol(part.substr(0, dash)));
      // Alive, ours, or not ours to judge.
      if (pid <= 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) stale = false;
      if (next == std::string::npos) break;
      rest = rest.substr(next + kTempMarker.size());
    }
    if (!stale) continue;
    std::error_code ignored;
    fs::remove(it->path(), ignored);
  }
}

void writeAtomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  writeAtomicallyTogether({{target, write}});
}

void writeAtomicallyTogether(const std::vector<AtomicOutput>& outputs) {
  for (const AtomicOutput& output : outputs) {
    requireWritableOutput(output.target);
    removeStaleTemporaries(output.target);
  }
  std::vector<fs::path> temps;
  std::vector<int> slots;
  auto cleanUp = [&] {
    std::error_code ignored;
    for (std::size_t i = 0; i < temps.size(); ++i) {
      fs::remove(temps[i], ignored);
      unregisterTemporary(slots[i]);
    }
  };
  std::size_t renamed = 0;
  try {
    for (const AtomicOutput& output : outputs) {
      temps.push_back(temporaryFor(output.target));
      slots.push_back(registerTemporary(temps.back()));
      output.write(temps.back());
    }
    for (; renamed < outputs.size(); ++renamed) {
      std::error_code ec;
      fs::rename(temps[renamed], outputs[renamed].target, ec);
      if (ec) throw InputError(outputs[renamed].target.string() + ": cannot replace file: " + ec.message());
      unregisterTemporary(slots[renamed]);
    }
  } catch (...) {
    // Renames within one directory fail only if the directory changed under us; the
    // files already renamed are complete, the rest are removed.
    temps.erase(temps.begin(), temps.begin() + std::ptrdiff_t(renamed));
    slots.erase(slots.begin(), slots.begin() + std::ptrdiff_t(renamed));
    cleanUp();
    throw;
  }
}

void throwWriteFailed(const fs::path& target, int error) {
  throw ResourceError(target.string() + ": write failed: " + std::strerror(error));
}

void removeTemporariesOnSignals() {
  struct sigaction action {};
  action.sa_handler = removeTemporariesAndReraise;
  sigemptyset(&action.sa_mask);
  // Once: the handler restores the default and re-raises, which must then terminate.
  action.sa_flags = SA_RESETHAND;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &action, nullptr);
}

}  // namespace sslpv

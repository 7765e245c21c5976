#include "volume/vdb_isolated_read.h"

#include <fcntl.h>
#include <openvdb/io/Stream.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <mutex>
#include <streambuf>
#include <string>
#include <vector>

#include "volume/error.h"
#include "volume/input_file.h"
#include "volume/material_set.h"

namespace sslpv {
namespace {
namespace fs = std::filesystem;

// Exit codes of the reader child; anything else (or a signal) means it failed.
constexpr int kChildOk = 0;
constexpr int kChildParseError = 1;
constexpr int kChildOutOfMemory = 2;
constexpr int kChildWriteError = 3;

std::string oneLine(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

/// A read-only, seekable view of bytes in memory, so parsing needs no second copy.
class MemoryReadBuffer : public std::streambuf {
 public:
  MemoryReadBuffer(const char* data, std::size_t size) {
    char* begin = const_cast<char*>(data);  // never written through: get area only
    setg(begin, begin, begin + size);
  }

 protected:
  pos_type seekoff(off_type offset, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    const off_type size = egptr() - eback();
    const off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? gptr() - eback() : size;
    const off_type target = base + offset;
    if (target < 0 || target > size) return pos_type(off_type(-1));
    setg(eback(), eback() + target, egptr());
    return pos_type(target);
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
};

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

/// Streams into a pipe, so the child never holds the re-serialized grids in memory too.
class FdWriteBuffer : public std::streambuf {
 public:
  explicit FdWriteBuffer(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof(buffer_)); }

 protected:
  int_type overflow(int_type ch) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    bool ok = writeFully(fd_, pbase(), std::size_t(pptr() - pbase()));
    setp(buffer_, buffer_ + sizeof(buffer_));
    return ok;
  }
  int fd_;
  char buffer_[1 << 16];
};

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

/// Memory the child may use beyond what it inherits. A legitimate file grows by its
/// compression ratio when loaded (zip of smooth data: tens, constant leaves: ~100); a
/// corrupt length field asks for gigabytes. Capped so a corrupt file cannot push the
/// machine into the OOM killer.
std::size_t readerMemoryBudget(std::size_t fileBytes) {
  const std::size_t wanted = (std::size_t(1) << 30) + 256 * fileBytes;
  return std::min(wanted, physicalMemoryBytes() / 4 * 3);
}

/// Runs in the forked child: parse the untrusted bytes, then write what was read as a
/// fresh stream from OpenVDB's writer. Only async-signal-safe-in-practice work: the child
/// of a multi-threaded parent has one thread, and OpenVDB's read/write paths used here
/// are serial (grid statistics, which use TBB, are switched off).
[[noreturn]] void runReaderChild(const std::string& bytes, int fd, std::size_t addressLimit) {
  // SIGINT and SIGTERM too: the parent's handlers would remove the parent's temporaries.
  for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL, SIGPIPE, SIGINT, SIGTERM, SIGHUP}) ::signal(sig, SIG_DFL);
  // glibc's "malloc(): corrupted ..." and OpenVDB's log (stdout or stderr) would reach
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
  auto fail = [fd](const std::string& message) {
    writeFully(fd, message.data(), message.size());
    ::_exit(kChildParseError);
  };
  // OpenVDB does not check its reads: past the end of a truncated file it goes on with
  // whatever the stream left in its variables (a "length" of gigabytes, or nothing at
  // all when the cut is in the last buffer). A stream that ran dry means truncation.
  const char* const kEndedEarly = "the file ends early (truncated)";
  MemoryReadBuffer source(bytes.data(), bytes.size());
  std::istream in(&source);
  openvdb::GridPtrVecPtr grids;
  openvdb::MetaMap::Ptr metadata;
  try {
    openvdb::io::Stream reader(in, /*delayLoad=*/false);
    grids = reader.getGrids();
    metadata = reader.getMetadata();
  } catch (const std::bad_alloc&) {
    if (in.fail()) fail(kEndedEarly);
    ::_exit(kChildOutOfMemory);
  } catch (const std::exception& e) {
    fail(in.fail() ? std::string(kEndedEarly) + ": " + oneLine(e.what()) : oneLine(e.what()));
  } catch (...) {
    fail(in.fail() ? kEndedEarly : "unknown error");
  }
  if (in.fail()) fail(kEndedEarly);
  try {
    FdWriteBuffer sink(fd);
    std::ostream out(&sink);
    openvdb::io::Stream writer(out);
    std::uint32_t compression = openvdb::io::COMPRESS_ACTIVE_MASK;
    if (openvdb::io::Archive::hasBloscCompression()) compression |= openvdb::io::COMPRESS_BLOSC;
    writer.setCompression(compression);
    writer.setGridStatsMetadataEnabled(false);
    writer.write(*grids, metadata ? *metadata : openvdb::MetaMap());
    out.flush();
    ::_exit(out ? kChildOk : kChildWriteError);
  } catch (const std::bad_alloc&) {
    ::_exit(kChildOutOfMemory);
  } catch (...) {
    ::_exit(kChildWriteError);
  }
}

/// Forks the reader child and collects its output: the re-serialized stream on success.
std::string parseInChild(const std::string& bytes, const std::string& name) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw ResourceError(name + ": cannot create a pipe to read the file: " + std::strerror(errno));
  const std::size_t budget = readerMemoryBudget(bytes.size());
  const std::size_t addressLimit = currentAddressSpaceBytes() + budget;
  const pid_t pid = ::fork();
  if (pid < 0) {
    int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw ResourceError(name + ": cannot start a reader process: " + std::strerror(err));
  }
  if (pid == 0) {
    ::close(fds[0]);
    runReaderChild(bytes, fds[1], addressLimit);
  }
  ::close(fds[1]);

  // Generous: a legitimate file is read at tens of MB/s; this only stops a reader that
  // loops forever on corrupt data.
  const auto timeout = std::chrono::seconds(120 + bytes.size() / (2u << 20));
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::string received;
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
    received.append(chunk.data(), std::size_t(n));
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
  if (waited < 0)  // SIGCHLD ignored by the application: the stream's own parse decides
    return received;
  if (WIFSIGNALED(status))
    throw InputError(name + ": corrupt VDB file (the OpenVDB reader crashed with signal " +
                     std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status)) + ")");
  switch (WEXITSTATUS(status)) {
    case kChildOk:
      return received;
    case kChildParseError:
      throw InputError(name + ": not a valid VDB file: " + (received.empty() ? "unreadable" : received));
    case kChildOutOfMemory:
      throw InputError(name + ": corrupt VDB file: reading it needs more than " + std::to_string(budget >> 20) +
                       " MiB of memory");
    default:
      throw InputError(name + ": the VDB reader process failed (exit code " + std::to_string(WEXITSTATUS(status)) +
                       ")");
  }
}

}  // namespace

VdbContents readVdbFileIsolated(const fs::path& file) {
  initializeOpenVdb();
  // OpenVDB's type registries (grids, maps, metadata) are guarded by mutexes: a fork
  // while another thread of ours holds one would deadlock the child, so reads in this
  // process, isolated or not, take turns.
  static std::mutex readMutex;
  std::lock_guard<std::mutex> lock(readMutex);
  const std::string name = file.string();
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(name + ": no such file");
  if (fs::is_directory(file, ec)) throw InputError(name + ": is a directory, not a VDB file");
  if (std::string why = whyNotRegularFile(file); !why.empty())
    throw InputError(name + ": cannot read material set (" + why + ")");

  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(name + ": cannot open: " + std::strerror(errno));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(name + ": cannot read the file");
  if (bytes.empty()) throw InputError(name + ": empty file, not a VDB file");
  std::int64_t magic = 0;
  if (bytes.size() >= sizeof(magic)) std::memcpy(&magic, bytes.data(), sizeof(magic));
  if (magic != std::int64_t(openvdb::OPENVDB_MAGIC)) throw InputError(name + ": not a VDB file (no OpenVDB header)");

  const std::string trusted = parseInChild(bytes, name);
  try {
    MemoryReadBuffer source(trusted.data(), trusted.size());
    std::istream stream(&source);
    openvdb::io::Stream reader(stream, /*delayLoad=*/false);
    VdbContents contents;
    contents.grids = reader.getGrids();
    contents.metadata = reader.getMetadata();
    if (!contents.grids) contents.grids = std::make_shared<openvdb::GridPtrVec>();
    if (!contents.metadata) contents.metadata = std::make_shared<openvdb::MetaMap>();
    return contents;
  } catch (const std::exception& e) {
    throw InputError(name + ": not a valid VDB file: " + oneLine(e.what()));
  }
}

}  // namespace sslpv

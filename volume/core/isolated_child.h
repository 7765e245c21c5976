#pragma once
// Running a third-party file parser that is not hardened (OpenVDB, assimp) in a forked
// child process, so that its crashes, aborts, runaway allocations and endless loops on a
// corrupt file become an InputError in this process instead of taking it down.
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>

namespace sslpv {

/// Exit codes a child body returns; anything else (or a signal) means the child failed.
inline constexpr int kChildOk = 0;
inline constexpr int kChildParseError = 1;   ///< what it wrote is the one-line reason
inline constexpr int kChildOutOfMemory = 2;
inline constexpr int kChildWriteError = 3;

/// How messages name the file kind and the parser: "corrupt VDB file (the OpenVDB reader
/// crashed with signal 11, ...)".
struct IsolatedParser {
  const char* fileKind;  ///< "VDB file"
  const char* parser;    ///< "the OpenVDB reader"
  const char* process;   ///< "the VDB reader process"
};

struct ChildOutput {
  bool parseError = false;  ///< the child returned kChildParseError; `bytes` is its reason
  std::string bytes;        ///< everything the child wrote to its pipe
};

/// Memory a reader child may use beyond what it inherits: 1 GiB plus `perInputByte` per
/// byte of input, capped at 3/4 of physical memory so a corrupt length field cannot push
/// the machine into the OOM killer.
std::size_t isolatedMemoryBudget(std::size_t inputBytes, std::size_t perInputByte);

/// Generous: a legitimate file is parsed at tens of MB/s; this only stops a parser that
/// loops forever on corrupt data.
std::chrono::seconds isolatedTimeout(std::size_t inputBytes);

/// Forks; the child (stdout/stderr to /dev/null, default crash signals, address space
/// limited to its current size + `memoryBudget`) runs `body(fd)`, which writes its result
/// to fd and returns an exit code above (std::bad_alloc counts as out of memory). Returns
/// what the child wrote. Throws InputError naming `name` when the child crashed, ran out
/// of memory, failed otherwise or exceeded `timeout`; ResourceError when no child starts.
ChildOutput runIsolated(const std::string& name, const IsolatedParser& parser, std::size_t memoryBudget,
                        std::chrono::seconds timeout, const std::function<int(int fd)>& body);

/// write(2) until done; false on error. For child bodies.
bool writeFully(int fd, const char* data, std::size_t size);

}  // namespace sslpv

#pragma once
// Every output file is written to a temporary sibling and renamed into place, so a
// failed run never leaves a truncated or half-overwritten file behind.
#include <filesystem>
#include <functional>
#include <vector>

namespace sslpv {

/// Fails with InputError naming `target` when its directory does not exist or is not
/// writable. Called before expensive work so a bad output path fails fast.
void requireWritableOutput(const std::filesystem::path& target);

/// Calls `write(tempPath)`, then renames tempPath over `target`. If `write` throws or
/// the rename fails, the temporary file is removed and `target` is left untouched.
void writeAtomically(const std::filesystem::path& target,
                     const std::function<void(const std::filesystem::path& tempPath)>& write);

/// One file of a set written by writeAtomicallyTogether.
struct AtomicOutput {
  std::filesystem::path target;
  std::function<void(const std::filesystem::path& tempPath)> write;
};

/// Files that belong together (an image and its standard-error image): every temporary
/// is written before any target is replaced, so a failed write (a full disk) leaves all
/// targets as they were rather than a new image beside a stale companion.
void writeAtomicallyTogether(const std::vector<AtomicOutput>& outputs);

/// Removes "<target>.tmp-<pid>-<n>" temporaries left beside `target` by a process that was
/// killed (SIGKILL, power loss) while writing it, when process <pid> no longer exists.
/// Every atomic write does this for its target; a program that may not write for a while
/// (an editor opening a document) calls it at start, so the debris goes at once.
void removeStaleTemporaries(const std::filesystem::path& target);

/// Throws ResourceError "<target>: write failed: <strerror(error)>"; for writers whose
/// stream failed (a full disk: "No space left on device").
[[noreturn]] void throwWriteFailed(const std::filesystem::path& target, int error);

/// Installs SIGINT, SIGTERM and SIGHUP handlers that remove the temporaries being
/// written, then re-raise the signal so the exit status stays the conventional one.
/// For programs (the CLI's main), not libraries.
void removeTemporariesOnSignals();

}  // namespace sslpv

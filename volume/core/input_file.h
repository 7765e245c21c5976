#pragma once
// Every reader of a user-named file (scene, stroke file, mesh and the files a mesh refers
// to, material set) goes through here first: a FIFO, a device (/dev/zero, /dev/urandom)
// or a /proc or /sys pseudo-file would block a read forever or yield endless bytes, so
// anything but a regular file on a real file system is refused before it is opened.
#include <cstdint>
#include <filesystem>
#include <string>

namespace sslpv {

/// Largest scene or stroke file read: far beyond any hand-written or exported document,
/// small enough that reading and parsing it cannot exhaust memory.
inline constexpr std::uint64_t kMaxJsonInputBytes = std::uint64_t(64) << 20;

/// Empty when `file` is a readable candidate, else the reason it is refused
/// ("not found", "is a FIFO, not a regular file", ...). Never opens the file.
std::string whyNotRegularFile(const std::filesystem::path& file);

/// Throws InputError "<file>: cannot read <what> (<reason>)" unless `file` is a regular
/// file on a real file system. Follows symbolic links. `what`: e.g. "scene file".
void requireRegularFile(const std::filesystem::path& file, const char* what);

/// The whole content of a regular file of at most `maxBytes` bytes; InputError naming
/// `file` and `what` otherwise (including the cap, when it is exceeded).
std::string readRegularFile(const std::filesystem::path& file, const char* what, std::uint64_t maxBytes);

}  // namespace sslpv

#include "volume/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <system_error>

#include "volume/error.h"

namespace sslpv {
namespace fs = std::filesystem;

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

void writeAtomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  requireWritableOutput(target);
  static std::atomic<unsigned> counter{0};
  // Same directory as the target, so the rename never crosses file systems.
  fs::path temp = target;
  temp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  try {
    write(temp);
    std::error_code ec;
    fs::rename(temp, target, ec);
    if (ec) throw InputError(target.string() + ": cannot replace file: " + ec.message());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
}

}  // namespace sslpv

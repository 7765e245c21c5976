#include "volume/core/input_file.h"

#include <linux/magic.h>
#include <sys/stat.h>
#include <sys/statfs.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "volume/core/error.h"

namespace sslpv {

namespace fs = std::filesystem;

namespace {

const char* kindOf(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string sizeText(std::uint64_t bytes) {
  if (bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

}  // namespace

std::string whyNotRegularFile(const fs::path& file) {
  struct stat info {};
  if (::stat(file.c_str(), &info) != 0) return std::strerror(errno);
  if (S_ISDIR(info.st_mode)) return std::strerror(EISDIR);
  if (!S_ISREG(info.st_mode)) {
    const std::string kind = kindOf(info.st_mode);
    return kind == "not a regular file" ? kind : "is " + kind + ", not a regular file";
  }
  // /proc and /sys files claim to be regular files of size 0 while producing unbounded
  // or unreadable content (/proc/self/mem fails every read at offset 0).
  struct statfs fsInfo {};
  if (::statfs(file.c_str(), &fsInfo) == 0 &&
      (fsInfo.f_type == PROC_SUPER_MAGIC || fsInfo.f_type == SYSFS_MAGIC))
    return "is a /proc or /sys pseudo-file, not a regular file";
  return {};
}

void requireRegularFile(const fs::path& file, const char* what) {
  const std::string reason = whyNotRegularFile(file);
  if (!reason.empty()) throw InputError(file.string() + ": cannot read " + what + " (" + reason + ")");
}

std::string readRegularFile(const fs::path& file, const char* what, std::uint64_t maxBytes) {
  requireRegularFile(file, what);
  auto cannotRead = [&](const std::string& reason) {
    return InputError(file.string() + ": cannot read " + what + " (" + reason + ")");
  };
  std::FILE* stream = std::fopen(file.c_str(), "rb");
  if (!stream) throw cannotRead(std::strerror(errno));
  std::string text;
  char buffer[65536];
  std::size_t got = 0;
  // The cap is enforced on the bytes read, not on st_size, which a file growing while it
  // is read would outrun.
  while ((got = std::fread(buffer, 1, sizeof buffer, stream)) > 0) {
    if (text.size() + got > maxBytes) {
      std::fclose(stream);
      throw cannotRead("larger than the " + sizeText(maxBytes) + " limit");
    }
    text.append(buffer, got);
  }
  const int readError = std::ferror(stream) ? errno : 0;
  std::fclose(stream);
  if (readError != 0) throw cannotRead(std::strerror(readError));
  return text;
}

}  // namespace sslpv

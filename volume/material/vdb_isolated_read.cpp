#include "volume/material/vdb_isolated_read.h"

#include <openvdb/io/Stream.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <mutex>
#include <streambuf>
#include <string>

#include "volume/core/error.h"
#include "volume/core/input_file.h"
#include "volume/core/isolated_child.h"
#include "volume/material/material_set.h"

namespace sslpv {
namespace {
namespace fs = std::filesystem;

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

/// The child's work: parse the untrusted bytes, then write what was read as a fresh stream
/// from OpenVDB's writer. OpenVDB's read/write paths used here are serial (grid
/// statistics, which use TBB, are switched off), so the forked child needs no other thread.
int readInChild(const std::string& bytes, int fd) {
  auto fail = [fd](const std::string& message) {
    writeFully(fd, message.data(), message.size());
    return kChildParseError;
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
    if (in.fail()) return fail(kEndedEarly);
    return kChildOutOfMemory;
  } catch (const std::exception& e) {
    return fail(in.fail() ? std::string(kEndedEarly) + ": " + oneLine(e.what()) : oneLine(e.what()));
  } catch (...) {
    return fail(in.fail() ? kEndedEarly : "unknown error");
  }
  if (in.fail()) return fail(kEndedEarly);
  FdWriteBuffer sink(fd);
  std::ostream out(&sink);
  openvdb::io::Stream writer(out);
  std::uint32_t compression = openvdb::io::COMPRESS_ACTIVE_MASK;
  if (openvdb::io::Archive::hasBloscCompression()) compression |= openvdb::io::COMPRESS_BLOSC;
  writer.setCompression(compression);
  writer.setGridStatsMetadataEnabled(false);
  writer.write(*grids, metadata ? *metadata : openvdb::MetaMap());
  out.flush();
  return out ? kChildOk : kChildWriteError;
}

/// The re-serialized stream the reader child wrote.
std::string parseInChild(const std::string& bytes, const std::string& name) {
  static const IsolatedParser kParser{"VDB file", "the OpenVDB reader", "the VDB reader process"};
  // A legitimate file grows by its compression ratio when loaded (zip of smooth data:
  // tens, constant leaves: ~100); a corrupt length field asks for gigabytes.
  ChildOutput output = runIsolated(name, kParser, isolatedMemoryBudget(bytes.size(), 256), isolatedTimeout(bytes.size()),
                                   [&bytes](int fd) { return readInChild(bytes, fd); });
  if (output.parseError)
    throw InputError(name + ": not a valid VDB file: " + (output.bytes.empty() ? "unreadable" : output.bytes));
  return std::move(output.bytes);
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

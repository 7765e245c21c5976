#pragma once
// Reading untrusted OpenVDB files without trusting OpenVDB's parser with them.
//
// OpenVDB 10's reader is not hardened. Fuzzing it here with truncated and byte-flipped
// material sets (2000 mutations over zip, blosc and uncompressed files) gave heap buffer
// overflows (io::bloscFromStream trusts the chunk size stored in the file) ending in
// glibc aborts ("malloc(): corrupted top size", "double free or corruption") in ~1% of
// the cases, allocations beyond 1 GiB in ~10% (one corrupt 100 kB file reached 10 GB
// resident), and truncated files that "load" because it never checks its reads.
// Parsing from memory (io::Stream over a string) crashed just the same, and checking
// with readGridMetadata first cannot help: the damage happens while trees are read.
//
// So the file is parsed in a forked child process with an address-space limit; the
// child writes the grids it read back through a pipe as a stream that OpenVDB's own
// writer produced, and only that stream is parsed in this process. A reader that ran
// past the end of its input reports the file as truncated.
#include <openvdb/openvdb.h>

#include <filesystem>

namespace sslpv {

struct VdbContents {
  openvdb::GridPtrVecPtr grids;    ///< every grid, fully loaded (no delayed loading)
  openvdb::MetaMap::Ptr metadata;  ///< file-level metadata
};

/// Reads every grid and the file metadata of `file`. Throws InputError naming the file
/// when it is missing, empty, not a VDB file, truncated or corrupt (including corruption
/// that crashes the OpenVDB reader or makes it exhaust memory). Never crashes.
VdbContents readVdbFileIsolated(const std::filesystem::path& file);

}  // namespace sslpv

#pragma once
// The two kinds of failure the tool reports. Bad input is the user's to fix and
// must name the file, key or voxel; resource errors (memory) say what was asked for.
#include <stdexcept>
#include <string>

namespace sslpv {

/// Invalid user input: malformed scene, bad material set, unreadable file, bad flag.
/// The message is one line and names the file and the key path / grid / voxel.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A request that cannot be met on this machine (for example a grid too large for memory).
class ResourceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace sslpv

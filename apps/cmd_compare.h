#pragma once
// `sslpv compare A B`: error metrics of a test image A (an SSLPV render) against a
// reference B (usually `sslpv reference`), over the object's pixels. Definitions of the
// metrics in volume/eval/image_metrics.h.
#include <CLI/CLI.hpp>
#include <string>

namespace sslpv {

struct CompareArgs {
  std::string a, b;             ///< linear .exr/.pfm images (PNG is refused: tone-mapped)
  std::string mask = "auto";    ///< "auto" (non-zero in A or B) or a mask image (value > 0)
  int block = 1;                ///< average K×K blocks first
  std::string json;             ///< optional JSON record, written atomically
  std::string ratioMap;         ///< optional per-channel map of A / B (ratioMap), written atomically
};

CLI::App* addCompareCommand(CLI::App& app, CompareArgs& args);

/// Prints the table to stdout; throws InputError (exit 2) naming the file on bad input.
int runCompare(const CompareArgs& args);

}  // namespace sslpv

#pragma once
// `sslpv render --frames A:B[:STEP] -o PATTERN`: which frames, and the file each goes to.
#include <string>
#include <vector>

namespace sslpv {

/// Frames first..last (inclusive) every `step`; a frame's time is frame / fps.
struct FrameRange {
  int first = 0, last = 0, step = 1;
  std::vector<int> frames() const;
};

/// Most frames one command renders: a typo like 0:1000000 should not start a day's run.
inline constexpr int kMaxFrames = 100000;

/// "A:B" or "A:B:STEP", whole numbers, 0 <= A <= B, STEP >= 1. InputError naming --frames.
FrameRange parseFrameRange(const std::string& text);

/// InputError naming -o unless `pattern` holds exactly one frame-number field, %d or
/// %0Nd (N from 1 to 9), and otherwise only %% for a literal percent sign.
void requireFramePattern(const std::string& pattern);

/// `pattern` with its frame-number field replaced by `frame` (a checked pattern).
std::string framePath(const std::string& pattern, int frame);

}  // namespace sslpv

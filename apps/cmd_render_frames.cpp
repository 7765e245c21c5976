#include "apps/cmd_render_frames.h"

#include <cctype>
#include <cstdio>

#include "volume/core/error.h"

namespace sslpv {
namespace {

/// A whole number in [0, 10^9) or -1.
long long wholeNumber(const std::string& text) {
  if (text.empty() || text.size() > 9) return -1;
  long long value = 0;
  for (char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return -1;
    value = value * 10 + (c - '0');
  }
  return value;
}

/// Walks `pattern`'s % fields: calls `field(width)` for each %d / %0Nd (width 0 for %d),
/// `literal(text)` for the rest; false on any other % sequence.
template <class Field, class Literal>
bool walkPattern(const std::string& pattern, Field field, Literal literal) {
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      literal(std::string(1, pattern[i]));
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      literal("%");
      ++i;
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == 'd') {
      field(0);
      ++i;
      continue;
    }
    if (i + 3 < pattern.size() && pattern[i + 1] == '0' && pattern[i + 2] >= '1' && pattern[i + 2] <= '9' &&
        pattern[i + 3] == 'd') {
      field(pattern[i + 2] - '0');
      i += 3;
      continue;
    }
    return false;
  }
  return true;
}

}  // namespace

std::vector<int> FrameRange::frames() const {
  std::vector<int> result;
  for (long long f = first; f <= last; f += step) result.push_back(int(f));
  return result;
}

FrameRange parseFrameRange(const std::string& text) {
  std::vector<std::string> parts(1);
  for (char c : text) {
    if (c == ':')
      parts.emplace_back();
    else
      parts.back() += c;
  }
  const std::string usage = "--frames: expected A:B or A:B:STEP (whole frame numbers, 0 <= A <= B, STEP >= 1), got '" +
                            text + "'";
  if (parts.size() < 2 || parts.size() > 3) throw InputError(usage);
  const long long a = wholeNumber(parts[0]), b = wholeNumber(parts[1]);
  const long long step = parts.size() == 3 ? wholeNumber(parts[2]) : 1;
  if (a < 0 || b < 0 || step < 1 || a > b) throw InputError(usage);
  if ((b - a) / step + 1 > kMaxFrames)
    throw InputError("--frames: " + text + " is " + std::to_string((b - a) / step + 1) + " frames, more than " +
                     std::to_string(kMaxFrames));
  return FrameRange{int(a), int(b), int(step)};
}

void requireFramePattern(const std::string& pattern) {
  int fields = 0;
  if (!walkPattern(pattern, [&](int) { ++fields; }, [](const std::string&) {}) || fields != 1)
    throw InputError("-o: " + pattern +
                     ": with --frames the output needs exactly one frame-number field, %d or %0Nd "
                     "(e.g. out_%04d.png; %% for a literal %)");
}

std::string framePath(const std::string& pattern, int frame) {
  std::string result;
  walkPattern(
      pattern,
      [&](int width) {
        char text[32];
        std::snprintf(text, sizeof text, "%0*d", width, frame);
        result += text;
      },
      [&](const std::string& literal) { result += literal; });
  return result;
}

}  // namespace sslpv

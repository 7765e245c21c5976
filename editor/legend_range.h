#pragma once
// The slice views' colour range. Fitted to the values on screen, except during a stroke:
// refitted after every dab, the colours of the voxels the stroke never touched would
// shift with each one (the whole slice flickers). Held, the range stays as the stroke
// found it, values beyond it show in the end colours, and the release refits once.
// Locked by the user, the range is theirs for every channel until unlocked: the same
// colour means the same value across strokes, channels and sessions of comparison.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

namespace sslpv {

class LegendRange {
 public:
  void hold(bool on) { held_ = on; }
  /// The range to show for `channel` whose values span [lo, hi]. Held, the previous range
  /// of the same channel; another channel is always fitted.
  std::pair<double, double> fit(const std::string& channel, double lo, double hi) {
    if (locked_) return *locked_;
    if (held_ && range_ && channel == channel_) return *range_;
    // A uniform slice still needs a visible legend range.
    if (!(hi > lo)) {
      const double pad = std::max(std::abs(lo) * 0.05, 1e-3);
      lo -= pad;
      hi += pad;
    }
    channel_ = channel;
    range_ = std::make_pair(lo, hi);
    return *range_;
  }

  /// Fixes the range to [lo, hi]; false (nothing changes) unless both are finite and lo < hi.
  bool lock(double lo, double hi) {
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) return false;
    locked_ = std::make_pair(lo, hi);
    return true;
  }
  void unlock() { locked_.reset(); }
  bool locked() const { return locked_.has_value(); }
  /// The range last shown (locked or fitted); absent before the first fit.
  std::optional<std::pair<double, double>> current() const { return locked_ ? locked_ : range_; }

 private:
  std::optional<std::pair<double, double>> locked_;
  bool held_ = false;
  std::string channel_;
  std::optional<std::pair<double, double>> range_;
};

}  // namespace sslpv

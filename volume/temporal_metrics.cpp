#include "volume/temporal_metrics.h"

#include <cmath>
#include <stdexcept>

#include "volume/image_metrics.h"

namespace sslpv {

TemporalChange temporalChange(const std::vector<Image>& frames) {
  if (frames.size() < 3) throw std::invalid_argument("temporalChange: needs at least 3 frames");
  const Image& first = frames.front();
  for (const Image& f : frames)
    if (f.width != first.width || f.height != first.height)
      throw std::invalid_argument("temporalChange: frames differ in size");
  TemporalChange change;
  double motion = 0.0, flicker = 0.0, total = 0.0;
  std::size_t firstDifferences = 0, secondDifferences = 0;
  for (std::size_t i = 0; i < first.pixels.size(); ++i) {
    bool litThroughout = true;
    for (const Image& f : frames) litThroughout = litThroughout && luminance(f.pixels[i]) > 0.0;
    if (!litThroughout) continue;
    ++change.pixels;
    for (std::size_t t = 0; t < frames.size(); ++t) {
      const double now = luminance(frames[t].pixels[i]);
      total += now;
      if (t + 1 < frames.size()) {
        motion += std::abs(luminance(frames[t + 1].pixels[i]) - now);
        ++firstDifferences;
      }
      if (t > 0 && t + 1 < frames.size()) {
        flicker += std::abs(luminance(frames[t + 1].pixels[i]) - 2.0 * now + luminance(frames[t - 1].pixels[i]));
        ++secondDifferences;
      }
    }
  }
  if (change.pixels == 0) return change;
  const double mean = total / double(change.pixels * frames.size());
  if (!(mean > 0.0)) return change;
  change.motion = motion / double(firstDifferences) / mean;
  change.flicker = flicker / double(secondDifferences) / mean;
  return change;
}

}  // namespace sslpv

#include "volume/eval/temporal_metrics.h"

#include <cmath>
#include <stdexcept>

#include "volume/eval/image_metrics.h"

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
  std::vector<unsigned char> lit(first.pixels.size(), 1);
  for (std::size_t i = 0; i < first.pixels.size(); ++i)
    for (const Image& f : frames) lit[i] = lit[i] && luminance(f.pixels[i]) > 0.0;
  const int w = first.width, h = first.height;
  for (std::size_t i = 0; i < first.pixels.size(); ++i) {
    // Next to a pixel dark in some frame lies a silhouette, whose pixels change by their
    // coverage as the object moves: motion of the outline, not of the shading.
    const int x = int(i % std::size_t(w)), y = int(i / std::size_t(w));
    const bool interior = lit[i] && (x == 0 || lit[i - 1]) && (x == w - 1 || lit[i + 1]) &&
                          (y == 0 || lit[i - std::size_t(w)]) && (y == h - 1 || lit[i + std::size_t(w)]);
    if (!interior) continue;
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

#pragma once
// Frame-to-frame stability of a preview sequence (a light or an object moving slowly over
// a static camera): how much of the change between frames is the scene's own smooth
// change, and how much is flicker (shadow-map texels, grid cells or a stopping rule
// switching from one frame to the next).
#include <cstddef>
#include <vector>

#include "volume/core/image_io.h"

namespace sslpv {

struct TemporalChange {
  /// Mean over pixels lit in every frame, as are their four neighbours (no silhouette pixel,
  /// whose change is the outline's coverage), and over consecutive frames of
  /// |L(t+1) − L(t)| (luminance), divided by the mean luminance: the change per frame.
  double motion = 0.0;
  /// The same for the second difference |L(t+1) − 2 L(t) + L(t−1)|. A change that is
  /// smooth in time has flicker ≈ motion × (step / the time over which it bends), which
  /// halves with the step; a jump from one frame to the next counts in both, so flicker
  /// stays near motion whatever the step.
  double flicker = 0.0;
  std::size_t pixels = 0;  ///< pixels counted: lit in every frame, and so are their neighbours
};

/// Throws std::invalid_argument for fewer than 3 frames or frames of different sizes.
TemporalChange temporalChange(const std::vector<Image>& frames);

}  // namespace sslpv

#pragma once
// Where each pixel of a scene's camera reads the LPV grid: the geometry gridBandAmplitude
// (image_metrics.h) bins a render's luminance by, for the CPU shading's own read point.
#include <vector>

#include "volume/eval/image_metrics.h"
#include "volume/scene/scene.h"

namespace sslpv {

/// The surface pixels of `scene`'s camera with the continuous grid coordinates of the
/// point the shading reads on an LPV of `resolution` cells along the object's longest
/// axis: half a cell inside the hit along the normal (volume/cpu/shade.cpp). Pixels that see
/// the surface from behind are left out, as the shading leaves them. Loads the object
/// (InputError on bad input).
std::vector<GridBandSample> gridBandSamples(const Scene& scene, int resolution);

}  // namespace sslpv

#pragma once
// Shared by the slab benchmarks, whose cameras see only a uniform patch of the slab: the
// whole image's mean radiance per channel.
#include <glm/vec3.hpp>

#include "volume/core/image_io.h"

namespace sslpv::bench {

inline glm::dvec3 meanRadiance(const Image& image) {
  glm::dvec3 sum(0.0);
  for (const glm::vec3& p : image.pixels) sum += glm::dvec3(p);
  return sum / double(image.pixels.size());
}

}  // namespace sslpv::bench

#pragma once
// Axis-aligned boxes in world space (meshes, material regions, grids).
#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace sslpv {

struct Bounds {
  glm::dvec3 min{1e300};
  glm::dvec3 max{-1e300};
  void extend(const glm::dvec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  bool empty() const { return min.x > max.x; }
  glm::dvec3 extent() const { return max - min; }
};

}  // namespace sslpv

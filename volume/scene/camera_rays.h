#pragma once
// The pinhole camera's pixel rays: pixel centres, vertical field of view, square pixels,
// row 0 at the top. The one definition CPU shading, the GPU shading's push constants
// (shaders/shade.comp repeats pixelDirection in GLSL), the path tracer and the band
// metric share, so all of them see the same pixels.
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

#include "volume/scene/scene.h"

namespace sslpv {

struct CameraRays {
  explicit CameraRays(const Camera& camera)
      : position(camera.position),
        forward(glm::normalize(camera.target - camera.position)),
        right(glm::normalize(glm::cross(forward, camera.up))),
        up(glm::cross(right, forward)),
        tanHalfY(std::tan(glm::radians(0.5 * camera.fovYDeg))),
        tanHalfX(tanHalfY * camera.width / camera.height),
        width(camera.width),
        height(camera.height) {}

  /// Unit direction through the centre of pixel (x, y).
  glm::dvec3 pixelDirection(int x, int y) const {
    const double u = (2.0 * (x + 0.5) / width - 1.0) * tanHalfX;
    const double v = (1.0 - 2.0 * (y + 0.5) / height) * tanHalfY;
    return glm::normalize(forward + u * right + v * up);
  }

  glm::dvec3 position, forward, right, up;
  double tanHalfY, tanHalfX;
  int width, height;
};

}  // namespace sslpv

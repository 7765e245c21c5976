#include "volume/grid_band_samples.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "volume/lpv_grid.h"
#include "volume/ray_scene.h"
#include "volume/scene_object.h"

namespace sslpv {

std::vector<GridBandSample> gridBandSamples(const Scene& scene, int resolution) {
  const SceneObject object(scene);
  const RayScene rays(object.mesh());
  const GridFrame frame = makeGridFrame(object.bounds(), resolution);
  const Camera& camera = scene.camera;
  // The same rays as traceShadingSurface casts (pixel centres, its camera basis).
  const glm::dvec3 forward = glm::normalize(camera.target - camera.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tanHalfY = std::tan(glm::radians(0.5 * camera.fovYDeg));
  const double tanHalfX = tanHalfY * camera.width / camera.height;
  std::vector<GridBandSample> samples;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const double u = (2.0 * (x + 0.5) / camera.width - 1.0) * tanHalfX;
      const double v = (1.0 - 2.0 * (y + 0.5) / camera.height) * tanHalfY;
      const glm::vec3 dir(glm::normalize(forward + u * right + v * up));
      const RayHit hit = rays.intersect(glm::vec3(camera.position), dir);
      if (!hit.hit || glm::dot(dir, hit.normal) >= 0.0f) continue;
      GridBandSample s;
      s.pixel = std::uint32_t(y) * std::uint32_t(camera.width) + std::uint32_t(x);
      s.normal = glm::dvec3(hit.normal);
      s.position = glm::dvec3(hit.position);
      s.grid = frame.toGrid(s.position - 0.5 * frame.cellSize * s.normal);
      samples.push_back(s);
    }
  return samples;
}

}  // namespace sslpv

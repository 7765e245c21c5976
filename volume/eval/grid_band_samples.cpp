#include "volume/eval/grid_band_samples.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "volume/lpv/lpv_grid.h"
#include "volume/scene/ray_scene.h"
#include "volume/material/scene_object.h"
#include "volume/scene/camera_rays.h"

namespace sslpv {

std::vector<GridBandSample> gridBandSamples(const Scene& scene, int resolution) {
  const SceneObject object(scene);
  const RayScene rays(object.mesh());
  const GridFrame frame = makeGridFrame(object.bounds(), resolution);
  const Camera& camera = scene.camera;
  const CameraRays pixelRays(camera);  // the rays traceShadingSurface casts
  std::vector<GridBandSample> samples;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const glm::vec3 dir(pixelRays.pixelDirection(x, y));
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

#pragma once
// Ray casting against the object's surface (Embree 3), used by the CPU shadow maps and
// camera shading. Thread-safe after construction.
#include <glm/vec3.hpp>
#include <memory>

#include "volume/scene/mesh.h"

namespace sslpv {

struct RayHit {
  bool hit = false;
  float t = 0.0f;
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};  ///< geometric unit normal, pointing out of the closed mesh
  unsigned triangle = 0;
};

class RayScene {
 public:
  explicit RayScene(const TriangleMesh& mesh);
  ~RayScene();
  RayScene(RayScene&&) noexcept;
  RayScene& operator=(RayScene&&) noexcept;
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  /// Closest hit along origin + t*dir, t in [tNear, tFar]. `dir` need not be normalized;
  /// t is in units of |dir|.
  RayHit intersect(const glm::vec3& origin, const glm::vec3& dir, float tNear = 0.0f,
                   float tFar = 3.0e38f) const;

  /// Intersects `count` rays at once (coherent batches are faster); results into hits.
  void intersectMany(const glm::vec3* origins, const glm::vec3* dirs, RayHit* hits,
                     std::size_t count) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sslpv

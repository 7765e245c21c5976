#pragma once
// Scenes that load fine but render black or wrong: the camera or a light inside the
// object, an object far larger or smaller than translucent objects are. Not errors (an
// artist may mean it, e.g. a camera inside a lamp shade); the CLI prints them as warnings.
#include <memory>
#include <string>
#include <vector>

#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"

namespace sslpv {

/// Longest extent in millimetres outside which an object is "far from" any translucent
/// object this tool is meant for (a grain of salt to a large statue): almost always a
/// transform.scale or units slip (scale 1000 for 1, "m" for "mm").
inline constexpr double kTypicalObjectMinMm = 0.1;
inline constexpr double kTypicalObjectMaxMm = 10000.0;

class RayScene;

/// Whether points lie inside the closed, outward-facing `worldMesh` (kept by reference):
/// rays in three directions vote on whether the first surface they meet is left (a back
/// face). The ray-casting structure is built once, when a point inside the bounds first
/// needs it.
class MeshInsideTest {
 public:
  explicit MeshInsideTest(const TriangleMesh& worldMesh);
  ~MeshInsideTest();
  bool operator()(const glm::dvec3& point);

 private:
  const TriangleMesh& mesh_;
  Bounds bounds_;
  std::unique_ptr<RayScene> rays_;
};

/// One-line warnings (without the "sslpv: warning: " prefix), each naming the scene file
/// and the key: "scene.json: camera.position (0, 0, 0) is inside the object ...".
/// `worldMesh` is the scene's mesh after its transform.
std::vector<std::string> sceneWarnings(const Scene& scene, const TriangleMesh& worldMesh);

/// As above, loading the mesh itself; no warnings when the mesh cannot be loaded (the
/// renderer reports that as an error).
std::vector<std::string> sceneWarnings(const Scene& scene);

}  // namespace sslpv

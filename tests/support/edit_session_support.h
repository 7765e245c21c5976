#pragma once
// The editor session tests' scene, strokes and reference render, shared by the session's
// file and preview tests (edit_session_test) and its asynchronous preview tests.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "editor/edit_session.h"
#include "test_support.h"
#include "volume/cpu/cpu_renderer.h"

namespace sslpv::test {

namespace fs = std::filesystem;
using ordered = nlohmann::ordered_json;

/// Box [-5,5]^3 seen from +z (front face z = 5), keys deliberately not in alphabetical
/// order, so a rewrite that sorts keys shows. Camera 64x48 (4:3).
inline ordered sceneJson() {
  return ordered::parse(R"({
    "units": "mm",
    "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
    "camera": {"position": [6, 8, 30], "target": [0, 0, 0], "fov_y_deg": 35, "width": 64, "height": 48},
    "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.1}, "ior": 1.3},
    "lights": [{"type": "point", "position": [10, 15, 30], "intensity": [2000, 2000, 2000]}],
    "lpv": {"resolution": 16, "steps": 8, "shadow_map": 128}
  })");
}

inline PreviewOptions smallPreview() {
  PreviewOptions options;
  options.longestSide = 64;
  return options;
}

/// A darkening stroke just under the front face: albedo 0.2-0.4, short mean free path.
inline Stroke darkStroke(double x = 0.0) {
  Stroke s;
  s.brush.channel = BrushChannel::AlbedoMfp;
  s.brush.mode = BrushMode::Set;
  s.brush.albedo = glm::dvec3(0.2, 0.3, 0.4);
  s.brush.meanFreePath = glm::dvec3(0.3);
  s.brush.radius = 1.5;
  s.points = {{x, 0.0, 4.0}, {x + 1.0, 1.0, 4.0}};
  return s;
}

/// A full render of `sceneFile` by a fresh CPU renderer, at the session's preview view.
inline Image freshRender(const fs::path& sceneFile, const EditSession& session) {
  Scene scene = loadScene(sceneFile);
  scene.camera = session.previewCamera();
  CpuRenderer renderer(scene);
  return renderer.render(session.previewSettings());
}

struct Files {
  TempDir dir;
  fs::path scene = dir / "scene.json";
  explicit Files(const ordered& json = sceneJson()) { writeText(scene, json.dump(2)); }
};

}  // namespace sslpv::test

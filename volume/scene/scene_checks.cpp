#include "volume/scene/scene_checks.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <glm/geometric.hpp>

#include "volume/core/error.h"
#include "volume/scene/ray_scene.h"
#include "volume/core/strict_json.h"

namespace sslpv {
namespace {

std::string point(const glm::dvec3& p) {
  return "(" + formatNumber(p.x) + ", " + formatNumber(p.y) + ", " + formatNumber(p.z) + ")";
}

std::string millimetres(double mm) {
  char text[64];
  if (mm >= 1000.0)
    std::snprintf(text, sizeof text, "%.3g m", mm / 1000.0);
  else
    std::snprintf(text, sizeof text, "%.3g mm", mm);
  return text;
}

}  // namespace

MeshInsideTest::MeshInsideTest(const TriangleMesh& worldMesh) : mesh_(worldMesh), bounds_(worldMesh.bounds()) {}

MeshInsideTest::~MeshInsideTest() = default;

bool MeshInsideTest::operator()(const glm::dvec3& point) {
  if (mesh_.triangles.empty() || bounds_.empty() || glm::any(glm::lessThan(point, bounds_.min)) ||
      glm::any(glm::greaterThan(point, bounds_.max)))
    return false;
  if (!rays_) rays_ = std::make_unique<RayScene>(mesh_);
  // Directions off every axis and diagonal, so a ray does not graze an edge of a box or
  // run along a face; three votes outvote one ray slipping through a crack between triangles.
  const glm::vec3 directions[] = {glm::normalize(glm::vec3(0.5773f, 0.6168f, 0.5350f)),
                                  glm::normalize(glm::vec3(-0.3419f, 0.2651f, -0.9016f)),
                                  glm::normalize(glm::vec3(0.7133f, -0.6702f, -0.2051f))};
  int inside = 0;
  for (const glm::vec3& d : directions) {
    const RayHit hit = rays_->intersect(glm::vec3(point), d);
    if (hit.hit && glm::dot(hit.normal, d) > 0.0f) ++inside;
  }
  return inside >= 2;
}

std::vector<std::string> sceneWarnings(const Scene& scene, const TriangleMesh& worldMesh) {
  std::vector<std::string> warnings;
  const std::string file = scene.file.string();
  const Bounds bounds = worldMesh.bounds();
  MeshInsideTest inside(worldMesh);
  if (inside(scene.camera.position))
    warnings.push_back(file + ": camera.position " + point(scene.camera.position) +
                       " is inside the object: the image shows its inside, usually black; move the camera out");
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    if (light.type == Light::Type::Directional) continue;
    if (inside(light.position))
      warnings.push_back(file + ": " + indexPath("lights", i) + ".position " + point(light.position) +
                         " is inside the object: the renderers light its surface from outside only, so this "
                         "light adds nothing; move it out");
  }
  if (!bounds.empty()) {
    const glm::dvec3 extent = bounds.extent();
    const double longestMm = std::max({extent.x, extent.y, extent.z}) * scene.unitInMm;
    if (longestMm < kTypicalObjectMinMm || longestMm > kTypicalObjectMaxMm)
      warnings.push_back(file + ": transform.scale: the object is " + millimetres(longestMm) + " across (scale " +
                         formatNumber(scene.transform.scale) + ", units \"" + scene.units +
                         "\"), outside the " + millimetres(kTypicalObjectMinMm) + " to " +
                         millimetres(kTypicalObjectMaxMm) +
                         " translucent objects span; check transform.scale and units (materials are per unit)");
  }
  return warnings;
}

std::vector<std::string> sceneWarnings(const Scene& scene) {
  TriangleMesh mesh;
  try {
    if (scene.deformers.empty()) {
      mesh = loadMesh(scene.mesh, scene.transform, /*warnReoriented=*/false);
    } else {
      // The warnings are about the object as posed (a camera inside the bent bar).
      MeshSource posed;
      posed.kind = MeshSource::Kind::InMemory;
      auto deformed = std::make_shared<TriangleMesh>(loadMesh(scene.mesh, Transform{}, false));
      deformed->positions =
          deformPositions(deformed->positions, DeformationPose(scene.deformers, scene.time), "", scene.time);
      posed.mesh = std::move(deformed);
      mesh = loadMesh(posed, scene.transform, false);
    }
  } catch (const InputError&) {
    return {};
  }
  return sceneWarnings(scene, mesh);
}

}  // namespace sslpv

#pragma once
// The scenes the grid-layer band metric is measured on (bench/band_metric and
// tests/eval/band_test.cpp): a 10 mm box or a 12 mm sphere of one measured material under a
// point light, seen from above and to the side so that three faces of the box show.
#include <glm/vec3.hpp>

#include "bench/slab_scene.h"
#include "volume/scene/material.h"
#include "volume/scene/scene.h"

namespace sslpv::bench {

/// The light and camera every band scene shares; `size` pixels square.
inline void bandLightAndCamera(Scene& scene, int size) {
  Light light;
  light.type = Light::Type::Point;
  light.position = glm::dvec3(-25.0, 35.0, 30.0);
  light.intensity = glm::vec3(2000.0f);
  scene.lights = {light};
  scene.camera.position = glm::dvec3(22.0, 16.0, 38.0);
  scene.camera.target = glm::dvec3(0.0);
  scene.camera.fovYDeg = 22.0;
  scene.camera.width = scene.camera.height = size;
}

/// A 10 mm box of `material` turned `yawDeg` about the vertical axis after tilting it
/// `tiltDeg` about x: its faces cross the grid's cell layers at those angles.
inline Scene bandBox(const MeasuredMaterial& material, double yawDeg, double tiltDeg, int size) {
  Scene scene = materialBox(material, material.eta, glm::dvec3(-5.0), glm::dvec3(5.0));
  scene.transform.rotateDeg = glm::dvec3(tiltDeg, yawDeg, 0.0);
  bandLightAndCamera(scene, size);
  return scene;
}

/// A sphere of radius 6 mm of `material`: every tilt against the grid at once.
inline Scene bandSphere(const MeasuredMaterial& material, int size) {
  Scene scene = materialBox(material, material.eta, glm::dvec3(-6.0), glm::dvec3(6.0));
  scene.mesh.kind = MeshSource::Kind::Sphere;
  scene.mesh.center = glm::dvec3(0.0);
  scene.mesh.radius = 6.0;
  bandLightAndCamera(scene, size);
  return scene;
}

}  // namespace sslpv::bench

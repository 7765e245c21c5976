#include "apps/view_controls.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include "volume/core/math_constants.h"

namespace sslpv {

namespace {

constexpr double kMaxElevation = 85.0 * kPi / 180.0;
constexpr double kRadiansPerPixel = 0.01;  // a 300-pixel drag turns about 170 degrees
constexpr double kZoomPerWheelStep = 0.9;
constexpr double kScrubStep = 0.05;  // of the [0, 1] animation range

/// Any unit vector normal to `n`.
glm::dvec3 perpendicular(const glm::dvec3& n) {
  const glm::dvec3 axis = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(n, axis));
}

/// Where the first light is seen from, relative to the camera's target: a directional
/// light comes from the opposite of the direction it travels.
glm::dvec3 lightOffset(const Light& light, const glm::dvec3& target) {
  return light.type == Light::Type::Directional ? -light.direction : light.position - target;
}

bool sameCamera(const Camera& a, const Camera& b) {
  return a.position == b.position && a.target == b.target && a.up == b.up && a.fovYDeg == b.fovYDeg;
}

}  // namespace

Orbit::Orbit(const glm::dvec3& offset, const glm::dvec3& up) {
  radius_ = glm::length(offset);
  up_ = glm::normalize(up);
  startDir_ = radius_ > 0.0 ? offset / radius_ : perpendicular(up_);
  glm::dvec3 horizontal = startDir_ - glm::dot(startDir_, up_) * up_;
  // Straight above or below: any horizontal direction serves as azimuth 0.
  horizontal = glm::length(horizontal) > 1e-9 ? glm::normalize(horizontal) : perpendicular(up_);
  right_ = glm::normalize(glm::cross(up_, horizontal));
  startElevation_ = std::asin(std::clamp(glm::dot(startDir_, up_), -1.0, 1.0));
  elevation_ = startElevation_;
}

void Orbit::turn(double azimuth, double elevation) {
  azimuth_ = std::remainder(azimuth_ + azimuth, 2.0 * kPi);
  elevation_ = std::clamp(elevation_ + elevation, -kMaxElevation, kMaxElevation);
}

void Orbit::scaleRadius(double factor, double minRadius, double maxRadius) {
  radius_ = std::clamp(radius_ * factor, minRadius, maxRadius);
}

glm::dquat Orbit::rotation() const {
  // About `right` a positive angle tips the horizontal direction down, hence the minus.
  return glm::angleAxis(azimuth_, up_) * glm::angleAxis(-(elevation_ - startElevation_), right_);
}

ViewControls::ViewControls(const Scene& scene, const LpvSettings& settings) : settings_(settings) {
  setCameraFrom(scene.camera);
  baseLights_ = scene.lights;
  if (!baseLights_.empty()) light_ = Orbit(lightOffset(baseLights_[0], baseCamera_.target), baseCamera_.up);
}

void ViewControls::setCameraFrom(const Camera& camera) {
  baseCamera_ = camera;
  camera_ = Orbit(camera.position - camera.target, camera.up);
  startRadius_ = camera_.radius();
}

void ViewControls::sceneChanged(const Scene& scene) {
  if (!sameCamera(scene.camera, baseCamera_)) setCameraFrom(scene.camera);
  const Orbit turned = light_;
  baseLights_ = scene.lights;
  if (!baseLights_.empty()) {
    light_ = Orbit(lightOffset(baseLights_[0], baseCamera_.target), baseCamera_.up);
    // The user's turn of the light carries over to the file's new light.
    light_.turn(turned.azimuthTurned(), turned.elevationTurned());
  }
  settings_.shadowMap = scene.lpv.shadowMap;
  settings_.scheme = scene.lpv.scheme;
}

void ViewControls::orbitCamera(double dx, double dy) {
  camera_.turn(-dx * kRadiansPerPixel, dy * kRadiansPerPixel);
}

void ViewControls::orbitDegrees(double degrees) { camera_.turn(degrees * kPi / 180.0, 0.0); }

void ViewControls::zoom(double wheelSteps) {
  camera_.scaleRadius(std::pow(kZoomPerWheelStep, wheelSteps), startRadius_ * 1e-3, startRadius_ * 1e3);
}

void ViewControls::moveLight(double dx, double dy) {
  light_.turn(dx * kRadiansPerPixel, dy * kRadiansPerPixel);
}

void ViewControls::cycleGrid() {
  constexpr int kGrids[] = {16, 32, 64};
  const int* next = std::upper_bound(std::begin(kGrids), std::end(kGrids), settings_.resolution);
  settings_.resolution = next == std::end(kGrids) ? kGrids[0] : *next;
}

void ViewControls::cycleSteps() {
  if (settings_.autoSteps) {
    settings_.autoSteps = false;
    settings_.steps = 8;
  } else if (settings_.steps < 32) {
    settings_.steps = settings_.steps < 8 ? 8 : settings_.steps < 16 ? 16 : 32;
  } else {
    settings_.autoSteps = true;
  }
}

void ViewControls::togglePlay() {
  if (animated_) playing_ = !playing_;
}

void ViewControls::scrub(double dt) {
  if (animated_) time_ = std::clamp(time_ + dt * kScrubStep, 0.0, 1.0);
}

bool ViewControls::tick(double seconds) {
  if (!animated_ || !playing_ || seconds <= 0.0) return false;
  time_ = std::fmod(time_ + seconds, 1.0);
  return true;
}

Camera ViewControls::camera(int width, int height) const {
  Camera c = baseCamera_;
  c.position = c.target + camera_.offset();
  // The scene's up stays: the horizon stays level, and the elevation limit keeps the view
  // direction from ever becoming parallel to it.
  c.width = width;
  c.height = height;
  return c;
}

std::vector<Light> ViewControls::lights() const {
  std::vector<Light> lights = baseLights_;
  if (lights.empty()) return lights;
  Light& first = lights[0];
  const glm::dquat turn = light_.rotation();
  const glm::dvec3 target = baseCamera_.target;
  if (first.type != Light::Type::Directional) first.position = target + turn * (first.position - target);
  first.direction = glm::normalize(turn * first.direction);
  return lights;
}

std::string ViewControls::settingsText() const {
  return std::to_string(settings_.resolution) + "^3 steps " +
         (settings_.autoSteps ? std::string("auto") : std::to_string(settings_.steps));
}

}  // namespace sslpv

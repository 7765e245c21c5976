#pragma once
// What the viewer's mouse and keys change, kept apart from the window so it can be
// driven by scripts and reasoned about alone: an orbiting camera, the first light moved
// on a sphere about the camera's target, the LPV grid and step settings, and an
// animation time (a no-op for scenes without animation).
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "volume/scene/scene.h"

namespace sslpv {

/// A direction about a centre in spherical coordinates: azimuth about `up`, elevation
/// above the plane normal to it. Azimuth 0 is the starting direction.
class Orbit {
 public:
  Orbit() = default;
  Orbit(const glm::dvec3& offset, const glm::dvec3& up);
  /// Angles in radians; the elevation stays within +-85 degrees so the view never flips.
  void turn(double azimuth, double elevation);
  void scaleRadius(double factor, double minRadius, double maxRadius);
  double radius() const { return radius_; }
  double azimuthTurned() const { return azimuth_; }
  double elevationTurned() const { return elevation_ - startElevation_; }
  glm::dvec3 offset() const { return rotation() * (startDir_ * radius_); }
  /// The rotation from the starting direction to the current one (moves a spot's aim too).
  glm::dquat rotation() const;

 private:
  glm::dvec3 up_{0.0, 1.0, 0.0}, right_{1.0, 0.0, 0.0}, startDir_{0.0, 0.0, 1.0};
  double radius_ = 1.0, startElevation_ = 0.0, azimuth_ = 0.0, elevation_ = 0.0;
};

class ViewControls {
 public:
  ViewControls(const Scene& scene, const LpvSettings& settings);

  /// A reloaded scene: its lights and lpv settings replace the old ones; the camera the
  /// user orbited stays unless the file moved it, and the light keeps the user's turn.
  void sceneChanged(const Scene& scene);

  // Input, in window pixels and wheel steps.
  void orbitCamera(double dx, double dy);
  void zoom(double wheelSteps);
  /// A turntable step: the camera about its target, about the scene's up vector.
  void orbitDegrees(double degrees);
  void moveLight(double dx, double dy);
  void cycleGrid();   ///< 16 -> 32 -> 64 -> 16
  void cycleSteps();  ///< auto -> 8 -> 16 -> 32 -> auto

  // Animation time. Scenes without animation ignore all of it ("static").
  void setAnimated(bool animated) { animated_ = animated; }
  bool animated() const { return animated_; }
  void togglePlay();
  void scrub(double dt);
  /// Advances a playing animation by `seconds` of wall time (wrapping over [0, 1]).
  /// Returns whether the time changed.
  bool tick(double seconds);
  double time() const { return time_; }
  bool playing() const { return playing_; }

  Camera camera(int width, int height) const;
  std::vector<Light> lights() const;
  const LpvSettings& settings() const { return settings_; }
  /// "32^3 steps auto", for the title and the overlay.
  std::string settingsText() const;

 private:
  void setCameraFrom(const Camera& camera);

  Camera baseCamera_;
  Orbit camera_;
  double startRadius_ = 1.0;
  std::vector<Light> baseLights_;
  Orbit light_;  ///< the first light's direction from the camera's target
  LpvSettings settings_;
  bool animated_ = false, playing_ = false;
  double time_ = 0.0;
};

}  // namespace sslpv

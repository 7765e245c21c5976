// The viewer's controls without a window: what drags, the wheel and the keys do to the
// camera, the first light and the LPV settings.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "apps/view_controls.h"
#include "apps/view_overlay.h"

namespace sslpv {
namespace {

Scene spotScene() {
  Scene scene;
  scene.camera.position = {0.0, 35.0, 85.0};
  scene.camera.target = {1.0, 2.0, 3.0};
  Light spot;
  spot.type = Light::Type::Spot;
  spot.position = {-105.0, 65.0, 25.0};
  spot.direction = glm::normalize(scene.camera.target - spot.position);
  Light point;
  point.position = {70.0, 15.0, -90.0};
  scene.lights = {spot, point};
  scene.lpv.resolution = 32;
  scene.lpv.autoSteps = true;
  return scene;
}

TEST(ViewControls, OrbitKeepsTheDistanceAndTargetAndTurnsTheView) {
  const Scene scene = spotScene();
  ViewControls controls(scene, scene.lpv);
  const Camera before = controls.camera(256, 256);
  EXPECT_LT(glm::length(before.position - scene.camera.position), 1e-12 * glm::length(scene.camera.position));
  controls.orbitCamera(120.0, -40.0);
  const Camera after = controls.camera(256, 256);
  const double distance = glm::length(scene.camera.position - scene.camera.target);
  EXPECT_NEAR(glm::length(after.position - after.target), distance, 1e-9 * distance);
  EXPECT_EQ(after.target, scene.camera.target);
  EXPECT_GT(glm::length(after.position - before.position), 0.5 * distance);
  // Back by the same drag: where it started.
  controls.orbitCamera(-120.0, 40.0);
  EXPECT_LT(glm::length(controls.camera(256, 256).position - before.position), 1e-9 * distance);
}

TEST(ViewControls, ElevationStopsShortOfThePoleSoTheViewNeverFlips) {
  const Scene scene = spotScene();
  ViewControls controls(scene, scene.lpv);
  controls.orbitCamera(0.0, 10000.0);  // far past straight up
  const Camera c = controls.camera(64, 64);
  const glm::dvec3 view = glm::normalize(c.position - c.target);
  EXPECT_GT(glm::dot(view, c.up), 0.99);
  EXPECT_LT(glm::dot(view, c.up), std::sin(glm::radians(85.0)) + 1e-9);
}

TEST(ViewControls, WheelZoomsTowardsTheTarget) {
  const Scene scene = spotScene();
  ViewControls controls(scene, scene.lpv);
  const double distance = glm::length(scene.camera.position - scene.camera.target);
  controls.zoom(2.0);
  const Camera c = controls.camera(64, 64);
  EXPECT_NEAR(glm::length(c.position - c.target), distance * 0.81, 1e-9 * distance);
}

TEST(ViewControls, LightMovesOnASphereAndTheSpotKeepsAimingAtTheTarget) {
  const Scene scene = spotScene();
  ViewControls controls(scene, scene.lpv);
  controls.moveLight(150.0, 30.0);
  const std::vector<Light> lights = controls.lights();
  ASSERT_EQ(lights.size(), 2u);
  const glm::dvec3 target = scene.camera.target;
  const double radius = glm::length(scene.lights[0].position - target);
  EXPECT_NEAR(glm::length(lights[0].position - target), radius, 1e-9 * radius);
  EXPECT_GT(glm::length(lights[0].position - scene.lights[0].position), 0.5 * radius);
  EXPECT_NEAR(glm::dot(lights[0].direction, glm::normalize(target - lights[0].position)), 1.0, 1e-9);
  // Only the first light moves.
  EXPECT_EQ(lights[1].position, scene.lights[1].position);
}

TEST(ViewControls, ReloadKeepsTheUsersTurnOfTheLightAndTheirCamera) {
  Scene scene = spotScene();
  ViewControls controls(scene, scene.lpv);
  controls.orbitCamera(50.0, 0.0);
  controls.moveLight(100.0, 0.0);
  const Camera orbited = controls.camera(64, 64);
  const glm::dvec3 turnedLight = controls.lights()[0].position;
  scene.lights[0].intensity = glm::vec3(5.0f);  // the file changed something else
  controls.sceneChanged(scene);
  EXPECT_EQ(controls.camera(64, 64).position, orbited.position);
  EXPECT_LT(glm::length(controls.lights()[0].position - turnedLight), 1e-9 * glm::length(turnedLight));
  EXPECT_EQ(controls.lights()[0].intensity, glm::vec3(5.0f));
  // A camera the file moved wins over the user's orbit.
  scene.camera.position = {0.0, 0.0, 50.0};
  controls.sceneChanged(scene);
  EXPECT_LT(glm::length(controls.camera(64, 64).position - scene.camera.position), 1e-12 * 50.0);
}

TEST(ViewControls, GridAndStepKeysCycle) {
  const Scene scene = spotScene();
  ViewControls controls(scene, scene.lpv);
  std::vector<int> grids;
  for (int i = 0; i < 4; ++i) {
    controls.cycleGrid();
    grids.push_back(controls.settings().resolution);
  }
  EXPECT_EQ(grids, (std::vector<int>{64, 16, 32, 64}));
  std::vector<std::string> steps;
  for (int i = 0; i < 4; ++i) {
    controls.cycleSteps();
    steps.push_back(controls.settingsText());
  }
  EXPECT_EQ(steps, (std::vector<std::string>{"64^3 steps 8", "64^3 steps 16", "64^3 steps 32", "64^3 steps auto"}));
}

TEST(ViewControls, TimeControlsDoNothingForAStaticScene) {
  const Scene scene = spotScene();
  ViewControls controls(scene, scene.lpv);
  controls.togglePlay();
  controls.scrub(1.0);
  EXPECT_FALSE(controls.tick(0.5));
  EXPECT_EQ(controls.time(), 0.0);
  EXPECT_FALSE(controls.playing());
  controls.setAnimated(true);
  controls.scrub(1.0);
  EXPECT_GT(controls.time(), 0.0);
  controls.togglePlay();
  EXPECT_TRUE(controls.tick(0.1));
}

// Before its first image the window shows how long it has waited; the note must be text
// on a plain frame, not a black or garbage buffer.
TEST(ViewOverlay, TheFirstFrameNoteIsWhiteTextOnAPlainDarkFrame) {
  const int width = 320, height = 120;
  const std::vector<unsigned char> rgb = noteFrame(width, height, {"PREPARING THE FIRST FRAME 1.5 S"});
  ASSERT_EQ(rgb.size(), std::size_t(width) * height * 3);
  int text = 0, box = 0, plain = 0, other = 0, textRight = 0, textBottom = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const unsigned char v = rgb[(std::size_t(y) * width + x) * 3];
      if (v == 255) {
        ++text;
        textRight = std::max(textRight, x);
        textBottom = std::max(textBottom, y);
      } else if (v == 48 / 3) {
        ++box;
      } else if (v == 48) {
        ++plain;
      } else {
        ++other;
      }
    }
  EXPECT_EQ(other, 0);
  // 27 glyphs of 5x7 with a few lit pixels each, on one line at the top left.
  EXPECT_GT(text, 27 * 8);
  EXPECT_LT(textBottom, 20);
  EXPECT_GT(textRight, 27 * 5);
  EXPECT_GT(box, text);
  EXPECT_GT(plain, width * height / 2);
}

}  // namespace
}  // namespace sslpv

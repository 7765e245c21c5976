// Where calibrated SSLPV leaves the thick-slab case it is calibrated on (docs/design.md §6.7.3, §6.7.5): the
// same thick slab lit at oblique incidence, and the slab tilted against the grid (its
// boundary a staircase of cells) lit and seen along its normal. Prints SSLPV over the
// path tracer per channel; the normal, grid-aligned row is the calibrated case itself.
//
//   slab_orientation [--grid 64] [--spp 256] [--materials ketchup,skin1,marble]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/image_mean.h"
#include "bench/slab_scene.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/scene/material.h"
#include "volume/reference/reference_tracer.h"
#include "volume/scene/scene.h"

namespace {

using namespace sslpv;

struct Orientation {
  const char* name;
  double incidenceDeg;  ///< light's angle to the slab's normal, in the plane of x and the normal
  glm::dvec3 tiltDeg;   ///< the slab's rotation (scene order: z, y, x)
};

/// A slab 60 x 30 x 60 mm (6 diffusion lengths of ketchup's red from the viewed middle to
/// the sides, the most diffusive channel here), top face through the origin; a 3-degree
/// view of its middle along the normal, so every pixel sees the same depth profile.
Scene slabScene(const MeasuredMaterial& material, const Orientation& o) {
  Scene scene = bench::materialBox(material, material.eta, glm::dvec3(-30.0, -30.0, -30.0), glm::dvec3(30.0, 0.0, 30.0));
  scene.transform.rotateDeg = o.tiltDeg;
  const glm::dmat4 rotation = scene.transform.matrix();
  const glm::dvec3 normal = glm::normalize(glm::dvec3(rotation * glm::dvec4(0, 1, 0, 0)));
  const glm::dvec3 along = glm::normalize(glm::dvec3(rotation * glm::dvec4(1, 0, 0, 0)));
  const double theta = o.incidenceDeg * M_PI / 180.0;
  Light light;
  light.type = Light::Type::Directional;
  light.direction = std::sin(theta) * along - std::cos(theta) * normal;
  light.irradiance = glm::vec3(1.0f);
  scene.lights = {light};
  scene.camera.position = 200.0 * normal;
  scene.camera.target = glm::dvec3(0.0);
  scene.camera.up = glm::normalize(glm::dvec3(rotation * glm::dvec4(0, 0, 1, 0)));
  scene.camera.fovYDeg = 3.0;
  scene.camera.width = scene.camera.height = 32;
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Flags flags(argc, argv, {"grid", "spp", "materials"},
                           "slab_orientation [--grid N] [--spp N] [--materials a,b]");
  if (!flags.ok()) return 2;
  bool known = true;
  const std::vector<std::string> names = flags.names("materials", {"ketchup", "skin1", "marble"});
  const std::vector<MeasuredMaterial> picked =
      bench::pickMaterials(measuredMaterials(), names, "slab_orientation", known);
  if (!known) return 2;
  const int grid = flags.integer("grid", 64), spp = flags.integer("spp", 256);
  const Orientation orientations[] = {
      {"normal", 0.0, glm::dvec3(0.0)},
      {"incidence 45", 45.0, glm::dvec3(0.0)},
      {"incidence 69", 69.0, glm::dvec3(0.0)},
      {"incidence 80", 80.0, glm::dvec3(0.0)},
      {"tilt 30", 0.0, glm::dvec3(0.0, 0.0, 30.0)},
      {"tilt 45", 0.0, glm::dvec3(0.0, 0.0, 45.0)},
      // Normal (1, 1, 1) / sqrt 3: a staircase along all three axes.
      {"tilt diagonal", 0.0, glm::dvec3(35.26, 0.0, 45.0)},
  };
  std::printf("# thick slab 60x30x60 mm, Jensen's eta; SSLPV calibrated, grid %d, steps auto;\n", grid);
  std::printf("# path tracer %d spp x 1024 pixels; SSLPV / path tracer of the mean radiance\n", spp);
  std::printf("%-9s %-14s %7s %7s %7s %9s\n", "material", "case", "R", "G", "B", "ref SE");
  for (const MeasuredMaterial& material : picked) {
    for (const Orientation& o : orientations) {
      const Scene scene = slabScene(material, o);
      ReferenceOptions options;
      options.spp = spp;
      const ReferenceResult truth = ReferenceTracer(scene).render(options);
      const glm::dvec3 reference = bench::meanRadiance(truth.radiance);
      // Pixels are independent: the mean's standard error is the pixels' over sqrt(1024).
      const glm::dvec3 error = bench::meanRadiance(truth.standardError) / 32.0;
      const glm::dvec3 lpv = bench::meanRadiance(CpuRenderer(scene).render(bench::calibratedAuto(grid)));
      const glm::dvec3 ratio = lpv / reference;
      const double worstSe = std::max({error.x / reference.x, error.y / reference.y, error.z / reference.z});
      std::printf("%-9s %-14s %7.3f %7.3f %7.3f %8.2f%%\n", std::string(material.name).c_str(), o.name, ratio.x,
                  ratio.y, ratio.z, 100.0 * worstSe);
      std::fflush(stdout);
    }
  }
  return 0;
}

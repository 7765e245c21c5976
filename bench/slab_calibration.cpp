// Thick-slab calibration table (docs/design.md §6.7.4): for each of Jensen's eleven measured materials
// and each RGB channel, the diffuse reflectance of a thick homogeneous slab under
// normal directional light as the reference path tracer sees it, as the dipole
// predicts it, and as SSLPV renders it with the calibrated and with the seed scheme.
//
// "Reflectance" here is π L / E at the middle of the top face seen from near the normal
// (L radiance, E irradiance): what a user compares in images. For the LPV, whose exit is
// Lambertian, that is its total diffuse reflectance times the exit Fresnel factor.
// The path tracer is exact for this scene at any ior (flat face, light at normal
// incidence: its light connection through the face is a straight line).
//
//   slab_calibration [--grid 64] [--spp 256] [--ior jensen|1] [--materials a,b,...]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench/image_mean.h"
#include "bench/slab_scene.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/calibration/lpv_calibration.h"
#include "volume/scene/material.h"
#include "volume/reference/reference_tracer.h"
#include "volume/reference/slab_reflectance.h"
#include "volume/scene/scene.h"

namespace {

using namespace sslpv;

Scene slabScene(const MeasuredMaterial& material, double ior) {
  // 200 x 200 x 100 mm: 5.5 diffusion lengths of the most diffusive channel (skim milk
  // red, 1/σtr = 18 mm) from the middle of the top face to the sides and the bottom.
  Scene scene = bench::materialBox(material, ior, glm::dvec3(-100.0, -100.0, -100.0), glm::dvec3(100.0, 100.0, 0.0));
  Light light;
  light.type = Light::Type::Directional;
  light.direction = glm::dvec3(0.0, 0.0, -1.0);
  light.irradiance = glm::vec3(1.0f);
  scene.lights = {light};
  // A 2-degree view of the face's middle from 10 degrees off the normal.
  scene.camera.position = glm::dvec3(0.0, -200.0 * std::sin(0.1745), 200.0 * std::cos(0.1745));
  scene.camera.target = glm::dvec3(0.0);
  scene.camera.up = glm::dvec3(0.0, 0.0, 1.0);
  scene.camera.fovYDeg = 2.0;
  scene.camera.width = scene.camera.height = 4;
  return scene;
}

glm::dvec3 meanReflectance(const Image& image) { return M_PI * bench::meanRadiance(image); }

}  // namespace

int main(int argc, char** argv) {
  const bench::Flags flags(argc, argv, {"grid", "spp", "ior", "materials"},
                           "slab_calibration [--grid N] [--spp N] [--ior jensen|1] [--materials a,b]");
  if (!flags.ok()) return 2;
  const int grid = flags.integer("grid", 64), spp = flags.integer("spp", 256);
  const bool jensenIor = flags.text("ior", "jensen") != "1";
  const std::vector<std::string> only = flags.names("materials", {});
  bool known = true;
  const std::vector<MeasuredMaterial> picked =
      only.empty() ? measuredMaterials() : bench::pickMaterials(measuredMaterials(), only, "slab_calibration", known);
  if (!known) return 2;
  std::printf("# thick slab, normal directional light, view 10 deg off normal; pi L / E per channel\n");
  std::printf("# grid %d, steps auto, path tracer %d spp x 16 pixels\n", grid, spp);
  std::printf("%-9s %2s %5s %16s %7s %7s %8s %7s %8s\n", "material", "ch", "ior", "path tracer", "dipole",
              "calib", "err", "seed", "err");
  double worst = 0.0;
  for (const MeasuredMaterial& material : picked) {
    const double ior = jensenIor ? material.eta : 1.0;
    Scene scene = slabScene(material, ior);
    ReferenceOptions options;
    options.spp = spp;
    const ReferenceResult truth = ReferenceTracer(scene).render(options);
    const glm::dvec3 reference = meanReflectance(truth.radiance);
    const glm::dvec3 error = meanReflectance(truth.standardError) / 4.0;  // 16 pixels: SE / sqrt(16)
    LpvSettings settings = bench::calibratedAuto(grid);
    const glm::dvec3 calibrated = meanReflectance(CpuRenderer(scene).render(settings));
    settings.scheme = LpvScheme::Seed;
    const glm::dvec3 seed = meanReflectance(CpuRenderer(scene).render(settings));
    for (int ch = 0; ch < 3; ++ch) {
      const double sPrime = material.sigmaSPrime[ch], sA = material.sigmaA[ch];
      const double dipole = dipoleRd(sPrime / (sPrime + sA), ior);
      const double calErr = calibrated[ch] / reference[ch] - 1.0;
      worst = std::max(worst, std::abs(calErr));
      std::printf("%-9s %2c %5.2f %9.5f±%.5f %7.4f %7.4f %+7.1f%% %7.4f %+7.1f%%\n", std::string(material.name).c_str(),
                  "RGB"[ch], ior, reference[ch], error[ch], dipole, calibrated[ch], 100.0 * calErr, seed[ch],
                  100.0 * (seed[ch] / reference[ch] - 1.0));
    }
    std::fflush(stdout);
  }
  std::printf("# worst |calibrated / path tracer - 1| = %.1f%%\n", 100.0 * worst);
  return 0;
}

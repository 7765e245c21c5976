// GPU shadow maps (rasterization) against the CPU reference sslpv::castShadowMap (Embree
// rays through the same texel centres, both planned by planShadowViews), texel by texel.
//
// How texels are matched: castShadowMap returns the hit texels in (view, row, column)
// order without their index; each CPU sample's texel is recovered from its position (the
// ray through a texel centre, projected back into the view, lands within 1e-3 texel of
// that centre, which the test checks) and the recovered indices must increase.
//
// Tolerances, and why:
// - Hit or miss: the rasterizer decides coverage at the texel centre in fixed point, the
//   ray caster in float; the resolve re-tests both ways with the exact ray (a covered
//   texel whose ray crosses nothing is dropped, an empty one whose ray crosses a triangle
//   its neighbours rasterized is taken), so only Embree's own float test can still differ
//   from the shared crossing test there. A texel is a silhouette texel when its 3x3
//   neighbourhood (within its view) in the CPU map holds both hits and misses. Every
//   other texel must agree exactly; silhouette disagreements at most one per view set or
//   0.1 % of the silhouette texels (measured 2026-12-04: 1 of 2106 in the box's cube map,
//   none elsewhere; 5 in all before the resolve took empty texels).
// - Where both hit, both intersect the same triangle's plane in float. The hit distance
//   along a ray is ill-conditioned by 1/cos θi at grazing incidence, so positions must
//   agree within |Δp| cos θi <= 1e-5 of the object's radius.
// - The triangle: the rasterizer snaps vertices (llvmpipe: 1/256 texel), so where a texel
//   centre lies that close to an edge it may report the neighbour; the resolve then
//   tests the exact ray against the neighbours and takes the one it crosses, as Embree
//   does. A texel whose GPU normal differs from the CPU's by more than 1e-4 (face normals
//   differ by degrees on these meshes) is an "other triangle" texel. Those are allowed
//   only where the CPU hit lies within float rounding of an edge of its triangle (2e-6
//   of the radius: coordinates of a few radii carry ~1e-7 relative rounding on both
//   sides, while the snapping band is 3e-5 radius at 256²): there the two ray casters
//   may legitimately split differently. Elsewhere at most 3, or 2 in 10,000 (before the
//   neighbour test 16 to 27 other-triangle texels per light on the sphere; now 1 to 4,
//   of which 0 or 1 off the band, where Embree's own float test is not watertight),
//   and in all at most 0.1 % of the common hits. They are excluded from the direction and flux checks.
// - Elsewhere normals and refracted directions agree within 3e-5, and flux (float texel
//   solid angle and Fresnel against double) within 3e-5 (measured up to 1.8e-5 since the
//   CPU runs Embree in robust mode and refines its hit with the shared float edge test) of |flux| + the largest texel
//   flux. With η < 1, texels within 0.2° of the critical angle are excluded from the
//   direction and flux checks: there sqrt(1 - sin²θt) amplifies float rounding without
//   bound (shaders/fresnel.glsl is checked against volume/core/fresnel.h separately); there
//   they must agree within 1e-3 (direction; flux relative to the largest texel flux).
// - Total transmitted flux and the statistics: within 0.5 % (silhouette texels).
#include "gpu/passes/gpu_shadow_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>

#include "gpu/vk/graphics.h"
#include "gpu_test_fixture.h"
#include "test_meshes.h"
#include "volume/core/fresnel.h"
#include "volume/scene/ray_scene.h"
#include "volume/cpu/shadow_map.h"

namespace {
using namespace sslpv;
using namespace sslpv::test;
using gpu::GpuFluxSample;

constexpr int kSize = 256;
constexpr double kCriticalBand = 0.2 * 3.14159265358979323846 / 180.0;  // 0.2° in radians

Light pointLight(glm::dvec3 position, glm::vec3 intensity) {
  Light l;
  l.type = Light::Type::Point;
  l.position = position;
  l.intensity = intensity;
  return l;
}

Light spotLight(glm::dvec3 position, glm::dvec3 direction, double fovDeg, glm::vec3 intensity) {
  Light l = pointLight(position, intensity);
  l.type = Light::Type::Spot;
  l.direction = glm::normalize(direction);
  l.fovDeg = fovDeg;
  return l;
}

Light directionalLight(glm::dvec3 direction, glm::vec3 irradiance) {
  Light l;
  l.type = Light::Type::Directional;
  l.direction = glm::normalize(direction);
  l.irradiance = irradiance;
  return l;
}

/// The texel (within `view`) whose centre ray passes through `p`, and how far (in
/// texels) the projection lands from that centre.
std::pair<int, double> texelOf(const ShadowView& view, const glm::dvec3& p) {
  const glm::dvec3 d = p - view.origin;
  double u, v;
  if (view.projection == ShadowView::Projection::Perspective) {
    const double c = glm::dot(d, view.forward);
    if (c <= 0.0) return {-1, 1e9};
    u = (glm::dot(d, view.right) / c / view.tanHalf + 1.0) * 0.5 * view.size - 0.5;
    v = (glm::dot(d, view.up) / c / view.tanHalf + 1.0) * 0.5 * view.size - 0.5;
  } else {
    u = (glm::dot(d, view.right) + view.halfSize) / view.orthographicTexel() - 0.5;
    v = (glm::dot(d, view.up) + view.halfSize) / view.orthographicTexel() - 0.5;
  }
  const double x = std::round(u), y = std::round(v);
  if (x < 0 || y < 0 || x >= view.size || y >= view.size) return {-1, 1e9};
  return {int(y) * view.size + int(x), std::max(std::abs(u - x), std::abs(v - y))};
}

/// castShadowMap's samples spread back onto the texels of `views`.
std::vector<std::optional<SurfaceFluxSample>> cpuTexels(const std::vector<SurfaceFluxSample>& samples,
                                                        const std::vector<ShadowView>& views) {
  const std::size_t perView = std::size_t(kSize) * kSize;
  std::vector<std::optional<SurfaceFluxSample>> texels(views.size() * perView);
  std::size_t previous = 0, v = 0;
  bool first = true;
  for (const SurfaceFluxSample& s : samples) {
    // Samples come view by view: try the current view, then the following ones.
    std::pair<int, double> found{-1, 1e9};
    for (; v < views.size(); ++v) {
      found = texelOf(views[v], glm::dvec3(s.position));
      if (found.first >= 0 && found.second < 1e-3 && (first || v * perView + found.first > previous)) break;
    }
    if (v == views.size()) {
      ADD_FAILURE() << "a CPU sample at (" << s.position.x << ", " << s.position.y << ", " << s.position.z
                    << ") lies on no texel centre ray after texel " << previous;
      return texels;
    }
    previous = v * perView + std::size_t(found.first);
    first = false;
    texels[previous] = s;
  }
  return texels;
}

struct Agreement {
  std::size_t cpuHits = 0, gpuHits = 0, silhouette = 0, silhouetteMismatches = 0, otherMismatches = 0;
  std::size_t common = 0, otherTriangle = 0, otherTriangleOffEdge = 0, nearCritical = 0;
  double worstPosition = 0;  ///< |Δp| cos θi / radius
  double worstNormal = 0, worstDirection = 0, worstFlux = 0;
  double worstCriticalDirection = 0, worstCriticalFlux = 0;  ///< within kCriticalBand, flux / max flux
  glm::dvec3 cpuFlux{0.0}, gpuFlux{0.0};
};

/// Distance from `p` (on the plane of `triangle`) to the nearest of its edges.
double distanceToEdges(const TriangleMesh& mesh, unsigned triangle, const glm::dvec3& p) {
  double nearest = 1e300;
  for (int e = 0; e < 3; ++e) {
    const glm::dvec3 a(mesh.positions[mesh.triangles[triangle][e]]);
    const glm::dvec3 b(mesh.positions[mesh.triangles[triangle][(e + 1) % 3]]);
    const double s = std::clamp(glm::dot(p - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0);
    nearest = std::min(nearest, glm::length(p - (a + s * (b - a))));
  }
  return nearest;
}

/// Compares one light's texels (`gpu` from its first sample on, `cpu` per texel). `rays`
/// and `mesh` find the CPU's triangle of the texels where the two disagree.
Agreement compareTexels(const GpuFluxSample* gpu, const std::vector<std::optional<SurfaceFluxSample>>& cpu,
                        const std::vector<ShadowView>& views, double radius, double ior, const RayScene& rays,
                        const TriangleMesh& mesh) {
  const std::size_t viewCount = views.size();
  Agreement a;
  double maxFlux = 0.0;
  for (const auto& c : cpu)
    if (c) maxFlux = std::max(maxFlux, double(std::max({c->flux.x, c->flux.y, c->flux.z})));
  for (std::size_t v = 0; v < viewCount; ++v)
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const std::size_t i = v * kSize * kSize + std::size_t(y) * kSize + x;
        const bool cpuHit = cpu[i].has_value(), gpuHit = gpu[i].positionValid.w != 0.0f;
        a.cpuHits += cpuHit;
        a.gpuHits += gpuHit;
        if (gpuHit) a.gpuFlux += glm::dvec3(glm::vec3(gpu[i].flux));
        if (cpuHit) a.cpuFlux += glm::dvec3(cpu[i]->flux);
        bool mixed = false;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= kSize || ny >= kSize) continue;
            mixed |= cpu[v * kSize * kSize + std::size_t(ny) * kSize + nx].has_value() != cpuHit;
          }
        a.silhouette += mixed;
        if (cpuHit != gpuHit) {
          (mixed ? a.silhouetteMismatches : a.otherMismatches) += 1;
          continue;
        }
        if (!cpuHit) continue;
        ++a.common;
        const SurfaceFluxSample& c = *cpu[i];
        const GpuFluxSample& g = gpu[i];
        const double cosI = -glm::dot(views[v].texelRay(x, y).dir, glm::dvec3(c.normal));
        const double dp = glm::length(glm::dvec3(glm::vec3(g.positionValid)) - glm::dvec3(c.position)) / radius;
        a.worstPosition = std::max(a.worstPosition, dp * cosI);
        const double normal = glm::length(glm::vec3(g.normal) - c.normal);
        if (normal > 1e-4) {
          ++a.otherTriangle;
          const TexelRay ray = views[v].texelRay(x, y);
          const RayHit hit = rays.intersect(glm::vec3(ray.origin), glm::vec3(ray.dir));
          if (!hit.hit || distanceToEdges(mesh, hit.triangle, glm::dvec3(hit.position)) > 2e-6 * radius)
            ++a.otherTriangleOffEdge;
          continue;
        }
        if (ior < 1.0 && std::abs(std::acos(std::min(1.0, cosI)) - std::asin(ior)) < kCriticalBand) {
          ++a.nearCritical;
          a.worstCriticalDirection =
              std::max(a.worstCriticalDirection, double(glm::length(glm::vec3(g.direction) - c.direction)));
          for (int ch = 0; ch < 3; ++ch)
            a.worstCriticalFlux = std::max(a.worstCriticalFlux, std::abs(double(g.flux[ch]) - c.flux[ch]) / maxFlux);
          continue;
        }
        a.worstNormal = std::max(a.worstNormal, normal);
        a.worstDirection = std::max(a.worstDirection, double(glm::length(glm::vec3(g.direction) - c.direction)));
        for (int ch = 0; ch < 3; ++ch)
          a.worstFlux = std::max(a.worstFlux,
                                 std::abs(double(g.flux[ch]) - c.flux[ch]) / (std::abs(double(c.flux[ch])) + maxFlux));
      }
  return a;
}

void expectAgreement(const Agreement& a, const std::string& what) {
  std::cout << what << ": cpu hits " << a.cpuHits << ", gpu hits " << a.gpuHits << ", silhouette texels "
            << a.silhouette << " (" << a.silhouetteMismatches << " disagree), other disagreements " << a.otherMismatches
            << ", other triangle " << a.otherTriangle << " of " << a.common << " (" << a.otherTriangleOffEdge
            << " off the edges), near the critical angle "
            << a.nearCritical << " (worst direction " << a.worstCriticalDirection << ", flux " << a.worstCriticalFlux
            << ")"
            << ", worst position " << a.worstPosition << " radius, normal " << a.worstNormal << ", direction "
            << a.worstDirection << ", flux " << a.worstFlux << ", total flux cpu " << a.cpuFlux.x << " gpu "
            << a.gpuFlux.x << "\n";
  EXPECT_GT(a.cpuHits, 1000u) << what << ": the case should light a good part of the map";
  EXPECT_EQ(a.otherMismatches, 0u) << what;
  EXPECT_LE(double(a.silhouetteMismatches), std::max(1.0, 1e-3 * double(a.silhouette))) << what;
  EXPECT_LE(double(a.otherTriangleOffEdge), std::max(3.0, 2e-4 * double(a.common))) << what;
  EXPECT_LE(double(a.otherTriangle), 0.001 * double(a.common)) << what;
  EXPECT_LE(a.worstPosition, 1e-5) << what;
  EXPECT_LE(a.worstNormal, 3e-5) << what;
  EXPECT_LE(a.worstDirection, 3e-5) << what;
  EXPECT_LE(a.worstFlux, 3e-5) << what;
  EXPECT_LE(a.worstCriticalDirection, 1e-3) << what;
  EXPECT_LE(a.worstCriticalFlux, 1e-3) << what;
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a.gpuFlux[ch], a.cpuFlux[ch], 0.005 * a.cpuFlux[ch]) << what;
}

struct Case {
  const char* name;
  TriangleMesh mesh;
  std::vector<Light> lights;
  std::vector<const char*> lightNames;
  double ior;
};

class GpuShadowMapTest : public GpuTest {
 protected:
  void compareWithCpu(const Case& c) {
    RayScene rays(c.mesh);
    gpu::GpuMesh mesh(device(), c.mesh);
    gpu::GpuShadowMapper mapper(device(), mesh, kSize);
    mapper.setLights(c.lights, c.ior);
    mapper.run();
    const std::vector<GpuFluxSample> samples = mapper.readSamples();
    const std::vector<ShadowMapStats> gpuStats = mapper.stats(samples);
    ASSERT_EQ(gpuStats.size(), c.lights.size());
    const double radius = shadowBoundingSphere(c.mesh.bounds()).radius;
    for (std::size_t l = 0; l < c.lights.size(); ++l) {
      const std::string what = std::string(c.name) + " / " + c.lightNames[l];
      ShadowMapStats cpuStats;
      const auto cpuSamples = castShadowMap(c.lights[l], rays, c.mesh.bounds(), kSize, c.ior, &cpuStats);
      const gpu::GpuShadowLight& placed = mapper.lights()[l];
      const std::vector<ShadowView> views(mapper.views().begin() + placed.firstView,
                                          mapper.views().begin() + placed.firstView + placed.viewCount);
      EXPECT_EQ(gpuStats[l].texels, cpuStats.texels) << what;
      EXPECT_EQ(gpuStats[l].culled, cpuStats.culled) << what;
      EXPECT_EQ(placed.sampleCount, cpuStats.texels) << what;
      if (cpuStats.culled) continue;
      const Agreement a =
          compareTexels(samples.data() + placed.firstSample, cpuTexels(cpuSamples, views), views, radius, c.ior,
                        rays, c.mesh);
      expectAgreement(a, what);
      EXPECT_EQ(gpuStats[l].hits, a.gpuHits) << what;
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(gpuStats[l].incidentFlux[ch], cpuStats.incidentFlux[ch], 0.005 * cpuStats.incidentFlux[ch]) << what;
        EXPECT_NEAR(gpuStats[l].transmittedFlux[ch], cpuStats.transmittedFlux[ch], 0.005 * cpuStats.transmittedFlux[ch])
            << what;
      }
    }
  }
};

TEST_F(GpuShadowMapTest, SphereMatchesCpuTexelByTexelForEveryLightKind) {
  Case c{"sphere",
         makeIcosphere(glm::vec3(0.1f, -0.2f, 0.3f), 1.0f, 5),
         {pointLight({0.6, 1.7, 3.2}, {1.0f, 2.0f, 3.0f}),
          pointLight({0.1, -0.2, 1.6}, {2.0f, 1.0f, 0.5f}),  // inside the bounding sphere: cube map
          spotLight({0.0, 0.5, 4.5}, {-0.05, -0.1, -1.0}, 20.0, {3.0f, 3.0f, 1.0f}),  // narrower than the sphere
          spotLight({2.0, -4.0, 1.0}, {-0.2, 1.0, -0.6}, 60.0, {1.0f, 1.0f, 1.0f}),   // cone edge across it
          spotLight({0.0, 0.0, 5.0}, {0.0, 0.0, 1.0}, 30.0, {1.0f, 1.0f, 1.0f}),      // pointing away: culled
          directionalLight({0.3, -1.0, -0.2}, {2.0f, 1.0f, 0.5f})},
         {"point outside", "point inside (cube)", "narrow spot", "spot edge", "culled spot", "directional"},
         1.4};
  compareWithCpu(c);
}

TEST_F(GpuShadowMapTest, BoxMatchesCpuTexelByTexelForEveryLightKindWithTotalInternalReflection) {
  // η < 1: beyond the critical angle the transmittance is 0 (valid texels with no flux).
  Case c{"box",
         makeBoxMesh(glm::vec3(-1.0f, -0.7f, -0.5f), glm::vec3(1.2f, 1.0f, 0.5f)),
         {pointLight({1.5, 2.0, 3.0}, {1.0f, 2.0f, 3.0f}),
          pointLight({0.0, 0.0, 0.7}, {1.0f, 1.0f, 1.0f}),  // 0.2 above the top face: cube map
          spotLight({0.5, 0.5, 4.0}, {-0.1, -0.1, -1.0}, 25.0, {3.0f, 1.0f, 1.0f}),
          directionalLight({-0.4, 0.5, -1.0}, {1.0f, 2.0f, 3.0f})},
         {"point outside", "point inside (cube)", "spot", "directional"},
         0.8};
  compareWithCpu(c);
}

TEST_F(GpuShadowMapTest, FresnelAndSnellInGlslMatchTheCpu) {
  // shaders/fresnel.glsl mirrors volume/core/fresnel.h in float: reflectance within 2e-6 and
  // refracted directions within 2e-6, except within 0.2° of the critical angle (η < 1),
  // where sqrt(1 - sin²θt) amplifies float rounding without bound.
  std::vector<glm::vec4> cases;
  std::vector<double> etas = {0.5, 0.8, 1.0, 1.33, 1.5, 2.4};
  for (double eta : etas)
    for (int i = 0; i < 400; ++i) {
      const double theta = 89.9 * i / 399.0 * 3.14159265358979323846 / 180.0;
      const double phi = 0.37 * i;
      cases.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), -std::cos(theta), eta);
    }
  gpu::VulkanDevice& dev = device();
  gpu::DescriptorSetLayout layout = gpu::makeStorageBufferSetLayout(dev, 2);
  gpu::ComputePipeline probe(dev, spirv::fresnel_probe_comp(), layout.get(), sizeof(std::uint32_t));
  constexpr VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  gpu::Buffer input(dev, cases.size() * sizeof(glm::vec4), usage, gpu::MemoryUse::Device);
  gpu::Buffer output(dev, cases.size() * sizeof(glm::vec4), usage, gpu::MemoryUse::Device);
  gpu::uploadToBuffer(dev, input, cases.data(), input.size());
  gpu::StorageBufferSets sets(dev, layout.get(), 2, 1);
  sets.write(0, 0, input);
  sets.write(0, 1, output);
  gpu::CommandContext commands(dev);
  VkCommandBuffer cmd = commands.begin();
  const std::uint32_t count = std::uint32_t(cases.size());
  probe.bind(cmd, sets.set(0), &count, sizeof count);
  vkCmdDispatch(cmd, (count + 63) / 64, 1, 1);
  gpu::toHostBarrier(cmd);
  commands.submitAndWait();
  std::vector<glm::vec4> results(cases.size());
  gpu::readFromBuffer(dev, output, results.data(), output.size());

  double worstR = 0.0, worstDir = 0.0;
  int checked = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const glm::dvec3 incident = glm::normalize(glm::dvec3(glm::vec3(cases[i])));
    const double eta = cases[i].w, cosI = -incident.z;
    if (eta < 1.0 && std::abs(std::acos(cosI) - std::asin(eta)) < 0.2 * 3.14159265358979323846 / 180.0) continue;
    ++checked;
    const double r = fresnelReflectance(cosI, eta);
    const glm::dvec3 t = refractInto(incident, glm::dvec3(0, 0, 1), eta);
    worstR = std::max(worstR, std::abs(double(results[i].w) - r));
    worstDir = std::max(worstDir, glm::length(glm::dvec3(glm::vec3(results[i])) - t));
    EXPECT_NEAR(results[i].w, r, 2e-6) << "eta " << eta << " cos " << cosI;
  }
  std::cout << checked << " cases: worst |ΔR| " << worstR << ", worst |Δdirection| " << worstDir << "\n";
  EXPECT_GT(checked, 2300);
  EXPECT_LE(worstDir, 2e-6);
}

TEST_F(GpuShadowMapTest, ReportsGpuTimeOfA256MapOfA20KTriangleSphere) {
  // Not a performance assertion: prints the GPU time (timestamps) of one point light's
  // 256² map on a 20,480-triangle sphere, median of 5 runs after a warm-up.
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.0f), 1.0f, 5);
  gpu::GpuMesh mesh(device(), sphere);
  gpu::GpuShadowMapper mapper(device(), mesh, kSize);
  mapper.setLights({pointLight({0.0, 1.0, 4.0}, glm::vec3(1.0f))}, 1.5);
  mapper.run();
  std::vector<double> ms;
  for (int i = 0; i < 5; ++i) ms.push_back(mapper.run());
  std::sort(ms.begin(), ms.end());
  std::cout << "GPU shadow map 256^2, " << sphere.triangles.size() << " triangles, " << device().name() << ": median "
            << ms[2] << " ms (min " << ms[0] << ", max " << ms[4] << ")\n";
  RecordProperty("gpu_shadow_map_ms", std::to_string(ms[2]));
  EXPECT_EQ(mapper.sampleCount(), std::uint32_t(kSize * kSize));
}

}  // namespace

// GPU injection against the CPU reference sslpv::injectSamples(): random samples on and
// near a voxelized sphere, compared coefficient by coefficient and in total power.
//
// Tolerances. (1) The GPU adds each cell's lobe contributions (hundreds) with float
// atomics in an arbitrary order and computes weights in float: a few float ulps per
// addition, so |gpu - cpu| <= 1e-5 * max |cpu| (measured ~1e-6). (2) The GPU computes the
// continuous grid coordinates of a sample from float positions, origin and cell size, so
// they are off by up to ~1e-5 cells; a sample whose active corners have a small total
// trilinear weight W (its lookup point at the edge of the active region) is renormalized
// by 1/W, which magnifies that error. Each coefficient gets, on top of (1), an allowance
// computed on the CPU: the sum over samples of |lobe coefficient| times how much the
// sample's weight in that cell changes when its position moves by that coordinate error
// along each axis. Well-conditioned cells get no allowance beyond (1). Flux totals are
// sums in double of float partial sums: 1e-5 relative.
#include "gpu/passes/gpu_inject.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "gpu_test_fixture.h"
#include "lpv_test_grids.h"
#include "seeded_draws.h"
#include "test_meshes.h"
#include "volume/lpv/sh.h"
#include "volume/lpv/voxelize.h"
#include "volume/cpu/inject.h"

namespace {
using namespace sslpv;
using namespace sslpv::test;
using gpu::GpuFluxSample;

constexpr double kCoefficientTolerance = 1e-5;
constexpr double kFluxTolerance = 1e-5;
const glm::vec3 kCenter(1.5f, -0.5f, 2.0f);
constexpr float kRadius = 4.0f;

MaterialGrid sphereMaterial(int resolution) {
  const TriangleMesh mesh = makeIcosphere(kCenter, kRadius, 4);
  MaterialGrid m;
  m.frame = makeGridFrame(mesh.bounds(), resolution);
  m.coverage = voxelizeCoverage(mesh, m.frame);
  const std::size_t n = m.frame.cellCount();
  m.sigmaT.assign(n, glm::vec3(1.0f));
  m.sigmaS.assign(n, glm::vec3(0.9f));
  m.g.assign(n, 0.0f);
  return m;
}

glm::vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<float> normal;
  glm::vec3 v;
  do v = drawVec3<glm::vec3>(normal, rng);
  while (glm::length(v) < 1e-3f);
  return glm::normalize(v);
}

/// 75 % samples on or near the surface (radius ±5 %, normals and refracted directions
/// perturbed), 5 % one to two cells outside it (some reach active cells only through the
/// fallback a full cell deeper), 10 % far outside the object (to be dropped; some beyond
/// the grid), 10 % misses (positionValid.w = 0) with a huge flux inside the object, which
/// must not count.
std::vector<GpuFluxSample> randomSamples(std::size_t count, unsigned seed, double cellSize) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<GpuFluxSample> samples(count);
  for (GpuFluxSample& s : samples) {
    const glm::vec3 u = randomUnit(rng);
    const float kind = uniform(rng);
    glm::vec3 position, normal = u;
    float valid = 1.0f;
    glm::vec3 flux = drawVec3<glm::vec3>(uniform, rng);
    flux *= 0.01f;
    if (kind < 0.75f) {
      position = kCenter + kRadius * (0.95f + 0.1f * uniform(rng)) * u;
      normal = glm::normalize(u + 0.3f * randomUnit(rng));
    } else if (kind < 0.8f) {
      position = kCenter + (kRadius + float(cellSize) * (1.0f + uniform(rng))) * u;
    } else if (kind < 0.9f) {
      position = kCenter + kRadius * (1.6f + 1.4f * uniform(rng)) * u;
    } else {
      position = kCenter + 0.9f * kRadius * u;
      valid = 0.0f;
      flux = glm::vec3(1000.0f);
    }
    glm::vec3 direction = -normal + 0.8f * randomUnit(rng);
    direction = glm::length(direction) > 1e-3f ? glm::normalize(direction) : -normal;
    s = GpuFluxSample{glm::vec4(position, valid), glm::vec4(normal, 0.0f), glm::vec4(direction, 0.0f),
                      glm::vec4(flux, 0.0f)};
  }
  return samples;
}

/// What a size x size orthographic shadow map of the sphere lit along `light` holds, in
/// texel order (neighbouring records land in neighbouring cells, as a real map's do):
/// hits on the analytic sphere with flux E·A·cosθ, refracted halfway towards -normal,
/// and misses (positionValid.w = 0) around the disc.
std::vector<GpuFluxSample> shadowMapSamples(int size, const glm::vec3& light) {
  const glm::vec3 w = glm::normalize(light);
  const glm::vec3 u = glm::normalize(glm::cross(w, std::fabs(w.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
  const glm::vec3 v = glm::cross(w, u);
  const float texel = 2.2f * kRadius / float(size);
  const glm::vec3 irradiance(1.0f, 0.8f, 0.6f);
  std::vector<GpuFluxSample> samples(std::size_t(size) * size, GpuFluxSample{});
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float a = (float(x) + 0.5f) * texel - 1.1f * kRadius, b = (float(y) + 0.5f) * texel - 1.1f * kRadius;
      const float r2 = a * a + b * b;
      if (r2 >= kRadius * kRadius) continue;  // a miss: zero record
      const glm::vec3 n = (a * u + b * v - std::sqrt(kRadius * kRadius - r2) * w) / kRadius;
      const float cosine = -glm::dot(n, w);
      const glm::vec3 direction = glm::normalize(w - n);
      samples[std::size_t(y) * size + x] =
          GpuFluxSample{glm::vec4(kCenter + kRadius * n, 1.0f), glm::vec4(n, 0.0f), glm::vec4(direction, 0.0f),
                        glm::vec4(irradiance * texel * texel * cosine, 0.0f)};
    }
  return samples;
}

std::vector<SurfaceFluxSample> validCpuSamples(const std::vector<GpuFluxSample>& samples) {
  std::vector<SurfaceFluxSample> cpu;
  for (const GpuFluxSample& s : samples)
    if (s.positionValid.w != 0.0f)
      cpu.push_back({glm::vec3(s.positionValid), glm::vec3(s.normal), glm::vec3(s.direction), glm::vec3(s.flux)});
  return cpu;
}

gpu::Buffer makeField(const gpu::VulkanDevice& device, const GridFrame& frame) {
  return gpu::Buffer(
      device, gpu::lightFieldBytes(frame),
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
      gpu::MemoryUse::Device);
}

/// The device field (3 vec4 per cell) as ShGrid planes, through a host copy so the test
/// works whether or not device memory is mappable.
ShGrid readField(const gpu::VulkanDevice& device, const gpu::Buffer& field, const GridFrame& frame) {
  gpu::Buffer host(device, field.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUse::Host);
  gpu::CommandContext commands(device);
  VkCommandBuffer cmd = commands.begin();
  gpu::deviceWritesBarrier(cmd);
  const VkBufferCopy region{0, 0, field.size()};
  vkCmdCopyBuffer(cmd, field.handle(), host.handle(), 1, &region);
  gpu::toHostBarrier(cmd);
  commands.submitAndWait();
  ShGrid grid;
  grid.resize(frame);
  const float* in = host.mappedAs<const float>();
  for (std::size_t i = 0; i < frame.cellCount(); ++i)
    for (int k = 0; k < ShGrid::kPlanes; ++k) grid.planes[k][i] = in[i * 12 + k];
  return grid;
}

void fillField(const gpu::VulkanDevice& device, const gpu::Buffer& field, float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  gpu::CommandContext commands(device);
  VkCommandBuffer cmd = commands.begin();
  vkCmdFillBuffer(cmd, field.handle(), 0, VK_WHOLE_SIZE, bits);
  commands.submitAndWait();
}

/// The cells a sample lands in, as injectSamples picks them: half a cell inside the
/// surface, else a full cell deeper.
int injectionCells(const MaterialGrid& m, const glm::dvec3& p, const glm::dvec3& n, std::size_t cells[8],
                   float weights[8]) {
  const double halfCell = 0.5 * m.frame.cellSize;
  const int used = activeTrilinearWeights(m, p - halfCell * n, cells, weights);
  return used > 0 ? used : activeTrilinearWeights(m, p - 2.0 * halfCell * n, cells, weights);
}

/// Bound, in cells, on the GPU's rounding of grid coordinates: float positions, origin
/// and cell size (world magnitudes in cells) and float grid coordinates, 4 ulps each.
double gridCoordinateError(const MaterialGrid& m, const std::vector<SurfaceFluxSample>& samples) {
  const auto largest = [](const auto& v) {
    return std::max({std::fabs(double(v.x)), std::fabs(double(v.y)), std::fabs(double(v.z))});
  };
  double world = largest(m.frame.origin);
  for (const SurfaceFluxSample& s : samples) world = std::max(world, largest(s.position));
  return 4.0 * std::ldexp(1.0, -24) * (world / m.frame.cellSize + largest(m.frame.dims));
}

/// Per coefficient allowance (2) of the header comment, for the given samples.
ShGrid conditioningAllowance(const std::vector<SurfaceFluxSample>& samples, const MaterialGrid& m) {
  const double delta = gridCoordinateError(m, samples) * m.frame.cellSize;  // world units
  ShGrid allowance;
  allowance.resize(m.frame);
  for (const SurfaceFluxSample& s : samples) {
    const glm::dvec3 p(s.position), n(s.normal);
    std::size_t cells[8], moved[8];
    float weights[8], movedWeights[8];
    const int used = injectionCells(m, p, n, cells, weights);
    // Cell -> Σ over axes of the largest weight change either way along that axis.
    std::vector<std::pair<std::size_t, double>> sensitivity;
    const auto entry = [&](std::size_t cell) -> double& {
      for (auto& e : sensitivity)
        if (e.first == cell) return e.second;
      sensitivity.emplace_back(cell, 0.0);
      return sensitivity.back().second;
    };
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<std::pair<std::size_t, double>> axisChange;
      for (double sign : {-1.0, 1.0}) {
        glm::dvec3 shifted = p;
        shifted[axis] += sign * delta;
        const int movedUsed = injectionCells(m, shifted, n, moved, movedWeights);
        const auto weightIn = [](std::size_t cell, const std::size_t* c, const float* w, int count) {
          for (int i = 0; i < count; ++i)
            if (c[i] == cell) return double(w[i]);
          return 0.0;
        };
        const auto note = [&](std::size_t cell) {
          const double change =
              std::fabs(weightIn(cell, moved, movedWeights, movedUsed) - weightIn(cell, cells, weights, used));
          for (auto& e : axisChange)
            if (e.first == cell) return void(e.second = std::max(e.second, change));
          axisChange.emplace_back(cell, change);
        };
        for (int i = 0; i < used; ++i) note(cells[i]);
        for (int i = 0; i < movedUsed; ++i) note(moved[i]);
      }
      for (const auto& [cell, change] : axisChange) entry(cell) += change;
    }
    for (int ch = 0; ch < 3; ++ch) {
      const sh::Coeffs lobe = sh::cosineLobe(s.direction, s.flux[ch] / sh::kPi);
      for (const auto& [cell, change] : sensitivity)
        for (int k = 0; k < 4; ++k) allowance.plane(ch, k)[cell] += float(std::fabs(lobe[k]) * change);
    }
  }
  return allowance;
}

double maxAbs(const ShGrid& grid) {
  double m = 0.0;
  for (const std::vector<float>& plane : grid.planes)
    for (float v : plane) m = std::max(m, double(std::fabs(v)));
  return m;
}

/// Checks |gpu - scale*cpu| <= scale * (1e-5 * max |cpu| + allowance) for every
/// coefficient, and prints the worst raw difference relative to max |scale*cpu|.
void expectMatchesCpu(const ShGrid& gpu, const ShGrid& cpu, const ShGrid& allowance, const std::string& what,
                      double scale = 1.0) {
  const double reference = scale * maxAbs(cpu);
  double worst = 0.0, worstAllowance = 0.0;
  std::size_t failures = 0, usingAllowance = 0;
  for (int k = 0; k < ShGrid::kPlanes; ++k)
    for (std::size_t i = 0; i < cpu.planes[k].size(); ++i) {
      const double d = std::fabs(double(gpu.planes[k][i]) - scale * cpu.planes[k][i]);
      const double base = kCoefficientTolerance * reference;
      worst = std::max(worst, d);
      worstAllowance = std::max(worstAllowance, scale * double(allowance.planes[k][i]));
      usingAllowance += d > base;
      if (d > base + scale * allowance.planes[k][i] && failures++ < 10)
        ADD_FAILURE() << what << ": plane " << k << " cell " << i << ": gpu " << gpu.planes[k][i] << ", cpu "
                      << scale * cpu.planes[k][i] << ", allowed " << base << " + " << scale * allowance.planes[k][i];
    }
  EXPECT_EQ(failures, 0u) << what;
  std::cout << "[ measured ] " << what << ": max |gpu - cpu| / max |cpu| = " << worst / reference << "; "
            << usingAllowance << " of " << ShGrid::kPlanes * cpu.planes[0].size()
            << " coefficients beyond 1e-5 (largest conditioning allowance " << worstAllowance / reference
            << " of max |cpu|)\n";
}

class GpuInjection : public GpuTest {};

TEST_F(GpuInjection, CellCoverageBufferHoldsCoverageOfActiveCellsOnly) {
  const MaterialGrid material = sphereMaterial(20);
  const std::vector<float> values = gpu::cellCoverageValues(material);
  const GridFrame& f = material.frame;
  ASSERT_EQ(values.size(), f.cellCount());
  std::size_t active = 0;
  for (int z = 0; z < f.dims.z; ++z)
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        const float expected = isActiveCell(material, x, y, z) ? material.coverage[i] : 0.0f;
        ASSERT_EQ(values[i], expected) << "cell " << x << "," << y << "," << z;
        active += expected > 0.0f;
      }
  EXPECT_GT(active, 100u);  // the sphere fills most of the grid

  const gpu::Buffer buffer = gpu::uploadCellCoverage(device(), material);
  gpu::Buffer host(device(), buffer.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUse::Host);
  gpu::CommandContext commands(device());
  VkCommandBuffer cmd = commands.begin();
  const VkBufferCopy region{0, 0, buffer.size()};
  vkCmdCopyBuffer(cmd, buffer.handle(), host.handle(), 1, &region);
  gpu::toHostBarrier(cmd);
  commands.submitAndWait();
  EXPECT_EQ(std::memcmp(host.mapped(), values.data(), values.size() * sizeof(float)), 0);
}

// Same cells, weights and lobes as the CPU; the injected field holds exactly the
// transmitted flux T·Φ of the samples that found an active cell (Σ c0 · 2√π per channel).
TEST_F(GpuInjection, RandomSamplesOnASphereMatchTheCpu) {
  const MaterialGrid material = sphereMaterial(24);
  const std::vector<GpuFluxSample> samples = randomSamples(20000, 7, material.frame.cellSize);
  const std::vector<SurfaceFluxSample> cpuSamples = validCpuSamples(samples);
  ASSERT_GT(cpuSamples.size(), 15000u);
  ASSERT_LT(cpuSamples.size(), samples.size());

  // Some samples need the fallback a full cell deeper, so that path is compared too.
  std::size_t fallbacks = 0;
  for (const SurfaceFluxSample& s : cpuSamples) {
    std::size_t cells[8];
    float weights[8];
    const double halfCell = 0.5 * material.frame.cellSize;
    const glm::dvec3 p(s.position), n(s.normal);
    fallbacks += activeTrilinearWeights(material, p - halfCell * n, cells, weights) == 0 &&
                 activeTrilinearWeights(material, p - 2.0 * halfCell * n, cells, weights) > 0;
  }
  ASSERT_GT(fallbacks, 0u);

  ShGrid cpu;
  cpu.resize(material.frame);
  const InjectionStats cpuStats = injectSamples(cpuSamples, material, cpu);

  const gpu::Buffer coverage = gpu::uploadCellCoverage(device(), material);
  const gpu::Buffer sampleBuffer = gpu::uploadFluxSamples(device(), samples);
  const gpu::Buffer field = makeField(device(), material.frame);
  fillField(device(), field, 5.0f);  // the injector clears the field first
  gpu::GpuInjector injector(device());
  const InjectionStats gpuStats =
      injector.run(sampleBuffer, std::uint32_t(samples.size()), coverage, material.frame, field);
  const ShGrid gpu = readField(device(), field, material.frame);

  std::cout << "[ measured ] " << cpuSamples.size() << " valid samples, " << fallbacks
            << " through the deeper fallback\n";
  expectMatchesCpu(gpu, cpu, conditioningAllowance(cpuSamples, material), "20000 samples");

  glm::dvec3 validFlux(0.0);
  for (const SurfaceFluxSample& s : cpuSamples) validFlux += glm::dvec3(s.flux);
  for (int ch = 0; ch < 3; ++ch) {
    // Both outcomes occur, so the comparisons below are not vacuous.
    ASSERT_GT(cpuStats.injectedFlux[ch], 0.5 * validFlux[ch]);
    ASSERT_GT(cpuStats.droppedFlux[ch], 0.02 * validFlux[ch]);
    EXPECT_NEAR(gpuStats.injectedFlux[ch], cpuStats.injectedFlux[ch], kFluxTolerance * cpuStats.injectedFlux[ch]);
    EXPECT_NEAR(gpuStats.droppedFlux[ch], cpuStats.droppedFlux[ch], kFluxTolerance * cpuStats.droppedFlux[ch]);
    // Every valid sample is either injected or dropped; misses count as neither.
    EXPECT_NEAR(gpuStats.injectedFlux[ch] + gpuStats.droppedFlux[ch], validFlux[ch], kFluxTolerance * validFlux[ch]);
    // The physical check: the lobes hold the transmitted flux (c0 total times 2√π).
    EXPECT_NEAR(channelPower(gpu, ch), cpuStats.injectedFlux[ch], kFluxTolerance * cpuStats.injectedFlux[ch])
        << "channel " << ch;
  }
}

// The calibrated scheme: isotropic sources at max(depth cos θt, Δx / 2), the depth per
// channel from the surface cell (here 1/σt' = 0.5, 1.25 and 3 cells, the first below the
// floor), on a heterogeneous sphere: half of it has twice the σt', so samples pick
// different depths on either side. Float against double grid coordinates move a source's
// trilinear weights by ~1e-6 of a cell, so the fields agree to 1e-5 of their total in L1
// and exactly in power; no linear band on either.
TEST_F(GpuInjection, CalibratedIsotropicSourcesAtDepthMatchTheCpu) {
  MaterialGrid material = sphereMaterial(24);
  const double cell = material.frame.cellSize;
  const glm::ivec3 d = material.frame.dims;
  for (int z = 0; z < d.z; ++z)
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x) {
        const std::size_t i = material.frame.index(x, y, z);
        const float scale = material.frame.cellCenter(x, y, z).x > kCenter.x ? 2.0f : 1.0f;
        material.sigmaT[i] = scale * glm::vec3(float(2.0 / cell), float(0.8 / cell), float(1.0 / (3.0 * cell)));
        material.sigmaS[i] = 0.9f * material.sigmaT[i];
      }
  const StepFactors factors = computeStepFactors(material, LpvScheme::Calibrated, 1.3);
  std::mt19937 rng(11);
  std::vector<GpuFluxSample> samples;
  for (int k = 0; k < 4000; ++k) {
    const glm::vec3 n = randomUnit(rng);
    const glm::vec3 inward = glm::normalize(-n + 0.6f * randomUnit(rng));
    const glm::vec3 dir = glm::dot(inward, n) < -0.05f ? inward : -n;
    samples.push_back(GpuFluxSample{glm::vec4(kCenter + kRadius * n, 1.0f), glm::vec4(n, 0.0f), glm::vec4(dir, 0.0f),
                                    glm::vec4(1.0f, 0.5f, 0.25f, 0.0f)});
  }
  const std::vector<SurfaceFluxSample> cpuSamples = validCpuSamples(samples);
  ShGrid cpu;
  cpu.resize(material.frame);
  const InjectionStats cpuStats = injectSamples(cpuSamples, material, cpu, &factors);

  const gpu::Buffer coverage = gpu::uploadCellCoverage(device(), material);
  const gpu::Buffer depths = gpu::uploadCalibratedInjection(device(), factors, material.frame);
  const gpu::Buffer sampleBuffer = gpu::uploadFluxSamples(device(), samples);
  const gpu::Buffer field = makeField(device(), material.frame);
  gpu::GpuInjector injector(device());
  const InjectionStats gpuStats = injector.run(sampleBuffer, std::uint32_t(samples.size()), coverage,
                                               material.frame, field, true, &depths);
  const ShGrid gpu = readField(device(), field, material.frame);

  for (int ch = 0; ch < 3; ++ch) {
    ASSERT_GT(cpuStats.injectedFlux[ch], 0.0);
    EXPECT_NEAR(gpuStats.injectedFlux[ch], cpuStats.injectedFlux[ch], kFluxTolerance * cpuStats.injectedFlux[ch]);
    EXPECT_NEAR(channelPower(gpu, ch), channelPower(cpu, ch), kFluxTolerance * channelPower(cpu, ch));
    double difference = 0.0, total = 0.0;
    for (std::size_t i = 0; i < material.frame.cellCount(); ++i) {
      difference += std::fabs(double(gpu.plane(ch, 0)[i]) - cpu.plane(ch, 0)[i]);
      total += std::fabs(double(cpu.plane(ch, 0)[i]));
      for (int k = 1; k < 4; ++k) {
        ASSERT_EQ(gpu.plane(ch, k)[i], 0.0f);
        ASSERT_EQ(cpu.plane(ch, k)[i], 0.0f);
      }
    }
    std::cout << "[ measured ] calibrated injection, channel " << ch << ": L1 |gpu - cpu| / L1 cpu = "
              << difference / total << "\n";
    EXPECT_LT(difference, 1e-5 * total) << "channel " << ch;
  }
}

TEST_F(GpuInjection, MissedSamplesContributeNothing) {
  const MaterialGrid material = sphereMaterial(16);
  std::vector<GpuFluxSample> misses = randomSamples(2000, 11, material.frame.cellSize);
  // Every record marked as a miss, though most lie where a hit would inject.
  for (GpuFluxSample& s : misses) s.positionValid.w = 0.0f;
  const gpu::Buffer coverage = gpu::uploadCellCoverage(device(), material);
  const gpu::Buffer sampleBuffer = gpu::uploadFluxSamples(device(), misses);
  const gpu::Buffer field = makeField(device(), material.frame);
  gpu::GpuInjector injector(device());
  const InjectionStats stats =
      injector.run(sampleBuffer, std::uint32_t(misses.size()), coverage, material.frame, field);
  const ShGrid gpu = readField(device(), field, material.frame);
  EXPECT_EQ(maxAbs(gpu), 0.0);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_EQ(stats.injectedFlux[ch], 0.0);
    EXPECT_EQ(stats.droppedFlux[ch], 0.0);
  }
}

// Without clearing, a second injection adds onto the first: the field doubles. With no
// samples, the field is only cleared.
TEST_F(GpuInjection, FieldIsClearedOrAddedToAsRequested) {
  const MaterialGrid material = sphereMaterial(16);
  const std::vector<GpuFluxSample> samples = randomSamples(3000, 5, material.frame.cellSize);
  const std::vector<SurfaceFluxSample> cpuSamples = validCpuSamples(samples);
  ShGrid cpu;
  cpu.resize(material.frame);
  injectSamples(cpuSamples, material, cpu);

  const gpu::Buffer coverage = gpu::uploadCellCoverage(device(), material);
  const gpu::Buffer sampleBuffer = gpu::uploadFluxSamples(device(), samples);
  const gpu::Buffer field = makeField(device(), material.frame);
  gpu::GpuInjector injector(device());
  const auto count = std::uint32_t(samples.size());
  injector.run(sampleBuffer, count, coverage, material.frame, field);
  injector.run(sampleBuffer, count, coverage, material.frame, field, /*clearField=*/false);
  expectMatchesCpu(readField(device(), field, material.frame), cpu, conditioningAllowance(cpuSamples, material),
                   "injected twice", 2.0);

  const InjectionStats empty = injector.run(sampleBuffer, 0, coverage, material.frame, field);
  EXPECT_EQ(maxAbs(readField(device(), field, material.frame)), 0.0);
  EXPECT_EQ(empty.injectedFlux.x + empty.droppedFlux.x, 0.0);
}

// A 256² shadow map in texel order (78 % hits): matches the CPU.
TEST_F(GpuInjection, ShadowMapOrderedSamplesMatchTheCpu) {
  const MaterialGrid material = sphereMaterial(32);
  const std::vector<GpuFluxSample> samples = shadowMapSamples(256, glm::vec3(-1.0f, -2.0f, -3.0f));
  const std::vector<SurfaceFluxSample> cpuSamples = validCpuSamples(samples);
  ShGrid cpu;
  cpu.resize(material.frame);
  const InjectionStats cpuStats = injectSamples(cpuSamples, material, cpu);

  const gpu::Buffer coverage = gpu::uploadCellCoverage(device(), material);
  const gpu::Buffer sampleBuffer = gpu::uploadFluxSamples(device(), samples);
  const gpu::Buffer field = makeField(device(), material.frame);
  gpu::GpuInjector injector(device());
  const InjectionStats gpuStats =
      injector.run(sampleBuffer, std::uint32_t(samples.size()), coverage, material.frame, field);
  expectMatchesCpu(readField(device(), field, material.frame), cpu, conditioningAllowance(cpuSamples, material),
                   "256x256 shadow map");
  for (int ch = 0; ch < 3; ++ch)
    EXPECT_NEAR(gpuStats.injectedFlux[ch], cpuStats.injectedFlux[ch], kFluxTolerance * cpuStats.injectedFlux[ch]);
}

}  // namespace

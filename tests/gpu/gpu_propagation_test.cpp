// GPU propagation against the CPU reference sslpv::propagate(): same field, same
// accumulated light, same steps and the same per-step energy bookkeeping, from host grids
// and device-resident, on full boxes and on shapes whose bounding box is mostly empty.
//
// Tolerances: the GPU sums in float in a different order (and may fuse multiply-adds),
// so values are compared with max |gpu - cpu| <= 1e-4 * max |cpu| over the whole grid,
// checked plane by plane; per-step powers with |gpu - cpu| <= 1e-4 * injected power.
#include "gpu/passes/gpu_propagation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "gpu/vk/compute.h"
#include "gpu_test_fixture.h"
#include "lpv_test_grids.h"
#include "seeded_draws.h"
#include "volume/core/error.h"
#include "volume/cpu/propagate.h"

namespace {
using namespace sslpv;
using namespace sslpv::test;

constexpr double kValueTolerance = 1e-4;
constexpr double kPowerTolerance = 1e-4;
constexpr double kDevicePowerTolerance = 1e-6;  // initial power summed in float on the GPU

struct Outcome {
  ShGrid field, accumulated;
  PropagationResult result;
};

Outcome runCpu(const MaterialGrid& material, const ShGrid& injected, const PropagationOptions& options,
               LpvScheme scheme = LpvScheme::Seed) {
  Outcome run;
  run.field = injected;
  run.accumulated.resize(material.frame);
  run.result = propagate(material, computeStepFactors(material, scheme, 1.4), run.field, run.accumulated, options);
  return run;
}

Outcome runGpu(const gpu::VulkanDevice& device, const MaterialGrid& material, const ShGrid& injected,
               const PropagationOptions& options, const gpu::GpuPropagatorOptions& gpuOptions = {},
               LpvScheme scheme = LpvScheme::Seed) {
  Outcome run;
  run.field = injected;
  run.accumulated.resize(material.frame);
  gpu::GpuPropagator propagator(device, material.frame, computeStepFactors(material, scheme, 1.4), gpuOptions);
  run.result = propagator.run(run.field, run.accumulated, options);
  return run;
}

double maxAbs(const ShGrid& grid) {
  double m = 0.0;
  for (const std::vector<float>& plane : grid.planes)
    for (float v : plane) m = std::max(m, double(std::fabs(v)));
  return m;
}

/// Largest difference seen so far relative to its tolerance, printed by each test: how
/// close the twins are, not only that they are within the tolerance.
double worstGridRatio = 0.0, worstPowerRatio = 0.0;

void reportWorst(const char* test) {
  std::printf("[ measured ] %s: max |gpu - cpu| = %.3g of the grid tolerance, %.3g of the power tolerance\n", test,
              worstGridRatio, worstPowerRatio);
  worstGridRatio = worstPowerRatio = 0.0;
}

void expectGridsMatch(const ShGrid& gpu, const ShGrid& cpu, const std::string& what) {
  const double tolerance = kValueTolerance * maxAbs(cpu);
  for (int k = 0; k < ShGrid::kPlanes; ++k) {
    double worst = 0.0;
    std::size_t worstCell = 0;
    for (std::size_t i = 0; i < cpu.planes[k].size(); ++i) {
      const double d = std::fabs(double(gpu.planes[k][i]) - cpu.planes[k][i]);
      if (d > worst) worst = d, worstCell = i;
    }
    EXPECT_LE(worst, tolerance) << what << " plane " << k << " cell " << worstCell << ": gpu "
                                << gpu.planes[k][worstCell] << " cpu " << cpu.planes[k][worstCell];
    if (tolerance > 0.0) worstGridRatio = std::max(worstGridRatio, worst / tolerance);
  }
}

/// `initialPowerTolerance`, relative: run() sums the injected power on the host in double
/// as the CPU does; device-resident runs sum it on the GPU in float (~1e-7 relative).
void expectEnergyMatches(const PropagationResult& gpu, const PropagationResult& cpu, const std::string& what,
                         double initialPowerTolerance = 1e-9) {
  ASSERT_EQ(gpu.stepsRun, cpu.stepsRun) << what;
  ASSERT_EQ(gpu.energy.size(), cpu.energy.size()) << what;
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(gpu.initialPower[ch], cpu.initialPower[ch], initialPowerTolerance * cpu.initialPower[ch]) << what;
    // r/(1-r) from float step sums: the steps' power agrees to kPowerTolerance, and near
    // r = 1 the scale magnifies the ratio's rounding by 1/(1-r).
    EXPECT_NEAR(gpu.tailScale[ch], cpu.tailScale[ch], 1e-3 * std::max(1.0, cpu.tailScale[ch])) << what << " tail";
    const double tolerance = kPowerTolerance * cpu.initialPower[ch];
    for (std::size_t s = 0; s < cpu.energy.size(); ++s) {
      const StepEnergy &g = gpu.energy[s], &c = cpu.energy[s];
      EXPECT_NEAR(g.inGrid[ch], c.inGrid[ch], tolerance) << what << " step " << s << " channel " << ch;
      EXPECT_NEAR(g.left[ch], c.left[ch], tolerance) << what << " step " << s << " channel " << ch;
      EXPECT_NEAR(g.absorbed[ch], c.absorbed[ch], tolerance) << what << " step " << s << " channel " << ch;
      EXPECT_NEAR(g.clampRemoved[ch], c.clampRemoved[ch], tolerance) << what << " step " << s << " channel " << ch;
      if (tolerance > 0.0)
        for (double d : {g.inGrid[ch] - c.inGrid[ch], g.left[ch] - c.left[ch], g.absorbed[ch] - c.absorbed[ch],
                         g.clampRemoved[ch] - c.clampRemoved[ch]})
          worstPowerRatio = std::max(worstPowerRatio, std::fabs(d) / tolerance);
    }
  }
}

void expectRunsMatch(const Outcome& gpu, const Outcome& cpu, const std::string& what,
                     double initialPowerTolerance = 1e-9) {
  expectEnergyMatches(gpu.result, cpu.result, what, initialPowerTolerance);
  expectGridsMatch(gpu.accumulated, cpu.accumulated, what + " accumulated");
  expectGridsMatch(gpu.field, cpu.field, what + " last field");
}

/// runOnDevice() from the injected light uploaded as injection leaves it, on a propagator
/// of its own (so that no path can pass on what another left in the buffers).
Outcome runDeviceResident(const gpu::VulkanDevice& device, const MaterialGrid& material, const StepFactors& factors,
                          const ShGrid& injected, const PropagationOptions& options,
                          const gpu::GpuPropagatorOptions& gpuOptions) {
  gpu::GpuPropagator propagator(device, material.frame, factors, gpuOptions);
  Outcome run;
  run.field.resize(material.frame);
  run.accumulated.resize(material.frame);
  propagator.uploadField(injected, propagator.sourceField(), true);
  run.result = propagator.runOnDevice(options);
  propagator.downloadField(propagator.accumulated(), run.accumulated);
  propagator.downloadLastField(run.field);
  return run;
}

/// The same through record(): one command buffer, no host in the loop, no energy records
/// (result.stepsRun only).
Outcome runRecorded(const gpu::VulkanDevice& device, const MaterialGrid& material, const StepFactors& factors,
                    const ShGrid& injected, const PropagationOptions& options,
                    const gpu::GpuPropagatorOptions& gpuOptions) {
  gpu::GpuPropagator propagator(device, material.frame, factors, gpuOptions);
  propagator.uploadField(injected, propagator.sourceField(), true);
  gpu::CommandContext commands(device);
  propagator.record(commands.begin(), options);
  commands.submitAndWait();
  Outcome run;
  run.field.resize(material.frame);
  run.accumulated.resize(material.frame);
  run.result.stepsRun = propagator.stepsRun();
  propagator.downloadField(propagator.accumulated(), run.accumulated);
  propagator.downloadLastField(run.field);
  return run;
}

PropagationOptions stepsWithEnergy(int steps) {
  PropagationOptions options;
  options.steps = steps;
  options.recordEnergy = true;
  return options;
}

using GpuPropagation = GpuTest;

TEST_F(GpuPropagation, UniformGridLobeMatchesCpuFor1_8_40Steps) {
  const MaterialGrid material = uniformMaterial(16, glm::vec3(0.8f, 1.0f, 1.5f), glm::vec3(0.7f, 0.9f, 0.6f), 0.3f);
  ShGrid injected;
  injected.resize(material.frame);
  putLobe(injected, 8, 8, 8, glm::normalize(glm::vec3(1, 2, 3)), 1.0f);
  for (int steps : {1, 8, 40}) {
    const PropagationOptions options = stepsWithEnergy(steps);
    expectRunsMatch(runGpu(device(), material, injected, options), runCpu(material, injected, options),
                    std::to_string(steps) + " steps");
  }
  reportWorst("UniformGridLobeMatchesCpuFor1_8_40Steps");
}

/// A random box of 5..20 cells per axis: random coverage with holes, σt from 0 to dense,
/// albedo up to exactly 1, g up to ±0.999, and cosine lobes in random active cells.
struct RandomCase {
  MaterialGrid material;
  ShGrid injected;
};

RandomCase randomCase(std::mt19937& rng) {
  std::uniform_int_distribution<int> dim(5, 20);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  RandomCase c;
  MaterialGrid& m = c.material;
  m.frame.cellSize = 0.1 + unit(rng);
  m.frame.dims = drawVec3<glm::ivec3>(dim, rng);
  const std::size_t n = m.frame.cellCount();
  const float holes = 0.4f * unit(rng);
  m.coverage.resize(n);
  m.sigmaT.resize(n);
  m.sigmaS.resize(n);
  m.g.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    m.coverage[i] = unit(rng) < holes ? 0.0f : std::max(1e-3f, unit(rng));
    for (int ch = 0; ch < 3; ++ch) {
      const float pick = unit(rng);
      const float sigmaT = pick < 0.1f ? 0.0f : std::exp(8.0f * unit(rng) - 4.0f);  // 0, or 0.02 .. 55
      const float albedo = pick > 0.7f ? 1.0f : unit(rng);
      m.sigmaT[i][ch] = sigmaT;
      m.sigmaS[i][ch] = albedo * sigmaT;
    }
    const float gPick = unit(rng);
    m.g[i] = gPick < 0.15f ? 0.999f : gPick < 0.3f ? -0.999f : 2.0f * unit(rng) - 1.0f;
  }
  c.injected.resize(m.frame);
  const int lobes = 1 + int(unit(rng) * 6);
  for (int placed = 0, tries = 0; placed < lobes && tries < 1000; ++tries) {
    const int x = int(unit(rng) * m.frame.dims.x), y = int(unit(rng) * m.frame.dims.y),
              z = int(unit(rng) * m.frame.dims.z);
    if (!m.frame.contains(x, y, z) || !isActiveCell(m, x, y, z)) continue;  // injection's contract
    const glm::vec3 dir = drawVec3<glm::vec3>([&] { return unit(rng) - 0.5f; });
    if (glm::length(dir) < 1e-3f) continue;
    putLobe(c.injected, x, y, z, glm::normalize(dir), 0.1f + 10.0f * unit(rng));
    ++placed;
  }
  return c;
}

TEST_F(GpuPropagation, RandomGridsMatchCpuFor1_8_40Steps) {
  std::mt19937 rng(20240611);
  for (int k = 0; k < 8; ++k) {
    const RandomCase c = randomCase(rng);
    const glm::ivec3 d = c.material.frame.dims;
    const std::string name = "case " + std::to_string(k) + " (" + std::to_string(d.x) + "x" + std::to_string(d.y) +
                             "x" + std::to_string(d.z) + ")";
    for (int steps : {1, 8, 40}) {
      const PropagationOptions options = stepsWithEnergy(steps);
      expectRunsMatch(runGpu(device(), c.material, c.injected, options), runCpu(c.material, c.injected, options),
                      name + ", " + std::to_string(steps) + " steps");
    }
  }
  reportWorst("RandomGridsMatchCpuFor1_8_40Steps");
}

/// A ball (or, with `shell`, its outer 2 cells) in a box whose sides are not multiples
/// of the tile size, so tiles are partly outside the grid and partly outside the object;
/// heterogeneous σt, albedo and g, and light in every active cell plus a few strong lobes.
RandomCase shapedCase(glm::ivec3 dims, bool shell, std::mt19937& rng) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  RandomCase c;
  MaterialGrid& m = c.material;
  m.frame.cellSize = 0.5;
  m.frame.dims = dims;
  const std::size_t n = m.frame.cellCount();
  m.coverage.assign(n, 0.0f);
  m.sigmaT.resize(n);
  m.sigmaS.resize(n);
  m.g.resize(n);
  const glm::vec3 centre = glm::vec3(dims) * 0.5f;
  const float radius = 0.45f * float(std::min({dims.x, dims.y, dims.z}));
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        const std::size_t i = m.frame.index(x, y, z);
        const float r = glm::length(glm::vec3(x, y, z) + 0.5f - centre);
        if (r < radius && (!shell || r > radius - 2.0f)) m.coverage[i] = 0.2f + 0.8f * unit(rng);
        for (int ch = 0; ch < 3; ++ch) {
          m.sigmaT[i][ch] = 0.2f + 4.0f * unit(rng);
          m.sigmaS[i][ch] = (0.5f + 0.5f * unit(rng)) * m.sigmaT[i][ch];
        }
        m.g[i] = 1.6f * unit(rng) - 0.8f;
      }
  c.injected.resize(m.frame);
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        if (!isActiveCell(m, x, y, z)) continue;  // injection's contract
        const std::size_t i = m.frame.index(x, y, z);
        for (int ch = 0; ch < 3; ++ch) {
          c.injected.plane(ch, 0)[i] = 0.1f * unit(rng);
          c.injected.plane(ch, 1 + ch)[i] = 0.05f * (unit(rng) - 0.5f);
        }
        if (unit(rng) < 0.01f) putLobe(c.injected, x, y, z, glm::normalize(glm::vec3(unit(rng) - 0.5f, 0.3f, 1.0f)), 5.0f);
      }
  return c;
}

TEST_F(GpuPropagation, SphereAndThinShellMatchCpuFor1_8_40Steps) {
  // Only the tiles holding active cells are dispatched: a sphere or a shell must still
  // propagate exactly as on the CPU, which walks every active row of the bounding box.
  std::mt19937 rng(99);
  for (const bool shell : {false, true}) {
    const RandomCase c = shapedCase(glm::ivec3(21, 18, 23), shell, rng);
    for (int steps : {1, 8, 40}) {
      const PropagationOptions options = stepsWithEnergy(steps);
      expectRunsMatch(runGpu(device(), c.material, c.injected, options), runCpu(c.material, c.injected, options),
                      std::string(shell ? "shell" : "sphere") + ", " + std::to_string(steps) + " steps");
    }
  }
  reportWorst("SphereAndThinShellMatchCpuFor1_8_40Steps");
}

TEST_F(GpuPropagation, CalibratedSphereAndShellWithBoundaryRetentionMatchCpu) {
  // The calibrated scheme: per-cell survival, no linear band, and boundary cells that
  // keep ρ per outside neighbour of what they send (on the GPU from the lobe sent along
  // +x, on the CPU from c0: equal for the isotropic cells this scheme holds, so the
  // injected light is isotropic here, as the calibrated injection writes it).
  std::mt19937 rng(7);
  for (const bool shell : {false, true}) {
    RandomCase c = shapedCase(glm::ivec3(21, 18, 23), shell, rng);
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 1; k < 4; ++k) std::fill(c.injected.plane(ch, k), c.injected.plane(ch, k) + c.material.frame.cellCount(), 0.0f);
    const StepFactors factors = computeStepFactors(c.material, LpvScheme::Calibrated, 1.4);
    ASSERT_GT(*std::max_element(factors.retention[0].begin(), factors.retention[0].end()), 0.0f);
    // σt' varies from cell to cell, so faces pass light at per-cell conductances too.
    ASSERT_FALSE(factors.conductance[0].empty());
    // Near its poles the sphere's faces are aligned and inside their cells: the injected
    // light enters the accumulated light with a fresh gain there (gridPhaseFreshGain).
    const auto [lowGain, highGain] = std::minmax_element(factors.freshGain[0].begin(), factors.freshGain[0].end());
    ASSERT_TRUE(*lowGain < 0.99f || *highGain > 1.01f) << "no fresh gain to compare";
    for (int steps : {1, 8, 40}) {
      const PropagationOptions options = stepsWithEnergy(steps);
      expectRunsMatch(runGpu(device(), c.material, c.injected, options, {}, LpvScheme::Calibrated),
                      runCpu(c.material, c.injected, options, LpvScheme::Calibrated),
                      std::string(shell ? "calibrated shell" : "calibrated sphere") + ", " + std::to_string(steps) +
                          " steps");
    }
  }
  reportWorst("CalibratedSphereAndShellWithBoundaryRetentionMatchCpu");
}

TEST_F(GpuPropagation, SkippedCellsStayDarkAndCostNothing) {
  // The work items cover the shell, not its bounding box; every cell outside the medium
  // ends dark (the CPU's propagate() leaves them 0 too), and light planted in a cell that
  // no item covers is never read on the device path (injection never puts any there).
  std::mt19937 rng(5);
  const RandomCase c = shapedCase(glm::ivec3(40, 40, 40), true, rng);
  const StepFactors factors = computeStepFactors(c.material);
  gpu::GpuPropagator propagator(device(), c.material.frame, factors);
  EXPECT_LT(propagator.coveredCells(), c.material.frame.cellCount() / 2) << "a thin shell covers little of its box";
  EXPECT_GE(propagator.coveredCells(), propagator.activeCells());

  ShGrid planted = c.injected;
  const std::size_t corner = c.material.frame.index(1, 1, 1);  // outside the ball, in no item
  ASSERT_FALSE(factors.active[corner]);
  for (int k = 0; k < ShGrid::kPlanes; ++k) planted.planes[k][corner] = 100.0f;
  propagator.uploadField(planted, propagator.sourceField());  // all cells, the corner too
  const PropagationOptions options = stepsWithEnergy(8);
  const PropagationResult result = propagator.runOnDevice(options);
  ShGrid accumulated, last;
  accumulated.resize(c.material.frame);
  last.resize(c.material.frame);
  propagator.downloadField(propagator.accumulated(), accumulated);
  propagator.downloadLastField(last);
  for (std::size_t i = 0; i < c.material.frame.cellCount(); ++i) {
    if (factors.active[i]) continue;
    for (int k = 0; k < ShGrid::kPlanes; ++k) {
      ASSERT_EQ(last.planes[k][i], 0.0f) << "inactive cell " << i << " plane " << k;
      ASSERT_EQ(accumulated.planes[k][i], 0.0f) << "inactive cell " << i << " plane " << k;
    }
  }
  const Outcome cpu = runCpu(c.material, c.injected, options);  // without the planted light
  expectEnergyMatches(result, cpu.result, "planted light outside the items", kDevicePowerTolerance);
  expectGridsMatch(accumulated, cpu.accumulated, "planted light outside the items, accumulated");
  reportWorst("SkippedCellsStayDarkAndCostNothing");
}

TEST_F(GpuPropagation, DeviceResidentRunsEqualTheHostRun) {
  // runOnDevice() and record() propagate from sourceField() into accumulated() with no
  // host grid: same steps, energy, last field and accumulated light as run() (which
  // matches the CPU), for fixed and auto steps, and the injected light alone for 0 steps.
  std::mt19937 rng(11);
  const RandomCase c = shapedCase(glm::ivec3(26, 20, 17), false, rng);
  const StepFactors factors = computeStepFactors(c.material);
  PropagationOptions autoOptions = stepsWithEnergy(0);
  autoOptions.autoSteps = true;
  autoOptions.autoTolerance = 1e-2;
  gpu::GpuPropagatorOptions gpuOptions;
  gpuOptions.stepsPerSubmission = 3;  // auto steps stop inside a submission
  for (const PropagationOptions& options : {stepsWithEnergy(7), stepsWithEnergy(8), autoOptions}) {
    const std::string what = options.autoSteps ? "auto steps" : std::to_string(options.steps) + " steps";
    // A propagator per path, so that no path can pass on what another left in the buffers.
    gpu::GpuPropagator hostPath(device(), c.material.frame, factors, gpuOptions);
    Outcome host;
    host.field = c.injected;
    host.accumulated.resize(c.material.frame);
    host.result = hostPath.run(host.field, host.accumulated, options);
    ASSERT_GT(host.result.stepsRun, 1) << what;

    expectRunsMatch(runDeviceResident(device(), c.material, factors, c.injected, options, gpuOptions), host,
                    what + " on the device", kDevicePowerTolerance);
    const Outcome recorded = runRecorded(device(), c.material, factors, c.injected, options, gpuOptions);
    EXPECT_EQ(recorded.result.stepsRun, host.result.stepsRun) << what << " recorded";
    expectGridsMatch(recorded.accumulated, host.accumulated, what + " recorded, accumulated");
    expectGridsMatch(recorded.field, host.field, what + " recorded, last field");
  }

  gpu::GpuPropagator propagator(device(), c.material.frame, factors);
  propagator.uploadField(c.injected, propagator.sourceField(), true);
  EXPECT_EQ(propagator.runOnDevice(stepsWithEnergy(0)).stepsRun, 0);
  ShGrid accumulated;
  accumulated.resize(c.material.frame);
  propagator.downloadField(propagator.accumulated(), accumulated);
  for (int k = 0; k < ShGrid::kPlanes; ++k) EXPECT_EQ(accumulated.planes[k], c.injected.planes[k]) << "plane " << k;
  reportWorst("DeviceResidentRunsEqualTheHostRun");
}

TEST_F(GpuPropagation, ChebyshevAutoStepsOnTheDeviceMatchTheCpu) {
  // --steps auto as the semi-iteration (PropagationOptions::chebyshev), device-resident
  // through runOnDevice() and record(), against the CPU: the same steps (probe, iterates
  // and stop, decided on the GPU in float), the first step's energy, the accumulated
  // light and the last iterate. Calibrated sphere and shell (retention, conductance,
  // fresh gain) with isotropic injected light, as the calibrated injection writes it
  // (see CalibratedSphereAndShellWithBoundaryRetentionMatchCpu); a few steps per
  // submission, so that the iterates' weights and the stop carry across submissions.
  std::mt19937 rng(23);
  for (const bool shell : {false, true}) {
    RandomCase c = shapedCase(glm::ivec3(21, 18, 23), shell, rng);
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 1; k < 4; ++k)
        std::fill(c.injected.plane(ch, k), c.injected.plane(ch, k) + c.material.frame.cellCount(), 0.0f);
    const StepFactors factors = computeStepFactors(c.material, LpvScheme::Calibrated, 1.4);
    PropagationOptions options = stepsWithEnergy(0);
    options.autoSteps = true;
    options.chebyshev = true;
    PropagationOptions plain = options;
    plain.chebyshev = false;
    const std::string what = shell ? "shell" : "sphere";
    const Outcome cpu = runCpu(c.material, c.injected, options, LpvScheme::Calibrated);
    const int plainSteps = runCpu(c.material, c.injected, plain, LpvScheme::Calibrated).result.stepsRun;
    ASSERT_GT(cpu.result.stepsRun, SSLPV_CHEBYSHEV_PROBE_STEPS + SSLPV_CHEBYSHEV_RATE_WINDOW) << what;
    EXPECT_LT(cpu.result.stepsRun, plainSteps) << what << ": the semi-iteration must take fewer steps";

    gpu::GpuPropagatorOptions gpuOptions;
    gpuOptions.stepsPerSubmission = 5;
    expectRunsMatch(runDeviceResident(device(), c.material, factors, c.injected, options, gpuOptions), cpu,
                    what + " on the device", kDevicePowerTolerance);
    const Outcome recorded = runRecorded(device(), c.material, factors, c.injected, options, gpuOptions);
    EXPECT_EQ(recorded.result.stepsRun, cpu.result.stepsRun) << what << " recorded";
    expectGridsMatch(recorded.accumulated, cpu.accumulated, what + " recorded, accumulated");
    expectGridsMatch(recorded.field, cpu.field, what + " recorded, last iterate");

    // From host grids the propagator keeps the plain steps (run() keeps no y).
    const Outcome host = runGpu(device(), c.material, c.injected, options, {}, LpvScheme::Calibrated);
    EXPECT_EQ(host.result.stepsRun, plainSteps) << what << " from the host";
  }
  // A dark grid stops after one probe step on both.
  RandomCase dark = shapedCase(glm::ivec3(12, 11, 13), false, rng);
  for (std::vector<float>& plane : dark.injected.planes) std::fill(plane.begin(), plane.end(), 0.0f);
  PropagationOptions options;
  options.autoSteps = true;
  options.chebyshev = true;
  const StepFactors darkFactors = computeStepFactors(dark.material, LpvScheme::Calibrated, 1.4);
  EXPECT_EQ(runDeviceResident(device(), dark.material, darkFactors, dark.injected, options, {}).result.stepsRun,
            runCpu(dark.material, dark.injected, options, LpvScheme::Calibrated).result.stepsRun);
  reportWorst("ChebyshevAutoStepsOnTheDeviceMatchTheCpu");
}

TEST_F(GpuPropagation, TileRowsZChunksAndStagingGiveTheSameResult) {
  // Results must not depend on how the grid is cut into work items (halo seams between
  // tiles and between the z pieces of a run) or on how data reaches the device; 2 steps
  // per submission also crosses submission boundaries.
  std::mt19937 rng(7);
  const RandomCase c = randomCase(rng);
  const PropagationOptions options = stepsWithEnergy(9);
  const Outcome cpu = runCpu(c.material, c.injected, options);
  for (const auto& [rows, zChunk, staging] : {std::tuple{8, 3, false}, std::tuple{16, 1, false},
                                              std::tuple{4, 5, true}, std::tuple{1, 0, true}, std::tuple{3, 2, false}}) {
    gpu::GpuPropagatorOptions gpuOptions;
    gpuOptions.tileRows = rows;
    gpuOptions.zChunk = zChunk;
    gpuOptions.forceStaging = staging;
    gpuOptions.stepsPerSubmission = 2;
    expectRunsMatch(runGpu(device(), c.material, c.injected, options, gpuOptions), cpu,
                    std::to_string(rows) + " rows z" + std::to_string(zChunk) + (staging ? " staged" : " mapped"));
  }
  reportWorst("TileRowsZChunksAndStagingGiveTheSameResult");
}

TEST_F(GpuPropagation, IsotropicFieldIsConserved) {
  // Transparent medium filled with the same isotropic intensity: every interior cell
  // receives exactly what it sends, so cells away from the boundary do not change.
  const MaterialGrid material = uniformMaterial(10, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f);
  const StepFactors factors = computeStepFactors(material);
  ShGrid field, accumulated;
  field.resize(material.frame);
  accumulated.resize(material.frame);
  for (std::size_t i = 0; i < material.frame.cellCount(); ++i)
    if (factors.active[i])
      for (int ch = 0; ch < 3; ++ch) field.plane(ch, 0)[i] = 1.0f;
  gpu::GpuPropagator propagator(device(), material.frame, factors);
  propagator.run(field, accumulated, stepsWithEnergy(1));
  for (int z = 2; z < 8; ++z)
    for (int y = 2; y < 8; ++y)
      for (int x = 2; x < 8; ++x) {
        const std::size_t i = material.frame.index(x, y, z);
        for (int ch = 0; ch < 3; ++ch) {
          EXPECT_NEAR(field.plane(ch, 0)[i], 1.0f, 1e-6f) << x << "," << y << "," << z;
          for (int k = 1; k < 4; ++k) EXPECT_NEAR(field.plane(ch, k)[i], 0.0f, 1e-6f);
        }
      }
}

TEST_F(GpuPropagation, EnergyBalanceClosesStepByStep) {
  // Grid + left + absorbed = injected at every step, with absorption per channel; with
  // albedo 1 in the first channel nothing of it is absorbed.
  const MaterialGrid material = uniformMaterial(14, glm::vec3(1.0f), glm::vec3(1.0f, 0.8f, 0.5f), 0.2f);
  ShGrid injected;
  injected.resize(material.frame);
  putLobe(injected, 7, 7, 7, glm::vec3(0, 0, 1), 1.0f);
  const Outcome gpu = runGpu(device(), material, injected, stepsWithEnergy(40));
  ASSERT_EQ(gpu.result.energy.size(), 40u);
  glm::dvec3 left(0.0), absorbed(0.0);
  for (std::size_t s = 0; s < gpu.result.energy.size(); ++s) {
    const StepEnergy& e = gpu.result.energy[s];
    left += e.left;
    absorbed += e.absorbed;
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(e.inGrid[ch] + left[ch] + absorbed[ch], gpu.result.initialPower[ch],
                  kPowerTolerance * gpu.result.initialPower[ch])
          << "step " << s << " channel " << ch;
    EXPECT_NEAR(e.absorbed.x, 0.0, 1e-6 * gpu.result.initialPower.x) << "albedo 1 absorbs nothing";
  }
  EXPECT_GT(left.x, 0.1 * gpu.result.initialPower.x) << "light reaches the boundary within 40 steps";
  EXPECT_GT(absorbed.z, absorbed.y) << "the lowest albedo channel absorbs most";
}

TEST_F(GpuPropagation, AutoStepsStopAtTheSameStepAsTheCpu) {
  const MaterialGrid material = uniformMaterial(16, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f);
  ShGrid injected;
  injected.resize(material.frame);
  putLobe(injected, 8, 8, 8, glm::vec3(0, 1, 0), 1.0f);
  // The last step's light is in either field depending on the count's parity, and the
  // tail must be read from the right one: tolerances that stop at odd and even counts.
  bool stoppedAt[2] = {false, false};
  for (double tolerance : {1e-3, 5e-4, 2e-4}) {
    PropagationOptions options = stepsWithEnergy(0);
    options.autoSteps = true;
    options.autoTolerance = tolerance;
    const std::string what = "auto steps, tolerance " + std::to_string(tolerance);
    const Outcome cpu = runCpu(material, injected, options);
    ASSERT_GT(cpu.result.stepsRun, 8) << "the case must need several submissions of 8 steps";
    ASSERT_GT(cpu.result.tailScale.x, 0.0) << "the stop adds a tail, which the GPU must add too";
    stoppedAt[cpu.result.stepsRun % 2] = true;
    gpu::GpuPropagatorOptions gpuOptions;
    gpuOptions.stepsPerSubmission = 8;  // the stop falls inside a submission
    expectRunsMatch(runGpu(device(), material, injected, options, gpuOptions), cpu, what);
  }
  EXPECT_TRUE(stoppedAt[0] && stoppedAt[1]) << "the tolerances must stop at both an odd and an even step count";
  reportWorst("AutoStepsStopAtTheSameStepAsTheCpu");
}

TEST_F(GpuPropagation, AutoStepsStopWhileAnAbsorbingChannelHasDecayedToNothing) {
  // Blue loses 60 % a step and reaches float's denormal range long before red settles;
  // on lavapipe its step sums then stall at a ratio of 1, which must not hold up the stop.
  const MaterialGrid material = uniformMaterial(16, glm::vec3(1.0f), glm::vec3(0.998f, 0.5f, 0.02f), 0.0f);
  ShGrid injected;
  injected.resize(material.frame);
  putLobe(injected, 8, 8, 8, glm::vec3(0, 1, 0), 1.0f);
  PropagationOptions options = stepsWithEnergy(0);
  options.autoSteps = true;
  const Outcome cpu = runCpu(material, injected, options);
  ASSERT_GT(cpu.result.stepsRun, 120) << "blue must have decayed by more than float's range";
  gpu::GpuPropagatorOptions gpuOptions;
  gpuOptions.stepsPerSubmission = 64;
  expectRunsMatch(runGpu(device(), material, injected, options, gpuOptions), cpu, "absorbing blue");
  reportWorst("AutoStepsStopWhileAnAbsorbingChannelHasDecayedToNothing");
}

TEST_F(GpuPropagation, GridsTooSmallToPropagateOnlyAccumulateTheInjectedLight) {
  const MaterialGrid material = uniformMaterial(2, glm::vec3(1.0f), glm::vec3(0.5f), 0.0f);
  ShGrid injected;
  injected.resize(material.frame);
  putLobe(injected, 1, 1, 1, glm::vec3(1, 0, 0), 2.0f);
  const PropagationOptions options = stepsWithEnergy(5);
  const Outcome gpu = runGpu(device(), material, injected, options);
  EXPECT_EQ(gpu.result.stepsRun, 0);
  expectRunsMatch(gpu, runCpu(material, injected, options), "2x2x2 grid");
}

TEST_F(GpuPropagation, ReportsKernelTimesWhenTimestampsExist) {
  const MaterialGrid material = uniformMaterial(12, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f);
  ShGrid field, accumulated;
  field.resize(material.frame);
  accumulated.resize(material.frame);
  putLobe(field, 6, 6, 6, glm::vec3(1, 0, 0), 1.0f);
  gpu::GpuPropagator propagator(device(), material.frame, computeStepFactors(material));
  propagator.run(field, accumulated, stepsWithEnergy(4));
  EXPECT_EQ(propagator.timings().steps, 4);
  if (device().timestampValidBits() == 0) GTEST_SKIP() << "SKIPPED, the queue has no timestamps";
  EXPECT_GT(propagator.timings().propagateMs, 0.0);
  EXPECT_GT(propagator.timings().reduceMs, 0.0);
}

TEST_F(GpuPropagation, GridBeyondTheStorageBufferRangeIsAResourceError) {
  GridFrame frame;
  frame.dims = glm::ivec3(256);
  const std::uint64_t needed = std::uint64_t(frame.cellCount()) * 3 * 16;
  if (needed <= device().properties().limits.maxStorageBufferRange)
    GTEST_SKIP() << "SKIPPED, this device binds " << needed << " bytes in one buffer";
  // The check comes before anything is allocated or uploaded, so no factors are needed.
  try {
    gpu::GpuPropagator propagator(device(), frame, StepFactors{});
    FAIL() << "a 256^3 grid was accepted";
  } catch (const ResourceError& e) {
    EXPECT_NE(std::string(e.what()).find("256x256x256"), std::string::npos) << e.what();
  }
}

TEST_F(GpuPropagation, MismatchedGridsAreRejected) {
  const MaterialGrid material = uniformMaterial(6, glm::vec3(1.0f), glm::vec3(0.5f), 0.0f);
  const MaterialGrid other = uniformMaterial(7, glm::vec3(1.0f), glm::vec3(0.5f), 0.0f);
  EXPECT_THROW(gpu::GpuPropagator(device(), material.frame, computeStepFactors(other)), GpuError);
  gpu::GpuPropagator propagator(device(), material.frame, computeStepFactors(material));
  ShGrid field, accumulated;
  field.resize(other.frame);
  accumulated.resize(material.frame);
  EXPECT_THROW(propagator.run(field, accumulated, stepsWithEnergy(1)), GpuError);
}

}  // namespace

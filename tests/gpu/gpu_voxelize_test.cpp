// The GPU voxelizer (gpu/passes/gpu_voxelize.h) against its CPU twin voxelizeParityDetailed()
// (volume/lpv/voxelize_parity.h), and through it against the OpenVDB voxelizer.
//
// Tolerances: every value the two sides compute comes from the same functions in
// device_shared/voxelize_shared.h with the same float operations, and the atomics (minimum,
// xor) are order-independent, so on lavapipe the packed per-cell words, the parity words
// and the coverage are identical to the last bit (the counts are printed). Vulkan lets a
// device round division and square root less tightly than the host, which can move a
// value that sits on a quantization tie by one step: so a differing word may differ by
// one distance step (5.3e-5 cells) and one step of each normal coordinate, and coverage by
// 2e-4 (a distance step through a slope <= 1.2 plus a normal step); parity words, which
// are exact integer decisions, must be identical.
#include "gpu/passes/gpu_voxelize.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "gpu_test_fixture.h"
#include "volume/core/error.h"
#include "volume/lpv/voxelize.h"
#include "volume/lpv/voxelize_parity.h"
#include "voxelize_parity_meshes.h"

namespace {
using namespace sslpv;
using namespace sslpv::test;

constexpr double kCoverageTolerance = 2e-4;

struct GpuResult {
  std::vector<float> coverage;
  std::vector<std::uint32_t> nearest, parity;
  gpu::GpuVoxelizeTimings timings;
};

GpuResult runGpu(const gpu::VulkanDevice& device, const TriangleMesh& mesh, const GridFrame& frame) {
  gpu::VoxelizerMesh buffers(device, mesh);
  gpu::GpuVoxelizer voxelizer(device, frame);
  GpuResult r;
  r.timings = voxelizer.run(buffers);
  r.coverage = voxelizer.readCoverage();
  r.nearest = voxelizer.readNearest();
  r.parity = voxelizer.readParity();
  return r;
}

/// GPU against the twin: words, parity and coverage; returns the coverage difference.
CoverageDifference expectMatchesTwin(const GpuResult& gpu, const ParityVoxelization& cpu, const std::string& what) {
  EXPECT_EQ(gpu.nearest.size(), cpu.nearest.size()) << what;
  EXPECT_EQ(gpu.parity.size(), cpu.parity.size()) << what;
  std::size_t nearestDiffer = 0, parityDiffer = 0, beyondOneStep = 0;
  const auto field = [](std::uint32_t word, int shift, std::uint32_t mask) { return int((word >> shift) & mask); };
  for (std::size_t i = 0; i < std::min(gpu.nearest.size(), cpu.nearest.size()); ++i) {
    const std::uint32_t g = gpu.nearest[i], c = cpu.nearest[i];
    if (g == c) continue;
    ++nearestDiffer;
    const bool oneStep = g != SSLPV_VOX_EMPTY && c != SSLPV_VOX_EMPTY &&
                         std::abs(field(g, 18, 0x3FFF) - field(c, 18, 0x3FFF)) <= 1 &&
                         std::abs(field(g, 9, 511) - field(c, 9, 511)) <= 1 &&
                         std::abs(field(g, 0, 511) - field(c, 0, 511)) <= 1;
    if (!oneStep && beyondOneStep++ < 5)
      ADD_FAILURE() << what << ": cell " << i << " GPU word " << std::hex << g << " twin " << c;
  }
  for (std::size_t i = 0; i < std::min(gpu.parity.size(), cpu.parity.size()); ++i)
    parityDiffer += gpu.parity[i] != cpu.parity[i];
  const CoverageDifference d = compareCoverage(gpu.coverage, cpu.coverage);
  std::printf("%s: GPU vs twin: %zu of %zu cell words and %zu parity words differ; coverage %s\n", what.c_str(),
              nearestDiffer, cpu.nearest.size(), parityDiffer, d.describe().c_str());
  EXPECT_EQ(beyondOneStep, 0u) << what;
  EXPECT_EQ(parityDiffer, 0u) << what;
  EXPECT_LE(d.maxAbs, kCoverageTolerance) << what;
  EXPECT_EQ(d.activeMismatch, 0u) << what;
  return d;
}

using GpuVoxelize = GpuTest;

TEST_F(GpuVoxelize, SphereMatchesTwinAndVolume) {
  // 20K-triangle icosphere, 64 cells across, off-grid centre: GPU = twin; volume within
  // 0.3% of the polyhedron's (as the CPU voxelizers); close to the OpenVDB path per cell.
  const double radius = 1.0;
  GridFrame frame = cubeFrame(72, 2.0 * radius / 64.0);
  frame.origin = glm::dvec3(-36.0 * frame.cellSize) + 0.3 * frame.cellSize;
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.0f), float(radius), 5);
  const GpuResult gpu = runGpu(device(), sphere, frame);
  expectMatchesTwin(gpu, voxelizeParityDetailed(sphere.positions, sphere.triangles, frame), "sphere");
  const double volume = sumCoverage(gpu.coverage) * std::pow(frame.cellSize, 3);
  EXPECT_NEAR(volume, enclosedVolume(sphere), 0.003 * enclosedVolume(sphere));
  const CoverageDifference vsVdb = compareCoverage(gpu.coverage, voxelizeCoverage(sphere, frame));
  std::printf("sphere: GPU volume %.5f, polyhedron %.5f, analytic %.5f; GPU vs OpenVDB: %s\n", volume,
              enclosedVolume(sphere), 4.0 / 3.0 * kVoxelizePi, vsVdb.describe().c_str());
  EXPECT_LT(vsVdb.meanBand, 0.01);
  EXPECT_LT(vsVdb.maxMismatchCoverage, 0.005);
  // Deep inside is 1, far outside 0.
  const int c = 36;
  EXPECT_EQ(gpu.coverage[frame.index(c, c, c)], 1.0f);
  EXPECT_EQ(gpu.coverage[frame.index(0, 0, 0)], 0.0f);
}

TEST_F(GpuVoxelize, BoxesPlateTorusAndOctahedronMatchTwin) {
  struct Case {
    std::string name;
    TriangleMesh mesh;
    GridFrame frame;
  };
  const std::vector<Case> cases = {
      {"aligned box", makeBoxMesh(glm::vec3(4.75f, 3.25f, 2.5f), glm::vec3(11.5f, 12.75f, 10.25f)), cubeFrame(16)},
      {"box on cell-centre columns", makeBoxMesh(glm::vec3(2.5f, 3.5f, 2.25f), glm::vec3(8.5f, 9.5f, 9.75f)),
       cubeFrame(12)},
      {"rotated box",
       rotated(makeBoxMesh(glm::vec3(7.0f, 8.5f, 9.5f), glm::vec3(17.0f, 15.5f, 14.5f)), glm::dvec3(12.0), 0.4, 0.7,
               0.25),
       cubeFrame(24)},
      {"thin plate", makeBoxMesh(glm::vec3(2.0f, 2.0f, 5.35f), glm::vec3(10.0f, 10.0f, 5.65f)), cubeFrame(12)},
      {"torus", makeTorus(glm::dvec3(12.2, 11.9, 12.1), 7.0, 2.5, 96, 32), cubeFrame(24)},
      {"octahedron", makeOctahedron(glm::dvec3(10.5, 9.5, 10.2), 7.0), cubeFrame(20)},
      {"height block with vertices on columns", makeHeightBlock(2, 11, 1.25, rollingHeight), cubeFrame(14)},
      {"mesh beside the frame", makeBoxMesh(glm::vec3(21.0f, 1.0f, 1.0f), glm::vec3(27.0f, 7.0f, 7.0f)), cubeFrame(8)},
      {"mesh below the frame", makeBoxMesh(glm::vec3(1.0f, 1.0f, -29.0f), glm::vec3(7.0f, 7.0f, -23.0f)),
       cubeFrame(8)},
      {"frame inside the mesh", makeBoxMesh(glm::vec3(-20.0f), glm::vec3(26.0f)), cubeFrame(8)},
      {"non-cubic frame", makeIcosphere(glm::vec3(5.3f, 7.1f, 3.9f), 3.0f, 3),
       GridFrame{glm::dvec3(0.1, 0.2, -0.3), 0.5, glm::ivec3(23, 31, 17)}},
  };
  for (const Case& c : cases) {
    const GpuResult gpu = runGpu(device(), c.mesh, c.frame);
    const ParityVoxelization cpu = voxelizeParityDetailed(c.mesh.positions, c.mesh.triangles, c.frame);
    expectMatchesTwin(gpu, cpu, c.name);
    for (float v : gpu.coverage) ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << c.name;
    if (c.name == "mesh beside the frame" || c.name == "mesh below the frame") {
      EXPECT_EQ(sumCoverage(gpu.coverage), 0.0) << c.name;
    }
    if (c.name == "frame inside the mesh") {
      EXPECT_EQ(sumCoverage(gpu.coverage), double(c.frame.cellCount()));
    }
    if (c.name == "torus") {
      // The hole is empty (its axis column crosses the mesh 0 times), the tube core full.
      const glm::dvec3 centre(12.2, 11.9, 12.1);
      for (int z = 0; z < 24; ++z)
        for (int y = 0; y < 24; ++y)
          for (int x = 0; x < 24; ++x) {
            const glm::dvec3 p = c.frame.cellCenter(x, y, z) - centre;
            const double tube = std::hypot(std::hypot(p.x, p.y) - 7.0, p.z) - 2.5;
            const float v = gpu.coverage[c.frame.index(x, y, z)];
            if (tube > 0.95) {
              ASSERT_EQ(v, 0.0f) << x << "," << y << "," << z;
            }
            if (tube < -0.95) {
              ASSERT_EQ(v, 1.0f) << x << "," << y << "," << z;
            }
          }
    }
  }
}

TEST_F(GpuVoxelize, DeformingMeshIsRevoxelizedEachFrame) {
  // The same buffers and voxelizer across frames, the positions rewritten in place: each
  // frame matches the twin at that frame's positions (nothing stale survives the clear).
  GridFrame frame = cubeFrame(32, 1.0, glm::dvec3(-16.0));
  TriangleMesh mesh = makeIcosphere(glm::vec3(0.0f), 9.0f, 4);
  gpu::VoxelizerMesh buffers(device(), mesh);
  gpu::GpuVoxelizer voxelizer(device(), frame);
  std::vector<float> previous;
  for (int step = 0; step < 3; ++step) {
    TriangleMesh deformed = mesh;
    for (glm::vec3& p : deformed.positions) {
      // Squash along z and move along x, more each frame.
      p.z *= 1.0f - 0.2f * float(step);
      p.x += 1.7f * float(step);
    }
    buffers.setPositions(deformed.positions);
    voxelizer.run(buffers);
    GpuResult gpu;
    gpu.coverage = voxelizer.readCoverage();
    gpu.nearest = voxelizer.readNearest();
    gpu.parity = voxelizer.readParity();
    expectMatchesTwin(gpu, voxelizeParityDetailed(deformed.positions, deformed.triangles, frame),
                      "deformed frame " + std::to_string(step));
    const double volume = sumCoverage(gpu.coverage);
    EXPECT_NEAR(volume, enclosedVolume(deformed), 0.01 * enclosedVolume(deformed)) << "frame " << step;
    if (!previous.empty()) {
      EXPECT_GT(compareCoverage(gpu.coverage, previous).maxAbs, 0.5);
    }
    previous = gpu.coverage;
  }
}

TEST_F(GpuVoxelize, RejectsTooFewIndices) {
  const TriangleMesh box = makeBoxMesh(glm::vec3(1.0f), glm::vec3(3.0f));
  gpu::VoxelizerMesh buffers(device(), box);
  gpu::GpuVoxelizer voxelizer(device(), cubeFrame(4));
  EXPECT_THROW(voxelizer.run(buffers.positions(), buffers.indices(), 13), GpuError);
  TriangleMesh broken = box;
  broken.triangles[0].x = 8;
  EXPECT_THROW(gpu::VoxelizerMesh(device(), broken), InputError);
}

/// Frame of n cells along the longest axis of the mesh's bounds plus one cell of margin on
/// every side (as makeGridFrame), cubic n^3 so that the cell count is the stated one.
GridFrame cubeFrameAround(const TriangleMesh& mesh, int n) {
  const Bounds b = mesh.bounds();
  const glm::dvec3 extent = b.extent();
  const double cell = std::max({extent.x, extent.y, extent.z}) / (n - 2);
  return cubeFrame(n, cell, 0.5 * (b.min + b.max) - 0.5 * n * cell);
}

// Tori keep the cells-per-triangle ratio of a typical closed mesh with a hole. The stage's
// time is bench/frame_bench's voxelize row, not a test's business.
TEST_F(GpuVoxelize, ToriOfGrowingSizeMatchTheTwinAt32And64) {
  for (const auto& [n, m] : {std::pair<int, int>{160, 64}, {384, 144}, {1024, 512}}) {
    const TriangleMesh torus = makeTorus(glm::dvec3(0.1, -0.2, 0.05), 1.0, 0.45, n, m);
    gpu::VoxelizerMesh buffers(device(), torus);
    for (int res : {32, 64}) {
      const GridFrame frame = cubeFrameAround(torus, res);
      gpu::GpuVoxelizer voxelizer(device(), frame);
      voxelizer.run(buffers);
      const ParityVoxelization cpu = voxelizeParityDetailed(torus.positions, torus.triangles, frame);
      GpuResult gpu;
      gpu.coverage = voxelizer.readCoverage();
      gpu.nearest = voxelizer.readNearest();
      gpu.parity = voxelizer.readParity();
      expectMatchesTwin(gpu, cpu, std::to_string(torus.triangles.size()) + " triangles at " + std::to_string(res));
    }
  }
}

}  // namespace

// Writes the heterogeneous accuracy suite into the folder given as argv[1]: scene JSON
// files, their material sets, and one stroke file that scripts/hetero-suite.sh turns into
// a painted material set with `sslpv paint`.
//
//   build/bench/hetero_scenes build/hetero
//
// The suite exists to test the calibrated scheme on materials nobody tuned it on, so its
// scenes change material within a few mean free paths of the surface (layers, veins,
// inclusions, a thin plate, paint strokes) and some are tilted against the grid (cell-layer
// bands). Every value is a fixed constant or an integer-hash noise, so two runs write the
// same scenes and voxels, and the reference cache (keyed by content) stays valid.
// Images are 128² so that a 128-spp path-traced reference takes minutes, not hours.
#include <openvdb/openvdb.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <glm/vec3.hpp>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "volume/core/error.h"
#include "volume/material/material_set.h"

namespace fs = std::filesystem;
using sslpv::MaterialSet;

namespace {

/// A medium in the reduced form artists' measurements come in (per mm): σs = σs'/(1 − g),
/// σt = σs + σa.
struct Medium {
  glm::vec3 sigmaSPrime;
  glm::vec3 sigmaA;
  float g = 0.0f;
  glm::vec3 sigmaS() const { return sigmaSPrime / (1.0f - g); }
  glm::vec3 sigmaT() const { return sigmaS() + sigmaA; }
};

std::string vec(const glm::vec3& v) {
  std::ostringstream s;
  s.precision(6);
  s << "[" << v.x << ", " << v.y << ", " << v.z << "]";
  return s.str();
}

std::string baseJson(const Medium& m) {
  return "{\"sigma_t\": " + vec(m.sigmaT()) + ", \"sigma_s\": " + vec(m.sigmaS()) +
         ", \"g\": " + std::to_string(m.g) + "}";
}

/// The material of one voxel centre (object space, mm), or nothing for the base material.
using VoxelMaterial = std::function<std::optional<Medium>(const glm::vec3&)>;

/// Writes the voxels of [lo, hi] (mm) whose material differs from the base; the rest stay
/// inactive and read as the scene's base material.
void writeMaterialSet(const fs::path& file, float voxelMm, const glm::vec3& lo, const glm::vec3& hi,
                      const VoxelMaterial& materialAt) {
  MaterialSet set;
  auto transform = openvdb::math::Transform::createLinearTransform(voxelMm);
  set.sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set.sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set.g = openvdb::FloatGrid::create(0.0f);
  for (auto grid : {openvdb::GridBase::Ptr(set.sigmaT), openvdb::GridBase::Ptr(set.sigmaS),
                    openvdb::GridBase::Ptr(set.g)})
    grid->setTransform(transform);
  set.sigmaT->setGridClass(openvdb::GRID_FOG_VOLUME);
  set.sigmaS->setGridClass(openvdb::GRID_FOG_VOLUME);
  set.sigmaT->setVectorType(openvdb::VEC_INVARIANT);
  set.sigmaS->setVectorType(openvdb::VEC_INVARIANT);
  set.creator = "sslpv hetero_scenes";
  auto t = set.sigmaT->getAccessor();
  auto s = set.sigmaS->getAccessor();
  auto g = set.g->getAccessor();
  const glm::ivec3 first(glm::floor(lo / voxelMm)), last(glm::ceil(hi / voxelMm));
  for (int k = first.z; k <= last.z; ++k)
    for (int j = first.y; j <= last.y; ++j)
      for (int i = first.x; i <= last.x; ++i) {
        const std::optional<Medium> m = materialAt(glm::vec3(i, j, k) * voxelMm);
        if (!m) continue;
        const openvdb::Coord c(i, j, k);
        const glm::vec3 st = m->sigmaT(), ss = m->sigmaS();
        t.setValue(c, openvdb::Vec3s(st.x, st.y, st.z));
        s.setValue(c, openvdb::Vec3s(ss.x, ss.y, ss.z));
        g.setValue(c, m->g);
      }
  sslpv::saveMaterialSet(set, file);
}

// Deterministic smooth noise (integer hash on a lattice, quintic interpolation): the same
// voxels on every standard library.
float lattice(int x, int y, int z, std::uint32_t seed) {
  std::uint32_t h = seed;
  for (std::uint32_t v : {std::uint32_t(x), std::uint32_t(y), std::uint32_t(z)}) {
    h ^= v + 0x9e3779b9u + (h << 6) + (h >> 2);
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
  }
  return float(h & 0xffffffu) / float(0xffffff) * 2.0f - 1.0f;
}

float smoothNoise(const glm::vec3& p, std::uint32_t seed) {
  const glm::vec3 cell = glm::floor(p), f = p - cell;
  auto q = [](float x) { return x * x * x * (x * (x * 6.0f - 15.0f) + 10.0f); };
  const glm::vec3 w(q(f.x), q(f.y), q(f.z));
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const float weight = (dx ? w.x : 1 - w.x) * (dy ? w.y : 1 - w.y) * (dz ? w.z : 1 - w.z);
    sum += weight * lattice(int(cell.x) + dx, int(cell.y) + dy, int(cell.z) + dz, seed);
  }
  return sum;
}

Medium mix(const Medium& a, const Medium& b, float t) {
  return {a.sigmaSPrime + (b.sigmaSPrime - a.sigmaSPrime) * t, a.sigmaA + (b.sigmaA - a.sigmaA) * t,
          a.g + (b.g - a.g) * t};
}

std::string camera(const glm::vec3& position, const glm::vec3& target) {
  return "  \"camera\": {\"position\": " + vec(position) + ", \"target\": " + vec(target) +
         ", \"up\": [0, 1, 0], \"fov_y_deg\": 35, \"width\": 128, \"height\": 128},\n";
}

const char* kLpv = "  \"lpv\": {\"resolution\": 64, \"steps\": \"auto\", \"shadow_map\": 256}\n";

struct SceneText {
  std::string mesh, transform, base, vdb, lights, camera;
  double ior = 1.4;
};

void writeScene(const fs::path& file, const SceneText& s) {
  std::ofstream out(file, std::ios::binary);
  out << "{\n  \"units\": \"mm\",\n  \"mesh\": " << s.mesh << ",\n";
  if (!s.transform.empty()) out << "  \"transform\": " << s.transform << ",\n";
  out << "  \"material\": {\"base\": " << s.base;
  if (!s.vdb.empty()) out << ", \"vdb\": \"" << s.vdb << "\"";
  out << ", \"ior\": " << s.ior << "},\n  \"lights\": [\n    " << s.lights << "\n  ],\n"
      << s.camera << kLpv << "}\n";
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

// The media. Values per mm; none of them is one of the calibration's eleven measured
// materials, and their albedos span 0.55-0.995.
const Medium kSkinLike{{1.1f, 0.95f, 0.8f}, {0.09f, 0.40f, 1.10f}, 0.0f};      // thin absorbing layer
const Medium kClearCore{{1.55f, 1.60f, 1.70f}, {0.008f, 0.012f, 0.020f}, 0.0f};  // ~5 mfp in 3 mm
const Medium kDarkBase{{2.5f, 2.2f, 2.0f}, {0.6f, 1.4f, 2.2f}, 0.0f};           // absorbing substrate
const Medium kWax{{0.9f, 0.95f, 1.0f}, {0.004f, 0.010f, 0.035f}, 0.2f};        // translucent top

void twoLayerBacklit(const fs::path& dir) {
  // 4 mm slab: a 0.9 mm absorbing layer (z > 1.1) over a 3.1 mm translucent core, lit from
  // behind through the core, seen from the absorbing side.
  writeMaterialSet(dir / "layers2_backlit.vdb", 0.1f, {-8.05f, -8.05f, 1.1f}, {8.05f, 8.05f, 2.05f},
                   [](const glm::vec3& p) -> std::optional<Medium> {
                     return p.z > 1.1f ? std::optional<Medium>(kSkinLike) : std::nullopt;
                   });
  writeScene(dir / "layers2_backlit.json",
             {"{\"primitive\": \"box\", \"min\": [-8, -8, -2], \"max\": [8, 8, 2]}", "", baseJson(kClearCore),
              "layers2_backlit.vdb",
              "{\"type\": \"directional\", \"direction\": [0.2, -0.15, 0.968], \"irradiance\": [4, 4, 4]}",
              camera({14.0f, 9.0f, 30.0f}, {0.0f, 0.0f, 0.0f}), 1.4});
}

void twoLayerFrontlit(const fs::path& dir) {
  // Translucent wax 1.5 mm thick over an absorbing substrate, lit from the front: the
  // substrate shows through the wax as a darker, redder tone.
  writeMaterialSet(dir / "layers2_frontlit.vdb", 0.1f, {-8.05f, -8.05f, 0.45f}, {8.05f, 8.05f, 2.05f},
                   [](const glm::vec3& p) -> std::optional<Medium> {
                     return p.z > 0.5f ? std::optional<Medium>(kWax) : std::nullopt;
                   });
  writeScene(dir / "layers2_frontlit.json",
             {"{\"primitive\": \"box\", \"min\": [-8, -8, -2], \"max\": [8, 8, 2]}", "", baseJson(kDarkBase),
              "layers2_frontlit.vdb",
              "{\"type\": \"spot\", \"position\": [-20, 25, 40], \"direction\": [0.381, -0.476, -0.793], "
              "\"fov_deg\": 40, \"intensity\": [9000, 9000, 9000]}",
              camera({10.0f, 6.0f, 32.0f}, {0.0f, 0.0f, 0.0f}), 1.45});
}

void threeLayerTilted(const fs::path& dir) {
  // Absorbing / translucent / absorbing (0.6 / 2.2 / 1.2 mm), rotated against the grid so
  // that its faces cross cell layers; a point light grazes the top face.
  writeMaterialSet(dir / "layers3_tilted.vdb", 0.1f, {-7.05f, -7.05f, -2.05f}, {7.05f, 7.05f, 2.05f},
                   [](const glm::vec3& p) -> std::optional<Medium> {
                     if (p.z > 1.4f) return kSkinLike;
                     if (p.z < -0.8f) return kDarkBase;
                     return std::nullopt;
                   });
  writeScene(dir / "layers3_tilted.json",
             {"{\"primitive\": \"box\", \"min\": [-7, -7, -2], \"max\": [7, 7, 2]}",
              "{\"rotate_deg\": [-23, 11, 7]}", baseJson(kClearCore), "layers3_tilted.vdb",
              "{\"type\": \"point\", \"position\": [-25, 30, 25], \"intensity\": [14000, 13500, 13000]}",
              camera({6.0f, 16.0f, 30.0f}, {0.0f, 0.0f, 0.0f}), 1.4});
}

void veinedBlock(const fs::path& dir) {
  // A 10 mm cube of pale stone with smooth low-albedo veins (σa ×9, σs' ×1.6, shifted to
  // green-brown), a point light at the upper front corner.
  const Medium stone{{1.9f, 2.0f, 2.1f}, {0.015f, 0.02f, 0.04f}, 0.0f};
  const Medium vein{{3.0f, 3.2f, 3.4f}, {0.12f, 0.16f, 0.45f}, 0.0f};
  writeMaterialSet(dir / "veins_block.vdb", 0.1f, glm::vec3(-5.05f), glm::vec3(5.05f),
                   [&](const glm::vec3& p) -> std::optional<Medium> {
                     const float warp = 1.6f * smoothNoise(p * 0.35f, 7u);
                     const float band = std::abs(std::sin(0.9f * (p.x + 0.6f * p.y - 0.3f * p.z) + warp));
                     const float v = glm::clamp((0.28f - band) / 0.18f, 0.0f, 1.0f);
                     if (v <= 0.0f) return std::nullopt;
                     return mix(stone, vein, v * v * (3.0f - 2.0f * v));
                   });
  writeScene(dir / "veins_block.json",
             {"{\"primitive\": \"box\", \"min\": [-5, -5, -5], \"max\": [5, 5, 5]}", "", baseJson(stone),
              "veins_block.vdb", "{\"type\": \"point\", \"position\": [-14, 18, 22], \"intensity\": [9000, 9000, 9000]}",
              camera({17.0f, 13.0f, 24.0f}, {0.0f, 0.0f, 0.0f}), 1.5});
}

void inclusionsSphere(const fs::path& dir) {
  // A forward-scattering sphere (g = 0.5) with an absorbing inclusion and a nearly clear
  // one, each ~1.5 mm under the surface on the lit side; spot light.
  const Medium body{{1.2f, 1.3f, 1.45f}, {0.01f, 0.03f, 0.07f}, 0.5f};
  const Medium absorbing{{1.0f, 1.0f, 1.0f}, {0.9f, 0.6f, 0.3f}, 0.5f};
  const Medium clear{{0.05f, 0.05f, 0.05f}, {0.002f, 0.002f, 0.004f}, 0.0f};
  writeMaterialSet(dir / "inclusions_sphere.vdb", 0.1f, glm::vec3(-8.05f), glm::vec3(8.05f),
                   [&](const glm::vec3& p) -> std::optional<Medium> {
                     if (glm::length(p - glm::vec3(2.5f, 2.0f, 3.5f)) < 2.2f) return absorbing;
                     if (glm::length(p - glm::vec3(-3.0f, -1.0f, 3.0f)) < 2.6f) return clear;
                     return std::nullopt;
                   });
  writeScene(dir / "inclusions_sphere.json",
             {"{\"primitive\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 8}", "", baseJson(body),
              "inclusions_sphere.vdb",
              "{\"type\": \"spot\", \"position\": [-18, 22, 30], \"direction\": [0.43, -0.52, -0.74], "
              "\"fov_deg\": 35, \"intensity\": [12000, 12000, 12000]}",
              camera({0.0f, 6.0f, 30.0f}, {0.0f, 0.0f, 0.0f}), 1.4});
}

void thinPlate(const fs::path& dir) {
  // A 1.6 mm plate of 2.4-4.8 mean free paths (scattering rising across it), back-lit at
  // an angle: most of what the camera sees crossed the plate once or twice.
  const Medium thin{{1.5f, 1.6f, 1.8f}, {0.03f, 0.06f, 0.12f}, 0.2f};
  writeMaterialSet(dir / "thin_plate.vdb", 0.1f, {-10.05f, -10.05f, -0.85f}, {10.05f, 10.05f, 0.85f},
                   [&](const glm::vec3& p) -> std::optional<Medium> {
                     const float t = glm::clamp((p.x + 10.0f) / 20.0f, 0.0f, 1.0f);
                     Medium m = thin;
                     m.sigmaSPrime *= 1.0f + t;
                     return m;
                   });
  writeScene(dir / "thin_plate.json",
             {"{\"primitive\": \"box\", \"min\": [-10, -10, -0.8], \"max\": [10, 10, 0.8]}", "", baseJson(thin),
              "thin_plate.vdb",
              "{\"type\": \"directional\", \"direction\": [-0.3, -0.2, 0.933], \"irradiance\": [3, 3, 3]}",
              camera({9.0f, 7.0f, 34.0f}, {0.0f, 0.0f, 0.0f}), 1.33});
}

void paintedStrokes(const fs::path& dir) {
  // A marble sphere an artist painted with `sslpv paint`: a ketchup band across the lit
  // side and a darker absorbing blot. scripts/hetero-suite.sh paints painted_strokes.vdb
  // from the unpainted scene (which names no material set yet) and the stroke file.
  SceneText scene{"{\"primitive\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 9}", "",
                  "{\"preset\": \"marble\"}", "",
                  "{\"type\": \"point\", \"position\": [-20, 20, 28], \"intensity\": [11000, 11000, 11000]}",
                  camera({4.0f, 4.0f, 32.0f}, {0.0f, 0.0f, 0.0f}), 1.5};
  writeScene(dir / "painted_strokes.unpainted.json", scene);
  scene.vdb = "painted_strokes.vdb";
  writeScene(dir / "painted_strokes.json", scene);
  std::ofstream strokes(dir / "painted_strokes.strokes.json", std::ios::binary);
  strokes << "{\"strokes\": [\n"
             "  {\"channel\": \"preset\", \"mode\": \"set\", \"value\": \"ketchup\", \"radius\": 2.2,\n"
             "   \"points\": [[-7, 3, 4.5], [-4, 3.8, 7.2], [0, 4, 8], [4, 3.6, 7.3], [7, 2.8, 4.9]]},\n"
             "  {\"channel\": \"sigma_t\", \"mode\": \"add\", \"value\": [0.4, 0.5, 0.7], \"radius\": 2.5,\n"
             "   \"points\": [[-2, -4, 7.6]]}\n"
             "]}\n";
  if (!strokes) throw std::runtime_error("cannot write the stroke file");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: hetero_scenes OUTPUT_DIR\n";
    return 2;
  }
  try {
    const fs::path dir = argv[1];
    fs::create_directories(dir);
    twoLayerBacklit(dir);
    twoLayerFrontlit(dir);
    threeLayerTilted(dir);
    veinedBlock(dir);
    inclusionsSphere(dir);
    thinPlate(dir);
    paintedStrokes(dir);
    std::cout << "hetero_scenes: wrote 7 scenes to " << dir.string() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "hetero_scenes: " << e.what() << "\n";
    return 1;
  }
}

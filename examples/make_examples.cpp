// Regenerates every shipped example asset (meshes, VDB material sets, scene JSON files)
// deterministically into the folder given as argv[1]:
//
//   build/examples/make_examples examples
//
// The outputs are committed; this program documents how they were made. Everything is
// derived from fixed constants and an integer-hash value noise, so two runs produce
// byte-identical meshes and scenes (and identical voxel data).
#include <openvdb/openvdb.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "volume/material/material_set.h"

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------
// Deterministic value noise. std::rand and <random> distributions are not guaranteed to
// produce the same numbers across standard libraries, so the lattice values come from an
// integer hash instead.

float latticeValue(int x, int y, int z, std::uint32_t seed) {
  std::uint32_t h = seed;
  for (std::uint32_t v : {static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                          static_cast<std::uint32_t>(z)}) {
    h ^= v + 0x9e3779b9u + (h << 6) + (h >> 2);
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
  }
  return static_cast<float>(h & 0xffffffu) / static_cast<float>(0xffffff) * 2.0f - 1.0f;
}

float quintic(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

/// Smooth (C2) value noise in [-1, 1].
float valueNoise(const glm::vec3& p, std::uint32_t seed) {
  const glm::vec3 cell(std::floor(p.x), std::floor(p.y), std::floor(p.z));
  const glm::vec3 f = p - cell;
  const int x0 = static_cast<int>(cell.x), y0 = static_cast<int>(cell.y),
            z0 = static_cast<int>(cell.z);
  const float u = quintic(f.x), v = quintic(f.y), w = quintic(f.z);
  float result = 0.0f;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const float weight = (dx ? u : 1.0f - u) * (dy ? v : 1.0f - v) * (dz ? w : 1.0f - w);
        result += weight * latticeValue(x0 + dx, y0 + dy, z0 + dz, seed);
      }
  return result;
}

/// Sum of |noise| octaves: the classic "turbulence" that bends marble veins.
float turbulence(const glm::vec3& p, int octaves, std::uint32_t seed) {
  float sum = 0.0f, amplitude = 1.0f, frequency = 1.0f;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * std::abs(valueNoise(p * frequency, seed + static_cast<std::uint32_t>(i)));
    amplitude *= 0.5f;
    frequency *= 2.03f;  // not exactly 2, so octave lattices do not line up
  }
  return sum;
}

float smoothstep(float edge0, float edge1, float x) {
  const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// ---------------------------------------------------------------------------------------
// The pebble: a radially displaced sphere, then scaled to the target extent. Being
// star-shaped about its centre lets the material generator test "inside" analytically.

constexpr std::uint32_t kPebbleSeed = 1234u;
constexpr glm::vec3 kPebbleExtentMm{40.0f, 28.0f, 30.0f};
/// Frequency of the geodesic subdivision: 20 * n^2 triangles (n = 24 gives 11520).
constexpr int kPebbleSubdivision = 24;

/// Radius of the unit pebble along unit direction `dir`: low-frequency noise only, so
/// the surface stays smooth and the shape stays star-shaped (radius well above zero).
float pebbleRadius(const glm::vec3& dir) {
  const float lumps = 0.14f * valueNoise(dir * 1.3f + glm::vec3(3.1f, 7.7f, 1.9f), kPebbleSeed) +
                      0.05f * valueNoise(dir * 2.6f + glm::vec3(-4.2f, 0.6f, 5.3f),
                                         kPebbleSeed + 1u);
  return 1.0f + lumps;
}

/// Maps the displaced unit pebble onto the target extent, centred at the origin.
struct PebbleFrame {
  glm::vec3 scale{1.0f};
  glm::vec3 offset{0.0f};  ///< subtracted after scaling
  glm::vec3 toWorld(const glm::vec3& unit) const { return unit * scale - offset; }
  glm::vec3 toUnit(const glm::vec3& world) const { return (world + offset) / scale; }
};

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

/// Icosahedron with outward, counter-clockwise faces.
Mesh icosahedron() {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  Mesh m;
  m.positions = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : m.positions) p = glm::normalize(p);
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  return m;
}

/// Geodesic subdivision of frequency n, projected onto the unit sphere. A point is
/// identified by its integer barycentric weights on the base vertices (zero weights
/// dropped, sorted by vertex), so points on shared edges get one index and one bitwise
/// identical position, whichever face produced them: the result is welded.
Mesh geodesicSphere(int n) {
  const Mesh base = icosahedron();
  using Key = std::vector<std::pair<int, int>>;
  std::map<Key, int> indexOf;
  Mesh out;
  auto vertex = [&](std::array<std::pair<int, int>, 3> weights) {
    Key key;
    for (const auto& w : weights)
      if (w.second > 0) key.push_back(w);
    std::sort(key.begin(), key.end());
    auto found = indexOf.find(key);
    if (found != indexOf.end()) return found->second;
    glm::dvec3 p(0.0);
    for (const auto& [vertexIndex, weight] : key)
      p += glm::dvec3(base.positions[vertexIndex]) * static_cast<double>(weight);
    out.positions.push_back(glm::vec3(glm::normalize(p)));
    const int index = static_cast<int>(out.positions.size()) - 1;
    indexOf.emplace(std::move(key), index);
    return index;
  };
  for (const auto& tri : base.triangles) {
    // Grid point (i, j) of the face: weight i on tri[1], j on tri[2], the rest on tri[0].
    auto at = [&](int i, int j) {
      return vertex({{{tri[0], n - i - j}, {tri[1], i}, {tri[2], j}}});
    };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        out.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j + 1 < n) out.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  return out;
}

/// Every edge must be used exactly twice, once in each direction (closed, consistently
/// oriented); the enclosed volume must be positive (outward facing).
void requireWatertight(const Mesh& mesh, const std::string& name) {
  std::map<std::pair<int, int>, int> directedUses;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++directedUses[{t[e], t[(e + 1) % 3]}];
  for (const auto& [edge, uses] : directedUses) {
    const auto reverse = directedUses.find({edge.second, edge.first});
    if (uses != 1 || reverse == directedUses.end() || reverse->second != 1)
      throw std::runtime_error(name + ": edge " + std::to_string(edge.first) + "-" +
                               std::to_string(edge.second) + " is not shared by exactly two "
                               "consistently oriented triangles");
  }
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
    volume += glm::dot(glm::dvec3(mesh.positions[t[0]]),
                       glm::cross(glm::dvec3(mesh.positions[t[1]]),
                                  glm::dvec3(mesh.positions[t[2]]))) / 6.0;
  if (!(volume > 0.0)) throw std::runtime_error(name + ": enclosed volume is not positive");
}

Mesh makePebble(PebbleFrame& frame) {
  Mesh mesh = geodesicSphere(kPebbleSubdivision);
  for (auto& p : mesh.positions) p *= pebbleRadius(p);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const auto& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  frame.scale = kPebbleExtentMm / (hi - lo);
  frame.offset = (lo + hi) * 0.5f * frame.scale;
  for (auto& p : mesh.positions) p = frame.toWorld(p);
  return mesh;
}

/// Inside the smooth pebble surface, grown by `marginMm` (approximately: the margin is
/// applied along the radial direction of the unit pebble).
bool insidePebble(const PebbleFrame& frame, const glm::vec3& world, float marginMm) {
  const glm::vec3 unit = frame.toUnit(world);
  const float r = glm::length(unit);
  if (r < 1e-6f) return true;
  const float meanScale = (frame.scale.x + frame.scale.y + frame.scale.z) / 3.0f;
  return r <= pebbleRadius(unit / r) + marginMm / meanScale;
}

void writeObj(const Mesh& mesh, const fs::path& file, const std::string& comment) {
  std::ofstream out(file, std::ios::binary);
  out << "# " << comment << "\n# units: mm, generated by sslpv make_examples\n";
  char line[96];
  for (const auto& p : mesh.positions) {
    std::snprintf(line, sizeof line, "v %.4f %.4f %.4f\n", p.x, p.y, p.z);
    out << line;
  }
  for (const auto& t : mesh.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

// ---------------------------------------------------------------------------------------
// The marble veins material set.

/// Optical properties in reduced form; sigma_s = sigma_s' / (1 - g), sigma_t = sigma_s + sigma_a.
struct Reduced {
  glm::vec3 sigmaSPrime;
  glm::vec3 sigmaA;
};

// Jensen 2001 marble: the scene's base material, which every inactive voxel takes.
constexpr Reduced kMarble{{2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}};
// Veins: darker (about half the scattering, ~50-100x the absorption), absorbing least
// in green for a grey-green tint.
constexpr Reduced kVein{{1.00f, 1.20f, 1.10f}, {0.30f, 0.20f, 0.32f}};
// The warm patch: about half the scattering of marble and less red absorption, so it
// glows more and lets warm light through.
constexpr Reduced kWarmPatch{{1.05f, 1.20f, 1.35f}, {0.0012f, 0.0040f, 0.0140f}};

constexpr float kVoxelSizeMm = 0.8f;
constexpr std::uint32_t kVeinSeed = 777u;

/// 1 at the core of a vein sheet, falling smoothly to 0 at its edges.
float veinWeight(const glm::vec3& p) {
  // Sheets are the level sets sin(phase) = 1 of a phase that increases along a tilted
  // axis and is bent by turbulence; thickness comes from how close to 1 sin must be.
  const glm::vec3 axis = glm::normalize(glm::vec3(0.8f, 0.45f, 0.4f));
  const float period = 14.0f;
  const float phase = 2.0f * 3.14159265f * glm::dot(p, axis) / period +
                      2.6f * turbulence(p * (1.0f / 11.0f), 4, kVeinSeed);
  const float main = smoothstep(0.90f, 1.0f, std::sin(phase));
  // Fainter, thinner secondary veins crossing the main ones.
  const glm::vec3 axis2 = glm::normalize(glm::vec3(-0.3f, 0.9f, -0.5f));
  const float phase2 = 2.0f * 3.14159265f * glm::dot(p, axis2) / 23.0f +
                       2.5f * turbulence(p * (1.0f / 9.0f) + glm::vec3(5.0f), 3, kVeinSeed + 10u);
  const float secondary = 0.6f * smoothstep(0.96f, 1.0f, std::sin(phase2));
  return std::max(main, secondary);
}

/// 1 in the centre of the warm patch, 0 outside it; a noisy ellipsoid on one flank.
float warmPatchWeight(const glm::vec3& p) {
  const glm::vec3 centre(9.0f, 5.0f, 7.0f), radii(9.0f, 7.0f, 7.5f);
  const float d = glm::length((p - centre) / radii) +
                  0.25f * valueNoise(p * (1.0f / 5.0f), kVeinSeed + 20u);
  return 1.0f - smoothstep(0.55f, 1.0f, d);
}

glm::vec3 mix(const glm::vec3& a, const glm::vec3& b, float t) { return a + (b - a) * t; }

openvdb::Vec3s toVdb(const glm::vec3& v) { return openvdb::Vec3s(v.x, v.y, v.z); }

struct MaterialCounts {
  std::size_t veinVoxels = 0, patchVoxels = 0;
};

MaterialCounts writeMarbleVeins(const PebbleFrame& frame, const fs::path& file) {
  auto transform = openvdb::math::Transform::createLinearTransform(kVoxelSizeMm);
  auto sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  auto sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  auto g = openvdb::FloatGrid::create(0.0f);
  auto tSigmaT = sigmaT->getAccessor();
  auto tSigmaS = sigmaS->getAccessor();
  auto tG = g->getAccessor();

  MaterialCounts counts;
  const glm::vec3 half = kPebbleExtentMm * 0.5f + glm::vec3(2.0f);
  const openvdb::Coord lo(static_cast<int>(std::floor(-half.x / kVoxelSizeMm)),
                          static_cast<int>(std::floor(-half.y / kVoxelSizeMm)),
                          static_cast<int>(std::floor(-half.z / kVoxelSizeMm)));
  const openvdb::Coord hi = -lo;
  for (int k = lo.z(); k <= hi.z(); ++k)
    for (int j = lo.y(); j <= hi.y(); ++j)
      for (int i = lo.x(); i <= hi.x(); ++i) {
        const glm::vec3 p = glm::vec3(i, j, k) * kVoxelSizeMm;  // voxel centre, rest space
        // One voxel of margin outside the surface, so trilinear lookups just inside the
        // mesh still see the painted value rather than a blend towards the base.
        if (!insidePebble(frame, p, kVoxelSizeMm)) continue;
        const float vein = veinWeight(p);
        const float patch = warmPatchWeight(p);
        if (vein <= 0.0f && patch <= 0.0f) continue;  // stays inactive: base marble
        const glm::vec3 sPrime = mix(mix(kMarble.sigmaSPrime, kWarmPatch.sigmaSPrime, patch),
                                     kVein.sigmaSPrime, vein);
        const glm::vec3 sA = mix(mix(kMarble.sigmaA, kWarmPatch.sigmaA, patch), kVein.sigmaA, vein);
        // Mild forward scattering inside veins only; sigma_s is raised with g so that the
        // reduced scattering sigma_s' stays what was painted.
        float asymmetry = 0.0f;
        if (vein > 0.0f) {
          asymmetry = 0.2f + 0.3f * vein;
          tG.setValue(openvdb::Coord(i, j, k), asymmetry);
          ++counts.veinVoxels;
        } else {
          ++counts.patchVoxels;
        }
        const glm::vec3 s = sPrime / (1.0f - asymmetry);
        tSigmaS.setValue(openvdb::Coord(i, j, k), toVdb(s));
        tSigmaT.setValue(openvdb::Coord(i, j, k), toVdb(s + sA));
      }

  openvdb::GridPtrVec grids;
  auto name = [&](openvdb::GridBase::Ptr grid, const char* gridName, openvdb::GridClass cls) {
    grid->setName(gridName);
    grid->setGridClass(cls);
    grid->setTransform(transform->copy());
    grid->insertMeta("units", openvdb::StringMetadata("mm"));
    grids.push_back(grid);
  };
  sigmaT->setVectorType(openvdb::VEC_INVARIANT);
  sigmaS->setVectorType(openvdb::VEC_INVARIANT);
  name(sigmaT, "sigma_t", openvdb::GRID_FOG_VOLUME);
  name(sigmaS, "sigma_s", openvdb::GRID_FOG_VOLUME);
  name(g, "g", openvdb::GRID_UNKNOWN);

  openvdb::MetaMap fileMeta;
  fileMeta.insertMeta("units", openvdb::StringMetadata("mm"));
  fileMeta.insertMeta("creator", openvdb::StringMetadata("sslpv make_examples"));
  fileMeta.insertMeta("version", openvdb::StringMetadata("1"));
  openvdb::io::File out(file.string());
  out.write(grids, fileMeta);
  out.close();
  return counts;
}

// ---------------------------------------------------------------------------------------
// Scenes. Written as text (not through a JSON library) so the files keep a readable,
// stable layout; directions are normalised here so the files hold unit vectors.

std::string vec(const glm::dvec3& v, int decimals = 4) {
  // Round first so a tiny negative never prints as "-0.0000" in a hand-edited file.
  const double unit = std::pow(10.0, decimals);
  auto rounded = [&](double x) { return std::round(x * unit) / unit + 0.0; };
  char buffer[128];
  std::snprintf(buffer, sizeof buffer, "[%.*f, %.*f, %.*f]", decimals, rounded(v.x), decimals,
                rounded(v.y), decimals, rounded(v.z));
  return buffer;
}

std::string unitVec(const glm::dvec3& v) { return vec(glm::normalize(v), 6); }

std::string camera(const glm::dvec3& position, const glm::dvec3& target, double fovYDeg) {
  std::ostringstream s;
  s << "  \"camera\": {\"position\": " << vec(position, 1) << ", \"target\": " << vec(target, 1)
    << ", \"up\": [0, 1, 0],\n             \"fov_y_deg\": " << fovYDeg
    << ", \"width\": 512, \"height\": 512},\n";
  return s.str();
}

std::string pointLight(const glm::dvec3& position, const glm::dvec3& intensity) {
  return "    {\"type\": \"point\", \"position\": " + vec(position, 1) +
         ", \"intensity\": " + vec(intensity, 0) + "}";
}

std::string spotLight(const glm::dvec3& position, const glm::dvec3& target, double fovDeg,
                      const glm::dvec3& intensity) {
  std::ostringstream s;
  s << "    {\"type\": \"spot\", \"position\": " << vec(position, 1)
    << ", \"direction\": " << unitVec(target - position) << ",\n     \"fov_deg\": " << fovDeg
    << ", \"intensity\": " << vec(intensity, 0) << "}";
  return s.str();
}

std::string directionalLight(const glm::dvec3& direction, const glm::dvec3& irradiance) {
  return "    {\"type\": \"directional\", \"direction\": " + unitVec(direction) +
         ", \"irradiance\": " + vec(irradiance, 2) + "}";
}

// The calibrated scheme needs its steps to converge (8 steps give a fraction of the
// right brightness at 64³), so the shipped scenes ask for --steps auto.
std::string lpv(int resolution, int shadowMap) {
  return "  \"lpv\": {\"resolution\": " + std::to_string(resolution) +
         ", \"steps\": \"auto\", \"shadow_map\": " + std::to_string(shadowMap) + "}\n";
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

// Light intensities: a white Lambertian plane at distance d under intensity I has
// radiance I / (pi d^2) (mm units), so I ~ 15000 W/sr at ~100 mm gives ~0.5; a
// directional irradiance E gives E / pi. Values aim for rendered radiance ~0.05-1.

std::string marblePebbleScene() {
  // Spot grazing from the upper left; a weaker, cooler point light behind-right so the
  // thin rim of the pebble glows through.
  return std::string("{\n") +
         "  \"units\": \"mm\",\n"
         "  \"mesh\": {\"path\": \"pebble.obj\"},\n"
         "  \"material\": {\"base\": {\"preset\": \"marble\"}, \"vdb\": \"marble_veins.vdb\", "
         "\"ior\": 1.5},\n"
         "  \"lights\": [\n" +
         spotLight({-105.0, 65.0, 25.0}, {0.0, 0.0, 0.0}, 40.0, {30000.0, 28500.0, 26000.0}) +
         ",\n" + pointLight({70.0, 15.0, -90.0}, {7000.0, 7500.0, 8000.0}) + "\n  ],\n" +
         camera({0.0, 35.0, 85.0}, {0.0, 0.0, 0.0}, 35.0) + lpv(32, 256) + "}\n";
}

std::string jadeSlabScene() {
  // A 4 mm slab seen from the front; the only light travels from behind through it
  // towards the camera side, so everything visible has crossed the slab.
  return std::string("{\n") +
         "  \"units\": \"mm\",\n"
         "  \"mesh\": {\"primitive\": \"box\", \"min\": [-20, -20, -2], \"max\": [20, 20, 2]},\n"
         "  \"material\": {\"base\": {\"sigma_t\": [1.0, 1.025, 0.85], "
         "\"sigma_s\": [0.8, 1.0, 0.7], \"g\": 0.0},\n"
         "               \"ior\": 1.5},\n"
         "  \"lights\": [\n" +
         directionalLight({0.25, -0.15, 1.0}, {4.0, 4.0, 4.0}) + "\n  ],\n" +
         camera({35.0, 22.0, 75.0}, {0.0, 0.0, 0.0}, 35.0) + lpv(64, 256) + "}\n";
}

std::string skinSphereScene() {
  return std::string("{\n") +
         "  \"units\": \"mm\",\n"
         "  \"mesh\": {\"primitive\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 15},\n"
         "  \"material\": {\"base\": {\"preset\": \"skin1\"}, \"ior\": 1.4},\n"
         "  \"lights\": [\n" +
         spotLight({-60.0, 60.0, 50.0}, {0.0, 0.0, 0.0}, 30.0, {16000.0, 15500.0, 15000.0}) +
         ",\n" + pointLight({40.0, -10.0, -50.0}, {5000.0, 4800.0, 4500.0}) + "\n  ],\n" +
         camera({0.0, 15.0, 63.0}, {0.0, 0.0, 0.0}, 35.0) + lpv(32, 256) + "}\n";
}

std::string ketchupBoxScene() {
  return std::string("{\n") +
         "  \"units\": \"mm\",\n"
         "  \"mesh\": {\"primitive\": \"box\", \"min\": [-15, -10, -12], \"max\": [15, 10, 12]},\n"
         "  \"transform\": {\"translate\": [0, 5, 0], \"rotate_deg\": [0, 30, 0], \"scale\": 1},\n"
         "  \"material\": {\"base\": {\"preset\": \"ketchup\"}, \"ior\": 1.3},\n"
         "  \"lights\": [\n" +
         directionalLight({0.3, -1.0, -0.4}, {4.0, 4.0, 4.0}) + ",\n" +
         pointLight({-50.0, 30.0, 60.0}, {10000.0, 10000.0, 10000.0}) + "\n  ],\n" +
         camera({40.0, 45.0, 75.0}, {0.0, 5.0, 0.0}, 35.0) + lpv(32, 256) + "}\n";
}

// The bending bar: a 40 x 8 x 8 mm bar along x whose far end carries a painted stripe,
// bent up a quarter turn about its left end and back over t in [0, 1] (the scene's
// "deformers"). The stripe lives in the bar's rest space, so it must ride up with the end.
constexpr double kStripeVoxelMm = 0.5;

std::size_t writeBarStripe(const fs::path& file) {
  auto set = std::make_shared<sslpv::MaterialSet>();
  set->sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaT->setName("sigma_t");
  set->sigmaS->setName("sigma_s");
  for (auto& grid : {set->sigmaT, set->sigmaS}) {
    grid->setTransform(openvdb::math::Transform::createLinearTransform(kStripeVoxelMm));
    grid->setVectorType(openvdb::VEC_INVARIANT);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  }
  set->units = "mm";
  set->creator = "sslpv make_examples";
  auto t = set->sigmaT->getAccessor();
  auto s = set->sigmaS->getAccessor();
  std::size_t voxels = 0;
  // x from 10 to 15 mm, one voxel beyond the bar's 8 x 8 mm cross section on each side so
  // trilinear lookups just inside the surface read the stripe, not a blend to the base.
  for (int i = 20; i <= 30; ++i)
    for (int j = -9; j <= 9; ++j)
      for (int k = -9; k <= 9; ++k) {
        // A dark wine-red band: strongly absorbing in green and blue, still scattering.
        t.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(3.0f, 9.0f, 10.0f));
        s.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(2.4f, 1.2f, 1.0f));
        ++voxels;
      }
  sslpv::saveMaterialSet(*set, file);
  return voxels;
}

std::string bendingBarScene() {
  return std::string("{\n") +
         "  \"units\": \"mm\",\n"
         "  \"mesh\": {\"primitive\": \"box\", \"min\": [-20, -4, -4], \"max\": [20, 4, 4], "
         "\"segments\": [40, 4, 4]},\n"
         "  \"material\": {\"base\": {\"preset\": \"skimmilk\"}, \"vdb\": \"bending_bar_stripe.vdb\", "
         "\"ior\": 1.3},\n"
         "  \"deformers\": [\n"
         "    {\"type\": \"bend\", \"axis\": \"x\", \"toward\": \"y\", \"center\": [-20, 0, 0], \"length\": 40,\n"
         "     \"angle\": [{\"t\": 0, \"value\": 0}, {\"t\": 0.5, \"value\": 90, \"ease\": \"smoothstep\"},\n"
         "               {\"t\": 1, \"value\": 0, \"ease\": \"smoothstep\"}]}\n"
         "  ],\n"
         "  \"lights\": [\n" +
         spotLight({-60.0, 70.0, 60.0}, {0.0, 5.0, 0.0}, 40.0, {16000.0, 15500.0, 15000.0}) + ",\n" +
         pointLight({30.0, 10.0, -50.0}, {5000.0, 5000.0, 5000.0}) + "\n  ],\n" +
         camera({0.0, 14.0, 100.0}, {-2.0, 10.0, 0.0}, 40.0) + lpv(32, 256) + "}\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_examples OUTPUT_DIR   (e.g. build/examples/make_examples examples)\n";
    return 2;
  }
  try {
    const fs::path dir = argv[1];
    fs::create_directories(dir);
    openvdb::initialize();

    PebbleFrame frame;
    const Mesh pebble = makePebble(frame);
    requireWatertight(pebble, "pebble.obj");
    writeObj(pebble, dir / "pebble.obj",
             "pebble: closed, welded, counter-clockwise outward; about 40 x 28 x 30 mm");
    const MaterialCounts counts = writeMarbleVeins(frame, dir / "marble_veins.vdb");

    writeText(dir / "marble_pebble.json", marblePebbleScene());
    writeText(dir / "jade_slab_backlit.json", jadeSlabScene());
    writeText(dir / "skin_sphere.json", skinSphereScene());
    writeText(dir / "ketchup_box.json", ketchupBoxScene());
    const std::size_t stripeVoxels = writeBarStripe(dir / "bending_bar_stripe.vdb");
    writeText(dir / "bending_bar.json", bendingBarScene());

    std::cout << "make_examples: wrote " << dir.string() << ": pebble.obj ("
              << pebble.positions.size() << " vertices, " << pebble.triangles.size()
              << " triangles), marble_veins.vdb (" << counts.veinVoxels << " vein voxels, "
              << counts.patchVoxels << " warm-patch voxels), bending_bar_stripe.vdb (" << stripeVoxels
              << " stripe voxels), 5 scenes\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "make_examples: error: " << e.what() << "\n";
    return 1;
  }
}

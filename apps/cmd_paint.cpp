#include "apps/cmd_paint.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <vector>
#include <glm/geometric.hpp>

#include "apps/cli_output.h"
#include "editor/brush_engine.h"
#include "editor/stroke_io.h"
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"
#include "volume/scene/scene_checks.h"
#include "volume/scene/scene_file_edit.h"
#include "volume/core/strict_json.h"

namespace sslpv {
namespace {

/// Squared distance from `p` to the triangle (a, b, c): the closest point by the region
/// of the triangle's plane p projects into (Ericson, Real-Time Collision Detection 5.1.5).
double squaredDistanceToTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                 const glm::dvec3& c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  auto sq = [&](const glm::dvec3& q) { return glm::dot(p - q, p - q); };
  if (d1 <= 0 && d2 <= 0) return sq(a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return sq(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return sq(a + ab * (d1 / (d1 - d3)));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return sq(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return sq(a + ac * (d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return sq(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1.0 / (va + vb + vc);
  return sq(a + ab * (vb * denom) + ac * (vc * denom));
}

/// True when a dab of `radius` at `p` overlaps the object: `p` inside it or within
/// `radius` of its surface.
bool dabTouchesObject(const TriangleMesh& mesh, MeshInsideTest& inside, const glm::dvec3& p, double radius) {
  const double r2 = radius * radius;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
    // The triangle's box grown by the radius: most triangles are rejected here.
    const glm::dvec3 lo = glm::min(a, glm::min(b, c)) - radius, hi = glm::max(a, glm::max(b, c)) + radius;
    if (glm::any(glm::lessThan(p, lo)) || glm::any(glm::greaterThan(p, hi))) continue;
    if (squaredDistanceToTriangle(p, a, b, c) <= r2) return true;
  }
  return inside(p);
}

std::string pointText(const glm::dvec3& p) {
  return "(" + formatNumber(p.x) + ", " + formatNumber(p.y) + ", " + formatNumber(p.z) + ")";
}

/// Warnings for the parts of stroke `index` that paint nothing the object shows: dabs
/// clear of the object (their voxels lie outside it) and rays that miss it.
void warnAboutStroke(const std::string& strokes, std::size_t index, const Stroke& stroke, const StrokeResult& result,
                     const TriangleMesh* mesh) {
  const std::string key = strokes + ": " + indexPath("strokes", index);
  if (mesh) {
    MeshInsideTest inside(*mesh);
    std::size_t clear = 0, first = 0;
    for (std::size_t i = 0; i < stroke.points.size(); ++i)
      if (!dabTouchesObject(*mesh, inside, stroke.points[i], stroke.brush.radius) && clear++ == 0) first = i;
    if (clear > 0)
      printWarning(key + ".points: " + std::to_string(clear) + " of " + std::to_string(stroke.points.size()) +
                   " points are farther than the brush radius (" + formatNumber(stroke.brush.radius) +
                   ") from the object and paint voxels it does not show (the first: points[" + std::to_string(first) +
                   "] " + pointText(stroke.points[first]) + ")");
  }
  if (result.raysMissed > 0)
    printWarning(key + ".rays: " + std::to_string(result.raysMissed) + " of " + std::to_string(stroke.rays.size()) +
                 " rays missed the object and painted nothing");
  if (result.voxelsChanged == 0) printWarning(key + ": changed no voxel");
}

}  // namespace

CLI::App* addPaintCommand(CLI::App& app, PaintArgs& args) {
  CLI::App* cmd = app.add_subcommand("paint", "Apply brush strokes (JSON) to a scene's material set, write a VDB");
  cmd->add_option("scene", args.scene, "Scene JSON file")->required();
  cmd->add_option("--strokes", args.strokes, "Stroke JSON file (format: README, editor/stroke_io.h)")->required();
  cmd->add_option("-o,--output", args.output, "Output material set (.vdb)")->required();
  cmd->add_option("--colour,--color", args.colour,
                  "Surface colour (linear diffuse reflectance, R,G,B or one number) of strokes that name no material");
  cmd->add_option("--scatter-distance", args.scatterDistance,
                  "Scatter distance 1/sigma_t' (scene units, R,G,B or one number) for --colour");
  cmd->add_option("--g", args.g, "Phase asymmetry g in [-0.99, 0.99] for --colour (default 0)");
  cmd->add_flag("--update-scene", args.updateScene,
                "Also set the scene's material.vdb to the output (only that value changes in the file)");
  return cmd;
}

namespace {

/// "x" or "r,g,b": finite numbers, the whole text consumed. Throws InputError naming the flag.
glm::dvec3 parseFlagRgb(const std::string& text, const std::string& flag) {
  std::vector<double> values;
  std::size_t at = 0;
  while (true) {
    const std::size_t comma = text.find(',', at);
    const std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v) ||
        item.find_first_of(" \t") != std::string::npos)
      throw InputError(flag + ": expected one number or R,G,B, got \"" + printable(text) + "\"");
    values.push_back(v);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  if (values.size() == 1) return glm::dvec3(values[0]);
  if (values.size() != 3)
    throw InputError(flag + ": expected one number or R,G,B, got " + std::to_string(values.size()) + " numbers");
  return {values[0], values[1], values[2]};
}

/// The flags' material, checked against the scene's ior; nullopt when no flag was given.
std::optional<ArtistParams> flagMaterial(const PaintArgs& args, double ior) {
  if (args.colour.empty() && args.scatterDistance.empty() && args.g.empty()) return std::nullopt;
  if (args.colour.empty())
    throw InputError(std::string(args.scatterDistance.empty() ? "--g" : "--scatter-distance") +
                     ": needs --colour (the material of strokes that name none)");
  if (args.scatterDistance.empty()) throw InputError("--colour: needs --scatter-distance");
  ArtistParams p;
  p.colour = parseFlagRgb(args.colour, "--colour");
  p.scatterDistance = parseFlagRgb(args.scatterDistance, "--scatter-distance");
  if (!args.g.empty()) {
    const glm::dvec3 g = parseFlagRgb(args.g, "--g");
    if (!(g.x == g.y && g.y == g.z)) throw InputError("--g: expected one number, got \"" + printable(args.g) + "\"");
    p.g = g.x;
  }
  // The mapping names its keys as the stroke file spells them; the flags' spelling here.
  std::string problem = artistParamsProblem(p, ior);
  if (!problem.empty()) {
    if (problem.rfind("scatter_distance", 0) == 0) problem.replace(0, 16, "scatter-distance");
    throw InputError("--" + problem);
  }
  return p;
}

}  // namespace

int runPaint(const PaintArgs& args) {
  const auto start = CliClock::now();
  std::string ext = std::filesystem::path(args.output).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".vdb") throw InputError("-o: " + args.output + ": the output must be a .vdb file");
  requireWritableOutput(args.output);
  if (args.updateScene) requireWritableOutput(args.scene);

  const Scene scene = loadScene(args.scene);
  // Parsed before the mesh and grids load, so a typo in the strokes fails fast.
  const std::optional<ArtistParams> bare = flagMaterial(args, scene.material.ior);
  const std::vector<Stroke> strokes = loadStrokes(args.strokes, bare ? &*bare : nullptr);
  // The target's own refusals name a role ("material set: ...", "box: ..."), not the
  // scene they come from.
  auto targetFor = [&] {
    try {
      return makePaintTarget(scene);
    } catch (const InputError& e) {
      if (std::string(e.what()).rfind(args.scene + ": ", 0) == 0) throw;
      throw InputError(args.scene + ": " + e.what());
    }
  };
  PaintTarget target = targetFor();
  const std::shared_ptr<const TriangleMesh> worldMesh = target.worldMesh;
  BrushEngine engine(std::move(target));

  std::size_t changed = 0;
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    StrokeResult result;
    try {
      result = engine.applyStroke(strokes[i]);
    } catch (const InputError& e) {
      // The engine's limits (a dab too large, too many dabs) name the key, not the stroke.
      throw InputError(args.strokes + ": strokes[" + std::to_string(i) + "]." + e.what());
    }
    std::printf("stroke %zu: %zu dabs, %zu voxels changed", i, result.dabs, result.voxelsChanged);
    if (!result.worldBounds.empty()) {
      const Bounds& b = result.worldBounds;
      std::printf(", world bounds (%.6g, %.6g, %.6g) .. (%.6g, %.6g, %.6g)", b.min.x, b.min.y, b.min.z, b.max.x,
                  b.max.y, b.max.z);
    }
    if (result.raysMissed > 0)
      std::printf(", %zu of %zu rays missed the object", result.raysMissed, strokes[i].rays.size());
    std::printf("\n");
    std::fflush(stdout);
    warnAboutStroke(args.strokes, i, strokes[i], result, worldMesh.get());
    changed += result.voxelsChanged;
  }
  // A run that paints nothing is a mistake a script must notice (a stroke file for another
  // scene, rays aimed the wrong way), not a success that quietly copies the input.
  if (changed == 0)
    throw InputError(args.strokes + ": no stroke changed any voxel (see the warnings above): nothing written to " +
                     args.output);

  MaterialSet out = *engine.materialSet();
  out.creator = "sslpv paint";
  const std::string detail = std::to_string(out.sigmaT->activeVoxelCount()) + " active voxels, units " + out.units;
  if (!args.updateScene) {
    saveMaterialSet(out, args.output);
    printWrote(args.output, detail, start);
    return 0;
  }
  const std::string original = readInputFile(args.scene, "scene file");
  std::string updated = sceneTextNamingVdb(args.scene, original, args.output);
  writeAtomicallyTogether({{args.output, [&](const std::filesystem::path& temp) { saveMaterialSet(out, temp); }},
                           sceneTextOutput(args.scene, std::move(updated))});
  printWrote(args.output, detail, start);
  printWrote(args.scene, "material.vdb now names " + scenePathValue(args.scene, args.output), start);
  return 0;
}

}  // namespace sslpv

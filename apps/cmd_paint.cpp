#include "apps/cmd_paint.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <vector>

#include "editor/brush_engine.h"
#include "editor/stroke_io.h"
#include "volume/atomic_file.h"
#include "volume/error.h"
#include "volume/material_set.h"
#include "volume/scene.h"
#include "volume/strict_json.h"

namespace sslpv {

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
  std::string ext = std::filesystem::path(args.output).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".vdb") throw InputError("-o: " + args.output + ": the output must be a .vdb file");
  requireWritableOutput(args.output);

  const Scene scene = loadScene(args.scene);
  // Parsed before the mesh and grids load, so a typo in the strokes fails fast.
  const std::optional<ArtistParams> bare = flagMaterial(args, scene.material.ior);
  const std::vector<Stroke> strokes = loadStrokes(args.strokes, bare ? &*bare : nullptr);
  // The target's own refusals name a role ("material set: ...", "box: ..."), not the
  // scene they come from.
  auto engineFor = [&] {
    try {
      return BrushEngine(makePaintTarget(scene));
    } catch (const InputError& e) {
      if (std::string(e.what()).rfind(args.scene + ": ", 0) == 0) throw;
      throw InputError(args.scene + ": " + e.what());
    }
  };
  BrushEngine engine = engineFor();

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
  }
  MaterialSet out = *engine.materialSet();
  out.creator = "sslpv paint";
  saveMaterialSet(out, args.output);
  std::printf("wrote %s (%llu active voxels, units %s)\n", args.output.c_str(),
              static_cast<unsigned long long>(out.sigmaT->activeVoxelCount()), out.units.c_str());
  return 0;
}

}  // namespace sslpv

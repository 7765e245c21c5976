#include "apps/cmd_paint.h"

#include <cctype>
#include <cstdio>
#include <filesystem>

#include "editor/brush_engine.h"
#include "editor/stroke_io.h"
#include "volume/atomic_file.h"
#include "volume/error.h"
#include "volume/material_set.h"
#include "volume/scene.h"

namespace sslpv {

CLI::App* addPaintCommand(CLI::App& app, PaintArgs& args) {
  CLI::App* cmd = app.add_subcommand("paint", "Apply brush strokes (JSON) to a scene's material set, write a VDB");
  cmd->add_option("scene", args.scene, "Scene JSON file")->required();
  cmd->add_option("--strokes", args.strokes, "Stroke JSON file (format: README, editor/stroke_io.h)")->required();
  cmd->add_option("-o,--output", args.output, "Output material set (.vdb)")->required();
  return cmd;
}

int runPaint(const PaintArgs& args) {
  std::string ext = std::filesystem::path(args.output).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".vdb") throw InputError("-o: " + args.output + ": the output must be a .vdb file");
  requireWritableOutput(args.output);

  const Scene scene = loadScene(args.scene);
  // Parsed before the mesh and grids load, so a typo in the strokes fails fast.
  const std::vector<Stroke> strokes = loadStrokes(args.strokes);
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

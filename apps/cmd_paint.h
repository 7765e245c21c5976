#pragma once
// `sslpv paint SCENE.json --strokes STROKES.json -o OUT.vdb [--colour C --scatter-distance D
// [--g G]]`: applies a stroke file (format in editor/stroke_io.h) to the scene's material
// set (or to empty grids when the scene has none) with the brush engine the editor uses,
// and writes the painted set atomically. The flags give the material, as surface colour
// and scatter distance (volume/material/artist_params.h), of strokes that name none, so one file of
// paths can be painted in any colour.
#include <CLI/CLI.hpp>
#include <string>

namespace sslpv {

struct PaintArgs {
  std::string scene;    ///< scene JSON
  std::string strokes;  ///< stroke JSON
  std::string output;   ///< .vdb material set
  /// The colour form for strokes that name no material (editor/stroke_io.h): "R,G,B" or
  /// one number each; empty when not given. g is optional, the other two go together.
  std::string colour, scatterDistance, g;
  bool updateScene = false;  ///< --update-scene: point the scene's material.vdb at the output
};

CLI::App* addPaintCommand(CLI::App& app, PaintArgs& args);

/// Prints one line per stroke (dabs, voxels changed, world bounds) to stdout and a warning
/// per stroke that paints what the object does not show. Throws InputError (exit 2) naming
/// the file and key path on bad input, and when no stroke changed a voxel; no output is
/// written then.
int runPaint(const PaintArgs& args);

}  // namespace sslpv

#pragma once
// `sslpv paint SCENE.json --strokes STROKES.json -o OUT.vdb`: applies a stroke file (format
// in editor/stroke_io.h) to the scene's material set (or to empty grids when the scene has
// none) with the brush engine the editor uses, and writes the painted set atomically.
#include <CLI/CLI.hpp>
#include <string>

namespace sslpv {

struct PaintArgs {
  std::string scene;    ///< scene JSON
  std::string strokes;  ///< stroke JSON
  std::string output;   ///< .vdb material set
  bool updateScene = false;  ///< --update-scene: point the scene's material.vdb at the output
};

CLI::App* addPaintCommand(CLI::App& app, PaintArgs& args);

/// Prints one line per stroke (dabs, voxels changed, world bounds) to stdout and a warning
/// per stroke that paints what the object does not show. Throws InputError (exit 2) naming
/// the file and key path on bad input, and when no stroke changed a voxel; no output is
/// written then.
int runPaint(const PaintArgs& args);

}  // namespace sslpv

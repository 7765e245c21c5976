#pragma once
// `sslpv export SCENE.json --pbrt OUT.pbrt [--grid N]`: the scene for another renderer.
// pbrt-v4 for now (volume/eval/pbrt_export.h), so sslpv can be checked independently.
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace sslpv {

struct ExportArgs {
  std::string scene;
  std::string pbrt;         ///< output .pbrt file
  std::optional<int> grid;  ///< medium cells along the object's longest axis
};

CLI::App* addExportCommand(CLI::App& app, ExportArgs& args);

/// Throws sslpv::InputError (exit 2) for bad input, sslpv::ResourceError (exit 3) when the
/// file cannot be written; prints a warning line on stderr when pbrt cannot represent the
/// scene's varying g.
int runExport(const ExportArgs& args);

}  // namespace sslpv

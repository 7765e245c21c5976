#include "apps/cmd_export.h"

#include <cctype>
#include <filesystem>
#include <iostream>

#include "apps/cli_output.h"
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/eval/pbrt_export.h"
#include "volume/scene/scene.h"

namespace sslpv {

CLI::App* addExportCommand(CLI::App& app, ExportArgs& args) {
  CLI::App* cmd = app.add_subcommand("export", "Write the scene for another renderer (pbrt-v4)");
  cmd->add_option("scene", args.scene, "Scene JSON file")->required();
  cmd->add_option("--pbrt", args.pbrt,
                  "pbrt-v4 scene to write (.pbrt); rendering it with pbrt writes the same name with .exr")
      ->required();
  cmd->add_option("--grid", args.grid,
                  "rgbgrid medium cells along the object's longest axis (default " +
                      std::to_string(kDefaultPbrtGrid) + ", at most " + std::to_string(kMaxPbrtGrid) +
                      ")");
  return cmd;
}

int runExport(const ExportArgs& args) {
  const auto start = CliClock::now();
  std::string ext = std::filesystem::path(args.pbrt).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  // A fixed extension keeps a slip of the fingers from replacing the scene JSON itself.
  if (ext != ".pbrt") throw InputError("--pbrt: " + args.pbrt + ": the output must end in .pbrt");
  const int grid = args.grid.value_or(kDefaultPbrtGrid);
  if (grid < 2 || grid > kMaxPbrtGrid)
    throw InputError("--grid: must be between 2 and " + std::to_string(kMaxPbrtGrid) + ", got " +
                     std::to_string(grid));
  requireWritableOutput(args.pbrt);

  const Scene scene = loadScene(args.scene);
  const PbrtExportSummary summary = exportPbrtScene(scene, args.pbrt, grid);
  if (summary.gVaries())
    std::cerr << "sslpv: warning: " << args.pbrt << ": g varies from " << summary.gMin << " to " << summary.gMax
              << " inside the object; pbrt's rgbgrid medium takes one g, so the file uses the mean "
              << summary.gMean << std::endl;
  printWrote(args.pbrt,
             "rgbgrid " + std::to_string(summary.dims.x) + "x" + std::to_string(summary.dims.y) + "x" +
                 std::to_string(summary.dims.z) + ", " + std::to_string(summary.triangles) + " triangles",
             start);
  return 0;
}

}  // namespace sslpv

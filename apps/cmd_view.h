#pragma once
// `sslpv view SCENE.json`: a live window on the SSLPV preview. Mouse and keys orbit the
// camera, zoom and move the first light; only the stages a change touches re-run, on a
// render thread, while the window shows the last finished frame with its stage timings.
// The scene and its material set are reloaded when they change on disk.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace sslpv {

struct ViewArgs {
  std::string scene, backend = "auto", steps, size, script, screenshot;
  std::optional<int> grid;
  int frames = 0;  ///< 0: until the window is closed
  float exposure = 1.0f;
  double turntableDeg = 0.0;
  bool noOverlay = false;
};

CLI::App* addViewCommand(CLI::App& app, ViewArgs& args);
/// InputError on bad flags or scene, ResourceError where no window can be presented.
int runView(const ViewArgs& args);

}  // namespace sslpv

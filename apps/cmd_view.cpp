#include "apps/cmd_view.h"

#include <filesystem>

#include "apps/cli_output.h"
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/core/image_io.h"
#include "volume/core/input_ranges.h"
#include "volume/scene/scene.h"
#include "volume/core/strict_json.h"
#ifdef SSLPV_HAVE_VIEWER
#include "apps/view_script.h"
#include "apps/view_window.h"
#endif

namespace sslpv {

CLI::App* addViewCommand(CLI::App& app, ViewArgs& args) {
  CLI::App* cmd = app.add_subcommand("view", "Watch the preview live in a window (orbit, zoom, move the light)");
  cmd->add_option("scene", args.scene, "Scene JSON file (reloaded when it or its material set changes)")->required();
  cmd->add_option("--backend", args.backend,
                  "cpu, vulkan, or auto (default: vulkan on a GPU, cpu where the only device is lavapipe)");
  cmd->add_option("--grid", args.grid, "LPV cells along the longest axis (overrides lpv.resolution; G cycles)");
  cmd->add_option("--steps", args.steps, "Propagation steps, or 'auto' (overrides lpv.steps; S cycles)");
  cmd->add_option("--size", args.size, "Window size WxH, e.g. 640x480 (default: camera.width x camera.height)");
  cmd->add_option("--exposure", args.exposure, "Multiply radiance before tone mapping, as render does for PNG");
  cmd->add_option("--frames", args.frames, "Present this many frames, then exit (headless runs; prints frames/s)");
  cmd->add_option("--screenshot", args.screenshot, "With --frames: write the last presented frame to this .png");
  cmd->add_option("--turntable", args.turntableDeg, "Orbit the camera by this many degrees every frame");
  cmd->add_flag("--no-overlay", args.noOverlay, "Timings in the window title only, not drawn in the image (H toggles)");
  // Scripted input for tests and demos (format in apps/view_script.h).
  cmd->add_option("--script", args.script, "Timed input events")->group("");
  return cmd;
}

int runView(const ViewArgs& args) {
  if (args.backend != "cpu" && args.backend != "vulkan" && args.backend != "auto")
    throw InputError("--backend: unknown backend '" + args.backend + "' (auto, vulkan, cpu)");
  if (args.frames < 0)
    throw InputError("--frames: must be 0 (until closed) or more, got " + std::to_string(args.frames));
  if (!args.screenshot.empty()) {
    if (args.frames == 0) throw InputError("--screenshot: needs --frames N (the frame it writes is the Nth)");
    if (std::filesystem::path(args.screenshot).extension() != ".png")
      throw InputError("--screenshot: " + args.screenshot + ": the window's frame is written as .png only");
    requireWritableOutput(args.screenshot);
  }
  if (!(args.exposure >= kMinExposure && args.exposure <= kMaxExposure))
    throw InputError("--exposure: must be in [" + formatNumber(kMinExposure) + ", " + formatNumber(kMaxExposure) +
                     "], got " + formatNumber(args.exposure));
  if (!(args.turntableDeg >= -360.0 && args.turntableDeg <= 360.0))
    throw InputError("--turntable: degrees per frame must be in [-360, 360], got " + formatNumber(args.turntableDeg));
  Camera sized;
  if (!args.size.empty()) applySizeFlag(args.size, sized);
#ifdef SSLPV_HAVE_VIEWER
  ViewSetup setup;
  if (!args.script.empty()) setup.script = loadViewScript(args.script);
  setup.scene = loadScene(args.scene);
  setup.settings = applyLpvFlags(setup.scene.lpv, {args.grid, args.steps, std::nullopt, ""});
  setup.width = args.size.empty() ? setup.scene.camera.width : sized.width;
  setup.height = args.size.empty() ? setup.scene.camera.height : sized.height;
  return runViewWindow(args, std::move(setup));
#else
  throw ResourceError("view: this sslpv was built without GLFW or Vulkan, so it has no window (install libglfw3-dev "
                      "and re-run cmake); `sslpv render` writes images without one");
#endif
}

}  // namespace sslpv

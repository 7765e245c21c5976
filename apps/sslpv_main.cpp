// The `sslpv` command line: one binary, subcommands (docs/design.md §5; flags in the README).
// Exit codes: 0 success, 1 internal error, 2 bad input, 3 not enough resources.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <utility>
#include <iostream>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <string_view>

#include "apps/cmd_bench_error.h"
#include "apps/cmd_compare.h"
#include "apps/cmd_paint.h"
#include "apps/cmd_render_frames.h"
#include "apps/cmd_export.h"
#include "apps/cmd_edit.h"
#include "apps/cmd_inspect.h"
#include "apps/cmd_view.h"
#include "apps/cli_output.h"
#include "backend/backends.h"
#ifdef SSLPV_HAVE_VULKAN
#include "gpu/vk/vk_check.h"
#endif
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/core/image_io.h"
#include "volume/core/input_ranges.h"
#include "volume/material/material_set.h"
#include "volume/scene/mesh.h"
#include "volume/reference/reference_tracer.h"
#include "volume/scene/scene.h"
#include "volume/scene/scene_checks.h"
#include "volume/core/strict_json.h"

namespace {

constexpr int kExitInternal = 1;
constexpr int kExitInput = 2;
constexpr int kExitResource = 3;

int fail(int code, std::string message) {
  for (char& c : message)
    if (c == '\n' || c == '\r') c = ' ';
  std::cerr << "sslpv: error: " << message << std::endl;
  return code;
}

/// A frame with a NaN or infinite pixel is refused rather than written: float radiance
/// overflows for lights or media near the float range, and a tone-mapped PNG would hide it.
void requireFiniteImage(const sslpv::Image& image, const std::string& scene, const std::string& backend) {
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const glm::vec3& p = image.at(x, y);
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) continue;
      throw sslpv::InputError(scene + ": the " + backend + " render has a non-finite pixel at (" + std::to_string(x) +
                              ", " + std::to_string(y) +
                              "): the radiance overflows float range; lower the light intensities or the "
                              "material's sigma_t / sigma_s");
    }
}

/// The calibrated lattice is a diffusion model: below a few mean free paths across most
/// light scatters a few times or not at all, which the single-scattering term and the
/// lattice's thin-object factor only approximate.
void warnIfOpticallyThin(const sslpv::RenderReport& report, const std::string& scene) {
  // Measured after the thin-object factor: x0.74 of the path tracer at 2 mean free paths,
  // ketchup_box's red at 3.9 and jade's at 5.7 as accurate as thick media (x1.05, x1.00).
  constexpr double kThinObject = 3.0;
  const glm::dvec3 tau = report.opticalThickness;
  const double thinnest = std::min({tau.x, tau.y, tau.z});
  if (!(thinnest > 0.0) || thinnest >= kThinObject) return;
  char text[400];
  std::snprintf(text, sizeof text,
                "sslpv: warning: %s: the object is optically thin (%.3g mean free paths across its mean chord in the "
                "thinnest channel, under %g): SSLPV assumes light diffuses, so expect the image up to about half as "
                "bright as `sslpv reference` (a sphere at 2e-5 to 2 mean free paths measured x0.48 to x0.74)\n",
                scene.c_str(), thinnest, kThinObject);
  std::cerr << text;
}

/// The scene warnings every renderer shares (camera or light inside the object, scale).
void warnAboutScene(const sslpv::Scene& scene) {
  for (const std::string& warning : sslpv::sceneWarnings(scene)) sslpv::printWarning(warning);
}

struct RenderArgs {
  std::string scene, output, backend = "auto", steps, scheme, size, frames;
  std::optional<int> grid, shadowMap;
  std::optional<double> time;
  double fps = 24.0;
  bool timings = false;
  float exposure = 1.0f;
};

int runRender(const RenderArgs& args) {
  using namespace sslpv;
  const auto start = CliClock::now();
  const BackendKind backendKind = parseBackendKind(args.backend);
  if (!isSupportedImageExtension(args.output))
    throw InputError(args.output + ": unsupported output format (use .png, .pfm or .exr)");
  // Checked before the render: a bad flag should not cost one.
  if (!(args.exposure >= kMinExposure && args.exposure <= kMaxExposure))
    throw InputError("--exposure: must be in [" + formatNumber(kMinExposure) + ", " + formatNumber(kMaxExposure) +
                     "], got " + formatNumber(args.exposure));
  if (!(args.fps > 0.0 && args.fps <= 1e6))
    throw InputError("--fps: must be in (0, 1000000], got " + formatNumber(args.fps));
  if (args.time && !args.frames.empty()) throw InputError("--time and --frames: give one, not both");

  // One entry per frame: the time and the file. A single render is frame "time".
  std::vector<std::pair<double, std::string>> frames;
  if (!args.frames.empty()) {
    const FrameRange range = parseFrameRange(args.frames);
    requireFramePattern(args.output);
    for (int f : range.frames()) frames.emplace_back(double(f) / args.fps, framePath(args.output, f));
  } else {
    frames.emplace_back(args.time.value_or(0.0), args.output);
  }
  for (const auto& frame : frames) requireWritableOutput(frame.second);

  Camera sized;
  if (!args.size.empty()) sslpv::applySizeFlag(args.size, sized);

  Scene scene = sceneAtTime(loadScene(args.scene), frames.front().first);
  const LpvSettings settings = applyLpvFlags(scene.lpv, {args.grid, args.steps, args.shadowMap, args.scheme});
  if (!args.size.empty()) {
    scene.camera.width = sized.width;
    scene.camera.height = sized.height;
  }
  warnAboutScene(scene);
  if (!scene.animated() && (args.time || frames.size() > 1))
    printWarning(args.scene + ": the scene has no \"deformers\" or mesh.animation: every time renders the same image");

  // One renderer kept across the frames of a sequence, so that each frame re-runs only
  // what the new pose changes.
  Backends backends(backendKind);
  // The first Vulkan frame compiles the device's pipelines unless Mesa's shader cache has
  // them (4 s on lavapipe with an empty cache): a terminal sees the wait, not silence.
  std::optional<WaitNotice> firstFrame;
  if (backends.usesVulkan()) firstFrame.emplace("render: preparing the Vulkan pipelines");
  std::unique_ptr<Renderer> renderer = backends.make(scene);
  const std::string autoNote = backends.note();
  if (!scene.deformers.empty() && frames.size() > 1) {
    // Every pose is checked before the first file is written: a fold at frame 40 must
    // not leave 39 frames behind. The renderer has checked the mesh itself.
    const TriangleMesh rest = loadMesh(scene.mesh, Transform{}, false);
    for (const auto& frame : frames)
      deformPositions(rest.positions, DeformationPose(scene.deformers, frame.first), scene.file.string(),
                      frame.first);
  }

  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto frameStart = CliClock::now();
    RenderReport report;
    Image image;
#ifdef SSLPV_HAVE_VULKAN
    try {
#endif
      if (i > 0) renderer->setTime(frames[i].first);
      image = renderer->render(settings, &report);
      firstFrame.reset();
#ifdef SSLPV_HAVE_VULKAN
    } catch (const GpuError& e) {
      throw ResourceError(std::string("--backend vulkan: ") + e.what() + " (--backend cpu needs no GPU)");
    }
#endif
    if (i == 0) warnIfOpticallyThin(report, args.scene);
    if (report.propagation.capped)
      std::cerr << "sslpv: warning: " << args.scene << ": --steps auto stopped at its cap of "
                << report.propagation.stepsRun
                << " steps before converging; the image may be off (fixed --steps N runs N)" << std::endl;
    requireFiniteImage(image, args.scene, report.backend);
    if (frames.size() == 1) warnIfBlack(image, args.scene);
    writeImage(image, frames[i].second, args.exposure);
    if (args.timings) {
      if (i == 0 && !autoNote.empty()) std::cout << autoNote << "\n";
      std::cout << formatTimings(report);
    }
    if (frames.size() > 1) {
      // One plain line per frame, never a carriage return: readable in a log as on a terminal.
      const double ms = std::chrono::duration<double, std::milli>(CliClock::now() - frameStart).count();
      std::cerr << "render: frame " << (i + 1) << "/" << frames.size() << " (t = " << formatNumber(frames[i].first)
                << ") " << frames[i].second << " " << long(ms + 0.5) << " ms" << std::endl;
    }
    printWrote(frames[i].second, imageSizeText(image), start);
  }
  return 0;
}

struct ReferenceArgs {
  std::string scene, output;
  double time = 0.0;
  int spp = 0;
  std::uint64_t seed = 0;
  int threads = 0;
  int maxScatter = 0;
  float exposure = 1.0f;
};

int runReference(const ReferenceArgs& args) {
  using namespace sslpv;
  const auto start = CliClock::now();
  std::string ext = std::filesystem::path(args.output).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr" && ext != ".pfm" && ext != ".png")
    throw InputError("-o: " + args.output +
                     ": unsupported output format (use .png tone-mapped, or .exr or .pfm: linear radiance)");
  if (!(args.exposure >= kMinExposure && args.exposure <= kMaxExposure))
    throw InputError("--exposure: must be in [" + formatNumber(kMinExposure) + ", " + formatNumber(kMaxExposure) +
                     "], got " + formatNumber(args.exposure));
  if (args.spp < 1 || args.spp > 1000000)
    throw InputError("--spp: must be a whole number from 1 to 1000000, got " + std::to_string(args.spp));
  if (args.threads < 0 || args.threads > 4096)
    throw InputError("--threads: must be between 0 (all cores) and 4096, got " + std::to_string(args.threads));
  if (args.maxScatter < 0)
    throw InputError("--max-scatter: must be 0 (unlimited) or more, got " + std::to_string(args.maxScatter));
  // The standard error stays linear radiance beside a PNG too: it is for measuring noise.
  std::filesystem::path errorFile(args.output);
  errorFile.replace_extension(".stderr" + (ext == ".png" ? std::string(".exr")
                                                         : std::filesystem::path(args.output).extension().string()));
  requireWritableOutput(args.output);
  requireWritableOutput(errorFile);

  const Scene scene = sceneAtTime(loadScene(args.scene), args.time);
  warnAboutScene(scene);
  const ReferenceTracer tracer(scene);
  ReferenceOptions options;
  options.spp = args.spp;
  options.seed = args.seed;
  options.threads = args.threads;
  options.maxScatterEvents = args.maxScatter;
  ProgressLine progress("reference");
  options.progress = [&](std::size_t done, std::size_t total) { progress.update(done, total); };
  const ReferenceResult result = tracer.render(options);
  progress.finish("traced " + std::to_string(args.spp) + " spp at " + imageSizeText(result.radiance));
  warnIfBlack(result.radiance, args.scene);
  // Together: a full disk must not leave a new image beside the old one's error image.
  writeAtomicallyTogether({imageOutput(result.radiance, args.output, args.exposure),
                           imageOutput(result.standardError, errorFile)});
  printWrote(args.output, imageSizeText(result.radiance), start);
  printWrote(errorFile.string(), "standard error per pixel, " + imageSizeText(result.standardError), start);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sslpv: author and preview translucent heterogeneous materials (SSLPV)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "sslpv " SSLPV_VERSION);

  std::string helpTopic;
  CLI::App* helpCmd = app.add_subcommand("help", "List the commands, or show one command's options");
  helpCmd->add_option("command", helpTopic, "The command to describe");

  RenderArgs render;
  CLI::App* renderCmd = app.add_subcommand("render", "Render a scene with SSLPV");
  renderCmd->add_option("scene", render.scene, "Scene JSON file")->required();
  renderCmd->add_option("-o,--output", render.output, "Output image (.png tone-mapped, .pfm/.exr linear)")
      ->required();
  renderCmd->add_option("--size", render.size, "Image size WxH, e.g. 640x480 (overrides camera.width/height)");
  renderCmd->add_option("--backend", render.backend,
                        "auto (default: Vulkan on a GPU, the CPU backend where Vulkan would be Mesa lavapipe), "
                        "vulkan or cpu");
  renderCmd->add_option("--grid", render.grid, "LPV cells along the longest axis (overrides lpv.resolution)");
  renderCmd->add_option("--steps", render.steps, "Propagation steps, or 'auto' (overrides lpv.steps)");
  renderCmd->add_option("--shadow-map", render.shadowMap, "Shadow-map texels per side (overrides lpv.shadow_map)");
  renderCmd->add_option("--scheme", render.scheme,
                         "Propagation coefficients: calibrated (default) or seed (overrides lpv.scheme)");
  renderCmd->add_option("--exposure", render.exposure, "PNG only: multiply radiance before tone mapping");
  renderCmd->add_flag("--timings", render.timings, "Print the per-stage timing table");
  renderCmd->add_option("--time", render.time, "Pose a deforming scene (its \"deformers\" or skinned mesh.animation) at this time, in seconds");
  renderCmd->add_option("--frames", render.frames,
                        "Render frames A:B[:STEP] (time = frame / --fps) to -o's %04d-style pattern");
  renderCmd->add_option("--fps", render.fps, "Frames per unit of scene time for --frames (default 24)");

  std::string inspectFile;
  CLI::App* inspectCmd = app.add_subcommand("inspect", "Report the grids of a VDB material set and validate it");
  inspectCmd->add_option("file", inspectFile, "VDB file")->required();

  ReferenceArgs reference;
  CLI::App* referenceCmd =
      app.add_subcommand("reference", "Render a ground-truth image with a volumetric path tracer");
  referenceCmd->add_option("scene", reference.scene, "Scene JSON file")->required();
  referenceCmd->add_option("-o,--output", reference.output,
                           "Output image (.png tone-mapped like render, .exr/.pfm linear); the standard error "
                           "goes beside it as NAME.stderr.exr/.pfm")
      ->required();
  referenceCmd->add_option("--spp", reference.spp, "Samples per pixel")->required();
  referenceCmd->add_option("--exposure", reference.exposure, "PNG only: multiply radiance before tone mapping");
  referenceCmd->add_option("--seed", reference.seed, "Random seed (same seed, same image)");
  referenceCmd->add_option("--time", reference.time, "Pose a deforming scene (its \"deformers\" or skinned mesh.animation) at this time, in seconds");
  referenceCmd->add_option("--threads", reference.threads, "Worker threads (0: all cores)");
  referenceCmd->add_option("--max-scatter", reference.maxScatter,
                           "End paths after this many scattering events (0: unlimited; 1: single scattering only)");

  // Subcommands from apps/cmd_*.cpp (each: Args struct, add<Name>Command, run<Name>).
  sslpv::EditArgs edit;
  CLI::App* editCmd = sslpv::addEditCommand(app, edit);
  sslpv::BenchErrorArgs benchError;
  CLI::App* benchErrorCmd = sslpv::addBenchErrorCommand(app, benchError);
  sslpv::PaintArgs paint;
  CLI::App* paintCmd = sslpv::addPaintCommand(app, paint);
  sslpv::ExportArgs exportArgs;
  CLI::App* exportCmd = sslpv::addExportCommand(app, exportArgs);
  sslpv::CompareArgs compare;
  CLI::App* compareCmd = sslpv::addCompareCommand(app, compare);
  sslpv::ViewArgs view;
  CLI::App* viewCmd = sslpv::addViewCommand(app, view);

  // CLI11 reports a stray subcommand only as "extra arguments"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    std::string known;
    bool found = false;
    for (const CLI::App* sub : std::as_const(app).get_subcommands([](const CLI::App*) { return true; })) {
      found = found || sub->get_name() == argv[1];
      known += (known.empty() ? "" : ", ") + sub->get_name();
    }
    if (!found) return fail(kExitInput, std::string("unknown subcommand '") + argv[1] + "' (expected " + known + ")");
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail(kExitInput, std::string(e.what()) + " (see sslpv --help)");
  }

  // A SIGINT or SIGTERM (Ctrl-C, a job scheduler's timeout) while an output is being
  // written must not leave its temporary behind.
  sslpv::removeTemporariesOnSignals();
  // What an out-of-memory message names: the subcommand and its main input.
  std::string activity = "sslpv";
  for (const CLI::App* sub : app.get_subcommands()) {
    activity = sub->get_name();
    for (const CLI::Option* option : sub->get_options())
      if (option->get_positional())
        for (const std::string& value : option->results()) activity += " " + value;
  }

  if (*helpCmd) {
    if (helpTopic.empty()) {
      // app.help() would describe the selected subcommand, `help` itself.
      std::cout << app.get_formatter()->make_help(&app, app.get_name(), CLI::AppFormatMode::Normal);
      return 0;
    }
    for (const CLI::App* sub : std::as_const(app).get_subcommands([](const CLI::App*) { return true; }))
      if (sub->get_name() == helpTopic && sub != helpCmd) {
        std::cout << sub->help(app.get_name());
        // The editor parses its own options: its list comes from the editor itself.
        if (sub == editCmd) std::cout << "The editor's options: sslpv edit --help\n";
        return 0;
      }
    return fail(kExitInput, "help: unknown command '" + helpTopic + "' (see sslpv help)");
  }

  try {
    if (*renderCmd) return runRender(render);
    if (*referenceCmd) return runReference(reference);
    // Dispatch of the apps/cmd_*.cpp subcommands.
    if (*editCmd) return sslpv::runEdit(edit);
    if (*benchErrorCmd) return sslpv::runBenchError(benchError);
    if (*paintCmd) return sslpv::runPaint(paint);
    if (*exportCmd) return sslpv::runExport(exportArgs);
    if (*compareCmd) return sslpv::runCompare(compare);
    if (*viewCmd) return sslpv::runView(view);
    if (*inspectCmd) {
      if (!sslpv::inspectVdbFile(inspectFile, std::cout))
        return fail(kExitInput, inspectFile + ": the material set has validation problems (listed above)");
      sslpv::printMaterialSummary(inspectFile, std::cout);
      return 0;
    }
  } catch (const sslpv::InputError& e) {
    return fail(kExitInput, e.what());
  } catch (const sslpv::ResourceError& e) {
    return fail(kExitResource, e.what());
  } catch (const std::bad_alloc&) {
    return fail(kExitResource, activity + ": out of memory");
  } catch (const std::exception& e) {
    return fail(kExitInternal, std::string("internal error: ") + e.what());
  }
  return kExitInternal;
}

#include "apps/cmd_bench_error.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/cli_output.h"
#include "backend/backends.h"
#include "volume/core/atomic_file.h"
#include "volume/eval/bench_table.h"
#include "volume/core/error.h"
#include "volume/core/image_io.h"
#include "volume/eval/image_metrics.h"
#include "volume/reference/reference_tracer.h"
#include "volume/scene/scene.h"

extern char** environ;

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string duration(double seconds) {
  char text[32];
  const long s = std::lround(std::max(0.0, seconds));
  if (s >= 3600)
    std::snprintf(text, sizeof text, "%ldh%02ldm", s / 3600, (s / 60) % 60);
  else if (s >= 60)
    std::snprintf(text, sizeof text, "%ldm%02lds", s / 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%lds", s);
  return text;
}

void writeText(const fs::path& file, const std::string& text) {
  writeAtomically(file, [&](const fs::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throwWriteFailed(file, errno);
  });
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool allFinite(const Image& image) { return !firstNonFinitePixel(image).has_value(); }

// --- references ------------------------------------------------------------------------

struct Reference {
  Image image;
  BenchReferenceInfo info;
};

/// Why the cached pair (EXR + sidecar) cannot be used, or empty when it can.
std::string cacheProblem(const fs::path& exr, const fs::path& side, const ReferenceSidecar& want, Image& image) {
  if (!fs::exists(side)) return "no sidecar " + side.filename().string();
  const std::optional<ReferenceSidecar> got = parseReferenceSidecar(readText(side));
  if (!got) return "sidecar " + side.filename().string() + " is not valid JSON of a reference";
  if (got->hash != want.hash || got->spp != want.spp || got->seed != want.seed || got->width != want.width ||
      got->height != want.height)
    return "sidecar " + side.filename().string() + " describes another render";
  if (fileContentHash(exr) != got->imageHash) return "image bytes differ from those written";
  try {
    image = readImage(exr);
  } catch (const std::exception& e) {  // InputError, or a decoder's own exception
    return e.what();
  }
  if (image.width != want.width || image.height != want.height) return "image has the wrong size";
  if (!allFinite(image)) return "image holds NaN or Inf";
  return {};
}

Reference obtainReference(const std::string& sceneArg, const Scene& scene, const fs::path& cacheDir, int spp,
                          std::uint64_t seed) {
  const ReferenceTracer tracer(scene);
  // Dielectric objects' references connect lights exactly through the boundary (flat faces,
  // internal reflections, curved meshes faceted); references that earlier versions cached
  // under the same scene content did not, so the connection kind is part of the cache key.
  const char* connection = "";
  switch (tracer.lightConnection()) {
    case ReferenceTracer::LightConnection::StraightLine: break;
    case ReferenceTracer::LightConnection::FlatFaces: connection = "exact flat-face light connections, internal reflections"; break;
    case ReferenceTracer::LightConnection::Faceted: connection = "exact faceted light connections"; break;
  }
  ReferenceSidecar want{sceneArg, sceneContentHash(scene, connection),
                        "", spp, seed, 0.0, scene.camera.width, scene.camera.height};
  const std::string stem = referenceCacheStem(scene, want.hash, spp, seed);
  const fs::path exr = cacheDir / (stem + ".exr"), side = cacheDir / (stem + ".json");
  Reference ref;
  ref.info = {sceneArg, exr.string(), "reused", 0.0};
  if (fs::exists(exr)) {
    const std::string problem = cacheProblem(exr, side, want, ref.image);
    if (problem.empty()) {
      ref.info.seconds = parseReferenceSidecar(readText(side))->seconds;
      std::printf("reference %s: reused %s (path-traced earlier in %.1f s)\n", sceneArg.c_str(),
                  exr.string().c_str(), ref.info.seconds);
      std::fflush(stdout);
      return ref;
    }
    std::fprintf(stderr, "bench-error: cached reference %s is unusable (%s): rendering it again\n",
                 exr.string().c_str(), problem.c_str());
  }

  std::fprintf(stderr, "bench-error: path tracing the reference of %s (%dx%d, %d spp, seed %llu)\n",
               sceneArg.c_str(), scene.camera.width, scene.camera.height, spp,
               static_cast<unsigned long long>(seed));
  ReferenceOptions options;
  options.spp = spp;
  options.seed = seed;
  const auto start = Clock::now();
  // Redrawn in place only on a terminal: a log gets one summary line, not carriage returns.
  ProgressLine progress("reference");
  options.progress = [&](std::size_t done, std::size_t total) { progress.update(done, total); };
  ReferenceResult result = tracer.render(options);
  progress.finish("traced " + std::to_string(spp) + " spp at " + imageSizeText(result.radiance));
  want.seconds = secondsSince(start);
  // The sidecar goes last: a run killed in between leaves an EXR without one, which the
  // next run re-renders instead of trusting.
  writeImage(result.radiance, exr);
  want.imageHash = fileContentHash(exr);
  writeText(side, referenceSidecarJson(want));
  ref.image = std::move(result.radiance);
  ref.info.status = "rendered";
  ref.info.seconds = want.seconds;
  std::printf("reference %s: rendered in %.1f s, cached as %s\n", sceneArg.c_str(), want.seconds,
              exr.string().c_str());
  std::fflush(stdout);
  return ref;
}

// --- one configuration -----------------------------------------------------------------

struct Frame {
  Image image;
  RenderReport report;
  double wallMs = 0;
};

/// One full render from a fresh renderer: the constructor (mesh load, BVH, upload) is
/// outside the timed region, render() (voxelize through shading) inside.
Frame renderFresh(const Scene& scene, const BenchConfig& config, Backends* vulkan) {
  const LpvSettings settings = config.apply(scene.lpv);
  std::unique_ptr<Renderer> renderer;
  try {
    renderer = config.backend == "cpu" ? makeRenderer(scene, BackendKind::Cpu) : vulkan->make(scene);
  } catch (const ResourceError& e) {
    throw ResourceError(scene.file.string() + ": " + e.what());
  }
  Frame frame;
  const auto start = Clock::now();
  frame.image = renderer->render(settings, &frame.report);
  frame.wallMs = 1000.0 * secondsSince(start);
  return frame;
}

ImageMetrics measure(const std::string& sceneArg, const Image& render, const Image& reference, int block) {
  if (!allFinite(render)) throw std::runtime_error(sceneArg + ": the render holds NaN or Inf");
  PixelMask mask = autoMask(render, reference);
  Image a = render, b = reference;
  if (block > 1) {
    a = blockAverage(render, block);
    b = blockAverage(reference, block);
    mask = blockMask(mask, block);
  }
  if (mask.count() == 0)
    throw InputError(sceneArg + ": no " + std::to_string(block) + "x" + std::to_string(block) +
                     " block lies entirely on the object; use a smaller --block");
  try {
    return computeImageMetrics(a, b, mask);
  } catch (const std::invalid_argument& e) {
    throw InputError(sceneArg + ": the reference is not positive over the object (" + e.what() + ")");
  }
}

BenchRow runConfig(const std::string& sceneArg, const Scene& scene, const BenchConfig& config,
                   const Image& reference, const BenchErrorArgs& args, Backends* vulkan) {
  BenchRow row;
  row.scene = sceneArg;
  row.config = config;
  row.repeats = args.repeats;
  // The warm-up pays for first-touch page faults, TBB's thread start and shader JIT; its
  // image is the one measured (renders are deterministic, so any would do).
  const Frame warm = renderFresh(scene, config, vulkan);
  row.stepsRun = warm.report.propagation.stepsRun;
  std::vector<double> vox, res, shadow, inject, prop, shade, total;
  for (int r = 0; r < args.repeats; ++r) {
    const Frame f = renderFresh(scene, config, vulkan);
    const StageTimes& t = f.report.times;
    vox.push_back(t.voxelize);
    res.push_back(t.resample);
    shadow.push_back(t.shadowMap);
    inject.push_back(t.injection);
    prop.push_back(t.propagation);
    shade.push_back(t.shading);
    total.push_back(f.wallMs);
  }
  row.ms = {median(vox), median(res), median(shadow), median(inject), median(prop), median(shade), median(total)};
  row.metrics = measure(sceneArg, warm.image, reference, args.block);
  return row;
}

// --- the plot, drawn by sslpv-plot in a child process ------------------------------------

std::optional<fs::path> findInPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  std::istringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

/// Runs argv[0] with stdout and stderr into `log`; the exit code, or -signal.
int runChild(const std::vector<std::string>& args, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<std::string> storage = args;
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw ResourceError("plot not written: cannot start " + args[0] + ": " + std::strerror(rc));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

std::string lastLine(const std::string& text) {
  std::istringstream in(text);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last.empty() ? "no output" : last;
}

/// Empty on success, else the one-line reason the plot is missing.
std::string makePlot(const fs::path& json, const fs::path& png) {
  const fs::path plot = fs::read_symlink("/proc/self/exe").parent_path() / "sslpv-plot";
  if (!fs::exists(plot)) {
#ifdef SSLPV_PLOT_CONFIGURED
    return plot.string() + " is missing (build the sslpv-plot target)";
#else
    return "this sslpv was configured without VTK, so there is no sslpv-plot (install libvtk9-dev and "
           "reconfigure)";
#endif
  }
  std::vector<std::string> argv;
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display) {
    // Debian's VTK renders through X only (no EGL/OSMesa) and aborts without a display.
    const std::optional<fs::path> xvfb = findInPath("xvfb-run");
    if (!xvfb)
      return "DISPLAY is unset and xvfb-run is not installed (VTK needs an X display: apt-get install xvfb "
             "xauth)";
    argv = {xvfb->string(), "-a", "-s", "-screen 0 1280x1024x24"};
  }
  argv.insert(argv.end(), {plot.string(), json.string(), png.string()});

  char logName[] = "/tmp/sslpv-plot-XXXXXX";
  const int fd = ::mkstemp(logName);
  if (fd < 0) return std::string("cannot create a log file in /tmp: ") + std::strerror(errno);
  ::close(fd);
  const int code = runChild(argv, logName);
  const std::string log = readText(logName);
  fs::remove(logName);
  if (code == 0 && fs::exists(png)) return {};
  const std::string how = code < 0 ? "killed by signal " + std::to_string(-code) : "exit " + std::to_string(code);
  return fs::path(argv[0]).filename().string() + " failed (" + how + "): " + lastLine(log);
}

void printTable(const std::vector<BenchRow>& rows) {
  std::printf("%-28s %-7s %-10s %4s %6s %6s %6s %10s %9s %9s %7s %6s\n", "scene", "backend", "scheme", "grid",
              "steps", "ran", "shadow", "total ms", "rel.MSE", "mean rel", "SSIM", "pareto");
  for (const BenchRow& r : rows)
    std::printf("%-28s %-7s %-10s %4d %6s %6d %6d %10.2f %9.4g %9.4g %7.4f %6s\n",
                fs::path(r.scene).filename().string().c_str(), r.config.backend.c_str(),
                lpvSchemeName(r.config.scheme).c_str(), r.config.grid, r.config.stepsText().c_str(), r.stepsRun,
                r.config.shadowMap, r.ms.total, r.metrics.relativeMse, r.metrics.meanRelativeError,
                r.metrics.ssim, r.pareto ? "*" : "");
}

}  // namespace

CLI::App* addBenchErrorCommand(CLI::App& app, BenchErrorArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "bench-error",
      "Run time against error: render every configuration of every scene, compare with a cached path-traced "
      "reference, write OUT.csv, OUT.json and OUT.png (error vs time, Pareto fronts)");
  cmd->add_option("scenes", args.scenes, "Scene JSON files")->required();
  cmd->add_option("-o,--output", args.output, "Output prefix: writes PREFIX.csv, PREFIX.json, PREFIX.png")
      ->required();
  cmd->add_option("--grid", args.grid, "Comma list of LPV resolutions")->capture_default_str();
  cmd->add_option("--steps", args.steps, "Comma list of step counts or 'auto'")->capture_default_str();
  cmd->add_option("--shadow-map", args.shadowMap, "Comma list of shadow-map sizes")->capture_default_str();
  cmd->add_option("--backend", args.backend, "Comma list of backends: cpu, vulkan (skipped, loudly, without "
                                             "a Vulkan device)")->capture_default_str();
  cmd->add_option("--scheme", args.scheme, "Comma list of schemes: seed, calibrated")->capture_default_str();
  cmd->add_option("--spp", args.spp, "Reference samples per pixel")->capture_default_str();
  cmd->add_option("--seed", args.seed, "Reference random seed")->capture_default_str();
  cmd->add_option("--block", args.block, "Compare KxK block means (suppresses reference noise)")
      ->capture_default_str();
  cmd->add_option("--repeats", args.repeats, "Timed renders per configuration after one warm-up (medians)")
      ->capture_default_str();
  cmd->add_option("--cache", args.cache,
                  "Reference cache directory (default: sslpv-reference-cache in the current directory); one "
                  "EXR + JSON sidecar per (scene content hash, spp, seed), reused when present");
  return cmd;
}

int runBenchError(const BenchErrorArgs& args) {
  // Everything the user can get wrong is checked before the first render.
  if (args.spp < 1 || args.spp > 1000000)
    throw InputError("--spp: must be a whole number from 1 to 1000000, got " + std::to_string(args.spp));
  if (args.block < 1) throw InputError("--block: must be at least 1, got " + std::to_string(args.block));
  if (args.repeats < 1 || args.repeats > 1000)
    throw InputError("--repeats: must be from 1 to 1000, got " + std::to_string(args.repeats));
  BenchAxes axes;
  axes.backends = parseNameList("--backend", args.backend, {"cpu", "vulkan"});
  axes.schemes = parseSchemeList("--scheme", args.scheme);
  axes.grids = parseIntList("--grid", args.grid, 2, kMaxLpvResolution);
  axes.steps = parseStepsList("--steps", args.steps);
  axes.shadowMaps = parseIntList("--shadow-map", args.shadowMap, 1, kMaxShadowMap);
  if (args.output.empty() || args.output.back() == '/' || fs::path(args.output).filename() == ".")
    throw InputError("-o: '" + args.output + "' is not a file prefix (PREFIX.csv, PREFIX.json, PREFIX.png)");
  const fs::path csv = args.output + ".csv", json = args.output + ".json", png = args.output + ".png";
  for (const fs::path& f : {csv, json, png}) requireWritableOutput(f);

  std::vector<Scene> scenes;
  std::set<fs::path> seen;
  for (const std::string& file : args.scenes) {
    if (!seen.insert(fs::weakly_canonical(file)).second) throw InputError(file + ": scene listed twice");
    scenes.push_back(loadScene(file));
    const Camera& c = scenes.back().camera;
    if (args.block > std::min(c.width, c.height))
      throw InputError("--block: " + std::to_string(args.block) + " is larger than the image of " + file + " (" +
                       std::to_string(c.width) + "x" + std::to_string(c.height) + ")");
  }
  const fs::path cacheDir = args.cache;
  std::error_code ec;
  fs::create_directories(cacheDir, ec);
  if (ec || !fs::is_directory(cacheDir))
    throw InputError("--cache: " + args.cache + ": cannot create the directory" +
                     (ec ? " (" + ec.message() + ")" : std::string()));
  requireWritableOutput(cacheDir / "probe.exr");

  BenchRunInfo info;
  info.spp = args.spp;
  info.seed = args.seed;
  info.block = args.block;
  info.repeats = args.repeats;
  std::vector<BenchConfig> configs = expandConfigs(axes);
  std::unique_ptr<Backends> vulkan;
  if (std::find(axes.backends.begin(), axes.backends.end(), "vulkan") != axes.backends.end()) {
    std::string why;
    try {
      vulkan = std::make_unique<Backends>(BackendKind::Vulkan);
    } catch (const ResourceError& e) {
      why = e.what();
    }
    if (!vulkan) {
      std::size_t skipped = 0;
      for (const BenchConfig& c : configs) skipped += c.backend == "vulkan";
      const std::string line = "skipped the " + std::to_string(skipped * scenes.size()) +
                               " vulkan configurations: " + why;
      std::fprintf(stderr, "bench-error: WARNING: %s\n", line.c_str());
      info.skipped.push_back(line);
      configs.erase(std::remove_if(configs.begin(), configs.end(),
                                   [](const BenchConfig& c) { return c.backend == "vulkan"; }),
                    configs.end());
      if (configs.empty()) throw ResourceError("--backend: nothing left to run without a Vulkan device");
    }
  }

  // References first, so the configurations' ETA is not thrown off by a path tracer run.
  std::vector<Image> references;
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    Reference ref = obtainReference(args.scenes[s], scenes[s], cacheDir, args.spp, args.seed);
    references.push_back(std::move(ref.image));
    info.references.push_back(ref.info);
  }

  std::vector<BenchRow> rows;
  const std::size_t total = scenes.size() * configs.size();
  const auto start = Clock::now();
  for (std::size_t s = 0; s < scenes.size(); ++s)
    for (const BenchConfig& config : configs) {
      const std::size_t done = rows.size();
      const std::string eta =
          done ? ", ETA " + duration(secondsSince(start) / double(done) * double(total - done)) : std::string();
      std::fprintf(stderr, "bench-error: [%zu/%zu] %s %s %s grid %d steps %s shadow map %d%s\n", done + 1, total,
                   args.scenes[s].c_str(), config.backend.c_str(), lpvSchemeName(config.scheme).c_str(),
                   config.grid, config.stepsText().c_str(), config.shadowMap, eta.c_str());
      rows.push_back(runConfig(args.scenes[s], scenes[s], config, references[s], args, vulkan.get()));
      std::fprintf(stderr, "bench-error:   %.1f ms (median of %d), %d steps, mean relative error %.4g\n",
                   rows.back().ms.total, args.repeats, rows.back().stepsRun, rows.back().metrics.meanRelativeError);
    }
  markParetoFronts(rows);

  writeText(csv, benchCsv(rows));
  writeText(json, benchJson(info, rows));
  printTable(rows);
  std::printf("wrote %s and %s (%zu rows, %s)\n", csv.string().c_str(), json.string().c_str(), rows.size(),
              duration(secondsSince(start)).c_str());
  std::fflush(stdout);

  const std::string plotProblem = makePlot(json, png);
  if (!plotProblem.empty()) {
    // A PNG of an earlier run beside the new tables would be read as this run's plot.
    const bool removed = fs::remove(png, ec);
    throw ResourceError("plot not written: " + plotProblem + (removed ? " (removed the older " + png.string() + ")" : ""));
  }
  std::printf("wrote %s\n", png.string().c_str());
  return 0;
}

}  // namespace sslpv

#pragma once
// The pure parts of `sslpv bench-error` (apps/cmd_bench_error.cpp): the option lists and
// their cross product, medians, the Pareto front, the CSV/JSON tables and the key under
// which a reference image is cached. Kept apart from the rendering so tests can check
// them on hand-made data.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "volume/eval/image_metrics.h"
#include "volume/calibration/lpv_calibration.h"
#include "volume/scene/scene.h"

namespace sslpv {

/// One point of the sweep. `steps` empty means `--steps auto`.
struct BenchConfig {
  std::string backend;  ///< "cpu" or "vulkan"
  LpvScheme scheme = LpvScheme::Calibrated;
  int grid = 32;
  std::optional<int> steps;
  int shadowMap = 256;
  std::string stepsText() const;  ///< "8" or "auto"
  /// The scene's settings with this configuration's overrides.
  LpvSettings apply(LpvSettings settings) const;
};

/// The comma lists of the command line, already parsed.
struct BenchAxes {
  std::vector<std::string> backends;
  std::vector<LpvScheme> schemes;
  std::vector<int> grids;
  std::vector<std::optional<int>> steps;
  std::vector<int> shadowMaps;
};

/// "32,64" -> {32, 64}. InputError naming `option` for an empty list or item, a non-integer,
/// a value outside [lo, hi] or a value listed twice.
std::vector<int> parseIntList(const std::string& option, const std::string& text, int lo, int hi);
/// "8,auto" -> {8, auto}; same rules, numbers from 1 to kMaxSteps.
std::vector<std::optional<int>> parseStepsList(const std::string& option, const std::string& text);
/// Names from `allowed` (case-sensitive); the message lists the allowed ones.
std::vector<std::string> parseNameList(const std::string& option, const std::string& text,
                                       const std::vector<std::string>& allowed);
/// "seed,calibrated" via parseLpvScheme.
std::vector<LpvScheme> parseSchemeList(const std::string& option, const std::string& text);

/// Every combination, backend outermost, then scheme, grid, steps, shadow map: the order
/// of the rows, so cheap and expensive runs of a backend are measured close in time.
std::vector<BenchConfig> expandConfigs(const BenchAxes& axes);

/// Median (mean of the middle two for an even count). Precondition: not empty.
double median(std::vector<double> values);

/// Milliseconds of one configuration, medians over the timed repeats.
struct BenchTimes {
  double voxelize = 0, resample = 0, shadowMap = 0, injection = 0, propagation = 0, shading = 0;
  double total = 0;  ///< wall clock of render() on a fresh renderer (load excluded)
};

struct BenchRow {
  std::string scene;  ///< the scene file as given on the command line
  BenchConfig config;
  int stepsRun = 0;
  int repeats = 0;
  BenchTimes ms;
  ImageMetrics metrics;
  bool pareto = false;
};

/// Errors closer than this fraction of the larger one count as equal on the Pareto front:
/// the two backends render the same image to about 1e-5 and the reference's Monte Carlo
/// noise is far larger, so a slower run whose error is smaller by 0.001 % is no better.
constexpr double kParetoErrorTolerance = 1e-3;

/// For each point (time, error), whether no other point is at least as good in both and
/// strictly better in one (equal points are all on the front), errors compared with
/// kParetoErrorTolerance. Points with a NaN coordinate are never on the front and
/// dominate nothing.
std::vector<bool> paretoFront(const std::vector<double>& time, const std::vector<double>& error);

/// Sets `pareto` on every row: the front of (total ms, mean relative error) among the rows
/// of the same scene.
void markParetoFronts(std::vector<BenchRow>& rows);

/// Header plus one line per row, columns as benchColumns().
std::string benchCsv(const std::vector<BenchRow>& rows);
/// The CSV header's column names, in order.
std::vector<std::string> benchColumns();

/// What a scene's reference was and where it came from, for the JSON record.
struct BenchReferenceInfo {
  std::string scene;       ///< as given on the command line
  std::string cacheFile;   ///< the EXR
  std::string status;      ///< "reused" or "rendered"
  double seconds = 0;      ///< the path tracer's time when it was rendered
};

/// How the sweep was run, for the JSON record.
struct BenchRunInfo {
  int spp = 0;
  std::uint64_t seed = 0;
  int block = 1;
  int repeats = 0;
  std::vector<BenchReferenceInfo> references;
  std::vector<std::string> skipped;  ///< one line per group of configurations not run
};

/// {"spp", "seed", "block", "repeats", "references": [...], "skipped": [...], "rows": [{
/// one key per CSV column, numbers as numbers, steps_requested a string, pareto a bool}]}.
std::string benchJson(const BenchRunInfo& info, const std::vector<BenchRow>& rows);

/// FNV-1a 64 of the scene file's JSON without its "lpv" block (which the reference does
/// not read) and of the bytes of the mesh and material-set files it names,
/// and of `salt` when not empty (what else the reference depends on, such as the
/// tracer's light-connection mode), as 16 hex digits: editing any of them changes the
/// reference. InputError when a file cannot be read.
std::string sceneContentHash(const Scene& scene, const std::string& salt = "");

/// FNV-1a 64 of one file's bytes as 16 hex digits (InputError when unreadable): the
/// sidecar keeps it so that a cached image damaged in any byte is not trusted.
std::string fileContentHash(const std::filesystem::path& file);

/// File name stem of a cached reference: "<scene stem>-<hash>-spp<N>-seed<S>".
std::string referenceCacheStem(const Scene& scene, const std::string& hash, int spp, std::uint64_t seed);

/// The JSON sidecar next to a cached reference EXR.
struct ReferenceSidecar {
  std::string scene, hash;
  std::string imageHash;  ///< fileContentHash of the EXR as written
  int spp = 0;
  std::uint64_t seed = 0;
  double seconds = 0;
  int width = 0, height = 0;
};
std::string referenceSidecarJson(const ReferenceSidecar& sidecar);
/// std::nullopt when the text is not a complete sidecar (a truncated or foreign file).
std::optional<ReferenceSidecar> parseReferenceSidecar(const std::string& text);

}  // namespace sslpv

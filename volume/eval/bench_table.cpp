#include "volume/eval/bench_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "volume/core/error.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> splitCommas(const std::string& option, const std::string& text) {
  std::vector<std::string> items;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ',')) items.push_back(item);
  if (!text.empty() && text.back() == ',') items.emplace_back();
  if (items.empty()) throw InputError(option + ": empty list");
  for (const std::string& i : items)
    if (i.empty()) throw InputError(option + ": empty item in '" + text + "'");
  return items;
}

template <typename T>
void rejectDuplicate(const std::string& option, std::vector<T>& seen, const T& value, const std::string& item) {
  if (std::find(seen.begin(), seen.end(), value) != seen.end())
    throw InputError(option + ": '" + item + "' is listed twice");
  seen.push_back(value);
}

std::optional<int> parseWholeNumber(const std::string& item) {
  std::size_t used = 0;
  try {
    const int value = std::stoi(item, &used);
    if (used == item.size() && std::isdigit(static_cast<unsigned char>(item[0]))) return value;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

std::string fixed(double value, const char* format) {
  if (!std::isfinite(value)) return "nan";
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

/// JSON has no NaN: a metric that could not be computed is null.
nlohmann::ordered_json number(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
}

void hashBytes(std::uint64_t& h, const std::string& bytes) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
}

std::string readBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read (needed for the reference cache)");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

std::string BenchConfig::stepsText() const { return steps ? std::to_string(*steps) : "auto"; }

LpvSettings BenchConfig::apply(LpvSettings settings) const {
  settings.resolution = grid;
  settings.autoSteps = !steps.has_value();
  if (steps) settings.steps = *steps;
  settings.shadowMap = shadowMap;
  settings.scheme = scheme;
  return settings;
}

std::vector<int> parseIntList(const std::string& option, const std::string& text, int lo, int hi) {
  std::vector<int> values;
  for (const std::string& item : splitCommas(option, text)) {
    const std::optional<int> value = parseWholeNumber(item);
    if (!value || *value < lo || *value > hi)
      throw InputError(option + ": '" + item + "' is not a whole number from " + std::to_string(lo) + " to " +
                       std::to_string(hi));
    rejectDuplicate(option, values, *value, item);
  }
  return values;
}

std::vector<std::optional<int>> parseStepsList(const std::string& option, const std::string& text) {
  std::vector<std::optional<int>> values;
  for (const std::string& item : splitCommas(option, text)) {
    std::optional<int> value;
    if (item != "auto") {
      value = parseWholeNumber(item);
      if (!value || *value < 1 || *value > kMaxSteps)
        throw InputError(option + ": '" + item + "' is neither 'auto' nor a whole number from 1 to " +
                         std::to_string(kMaxSteps));
    }
    rejectDuplicate(option, values, value, item);
  }
  return values;
}

std::vector<std::string> parseNameList(const std::string& option, const std::string& text,
                                       const std::vector<std::string>& allowed) {
  std::vector<std::string> values;
  for (const std::string& item : splitCommas(option, text)) {
    if (std::find(allowed.begin(), allowed.end(), item) == allowed.end()) {
      std::string names;
      for (const std::string& a : allowed) names += (names.empty() ? "" : ", ") + a;
      throw InputError(option + ": unknown value '" + item + "' (expected " + names + ")");
    }
    rejectDuplicate(option, values, item, item);
  }
  return values;
}

std::vector<LpvScheme> parseSchemeList(const std::string& option, const std::string& text) {
  std::vector<LpvScheme> values;
  for (const std::string& item : parseNameList(option, text, {"seed", "calibrated"})) {
    LpvScheme scheme{};
    if (!parseLpvScheme(item, scheme)) throw InputError(option + ": unknown scheme '" + item + "'");
    values.push_back(scheme);
  }
  return values;
}

std::vector<BenchConfig> expandConfigs(const BenchAxes& axes) {
  std::vector<BenchConfig> configs;
  for (const std::string& backend : axes.backends)
    for (LpvScheme scheme : axes.schemes)
      for (int grid : axes.grids)
        for (const std::optional<int>& steps : axes.steps)
          for (int shadowMap : axes.shadowMaps) configs.push_back({backend, scheme, grid, steps, shadowMap});
  return configs;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::vector<bool> paretoFront(const std::vector<double>& time, const std::vector<double>& error) {
  const std::size_t n = time.size();
  std::vector<bool> front(n, false);
  auto valid = [&](std::size_t i) { return !std::isnan(time[i]) && !std::isnan(error[i]); };
  // -1: a's error is smaller, 0: equal within the tolerance, 1: larger.
  auto compareError = [](double a, double b) {
    if (std::abs(a - b) <= kParetoErrorTolerance * std::max(std::abs(a), std::abs(b))) return 0;
    return a < b ? -1 : 1;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!valid(i)) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < n && !dominated; ++j) {
      if (j == i || !valid(j) || time[j] > time[i]) continue;
      const int e = compareError(error[j], error[i]);
      dominated = e < 0 || (e == 0 && time[j] < time[i]);
    }
    front[i] = !dominated;
  }
  return front;
}

void markParetoFronts(std::vector<BenchRow>& rows) {
  std::set<std::string> scenes;
  for (const BenchRow& row : rows) scenes.insert(row.scene);
  for (const std::string& scene : scenes) {
    std::vector<std::size_t> index;
    std::vector<double> time, error;
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (rows[i].scene == scene) {
        index.push_back(i);
        time.push_back(rows[i].ms.total);
        error.push_back(rows[i].metrics.meanRelativeError);
      }
    const std::vector<bool> front = paretoFront(time, error);
    for (std::size_t k = 0; k < index.size(); ++k) rows[index[k]].pareto = front[k];
  }
}

std::vector<std::string> benchColumns() {
  return {"scene",          "backend",      "scheme",          "grid",         "steps_requested",
          "steps_run",      "shadow_map",   "voxelize_ms",     "resample_ms",  "shadow_map_ms",
          "injection_ms",   "propagation_ms", "shading_ms",    "total_ms",     "relative_mse",
          "mean_relative_error", "mean_relative_error_r", "mean_relative_error_g", "mean_relative_error_b",
          "rmse",           "ssim",         "mean_ratio",      "pareto"};
}

std::string benchCsv(const std::vector<BenchRow>& rows) {
  std::string text;
  for (const std::string& column : benchColumns()) text += (text.empty() ? "" : ",") + column;
  text += "\n";
  for (const BenchRow& r : rows) {
    const std::vector<std::string> fields = {
        csvField(r.scene), r.config.backend, lpvSchemeName(r.config.scheme), std::to_string(r.config.grid),
        r.config.stepsText(), std::to_string(r.stepsRun), std::to_string(r.config.shadowMap),
        fixed(r.ms.voxelize, "%.3f"), fixed(r.ms.resample, "%.3f"), fixed(r.ms.shadowMap, "%.3f"),
        fixed(r.ms.injection, "%.3f"), fixed(r.ms.propagation, "%.3f"), fixed(r.ms.shading, "%.3f"),
        fixed(r.ms.total, "%.3f"), fixed(r.metrics.relativeMse, "%.6g"), fixed(r.metrics.meanRelativeError, "%.6g"),
        fixed(r.metrics.meanRelativeErrorRgb.r, "%.6g"), fixed(r.metrics.meanRelativeErrorRgb.g, "%.6g"),
        fixed(r.metrics.meanRelativeErrorRgb.b, "%.6g"), fixed(r.metrics.rmse, "%.6g"),
        fixed(r.metrics.ssim, "%.6g"), fixed(r.metrics.meanRatio, "%.6g"), r.pareto ? "1" : "0"};
    std::string line;
    for (const std::string& f : fields) line += (line.empty() ? "" : ",") + f;
    text += line + "\n";
  }
  return text;
}

std::string benchJson(const BenchRunInfo& info, const std::vector<BenchRow>& rows) {
  nlohmann::ordered_json references = nlohmann::ordered_json::array();
  for (const BenchReferenceInfo& r : info.references)
    references.push_back({{"scene", r.scene}, {"cache_file", r.cacheFile}, {"status", r.status},
                          {"seconds", number(r.seconds)}});
  nlohmann::ordered_json table = nlohmann::ordered_json::array();
  for (const BenchRow& r : rows)
    table.push_back({{"scene", r.scene},
                     {"backend", r.config.backend},
                     {"scheme", lpvSchemeName(r.config.scheme)},
                     {"grid", r.config.grid},
                     {"steps_requested", r.config.stepsText()},
                     {"steps_run", r.stepsRun},
                     {"shadow_map", r.config.shadowMap},
                     {"voxelize_ms", number(r.ms.voxelize)},
                     {"resample_ms", number(r.ms.resample)},
                     {"shadow_map_ms", number(r.ms.shadowMap)},
                     {"injection_ms", number(r.ms.injection)},
                     {"propagation_ms", number(r.ms.propagation)},
                     {"shading_ms", number(r.ms.shading)},
                     {"total_ms", number(r.ms.total)},
                     {"relative_mse", number(r.metrics.relativeMse)},
                     {"mean_relative_error", number(r.metrics.meanRelativeError)},
                     {"mean_relative_error_r", number(r.metrics.meanRelativeErrorRgb.r)},
                     {"mean_relative_error_g", number(r.metrics.meanRelativeErrorRgb.g)},
                     {"mean_relative_error_b", number(r.metrics.meanRelativeErrorRgb.b)},
                     {"rmse", number(r.metrics.rmse)},
                     {"ssim", number(r.metrics.ssim)},
                     {"mean_ratio", number(r.metrics.meanRatio)},
                     {"pareto", r.pareto}});
  const nlohmann::ordered_json record = {{"spp", info.spp},         {"seed", info.seed},
                                         {"block", info.block},     {"repeats", info.repeats},
                                         {"references", references}, {"skipped", info.skipped},
                                         {"rows", table}};
  return record.dump(2) + "\n";
}

namespace {

/// OpenVDB stamps every file it writes with a random UUID (36 characters after the 21-byte
/// start of the header) and nothing else differs between two writes of the same grids, so
/// a material set saved again, or regenerated by a script, keeps its cached reference.
std::string withoutVdbFileUuid(std::string bytes) {
  constexpr std::size_t kOffset = 21, kLength = 36;
  if (bytes.size() < kOffset + kLength || bytes.compare(0, 4, " BDV") != 0) return bytes;
  const char* uuid = bytes.data() + kOffset;
  if (uuid[8] != '-' || uuid[13] != '-' || uuid[18] != '-' || uuid[23] != '-') return bytes;
  bytes.replace(kOffset, kLength, kLength, '0');
  return bytes;
}

}  // namespace

std::string sceneContentHash(const Scene& scene, const std::string& salt) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  // Lengths between the parts, so moving bytes from one file to the next changes the key.
  auto add = [&h](const std::string& bytes) {
    hashBytes(h, std::to_string(bytes.size()) + ":");
    hashBytes(h, bytes);
  };
  // The "lpv" block only steers SSLPV, never the path tracer, so trying another grid or
  // step count in the scene file reuses the reference (minutes of tracing) instead of
  // keying a new one. The rest counts by value (layout and key order do not matter); a
  // scene that is not a JSON object counts byte for byte.
  const std::string sceneBytes = readBytes(scene.file);
  nlohmann::json parsed = nlohmann::json::parse(sceneBytes, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_object()) {
    parsed.erase("lpv");
    add("scene without lpv:" + parsed.dump());
  } else {
    add(sceneBytes);
  }
  if (scene.mesh.kind == MeshSource::Kind::File) add(readBytes(scene.mesh.path));
  if (scene.material.vdb) add(withoutVdbFileUuid(readBytes(*scene.material.vdb)));
  if (!salt.empty()) add(salt);
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

std::string fileContentHash(const fs::path& file) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  hashBytes(h, readBytes(file));
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

std::string referenceCacheStem(const Scene& scene, const std::string& hash, int spp, std::uint64_t seed) {
  return scene.file.stem().string() + "-" + hash + "-spp" + std::to_string(spp) + "-seed" + std::to_string(seed);
}

std::string referenceSidecarJson(const ReferenceSidecar& s) {
  const nlohmann::ordered_json record = {{"scene", s.scene},   {"hash", s.hash},       {"image_hash", s.imageHash},
                                         {"spp", s.spp},       {"seed", s.seed},       {"seconds", s.seconds},
                                         {"width", s.width},   {"height", s.height}};
  return record.dump(2) + "\n";
}

std::optional<ReferenceSidecar> parseReferenceSidecar(const std::string& text) {
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    ReferenceSidecar s;
    s.scene = j.at("scene").get<std::string>();
    s.hash = j.at("hash").get<std::string>();
    s.imageHash = j.at("image_hash").get<std::string>();
    s.spp = j.at("spp").get<int>();
    s.seed = j.at("seed").get<std::uint64_t>();
    s.seconds = j.at("seconds").get<double>();
    s.width = j.at("width").get<int>();
    s.height = j.at("height").get<int>();
    return s;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

}  // namespace sslpv

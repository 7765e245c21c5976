#include "volume/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "volume/core/error.h"
#include "volume/core/input_ranges.h"
#include "volume/core/strict_json.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// Turns nlohmann's byte offset into the line and column an editor shows (both from 1).
std::string lineAndColumn(const std::string& text, std::size_t byte) {
  std::size_t index = byte == 0 ? 0 : std::min(byte - 1, text.size());
  std::size_t line = 1, lineStart = 0;
  for (std::size_t i = 0; i < index; ++i) {
    if (text[i] == '\n') {
      ++line;
      lineStart = i + 1;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(index - lineStart + 1);
}

/// nlohmann prefixes its messages with "[json.exception.parse_error.101] parse error at
/// line 1, column 2: "; the location is reported separately, so keep only the reason.
std::string jsonReason(const std::string& what) {
  std::string reason = what;
  if (auto bracket = reason.find("] "); reason.rfind("[json.exception", 0) == 0 &&
                                        bracket != std::string::npos)
    reason = reason.substr(bracket + 2);
  if (reason.rfind("parse error", 0) == 0) {
    if (auto colon = reason.find(": "); colon != std::string::npos) reason = reason.substr(colon + 2);
  }
  return printable(reason);
}

/// Reads values out of the parsed document; every failure names the file and key path.
class SceneReader : public StrictJsonReader {
 public:
  using StrictJsonReader::StrictJsonReader;

  /// Finite is not enough (volume/core/input_ranges.h); the message names the range.
  void requireRange(double value, const std::string& path, double lo, double hi) const {
    if (!(value >= lo && value <= hi))
      fail(path, "must be in [" + formatNumber(lo) + ", " + formatNumber(hi) + "], got " + formatNumber(value));
  }

  /// [x, y, z] with every element in [lo, hi] (a bad one named by its index).
  glm::dvec3 boundedVec3(const json& value, const std::string& path, double lo, double hi) const {
    const glm::dvec3 result = vec3(value, path);
    for (int i = 0; i < 3; ++i) requireRange(result[i], indexPath(path, std::size_t(i)), lo, hi);
    return result;
  }

  /// A point in scene units.
  glm::dvec3 coordinate(const json& value, const std::string& path) const {
    return boundedVec3(value, path, -kMaxCoordinate, kMaxCoordinate);
  }

  /// RGB radiometric quantities and coefficients: finite, non-negative, at most `max`.
  /// One number means the same value in every channel, as in stroke files: a grey
  /// light or material should not need three copies of one number.
  glm::dvec3 nonNegativeRgb(const json& value, const std::string& path, double max) const {
    if (value.is_number()) {
      const double x = number(value, path);
      if (x < 0.0) fail(path, "expected a non-negative number, got " + formatNumber(x));
      requireRange(x, path, 0.0, max);
      return glm::dvec3(x);
    }
    if (!value.is_array())
      fail(path, "expected a non-negative number or an array of 3 non-negative numbers, got " + describeType(value));
    glm::dvec3 result = vec3(value, path, "non-negative numbers");
    for (int i = 0; i < 3; ++i) {
      if (result[i] < 0.0)
        fail(indexPath(path, i), "expected a non-negative number, got " + formatNumber(result[i]));
      requireRange(result[i], indexPath(path, i), 0.0, max);
    }
    return result;
  }

  glm::dvec3 direction(const json& value, const std::string& path) const {
    glm::dvec3 result = boundedVec3(value, path, -kMaxDirectionComponent, kMaxDirectionComponent);
    double length = glm::length(result);
    if (!(length > 0.0)) fail(path, "expected a non-zero direction vector");
    if (!(length >= kMinDirectionLength))
      fail(path, "expected a direction vector of length at least " + formatNumber(kMinDirectionLength) +
                     ", got " + formatNumber(length));
    return result / length;
  }

  double openInterval(const json& value, const std::string& path, double lo, double hi) const {
    double result = number(value, path);
    if (!(result > lo && result < hi))
      fail(path, "must be in (" + formatNumber(lo) + ", " + formatNumber(hi) + "), got " +
                     formatNumber(result));
    return result;
  }

  /// Relative paths are taken from the scene file's folder, so a scene works from any cwd.
  fs::path filePath(const json& value, const std::string& path) const {
    std::string text = string(value, path);
    if (text.empty()) fail(path, "expected a non-empty file path");
    // The operating system ends a path at its first NUL: "a.obj\u0000x" would silently
    // open a.obj.
    if (text.find('\0') != std::string::npos) fail(path, "a file path must not contain a NUL character (\\u0000)");
    return (file().parent_path() / fs::path(text)).lexically_normal();
  }
};

MeshSource parseMesh(const SceneReader& in, const json& node) {
  const std::string path = "mesh";
  in.requireObject(node, path);
  MeshSource mesh;
  const json* file = in.optional(node, "path");
  const json* primitive = in.optional(node, "primitive");
  if (file && primitive) in.fail(path, "give either \"path\" or \"primitive\", not both");
  if (!file && !primitive) in.fail(path, "missing required key \"path\" or \"primitive\"");
  if (file) {
    in.allowOnly(node, path, {"path", "animation"});
    mesh.kind = MeshSource::Kind::File;
    mesh.path = in.filePath(*file, childPath(path, "path"));
    if (const json* animation = in.optional(node, "animation")) {
      const std::string animationPath = childPath(path, "animation");
      if (animation->is_number_integer() || animation->is_number_unsigned()) {
        mesh.animationIndex = in.integer(*animation, animationPath, 0, 1 << 20);
      } else if (animation->is_string()) {
        mesh.animationName = in.string(*animation, animationPath);
        if (mesh.animationName.empty()) in.fail(animationPath, "expected a clip name or index, got an empty string");
      } else {
        in.fail(animationPath, "expected a clip name (string) or index (whole number), got " + describeType(*animation));
      }
    }
    return mesh;
  }
  std::string kind = in.string(*primitive, childPath(path, "primitive"));
  if (kind == "box") {
    in.allowOnly(node, path, {"primitive", "min", "max", "segments"});
    mesh.kind = MeshSource::Kind::Box;
    if (const json* v = in.optional(node, "segments")) {
      const std::string segmentsPath = childPath(path, "segments");
      if (!v->is_array() || v->size() != 3)
        in.fail(segmentsPath, "expected an array of 3 whole numbers in [1, " + std::to_string(kMaxBoxSegments) +
                                  "], got " + describeType(*v));
      for (int i = 0; i < 3; ++i)
        mesh.boxSegments[i] = in.integer((*v)[std::size_t(i)], indexPath(segmentsPath, std::size_t(i)), 1,
                                         kMaxBoxSegments);
    }
    mesh.boxMin = in.coordinate(in.required(node, path, "min"), childPath(path, "min"));
    mesh.boxMax = in.coordinate(in.required(node, path, "max"), childPath(path, "max"));
    static const char* const kAxis[] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      if (!(mesh.boxMin[i] < mesh.boxMax[i]))
        in.fail(childPath(path, "max"), std::string("must exceed mesh.min on every axis (") +
                                            kAxis[i] + ": " + formatNumber(mesh.boxMax[i]) +
                                            " <= " + formatNumber(mesh.boxMin[i]) + ")");
    }
  } else if (kind == "sphere") {
    in.allowOnly(node, path, {"primitive", "center", "radius"});
    mesh.kind = MeshSource::Kind::Sphere;
    mesh.center = in.coordinate(in.required(node, path, "center"), childPath(path, "center"));
    std::string radiusPath = childPath(path, "radius");
    mesh.radius = in.number(in.required(node, path, "radius"), radiusPath);
    if (!(mesh.radius > 0.0)) in.fail(radiusPath, "must be positive, got " + formatNumber(mesh.radius));
    in.requireRange(mesh.radius, radiusPath, kMinPrimitiveSize, kMaxCoordinate);
  } else {
    in.fail(childPath(path, "primitive"),
            "unknown primitive \"" + printable(kind) + "\" (accepted: \"box\", \"sphere\")");
  }
  return mesh;
}

Transform parseTransform(const SceneReader& in, const json& node) {
  const std::string path = "transform";
  in.requireObject(node, path);
  in.allowOnly(node, path, {"translate", "rotate_deg", "scale"});
  Transform transform;
  if (const json* v = in.optional(node, "translate")) transform.translate = in.coordinate(*v, childPath(path, "translate"));
  if (const json* v = in.optional(node, "rotate_deg"))
    transform.rotateDeg = in.boundedVec3(*v, childPath(path, "rotate_deg"), -kMaxRotationDeg, kMaxRotationDeg);
  if (const json* v = in.optional(node, "scale")) {
    std::string scalePath = childPath(path, "scale");
    transform.scale = in.number(*v, scalePath);
    if (!(transform.scale > 0.0)) in.fail(scalePath, "must be positive, got " + formatNumber(transform.scale));
    in.requireRange(transform.scale, scalePath, kMinScale, kMaxScale);
  }
  return transform;
}

float parseG(const SceneReader& in, const json& value, const std::string& path) {
  double g = in.number(value, path);
  if (!(std::abs(g) < 1.0)) in.fail(path, "must be in (-1, 1), got " + formatNumber(g));
  return static_cast<float>(g);
}

MaterialSpec parseMaterial(const SceneReader& in, const json& node, double unitMm) {
  const std::string path = "material";
  in.requireObject(node, path);
  in.allowOnly(node, path, {"base", "vdb", "ior"});
  MaterialSpec spec;

  const std::string basePath = childPath(path, "base");
  const json& base = in.required(node, path, "base");
  in.requireObject(base, basePath);
  if (const json* preset = in.optional(base, "preset")) {
    in.allowOnly(base, basePath, {"preset", "g"});
    std::string presetPath = childPath(basePath, "preset");
    spec.presetName = in.string(*preset, presetPath);
    float g = 0.0f;
    if (const json* v = in.optional(base, "g")) g = parseG(in, *v, childPath(basePath, "g"));
    std::optional<MaterialSample> sample = presetMaterial(spec.presetName, g, unitMm);
    if (!sample)
      in.fail(presetPath, "unknown preset \"" + printable(spec.presetName) + "\" (accepted: " +
                              presetNames() + ")");
    spec.base = *sample;
  } else {
    in.allowOnly(base, basePath, {"sigma_t", "sigma_s", "g", "preset"});
    std::string tPath = childPath(basePath, "sigma_t"), sPath = childPath(basePath, "sigma_s");
    glm::dvec3 sigmaT = in.nonNegativeRgb(in.required(base, basePath, "sigma_t"), tPath, kMaxSigma);
    glm::dvec3 sigmaS = in.nonNegativeRgb(in.required(base, basePath, "sigma_s"), sPath, kMaxSigma);
    for (int c = 0; c < 3; ++c) {
      if (sigmaS[c] > sigmaT[c])
        in.fail(indexPath(sPath, c), "exceeds sigma_t (" + formatNumber(sigmaS[c]) + " > " +
                                         formatNumber(sigmaT[c]) + "): albedo above 1");
    }
    spec.base.sigmaT = glm::vec3(sigmaT);
    spec.base.sigmaS = glm::vec3(sigmaS);
    // Rounding to float must not push the albedo above 1 when sigma_s == sigma_t.
    spec.base.sigmaS = glm::min(spec.base.sigmaS, spec.base.sigmaT);
    if (const json* v = in.optional(base, "g")) spec.base.g = parseG(in, *v, childPath(basePath, "g"));
  }

  if (const json* v = in.optional(node, "vdb")) spec.vdb = in.filePath(*v, childPath(path, "vdb"));
  if (const json* v = in.optional(node, "ior")) {
    std::string iorPath = childPath(path, "ior");
    spec.ior = in.number(*v, iorPath);
    // Relative indices outside this range do not occur in real materials; such a value is
    // almost certainly a typo (e.g. 15 for 1.5).
    if (!(spec.ior >= 0.2 && spec.ior <= 5.0))
      in.fail(iorPath, "must be in [0.2, 5], got " + formatNumber(spec.ior));
  }
  return spec;
}

Light parseLight(const SceneReader& in, const json& node, const std::string& path) {
  in.requireObject(node, path);
  Light light;
  std::string typePath = childPath(path, "type");
  std::string type = in.string(in.required(node, path, "type"), typePath);
  auto rgb = [&](const char* key) {
    return glm::vec3(in.nonNegativeRgb(in.required(node, path, key), childPath(path, key), kMaxRadiometric));
  };
  auto vec = [&](const char* key) { return in.coordinate(in.required(node, path, key), childPath(path, key)); };
  auto dir = [&](const char* key) {
    return in.direction(in.required(node, path, key), childPath(path, key));
  };
  if (type == "point") {
    in.allowOnly(node, path, {"type", "position", "intensity"});
    light.type = Light::Type::Point;
    light.position = vec("position");
    light.intensity = rgb("intensity");
  } else if (type == "spot") {
    in.allowOnly(node, path, {"type", "position", "direction", "fov_deg", "intensity"});
    light.type = Light::Type::Spot;
    light.position = vec("position");
    light.direction = dir("direction");
    light.fovDeg = in.openInterval(in.required(node, path, "fov_deg"), childPath(path, "fov_deg"), 0.0, 180.0);
    light.intensity = rgb("intensity");
  } else if (type == "directional") {
    in.allowOnly(node, path, {"type", "direction", "irradiance"});
    light.type = Light::Type::Directional;
    light.direction = dir("direction");
    light.irradiance = rgb("irradiance");
  } else {
    in.fail(typePath, "unknown light type \"" + printable(type) +
                          "\" (accepted: \"point\", \"spot\", \"directional\")");
  }
  return light;
}

Camera parseCamera(const SceneReader& in, const json& node) {
  const std::string path = "camera";
  in.requireObject(node, path);
  in.allowOnly(node, path, {"position", "target", "up", "fov_y_deg", "width", "height"});
  Camera camera;
  camera.position = in.coordinate(in.required(node, path, "position"), childPath(path, "position"));
  camera.target = in.coordinate(in.required(node, path, "target"), childPath(path, "target"));
  if (const json* v = in.optional(node, "up")) camera.up = in.direction(*v, childPath(path, "up"));
  camera.fovYDeg = in.openInterval(in.required(node, path, "fov_y_deg"), childPath(path, "fov_y_deg"), 0.0, 180.0);
  camera.width = in.integer(in.required(node, path, "width"), childPath(path, "width"), 1, kMaxImageSide);
  camera.height = in.integer(in.required(node, path, "height"), childPath(path, "height"), 1, kMaxImageSide);

  glm::dvec3 view = camera.target - camera.position;
  double viewLength = glm::length(view);
  if (!(viewLength > 0.0)) in.fail(childPath(path, "target"), "equals camera.position: the view direction is undefined");
  // Closer than float resolves at these coordinates, the view direction would be noise.
  const double resolvable = kMinDirectionLength * std::max({1.0, glm::length(camera.position), glm::length(camera.target)});
  if (!(viewLength >= resolvable))
    in.fail(childPath(path, "target"), "is only " + formatNumber(viewLength) + " from camera.position (at least " +
                                           formatNumber(resolvable) + " needed for a defined view direction)");
  // A nearly parallel up vector leaves the camera's roll undefined (and its basis noisy).
  if (glm::length(glm::cross(view / viewLength, camera.up)) < 1e-6)
    in.fail(childPath(path, "up"), "is parallel to the view direction (camera.target - camera.position)");
  return camera;
}

LpvSettings parseLpv(const SceneReader& in, const json& node) {
  const std::string path = "lpv";
  in.requireObject(node, path);
  in.allowOnly(node, path, {"resolution", "steps", "shadow_map", "scheme"});
  LpvSettings lpv;
  if (const json* v = in.optional(node, "resolution"))
    lpv.resolution = in.integer(*v, childPath(path, "resolution"), 2, kMaxLpvResolution);
  if (const json* v = in.optional(node, "steps")) {
    std::string stepsPath = childPath(path, "steps");
    if (v->is_string()) {
      if (v->get<std::string>() != "auto")
        in.fail(stepsPath, "expected an integer in [1, " + std::to_string(kMaxSteps) +
                               "] or \"auto\", got \"" + printable(v->get<std::string>()) + "\"");
      lpv.autoSteps = true;
    } else {
      lpv.steps = in.integer(*v, stepsPath, 1, kMaxSteps);
    }
  }
  if (const json* v = in.optional(node, "shadow_map"))
    lpv.shadowMap = in.integer(*v, childPath(path, "shadow_map"), 1, kMaxShadowMap);
  if (const json* v = in.optional(node, "scheme")) {
    if (!v->is_string() || !parseLpvScheme(v->get<std::string>(), lpv.scheme))
      in.fail(childPath(path, "scheme"), "expected \"calibrated\" or \"seed\"");
  }
  return lpv;
}

}  // namespace

glm::dmat4 Transform::matrix() const {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
  m = glm::rotate(m, glm::radians(rotateDeg.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(rotateDeg.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(rotateDeg.x), glm::dvec3(1, 0, 0));
  return glm::scale(m, glm::dvec3(scale));
}

Scene parseScene(const std::string& jsonText, const fs::path& file) {
  if (jsonText.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(file.string() + ": empty file");
  json root;
  try {
    root = json::parse(jsonText, JsonPathTracker(file));
  } catch (const json::parse_error& e) {
    throw InputError(file.string() + ": " + lineAndColumn(jsonText, e.byte) +
                     ": malformed JSON: " + jsonReason(e.what()));
  } catch (const json::exception& e) {
    throw InputError(file.string() + ": malformed JSON: " + jsonReason(e.what()));
  }

  SceneReader in(file);
  if (!root.is_object()) in.fail("", "expected a JSON object at the top level, got " + describeType(root));
  in.allowOnly(root, "", {"units", "mesh", "transform", "material", "lights", "camera", "lpv", "deformers"});

  Scene scene;
  scene.file = file;
  if (const json* v = in.optional(root, "units")) {
    scene.units = in.string(*v, "units");
    std::optional<double> mm = unitInMm(scene.units);
    if (!mm) in.fail("units", "unknown unit \"" + printable(scene.units) + "\" (accepted: \"mm\", \"cm\", \"m\", \"in\")");
    scene.unitInMm = *mm;
  }
  scene.mesh = parseMesh(in, in.required(root, "", "mesh"));
  if (const json* v = in.optional(root, "transform")) scene.transform = parseTransform(in, *v);
  scene.material = parseMaterial(in, in.required(root, "", "material"), scene.unitInMm);

  const json& lights = in.required(root, "", "lights");
  if (!lights.is_array()) in.fail("lights", "expected an array of lights, got " + describeType(lights));
  if (lights.empty()) in.fail("lights", "expected at least one light");
  for (std::size_t i = 0; i < lights.size(); ++i)
    scene.lights.push_back(parseLight(in, lights[i], indexPath("lights", i)));

  scene.camera = parseCamera(in, in.required(root, "", "camera"));
  if (const json* v = in.optional(root, "lpv")) {
    scene.lpv = parseLpv(in, *v);
  } else {
    // A scene that says nothing about the lattice asks for a converged image, not for
    // whatever a fixed step count happens to reach (8 steps leave a large object dark).
    scene.lpv.autoSteps = true;
  }
  if (const json* v = in.optional(root, "deformers")) scene.deformers = parseDeformers(in, *v);
  // One pose source at a time: the deformers act on rest space, which a skinned clip
  // already moves; composing the two is not defined yet.
  if (scene.mesh.animated() && !scene.deformers.empty())
    in.fail("deformers", "cannot be combined with mesh.animation (a skinned clip); use one or the other");
  return scene;
}

Scene sceneAtTime(const Scene& scene, double t) {
  if (!(std::abs(t) <= kMaxTime))
    throw InputError("--time: must be a number in [" + formatNumber(-kMaxTime) + ", " + formatNumber(kMaxTime) +
                     "], got " + formatNumber(t));
  Scene posed = scene;
  posed.time = t;
  return posed;
}

Scene loadScene(const fs::path& file) {
  return parseScene(readInputFile(file, "scene file"), file);
}

LpvSettings applyLpvFlags(LpvSettings settings, const LpvFlags& flags) {
  if (flags.grid) {
    if (*flags.grid < 2 || *flags.grid > kMaxLpvResolution)
      throw InputError("--grid: must be between 2 and " + std::to_string(kMaxLpvResolution) + ", got " +
                       std::to_string(*flags.grid));
    settings.resolution = *flags.grid;
  }
  if (!flags.steps.empty()) {
    if (flags.steps == "auto") {
      settings.autoSteps = true;
    } else {
      std::size_t used = 0;
      int steps = -1;
      try {
        steps = std::stoi(flags.steps, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != flags.steps.size() || steps < 1 || steps > kMaxSteps)
        throw InputError("--steps: expected 'auto' or a whole number from 1 to " + std::to_string(kMaxSteps) +
                         ", got '" + flags.steps + "'");
      settings.steps = steps;
      settings.autoSteps = false;
    }
  }
  if (flags.shadowMap) {
    if (*flags.shadowMap < 1 || *flags.shadowMap > kMaxShadowMap)
      throw InputError("--shadow-map: must be between 1 and " + std::to_string(kMaxShadowMap));
    settings.shadowMap = *flags.shadowMap;
  }
  if (!flags.scheme.empty() && !parseLpvScheme(flags.scheme, settings.scheme))
    throw InputError("--scheme: unknown scheme '" + flags.scheme + "' (calibrated, seed)");
  return settings;
}

}  // namespace sslpv

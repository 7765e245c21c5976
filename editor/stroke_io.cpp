// Stroke files (format in stroke_io.h): strict parsing with key paths in every message.
#include "editor/stroke_io.h"

#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <utility>

#include "volume/core/error.h"
#include "volume/core/strict_json.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// The stroke file's own value kinds on top of the strict reader.
class Reader : public StrictJsonReader {
 public:
  using StrictJsonReader::StrictJsonReader;

  /// [r,g,b] or one number for all three channels, each in [lo, hi].
  glm::dvec3 rgb(const json& v, const std::string& path, double lo, double hi, const char* range) const {
    if (v.is_number()) {
      const double x = number(v, path);
      if (!(x >= lo && x <= hi)) fail(path, std::string("must be ") + range + ", got " + formatNumber(x));
      return glm::dvec3(x);
    }
    if (!v.is_array()) fail(path, "expected a number or an array of 3 numbers, got " + describeType(v));
    const glm::dvec3 result = vec3OfNumbers(v, path);
    for (int i = 0; i < 3; ++i)
      if (!(result[i] >= lo && result[i] <= hi))
        fail(indexPath(path, std::size_t(i)), std::string("must be ") + range + ", got " + formatNumber(result[i]));
    return result;
  }
};

constexpr double kInf = HUGE_VAL;

const std::initializer_list<std::pair<const char*, BrushChannel>> kChannelNames = {
    {"sigma_t", BrushChannel::SigmaT},
    {"sigma_s", BrushChannel::SigmaS},
    {"g", BrushChannel::G},
    {"albedo_mfp", BrushChannel::AlbedoMfp},
    {"preset", BrushChannel::Preset}};
const std::initializer_list<std::pair<const char*, BrushMode>> kModeNames = {{"set", BrushMode::Set},
                                                                             {"add", BrushMode::Add},
                                                                             {"multiply", BrushMode::Multiply},
                                                                             {"smooth", BrushMode::Smooth},
                                                                             {"erase", BrushMode::Erase}};
const std::initializer_list<std::pair<const char*, BrushFalloff>> kFalloffNames = {
    {"constant", BrushFalloff::Constant},
    {"linear", BrushFalloff::Linear},
    {"smooth", BrushFalloff::Smooth},
    {"gaussian", BrushFalloff::Gaussian}};
const std::initializer_list<std::pair<const char*, int>> kAxisNames = {{"x", 0}, {"y", 1}, {"z", 2}};

template <class Enum>
const char* nameOf(std::initializer_list<std::pair<const char*, Enum>> names, Enum value) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return "";
}

void parseValue(const Reader& in, const json& v, const std::string& path, Brush& b) {
  const bool set = b.mode == BrushMode::Set, multiply = b.mode == BrushMode::Multiply;
  switch (b.channel) {
    case BrushChannel::SigmaT:
    case BrushChannel::SigmaS:
      b.rgb = set        ? in.rgb(v, path, 0.0, kInf, "a non-negative sigma")
              : multiply ? in.rgb(v, path, 0.0, kInf, "a non-negative factor")
                         : in.rgb(v, path, -kInf, kInf, "finite");
      break;
    case BrushChannel::G:
      b.scalar = in.number(v, path);
      if (set && !(std::abs(b.scalar) <= double(kBrushMaxG)))
        in.fail(path, "g must be in [-0.99, 0.99], got " + formatNumber(b.scalar));
      break;
    case BrushChannel::AlbedoMfp:
      in.requireObject(v, path);
      in.allowOnly(v, path, {"albedo", "mean_free_path"});
      b.albedo = in.rgb(in.required(v, path, "albedo"), childPath(path, "albedo"), 0.0, 1.0, "in [0, 1]");
      b.meanFreePath = in.rgb(in.required(v, path, "mean_free_path"), childPath(path, "mean_free_path"),
                              std::nextafter(0.0, 1.0), kInf, "positive");
      break;
    case BrushChannel::Preset:
      b.preset = in.string(v, path);
      if (!presetMaterial(b.preset, 0.0f, 1.0))
        in.fail(path, "unknown preset \"" + printable(b.preset) + "\" (accepted: " + presetNames() + ")");
      break;
    case BrushChannel::Colour:
    case BrushChannel::All:
      break;
  }
}

/// The artist's form of a set stroke: "colour" (or "color") + "scatter_distance" (+ "g")
/// instead of "channel" + "value". Returns whether the stroke uses it; exactly one form.
/// `bare`, when given, is the material of a stroke that names none (no "channel", "value"
/// or colour-form key, mode "set" or absent).
bool parseArtistForm(const Reader& in, const json& node, const std::string& path, Brush& b,
                     const ArtistParams* bare) {
  const json* colour = in.optional(node, "colour");
  const json* color = in.optional(node, "color");
  const json* distance = in.optional(node, "scatter_distance");
  const json* g = in.optional(node, "g");
  if (!colour && !color && !distance && !g) {
    const json* mode = in.optional(node, "mode");
    if (!bare || in.optional(node, "channel") || in.optional(node, "value") ||
        (mode && !(mode->is_string() && mode->get<std::string>() == "set")))
      return false;
    b.channel = BrushChannel::Colour;
    b.mode = BrushMode::Set;
    b.artist = *bare;
    return true;
  }
  if (colour && color) in.fail(childPath(path, "color"), "duplicates \"colour\" (give one spelling)");
  const char* colourKey = colour ? "colour" : "color";
  if (!colour) colour = color;
  for (const char* key : {"channel", "value"})
    if (in.optional(node, key))
      in.fail(childPath(path, key), "a stroke gives either \"colour\" + \"scatter_distance\" (+ \"g\") or "
                                    "\"channel\" + \"value\", not both");
  if (!colour)
    in.fail(path, std::string("missing required key \"colour\" (\"") + (distance ? "scatter_distance" : "g") +
                      "\" belongs to the colour form)");
  if (!distance) in.fail(path, "missing required key \"scatter_distance\" (\"" + std::string(colourKey) + "\" needs one)");
  b.channel = BrushChannel::Colour;
  b.mode = BrushMode::Set;
  b.artist.colour = in.rgb(*colour, childPath(path, colourKey), 0.0, 1.0, "a surface colour in [0, 1]");
  b.artist.scatterDistance =
      in.rgb(*distance, childPath(path, "scatter_distance"), kMinScatterDistance, kInf, "a distance >= 1e-36");
  b.artist.g = 0.0;
  if (g) {
    b.artist.g = in.number(*g, childPath(path, "g"));
    if (!(std::abs(b.artist.g) <= kArtistMaxG))
      in.fail(childPath(path, "g"), "must be in [-0.99, 0.99], got " + formatNumber(b.artist.g));
  }
  return true;
}

Stroke parseStroke(const Reader& in, const json& node, const std::string& path, const ArtistParams* bare) {
  in.requireObject(node, path);
  in.allowOnly(node, path,
               {"channel", "mode", "value", "colour", "color", "scatter_distance", "g", "radius", "falloff",
                "strength", "mirror", "points", "rays", "depth"});
  Stroke stroke;
  Brush& b = stroke.brush;
  const bool artist = parseArtistForm(in, node, path, b, bare);
  if (const json* v = in.optional(node, "mode"); v || !artist)
    b.mode = in.choice(in.required(node, path, "mode"), childPath(path, "mode"), "mode", kModeNames);
  const bool valued = b.mode == BrushMode::Set || b.mode == BrushMode::Add || b.mode == BrushMode::Multiply;
  const char* modeName = nameOf(kModeNames, b.mode);
  if (artist) {
    if (b.mode != BrushMode::Set)
      in.fail(childPath(path, "mode"), std::string("the colour form takes mode \"set\" only, got \"") + modeName + "\"");
  } else if (const json* v = in.optional(node, "channel")) {
    b.channel = in.choice(*v, childPath(path, "channel"), "channel", kChannelNames);
  } else if (valued) {
    in.fail(path, std::string("missing required key \"channel\" (mode \"") + modeName + "\" needs one)");
  }
  if ((b.channel == BrushChannel::AlbedoMfp || b.channel == BrushChannel::Preset) && b.mode != BrushMode::Set)
    in.fail(childPath(path, "mode"), std::string("channel \"") + nameOf(kChannelNames, b.channel) +
                                         "\" takes mode \"set\" only, got \"" + modeName + "\"");
  if (const json* v = artist ? nullptr : in.optional(node, "value")) {
    if (!valued) in.fail(childPath(path, "value"), std::string("not used by mode \"") + modeName + "\" (remove it)");
    parseValue(in, *v, childPath(path, "value"), b);
  } else if (valued && !artist) {
    in.fail(path, std::string("missing required key \"value\" (mode \"") + modeName + "\" needs one)");
  }
  const std::string radiusPath = childPath(path, "radius");
  b.radius = in.number(in.required(node, path, "radius"), radiusPath);
  if (!(b.radius > 0.0)) in.fail(radiusPath, "must be positive, got " + formatNumber(b.radius));
  if (const json* v = in.optional(node, "falloff"))
    b.falloff = in.choice(*v, childPath(path, "falloff"), "falloff", kFalloffNames);
  if (const json* v = in.optional(node, "strength")) {
    b.strength = in.number(*v, childPath(path, "strength"));
    if (!(b.strength >= 0.0 && b.strength <= 1.0))
      in.fail(childPath(path, "strength"), "must be in [0, 1], got " + formatNumber(b.strength));
  }
  if (const json* v = in.optional(node, "mirror")) {
    const std::string mirrorPath = childPath(path, "mirror");
    in.requireObject(*v, mirrorPath);
    in.allowOnly(*v, mirrorPath, {"axis", "at"});
    BrushMirror mirror;
    mirror.axis = in.choice(in.required(*v, mirrorPath, "axis"), childPath(mirrorPath, "axis"), "axis", kAxisNames);
    if (const json* at = in.optional(*v, "at")) mirror.at = in.number(*at, childPath(mirrorPath, "at"));
    b.mirror = mirror;
  }

  const json* points = in.optional(node, "points");
  const json* rays = in.optional(node, "rays");
  if (!points == !rays) in.fail(path, "expected exactly one of \"points\" and \"rays\"");
  if (points) {
    const std::string p = childPath(path, "points");
    if (!points->is_array() || points->empty())
      in.fail(p, "expected a non-empty array of [x,y,z] points, got " + describeType(*points));
    for (std::size_t i = 0; i < points->size(); ++i)
      stroke.points.push_back(in.vec3OfNumbers((*points)[i], indexPath(p, i)));
    if (in.optional(node, "depth")) in.fail(childPath(path, "depth"), "only used with \"rays\"");
  } else {
    const std::string p = childPath(path, "rays");
    if (!rays->is_array() || rays->empty())
      in.fail(p, "expected a non-empty array of rays, got " + describeType(*rays));
    for (std::size_t i = 0; i < rays->size(); ++i) {
      const json& ray = (*rays)[i];
      const std::string rp = indexPath(p, i);
      in.requireObject(ray, rp);
      in.allowOnly(ray, rp, {"origin", "direction"});
      SurfaceRay r;
      r.origin = in.vec3OfNumbers(in.required(ray, rp, "origin"), childPath(rp, "origin"));
      r.direction = in.vec3OfNumbers(in.required(ray, rp, "direction"), childPath(rp, "direction"));
      if (!(r.direction.x != 0.0 || r.direction.y != 0.0 || r.direction.z != 0.0))
        in.fail(childPath(rp, "direction"), "must be a non-zero vector");
      stroke.rays.push_back(r);
    }
    if (const json* v = in.optional(node, "depth")) {
      b.depth = in.number(*v, childPath(path, "depth"));
      if (!(b.depth >= 0.0)) in.fail(childPath(path, "depth"), "must be non-negative, got " + formatNumber(b.depth));
    }
  }
  // A safety net: the engine's own checks must agree with the ones above.
  if (std::string problem = brushProblem(b); !problem.empty()) in.fail(path, problem);
  return stroke;
}

nlohmann::ordered_json rgbJson(const glm::dvec3& v) { return nlohmann::ordered_json::array({v.x, v.y, v.z}); }

}  // namespace

std::vector<Stroke> parseStrokes(const std::string& jsonText, const fs::path& file, const ArtistParams* bare) {
  if (jsonText.find_first_not_of(" \t\r\n") == std::string::npos) throw InputError(file.string() + ": empty file");
  JsonPathTracker tracker(file);
  json root;
  try {
    root = json::parse(jsonText, tracker);
  } catch (const json::parse_error& e) {
    std::string reason = e.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error ..."
    if (auto at = reason.find("parse error"); at != std::string::npos) reason = reason.substr(at);
    const std::string path = tracker.path();
    throw InputError(file.string() + ": " + (path.empty() ? "" : path + ": ") + "malformed JSON (" + printable(reason) +
                     ")");
  } catch (const json::exception& e) {
    throw InputError(file.string() + ": malformed JSON (" + printable(e.what()) + ")");
  }
  Reader in(file);
  if (!root.is_object()) in.fail("", "expected a JSON object at the top level, got " + describeType(root));
  in.allowOnly(root, "", {"strokes"});
  const json& strokes = in.required(root, "", "strokes");
  if (!strokes.is_array()) in.fail("strokes", "expected an array of strokes, got " + describeType(strokes));
  std::vector<Stroke> result;
  for (std::size_t i = 0; i < strokes.size(); ++i)
    result.push_back(parseStroke(in, strokes[i], indexPath("strokes", i), bare));
  return result;
}

std::vector<Stroke> loadStrokes(const fs::path& file, const ArtistParams* bare) {
  return parseStrokes(readInputFile(file, "stroke file"), file, bare);
}

std::string formatStrokes(const std::vector<Stroke>& strokes) {
  using ojson = nlohmann::ordered_json;
  ojson list = ojson::array();
  for (const Stroke& stroke : strokes) {
    const Brush& b = stroke.brush;
    ojson s = ojson::object();
    if (b.channel != BrushChannel::All && b.channel != BrushChannel::Colour)
      s["channel"] = nameOf(kChannelNames, b.channel);
    s["mode"] = nameOf(kModeNames, b.mode);
    if (b.channel == BrushChannel::Colour) {
      s["colour"] = rgbJson(b.artist.colour);
      s["scatter_distance"] = rgbJson(b.artist.scatterDistance);
      s["g"] = b.artist.g;
    } else if (b.mode == BrushMode::Set || b.mode == BrushMode::Add || b.mode == BrushMode::Multiply) {
      switch (b.channel) {
        case BrushChannel::SigmaT:
        case BrushChannel::SigmaS:
          s["value"] = rgbJson(b.rgb);
          break;
        case BrushChannel::G:
          s["value"] = b.scalar;
          break;
        case BrushChannel::AlbedoMfp:
          s["value"] = {{"albedo", rgbJson(b.albedo)}, {"mean_free_path", rgbJson(b.meanFreePath)}};
          break;
        case BrushChannel::Preset:
          s["value"] = b.preset;
          break;
        case BrushChannel::Colour:
        case BrushChannel::All:
          break;
      }
    }
    s["radius"] = b.radius;
    s["falloff"] = nameOf(kFalloffNames, b.falloff);
    s["strength"] = b.strength;
    if (b.mirror) {
      ojson mirror = {{"axis", nameOf(kAxisNames, b.mirror->axis)}};
      if (b.mirror->at) mirror["at"] = *b.mirror->at;
      s["mirror"] = mirror;
    }
    if (!stroke.rays.empty()) {
      ojson rays = ojson::array();
      for (const SurfaceRay& r : stroke.rays)
        rays.push_back({{"origin", rgbJson(r.origin)}, {"direction", rgbJson(r.direction)}});
      s["rays"] = rays;
      if (b.depth != 0.0) s["depth"] = b.depth;
    } else {
      ojson points = ojson::array();
      for (const glm::dvec3& p : stroke.points) points.push_back(rgbJson(p));
      s["points"] = points;
    }
    list.push_back(s);
  }
  return ojson{{"strokes", list}}.dump(1) + "\n";
}

}  // namespace sslpv

#include "editor/brush_controls.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <glm/common.hpp>
#include <vector>

#include "volume/scene/material.h"
#include "volume/material/material_set.h"

namespace sslpv {
namespace {

constexpr double kValueStep = 1.25;
constexpr double kGStep = 0.05;
constexpr double kAlbedoStep = 0.02;
// Scatter distances beyond this are an empty medium for any object; keeps repeated x1.25
// steps finite.
constexpr double kMaxScatterDistance = 1e30;

bool valuedMode(BrushMode mode) {
  return mode == BrushMode::Set || mode == BrushMode::Add || mode == BrushMode::Multiply;
}

}  // namespace

// The modes each channel accepts, in cycling order (brushProblem's rules).
std::vector<BrushMode> BrushControls::modesOf(BrushChannel channel) {
  switch (channel) {
    case BrushChannel::Colour:
    case BrushChannel::AlbedoMfp:
    case BrushChannel::Preset:
      return {BrushMode::Set};
    case BrushChannel::All:
      return {BrushMode::Smooth, BrushMode::Erase};
    default:
      return {BrushMode::Set, BrushMode::Add, BrushMode::Multiply, BrushMode::Smooth, BrushMode::Erase};
  }
}

namespace {

const char* channelName(BrushChannel c) {
  switch (c) {
    case BrushChannel::Colour: return "colour";
    case BrushChannel::SigmaT: return "sigma_t";
    case BrushChannel::SigmaS: return "sigma_s";
    case BrushChannel::G: return "g";
    case BrushChannel::AlbedoMfp: return "albedo+mfp";
    case BrushChannel::Preset: return "preset";
    case BrushChannel::All: return "all channels";
  }
  return "?";
}

const char* modeName(BrushMode m) {
  switch (m) {
    case BrushMode::Set: return "set";
    case BrushMode::Add: return "add";
    case BrushMode::Multiply: return "multiply";
    case BrushMode::Smooth: return "smooth";
    case BrushMode::Erase: return "erase";
  }
  return "?";
}

const char* falloffName(BrushFalloff f) {
  switch (f) {
    case BrushFalloff::Constant: return "constant";
    case BrushFalloff::Linear: return "linear";
    case BrushFalloff::Smooth: return "smooth";
    case BrushFalloff::Gaussian: return "gaussian";
  }
  return "?";
}

std::string formatRgb(const glm::dvec3& v) {
  char text[96];
  if (v.x == v.y && v.y == v.z)
    std::snprintf(text, sizeof text, "%.3g", v.x);
  else
    std::snprintf(text, sizeof text, "[%.3g %.3g %.3g]", v.x, v.y, v.z);
  return text;
}

/// Numbers separated by commas and/or spaces, all of the text used; empty on any junk.
std::vector<double> parseNumbers(const std::string& text) {
  std::vector<double> values;
  const char* p = text.c_str();
  while (true) {
    while (*p == ' ' || *p == ',') ++p;
    if (!*p) break;
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || !std::isfinite(v) || (*end && *end != ' ' && *end != ',')) return {};
    values.push_back(v);
    p = end;
  }
  return values;
}

}  // namespace

BrushControls::BrushControls(const MaterialSample& base, double objectWorldExtent, std::string sceneUnits,
                             double ior)
    : ior_(ior > 0.0 && std::isfinite(ior) ? ior : 1.0), units_(std::move(sceneUnits)) {
  // The base as the artist sees it, darkened so a first stroke shows; an empty channel
  // (infinite distance) starts at a unit distance.
  artist_ = physicalToArtist(base, ior_);
  artist_.colour *= 0.5;
  for (int c = 0; c < 3; ++c)
    if (!(artist_.scatterDistance[c] >= kMinScatterDistance && artist_.scatterDistance[c] <= kMaxScatterDistance))
      artist_.scatterDistance[c] = 1.0;
  artist_.g = std::clamp(artist_.g, -kArtistMaxG, kArtistMaxG);
  const double unit = unitInMm(units_).value_or(1.0);
  for (const MeasuredMaterial& m : measuredMaterials())
    swatches_.push_back(physicalToArtist(*presetMaterial(m.name, 0.0f, unit), ior_));
  const glm::dvec3 sigmaT(base.sigmaT), sigmaS(base.sigmaS);
  // Where the base is empty (σt = 0) a unit density is a sensible first stroke.
  const glm::dvec3 denser = glm::max(2.0 * sigmaT, glm::dvec3(1e-3));
  rgb_[{BrushChannel::SigmaT, BrushMode::Set}] = denser;
  rgb_[{BrushChannel::SigmaT, BrushMode::Add}] = glm::max(0.5 * sigmaT, glm::dvec3(1e-3));
  rgb_[{BrushChannel::SigmaT, BrushMode::Multiply}] = glm::dvec3(1.5);
  rgb_[{BrushChannel::SigmaS, BrushMode::Set}] = 0.5 * sigmaS;
  rgb_[{BrushChannel::SigmaS, BrushMode::Add}] = glm::max(0.25 * sigmaS, glm::dvec3(1e-3));
  rgb_[{BrushChannel::SigmaS, BrushMode::Multiply}] = glm::dvec3(0.5);
  scalar_[{BrushChannel::G, BrushMode::Set}] = 0.6;
  scalar_[{BrushChannel::G, BrushMode::Add}] = 0.1;
  scalar_[{BrushChannel::G, BrushMode::Multiply}] = 0.5;
  for (int c = 0; c < 3; ++c) {
    albedo_[c] = sigmaT[c] > 0.0 ? std::clamp(sigmaS[c] / sigmaT[c], 0.0, 1.0) : 0.9;
    meanFreePath_[c] = sigmaT[c] > 0.0 ? 1.0 / sigmaT[c] : 1.0;
  }
  radius_ = objectWorldExtent > 0.0 && std::isfinite(objectWorldExtent) ? 0.08 * objectWorldExtent : 1.0;
}

glm::dvec3& BrushControls::rgbValue() { return rgb_[{channel_, mode_}]; }
double& BrushControls::scalarValue() { return scalar_[{channel_, mode_}]; }

Brush BrushControls::brush() const {
  Brush b;
  b.channel = channel_;
  b.mode = mode_;
  const Key key{channel_, mode_};
  if (auto it = rgb_.find(key); it != rgb_.end()) b.rgb = it->second;
  if (auto it = scalar_.find(key); it != scalar_.end()) b.scalar = it->second;
  b.albedo = albedo_;
  b.meanFreePath = meanFreePath_;
  b.preset = std::string(measuredMaterials()[preset_].name);
  b.artist = artist_;
  b.radius = radius_;
  b.falloff = falloff_;
  b.strength = strength_;
  if (mirrorAxis_ >= 0) b.mirror = BrushMirror{mirrorAxis_, std::nullopt};
  b.depth = depth_;
  return b;
}

void BrushControls::cycleChannel(int direction) {
  constexpr BrushChannel order[] = {BrushChannel::Colour,    BrushChannel::SigmaT, BrushChannel::SigmaS,
                                    BrushChannel::G,         BrushChannel::AlbedoMfp, BrushChannel::Preset,
                                    BrushChannel::All};
  constexpr int n = 7;
  int i = int(std::find(order, order + n, channel_) - order);
  i = ((i + (direction >= 0 ? 1 : -1)) % n + n) % n;
  channel_ = order[i];
  const std::vector<BrushMode> modes = modesOf(channel_);
  if (std::find(modes.begin(), modes.end(), mode_) == modes.end()) mode_ = modes.front();
}

void BrushControls::cycleMode(int direction) {
  const std::vector<BrushMode> modes = modesOf(channel_);
  const int n = int(modes.size());
  int i = int(std::find(modes.begin(), modes.end(), mode_) - modes.begin());
  i = ((i + (direction >= 0 ? 1 : -1)) % n + n) % n;
  mode_ = modes[i];
}

void BrushControls::cycleFalloff() {
  falloff_ = BrushFalloff((int(falloff_) + 1) % 4);
}

void BrushControls::scaleRadius(double factor) {
  const double next = radius_ * factor;
  if (next > 0.0 && std::isfinite(next)) radius_ = next;
}

void BrushControls::adjustStrength(double delta) {
  strength_ = std::clamp(std::round((strength_ + delta) * 100.0) / 100.0, 0.0, 1.0);
}

void BrushControls::adjustValue(int direction) {
  const double factor = direction >= 0 ? kValueStep : 1.0 / kValueStep;
  auto scale = [&](glm::dvec3& v) {
    for (int c = 0; c < 3; ++c)
      if (component_ < 0 || component_ == c) {
        // A zero value cannot grow by a factor: step it to a small amount instead.
        if (v[c] == 0.0 && direction > 0) v[c] = 1e-3;
        else v[c] *= factor;
      }
  };
  switch (channel_) {
    case BrushChannel::SigmaT:
    case BrushChannel::SigmaS:
      if (valuedMode(mode_)) scale(rgbValue());
      break;
    case BrushChannel::G:
      if (valuedMode(mode_)) {
        double& g = scalarValue();
        // Rounded so repeated steps do not drift (0.6 + 0.05 + ... stays 0.75, not 0.7500001).
        g = std::round((g + (direction >= 0 ? kGStep : -kGStep)) * 1000.0) / 1000.0;
        if (mode_ == BrushMode::Set) g = std::clamp(g, -double(kBrushMaxG), double(kBrushMaxG));
        if (mode_ == BrushMode::Multiply) g = std::max(g, 0.0);
      }
      break;
    case BrushChannel::AlbedoMfp:
      scale(meanFreePath_);
      break;
    case BrushChannel::Colour:
      scale(artist_.scatterDistance);
      artist_.scatterDistance =
          glm::clamp(artist_.scatterDistance, glm::dvec3(kMinScatterDistance), glm::dvec3(kMaxScatterDistance));
      break;
    case BrushChannel::Preset: {
      const std::size_t n = measuredMaterials().size();
      preset_ = (preset_ + (direction >= 0 ? 1 : n - 1)) % n;
      break;
    }
    case BrushChannel::All:
      break;
  }
}

void BrushControls::adjustAlbedo(int direction) {
  if (channel_ == BrushChannel::Colour) {
    const double top = maxSurfaceColour(ior_);
    for (int c = 0; c < 3; ++c)
      if (component_ < 0 || component_ == c)
        artist_.colour[c] = std::clamp(
            std::round((artist_.colour[c] + (direction >= 0 ? kAlbedoStep : -kAlbedoStep)) * 1000.0) / 1000.0, 0.0, top);
    return;
  }
  for (int c = 0; c < 3; ++c)
    if (component_ < 0 || component_ == c)
      albedo_[c] = std::clamp(std::round((albedo_[c] + (direction >= 0 ? kAlbedoStep : -kAlbedoStep)) * 1000.0) / 1000.0,
                              0.0, 1.0);
}

void BrushControls::adjustArtistG(int direction) {
  if (channel_ != BrushChannel::Colour) return;
  artist_.g = std::clamp(std::round((artist_.g + (direction >= 0 ? kGStep : -kGStep)) * 1000.0) / 1000.0, -kArtistMaxG,
                         kArtistMaxG);
}

std::string BrushControls::swatchName(std::size_t i) const {
  return i < swatches_.size() ? std::string(measuredMaterials()[i].name) : std::string();
}

bool BrushControls::pickSwatch(std::size_t i) {
  if (i >= swatches_.size()) return false;
  swatch_ = i;
  artist_ = swatches_[i];
  channel_ = BrushChannel::Colour;
  mode_ = BrushMode::Set;
  return true;
}

void BrushControls::selectColourChannel() {
  channel_ = BrushChannel::Colour;
  mode_ = BrushMode::Set;
}

void BrushControls::cycleSwatch(int direction) {
  const std::size_t n = swatches_.size();
  if (n == 0) return;
  pickSwatch((swatch_ + (direction >= 0 ? 1 : n - 1)) % n);
}

const char* BrushControls::artistFieldName(int field) {
  return field == 0 ? "colour" : field == 1 ? "scatter distance" : "g";
}

std::string BrushControls::artistFieldText(int field) const {
  char text[96];
  if (field == 2) {
    std::snprintf(text, sizeof text, "%.6g", artist_.g);
  } else {
    const glm::dvec3& v = field == 0 ? artist_.colour : artist_.scatterDistance;
    if (v.x == v.y && v.y == v.z)
      std::snprintf(text, sizeof text, "%.6g", v.x);
    else
      std::snprintf(text, sizeof text, "%.6g, %.6g, %.6g", v.x, v.y, v.z);
  }
  return text;
}

void BrushControls::setChannel(BrushChannel channel) {
  channel_ = channel;
  const std::vector<BrushMode> modes = modesOf(channel_);
  if (std::find(modes.begin(), modes.end(), mode_) == modes.end()) mode_ = modes.front();
}

bool BrushControls::setMode(BrushMode mode) {
  const std::vector<BrushMode> modes = modesOf(channel_);
  if (std::find(modes.begin(), modes.end(), mode) == modes.end()) return false;
  mode_ = mode;
  return true;
}

bool BrushControls::setRadius(double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius)) return false;
  radius_ = radius;
  return true;
}

void BrushControls::setStrength(double strength) {
  if (std::isfinite(strength)) strength_ = std::clamp(strength, 0.0, 1.0);
}

void BrushControls::setDepth(double depth) {
  if (std::isfinite(depth)) depth_ = std::max(0.0, depth);
}

std::string BrushControls::setArtist(const ArtistParams& artist) {
  if (std::string problem = artistParamsProblem(artist, ior_); !problem.empty()) return problem;
  for (int c = 0; c < 3; ++c)
    if (artist.scatterDistance[c] > kMaxScatterDistance)
      return "scatter_distance[" + std::to_string(c) + "]: the editor takes at most 1e30";
  artist_ = artist;
  selectColourChannel();
  return {};
}

std::string BrushControls::enterArtistField(int field, const std::string& text) {
  const std::vector<double> values = parseNumbers(text);
  const bool scalarOnly = field == 2;
  if (values.empty() || (values.size() != 1 && (scalarOnly || values.size() != 3)))
    return std::string(artistFieldName(field)) + ": expected " + (scalarOnly ? "one number" : "one number or three") +
           ", got \"" + text + "\"";
  ArtistParams next = artist_;
  const glm::dvec3 v = values.size() == 1 ? glm::dvec3(values[0]) : glm::dvec3(values[0], values[1], values[2]);
  if (field == 0) next.colour = v;
  else if (field == 1) next.scatterDistance = v;
  else next.g = values[0];
  if (std::string problem = artistParamsProblem(next, ior_); !problem.empty()) return problem;
  for (int c = 0; c < 3; ++c)
    if (next.scatterDistance[c] > kMaxScatterDistance)
      return "scatter_distance[" + std::to_string(c) + "]: the editor takes at most 1e30";
  artist_ = next;
  channel_ = BrushChannel::Colour;
  mode_ = BrushMode::Set;
  return {};
}

void BrushControls::cycleComponent() { component_ = component_ >= 2 ? -1 : component_ + 1; }

void BrushControls::negateValue() {
  if (mode_ != BrushMode::Add) return;
  if (channel_ == BrushChannel::SigmaT || channel_ == BrushChannel::SigmaS) rgbValue() = -rgbValue();
  if (channel_ == BrushChannel::G) scalarValue() = -scalarValue();
}

void BrushControls::cycleMirror() { mirrorAxis_ = mirrorAxis_ >= 2 ? -1 : mirrorAxis_ + 1; }

void BrushControls::adjustDepth(int direction) {
  depth_ = std::max(0.0, depth_ + (direction >= 0 ? 0.1 : -0.1) * radius_);
  if (depth_ < 1e-9 * radius_) depth_ = 0.0;
}

std::string BrushControls::describe() const {
  const Brush b = brush();
  std::string text = std::string(paintMode_ ? "PAINT" : "CAMERA") + " | " + channelName(channel_) + " " + modeName(mode_);
  // Spelled out: "(editing g)" would read as the phase function's g.
  const char* components[] = {"red", "green", "blue"};
  const std::string per = " /" + units_;
  switch (channel_) {
    case BrushChannel::SigmaT:
    case BrushChannel::SigmaS:
      if (valuedMode(mode_)) text += " " + formatRgb(b.rgb) + (mode_ == BrushMode::Multiply ? "x" : per);
      break;
    case BrushChannel::G:
      if (valuedMode(mode_)) {
        char v[32];
        std::snprintf(v, sizeof v, " %.3g", b.scalar);
        text += v;
      }
      break;
    case BrushChannel::AlbedoMfp:
      text += " albedo " + formatRgb(b.albedo) + " mfp " + formatRgb(b.meanFreePath) + " " + units_;
      break;
    case BrushChannel::Preset:
      text += " " + b.preset;
      break;
    case BrushChannel::Colour: {
      char g[64];
      std::snprintf(g, sizeof g, " g %.3g", b.artist.g);
      text += " " + formatRgb(b.artist.colour) + " dist " + formatRgb(b.artist.scatterDistance) + " " + units_ + g;
      break;
    }
    case BrushChannel::All:
      break;
  }
  if (component_ >= 0) text += std::string(" (editing ") + components[component_] + ")";
  char rest[160];
  std::snprintf(rest, sizeof rest, " | radius %.3g %s | %s | strength %.2f", b.radius, units_.c_str(),
                falloffName(b.falloff), b.strength);
  text += rest;
  if (b.mirror) text += std::string(" | mirror ") + "xyz"[b.mirror->axis];
  if (b.depth > 0.0) {
    char d[48];
    std::snprintf(d, sizeof d, " | depth %.3g", b.depth);
    text += d;
  }
  return text;
}

std::string BrushControls::describeStored() const {
  if (channel_ != BrushChannel::Colour) return {};
  const MaterialSample m = artistToPhysical(artist_, ior_);
  char g[48];
  std::snprintf(g, sizeof g, ", g %.3g", double(m.g));
  return "stores sigma_t " + formatRgb(glm::dvec3(m.sigmaT)) + " sigma_s " + formatRgb(glm::dvec3(m.sigmaS)) + " /" +
         units_ + g;
}

std::string BrushControls::displayChannel() const {
  switch (channel_) {
    case BrushChannel::SigmaS: return "sigma_s";
    case BrushChannel::G: return "g";
    case BrushChannel::AlbedoMfp:
    case BrushChannel::Colour: return "albedo";
    default: return "sigma_t";
  }
}

}  // namespace sslpv

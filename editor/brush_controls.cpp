#include "editor/brush_controls.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "volume/material.h"

namespace sslpv {
namespace {

constexpr double kValueStep = 1.25;
constexpr double kGStep = 0.05;
constexpr double kAlbedoStep = 0.02;

bool valuedMode(BrushMode mode) {
  return mode == BrushMode::Set || mode == BrushMode::Add || mode == BrushMode::Multiply;
}

// The modes each channel accepts, in cycling order (brushProblem's rules).
std::vector<BrushMode> modesOf(BrushChannel channel) {
  switch (channel) {
    case BrushChannel::AlbedoMfp:
    case BrushChannel::Preset:
      return {BrushMode::Set};
    case BrushChannel::All:
      return {BrushMode::Smooth, BrushMode::Erase};
    default:
      return {BrushMode::Set, BrushMode::Add, BrushMode::Multiply, BrushMode::Smooth, BrushMode::Erase};
  }
}

const char* channelName(BrushChannel c) {
  switch (c) {
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

}  // namespace

BrushControls::BrushControls(const MaterialSample& base, double objectWorldExtent, std::string sceneUnits)
    : units_(std::move(sceneUnits)) {
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
  b.radius = radius_;
  b.falloff = falloff_;
  b.strength = strength_;
  if (mirrorAxis_ >= 0) b.mirror = BrushMirror{mirrorAxis_, std::nullopt};
  b.depth = depth_;
  return b;
}

void BrushControls::cycleChannel(int direction) {
  constexpr BrushChannel order[] = {BrushChannel::SigmaT, BrushChannel::SigmaS, BrushChannel::G,
                                    BrushChannel::AlbedoMfp, BrushChannel::Preset, BrushChannel::All};
  constexpr int n = 6;
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
  for (int c = 0; c < 3; ++c)
    if (component_ < 0 || component_ == c)
      albedo_[c] = std::clamp(std::round((albedo_[c] + (direction >= 0 ? kAlbedoStep : -kAlbedoStep)) * 1000.0) / 1000.0,
                              0.0, 1.0);
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
  const char* components[] = {"r", "g", "b"};
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

std::string BrushControls::displayChannel() const {
  switch (channel_) {
    case BrushChannel::SigmaS: return "sigma_s";
    case BrushChannel::G: return "g";
    case BrushChannel::AlbedoMfp: return "albedo";
    default: return "sigma_t";
  }
}

}  // namespace sslpv

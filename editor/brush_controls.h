#pragma once
// The editor's brush panel as state: which channel, mode, value, radius, falloff, strength,
// mirror and depth the next stroke uses, changed by the window's keys. No VTK, so the
// rules (what each key does, which modes a channel accepts) are tested headless.
//
// Values are remembered per channel and mode: a set target, an add amount and a multiply
// factor mean different things, so switching mode does not reinterpret the last number.
#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "editor/brush_engine.h"

namespace sslpv {

class BrushControls {
 public:
  /// Defaults from the scene: set targets start at the base material (σt doubled, the
  /// colour halved, so a first stroke is visible), radius at 8 % of the object's longest
  /// world extent. The first channel is the artist's one: surface colour, scatter distance
  /// and g (volume/material/artist_params.h), seen through the scene's boundary index `ior`.
  BrushControls(const MaterialSample& basePerSceneUnit, double objectWorldExtent, std::string sceneUnits,
                double ior = 1.0);

  /// The brush the next stroke uses (always passes brushProblem()).
  Brush brush() const;

  void cycleChannel(int direction);  ///< colour, sigma_t, sigma_s, g, albedo_mfp, preset, all
  void cycleMode(int direction);     ///< only the modes the channel accepts
  void cycleFalloff();
  void scaleRadius(double factor);
  void adjustStrength(double delta);
  /// The channel's main number one notch up (+1) or down (-1): σ values, mean free paths
  /// and scatter distances by a factor 1.25, g by 0.05, a preset to the next/previous
  /// Jensen material.
  void adjustValue(int direction);
  /// albedo_mfp: the albedo of the selected component(s) by 0.02; colour: the surface
  /// colour by 0.02, within [0, the brightest the scene's ior allows].
  void adjustAlbedo(int direction);
  /// colour: g by 0.05 within [-0.99, 0.99]; other channels: nothing.
  void adjustArtistG(int direction);

  /// The colour swatches: the Jensen materials as surface colour, scatter distance (scene
  /// units) and g = 0 at the scene's ior, in measuredMaterials() order.
  const std::vector<ArtistParams>& swatches() const { return swatches_; }
  std::string swatchName(std::size_t i) const;
  /// Picks swatch i (colour channel; switches to it). False when i is out of range.
  bool pickSwatch(std::size_t i);
  /// The next (+1) / previous (-1) swatch after the last one picked.
  void cycleSwatch(int direction);
  /// Typed entry of the colour channel's fields: 0 colour, 1 scatter distance, 2 g; text is
  /// one number or three separated by commas or spaces (g: one). Returns "" when applied,
  /// else why not ("colour[1]: must be in [0, 0.96], got 1.2"); nothing changes then.
  std::string enterArtistField(int field, const std::string& text);
  /// The field's current value as enterArtistField reads it ("0.8, 0.4, 0.2").
  std::string artistFieldText(int field) const;
  static const char* artistFieldName(int field);  ///< "colour", "scatter distance", "g"
  const ArtistParams& artist() const { return artist_; }
  void selectColourChannel();  ///< the colour channel, mode set, values unchanged
  double ior() const { return ior_; }
  /// Which RGB component adjustValue/adjustAlbedo change: all, then r, g, b.
  void cycleComponent();
  void negateValue();  ///< add mode: paint the opposite amount
  void cycleMirror();  ///< off, x, y, z (across the object's rest-space centre)
  void adjustDepth(int direction);  ///< surface strokes' depth by a tenth of the radius

  // Direct setters for the brush panel (editor/ui/brush_panel.cpp): the same state the keys
  // step through, validated the same way (an unaccepted value leaves the brush unchanged).
  BrushChannel channel() const { return channel_; }
  BrushMode mode() const { return mode_; }
  BrushFalloff falloff() const { return falloff_; }
  int mirrorAxis() const { return mirrorAxis_; }
  /// The modes `channel` accepts, in cycling order.
  static std::vector<BrushMode> modesOf(BrushChannel channel);
  void setChannel(BrushChannel channel);  ///< keeps the mode if the channel accepts it
  bool setMode(BrushMode mode);           ///< false when the channel does not accept it
  void setFalloff(BrushFalloff falloff) { falloff_ = falloff; }
  void setMirror(int axis) { mirrorAxis_ = axis >= 0 && axis <= 2 ? axis : -1; }
  bool setRadius(double radius);      ///< false unless finite and > 0
  void setStrength(double strength);  ///< clamped to [0, 1]
  void setDepth(double depth);        ///< clamped to >= 0
  /// The colour brush's whole artist view at once (the colour dialog, the panel's fields);
  /// "" when applied (the colour channel is selected), else why not, nothing changed.
  std::string setArtist(const ArtistParams& artist);

  bool paintMode() const { return paintMode_; }
  void setPaintMode(bool on) { paintMode_ = on; }

  /// One status line: "sigma_t set [1.2 1.5 2] /mm | radius 1.5 mm | smooth | ...".
  std::string describe() const;
  /// The colour brush's other view, what the grids will hold: "stores sigma_t [..] sigma_s
  /// [..] /mm, g 0.3" ("" for the other channels, whose values are σ already).
  std::string describeStored() const;
  /// What the slice views show for this brush: "sigma_t", "sigma_s", "g" or "albedo"
  /// (colour: "albedo", σs/σt, the closest of the four to what it sets).
  std::string displayChannel() const;

 private:
  using Key = std::pair<BrushChannel, BrushMode>;
  glm::dvec3& rgbValue();
  double& scalarValue();

  BrushChannel channel_ = BrushChannel::Colour;
  BrushMode mode_ = BrushMode::Set;
  std::map<Key, glm::dvec3> rgb_;
  std::map<Key, double> scalar_;
  glm::dvec3 albedo_{0.9};
  glm::dvec3 meanFreePath_{1.0};
  std::size_t preset_ = 0;
  ArtistParams artist_;
  double ior_ = 1.0;
  std::vector<ArtistParams> swatches_;
  std::size_t swatch_ = 0;
  int component_ = -1;  ///< -1: all three
  double radius_ = 1.0;
  BrushFalloff falloff_ = BrushFalloff::Smooth;
  double strength_ = 0.5;
  int mirrorAxis_ = -1;
  double depth_ = 0.0;
  bool paintMode_ = true;
  std::string units_;
};

}  // namespace sslpv

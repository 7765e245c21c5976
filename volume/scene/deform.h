#pragma once
// Procedural space deformers, the scene's optional `deformers` key: bend, twist, taper and
// squash_stretch about an axis through a centre, in the object's rest space (before the
// scene's transform), applied in the order listed, each with an animated parameter.
// Every deformer has an exact analytic inverse on the region where it is one-to-one, so
// a point of the deformed object maps back to the rest-space point it came from: the
// material set stays in rest space and each frame is resampled through that inverse
// (docs/design.md §4), which keeps a painted stripe on the part of the object it was
// painted on as the object bends.
#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace sslpv {

class StrictJsonReader;

enum class Ease { Linear, Smoothstep };

struct Keyframe {
  double t = 0.0;
  double value = 0.0;
  Ease ease = Ease::Linear;  ///< the interpolation of the segment that ends at this key
};

/// A parameter that is either constant (one key) or keyframed: keys in strictly increasing
/// t; before the first key the first value holds, after the last the last value.
struct AnimatedValue {
  std::vector<Keyframe> keys;
  double at(double t) const;
  bool animated() const { return keys.size() > 1; }
};

struct Deformer {
  enum class Type { Bend, Twist, Taper, SquashStretch };
  Type type = Type::Bend;
  int axis = 1;              ///< 0 x, 1 y, 2 z: the deformer's axis through `center`
  int toward = 2;            ///< bend: the axis the bend curves towards (not `axis`)
  glm::dvec3 center{0.0};    ///< rest space
  double length = 1.0;       ///< bend, twist, taper: `amount` is per this many scene units
  /// bend and twist: degrees per `length` along the axis; taper: change of the cross
  /// section's scale per `length`; squash_stretch: the scale along the axis (the cross
  /// section scales by 1/sqrt of it, keeping the volume).
  AnimatedValue amount;
};

/// "bend", "twist", ...: the name the scene file uses.
const char* deformerTypeName(Deformer::Type type);

/// One deformer with its parameter evaluated at one time.
struct PosedDeformer {
  Deformer::Type type = Deformer::Type::Bend;
  int axis = 1, toward = 2;
  glm::dvec3 center{0.0};
  /// bend, twist: radians per scene unit; taper: scale change per scene unit;
  /// squash_stretch: the scale along the axis.
  double k = 0.0;

  glm::dvec3 forward(const glm::dvec3& rest) const;
  /// The exact inverse of forward() on its one-to-one domain; NaN components where a
  /// point has no preimage (behind a taper's apex).
  glm::dvec3 inverse(const glm::dvec3& deformed) const;
  /// Empty when forward() is one-to-one around `rest`, else why not: a bend of more than
  /// half a turn either side of the centre or past its centre of curvature, a taper whose
  /// cross section shrinks to nothing.
  std::string outsideDomain(const glm::dvec3& rest) const;
};

/// A posed object's map between its rest space, where the material set lives, and its
/// deformed space: what the material field and the resampling need, whether the pose
/// comes from procedural deformers or from a skinned clip (volume/scene/skin.h).
class SpaceDeformation {
 public:
  virtual ~SpaceDeformation() = default;
  virtual glm::dvec3 forward(const glm::dvec3& rest) const = 0;
  /// NaN components where a point has no rest-space point (the field then reads the base).
  virtual glm::dvec3 inverse(const glm::dvec3& deformed) const = 0;
};

/// The whole stack at one time.
class DeformationPose : public SpaceDeformation {
 public:
  DeformationPose() = default;
  DeformationPose(const std::vector<Deformer>& deformers, double t);
  glm::dvec3 forward(const glm::dvec3& rest) const override;
  glm::dvec3 inverse(const glm::dvec3& deformed) const override;
  const std::vector<PosedDeformer>& stages() const { return stages_; }

 private:
  std::vector<PosedDeformer> stages_;
};

/// Rest-space vertices deformed by `pose`. Throws InputError "<file>: deformers[i]: ..."
/// (`file` names the scene) when a vertex reaches deformer i outside its one-to-one
/// domain: the object would fold onto itself and its material could not be mapped back.
/// A closed mesh's interior lies in the convex hull of its vertices and every domain is
/// convex, so checking the vertices checks the interior.
std::vector<glm::vec3> deformPositions(const std::vector<glm::vec3>& rest, const DeformationPose& pose,
                                       const std::string& file, double t);

/// Parses the scene's `deformers` array (key paths like deformers[0].amount[1].t).
std::vector<Deformer> parseDeformers(const StrictJsonReader& in, const nlohmann::json& node);

/// Accepted `--time` / keyframe t values: within ±kMaxTime.
inline constexpr double kMaxTime = 1e6;

}  // namespace sslpv

#pragma once
// The scene contract (docs/design.md §3; keys in the README's "Scene file"): parsed strictly from JSON. Unknown keys, wrong types,
// missing required keys and out-of-range values are InputErrors naming the key path,
// e.g. "scene.json: lights[1].intensity: expected an array of 3 non-negative numbers".
#include <filesystem>
#include <memory>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <vector>

#include "volume/scene/deform.h"
#include "volume/calibration/lpv_scheme.h"
#include "volume/scene/material.h"

namespace sslpv {

struct TriangleMesh;

struct MeshSource {
  /// InMemory: a mesh made by a program (a generated benchmark mesh, an editor's
  /// deformed copy), never from a scene file.
  enum class Kind { File, Box, Sphere, InMemory };
  Kind kind = Kind::Box;
  std::filesystem::path path;  ///< Kind::File: resolved against the scene file's folder
  std::shared_ptr<const TriangleMesh> mesh;  ///< Kind::InMemory: in the object's rest space
  glm::dvec3 boxMin{-0.5}, boxMax{0.5};
  /// Box: quads along x, y, z per face (1, 1, 1: the 12-triangle box). A deformer bends
  /// only what has vertices to move, so a bar that bends needs segments along its length.
  glm::ivec3 boxSegments{1};
  glm::dvec3 center{0.0};
  double radius = 0.5;
  /// Kind::File, "animation": the skinned clip to play, by name, or by index when
  /// animationIndex >= 0 (volume/scene/skin.h). Neither: the file's rest pose, read as
  /// any mesh file is.
  std::string animationName;
  int animationIndex = -1;
  bool animated() const { return animationIndex >= 0 || !animationName.empty(); }
};

/// Similarity transform: scale, then rotate (X, then Y, then Z, degrees), then translate.
struct Transform {
  glm::dvec3 translate{0.0};
  glm::dvec3 rotateDeg{0.0};
  double scale = 1.0;
  glm::dmat4 matrix() const;  ///< rest (object) space -> world space
};

struct MaterialSpec {
  MaterialSample base;      ///< per scene unit
  std::string presetName;   ///< empty when base was given as explicit sigmas
  std::optional<std::filesystem::path> vdb;  ///< resolved against the scene file's folder
  double ior = 1.0;         ///< 1.0 = index-matched boundary
};

struct Light {
  enum class Type { Point, Spot, Directional };
  Type type = Type::Point;
  glm::dvec3 position{0.0};    ///< point, spot
  glm::dvec3 direction{0.0, -1.0, 0.0};  ///< spot, directional: unit vector the light travels along
  double fovDeg = 40.0;        ///< spot: full cone angle, hard edge, in (0, 180)
  glm::vec3 intensity{0.0f};   ///< point, spot: W/sr per channel
  glm::vec3 irradiance{0.0f};  ///< directional: W per scene-unit^2 on a surface facing it
};

struct Camera {
  glm::dvec3 position{0.0, 0.0, 5.0};
  glm::dvec3 target{0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fovYDeg = 35.0;
  int width = 512;
  int height = 512;
};

struct LpvSettings {
  int resolution = 32;  ///< cells along the longest axis of the object's padded bounds
  int steps = 8;        ///< propagation steps (ignored when autoSteps)
  bool autoSteps = false;
  int shadowMap = 256;  ///< shadow-map texels per side
  LpvScheme scheme = LpvScheme::Calibrated;  ///< per-step coefficients (volume/calibration/lpv_scheme.h)
};

struct Scene {
  std::filesystem::path file;  ///< the JSON it came from (for messages)
  std::string units = "mm";
  double unitInMm = 1.0;
  MeshSource mesh;
  Transform transform;
  MaterialSpec material;
  std::vector<Light> lights;
  Camera camera;
  LpvSettings lpv;
  /// Applied in order to the mesh in rest space, before `transform` (volume/scene/deform.h).
  std::vector<Deformer> deformers;
  /// The time the deformers or the mesh's clip are evaluated at (`--time`, seconds);
  /// unused without either.
  double time = 0.0;
  /// Deformers or a skinned clip: the object's pose depends on `time`.
  bool animated() const { return !deformers.empty() || mesh.animated(); }
};

/// `scene` posed at time `t`: every backend that loads it deforms the mesh at `t` and
/// samples the rest-space material set through the inverse deformation. InputError
/// naming the flag when `t` is not finite or beyond ±kMaxTime.
Scene sceneAtTime(const Scene& scene, double t);

/// Largest accepted lpv.resolution / --grid: beyond it the grids do not fit in memory.
inline constexpr int kMaxLpvResolution = 512;
inline constexpr int kMaxShadowMap = 8192;
inline constexpr int kMaxImageSide = 16384;
inline constexpr int kMaxSteps = 1000000;
/// mesh.segments per axis of a box primitive.
inline constexpr int kMaxBoxSegments = 256;

/// Command-line overrides of a scene's lpv settings (`render`, `edit`); empty = keep.
struct LpvFlags {
  std::optional<int> grid;    ///< --grid
  std::string steps;          ///< --steps: a whole number or "auto"
  std::optional<int> shadowMap;  ///< --shadow-map
  std::string scheme;         ///< --scheme: calibrated | seed
};

/// `settings` with the flags applied. InputError naming the flag on a bad value.
LpvSettings applyLpvFlags(LpvSettings settings, const LpvFlags& flags);

/// Reads and validates a scene file. Throws InputError (file and key path in the message).
Scene loadScene(const std::filesystem::path& file);

/// Parses scene JSON text; `file` names it in messages and anchors relative paths.
Scene parseScene(const std::string& jsonText, const std::filesystem::path& file);

}  // namespace sslpv

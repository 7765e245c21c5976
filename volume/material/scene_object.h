#pragma once
// The object of a scene as every backend needs it: the closed mesh in world space and
// its material field (base material + optional painted material set).
#include <glm/mat4x4.hpp>
#include <memory>
#include <string>

#include "volume/material/material_field.h"
#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"
#include "volume/scene/skin.h"

namespace sslpv {

class SceneObject {
 public:
  /// Loads the mesh (in world space, closed-ness checked) and the material set. Throws
  /// InputError on bad input. With deformers or a skinned clip (mesh.animation), the mesh
  /// is posed at scene.time and the field maps points back to rest space through the
  /// pose's inverse.
  explicit SceneObject(const Scene& scene);

  /// Poses the mesh at time `t` from the rest mesh kept at load (no file is read again)
  /// and points the field at the new pose. InputError naming the deformer when the pose
  /// folds the mesh; the object is then unchanged. Without deformers or a clip, nothing
  /// changes.
  void setTime(double t);
  bool deformed() const { return !deformers_.empty() || skinned_; }
  /// The pose of the last setTime (null for a static object).
  const std::shared_ptr<const SpaceDeformation>& pose() const { return pose_; }

  /// A painted material set in the scene's material.vdb units (nullptr: base only).
  void setMaterialSet(std::shared_ptr<const MaterialSet> set);

  const TriangleMesh& mesh() const { return mesh_; }
  const Bounds& bounds() const { return bounds_; }
  /// The bounds the LPV grid is fitted to: bounds() for a static object; for a deformed
  /// one, the union of its poses over the deformers' keyframed time span (sampled), so
  /// that the grid's cells stay where they are as the object moves. A grid refitted to
  /// each pose shifts every cell by a fraction of a cell per frame, and the image jumps
  /// by the lattice's cell-phase error each time (bench/flicker --animate).
  const Bounds& gridBounds() const { return deformed() ? animationBounds_ : bounds_; }
  const MaterialField& field() const { return *field_; }
  /// Milliseconds the constructor took (reported as the "load" stage).
  double loadMs() const { return loadMs_; }

 private:
  Bounds boundsOverAnimation() const;
  /// The rest-space vertices at time t: InputError when a pose folds or leaves the range.
  std::vector<glm::vec3> posedPositions(double t, const std::string& file,
                                        std::shared_ptr<const SpaceDeformation>* pose) const;

  // What the material field needs from the scene (copied: the object outlives no scene).
  MaterialSample base_;
  std::string vdbName_;
  double unitInMm_;
  glm::dmat4 worldToRest_;
  std::filesystem::path sceneFile_;
  Transform transform_;
  std::vector<Deformer> deformers_;
  TriangleMesh restMesh_;  ///< deformed scenes only: the mesh before deformers and transform
  /// Skinned scenes only: the file's skin, the clip played and the rest vertices' grid.
  std::shared_ptr<const SkinnedMesh> skinned_;
  const SkinClip* clip_ = nullptr;
  std::shared_ptr<const PointGrid> restGrid_;
  std::shared_ptr<const SpaceDeformation> pose_;
  TriangleMesh mesh_;
  Bounds bounds_;
  Bounds animationBounds_;  ///< deformed objects only: see gridBounds()
  std::shared_ptr<const MaterialSet> set_;
  std::unique_ptr<MaterialField> field_;
  double loadMs_ = 0.0;
};

}  // namespace sslpv

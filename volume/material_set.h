#pragma once
// Material sets: OpenVDB files with sigma_t, sigma_s (Vec3SGrid) and g (FloatGrid), and
// the one continuous material field every consumer samples (docs/design.md §4).
#include <openvdb/openvdb.h>

#include <filesystem>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <memory>
#include <string>
#include <vector>

#include "volume/deform.h"
#include "volume/lpv_grid.h"
#include "volume/material.h"
#include "volume/mesh.h"

namespace sslpv {

struct MaterialSet {
  openvdb::Vec3SGrid::Ptr sigmaT;  ///< required
  openvdb::Vec3SGrid::Ptr sigmaS;  ///< required
  openvdb::FloatGrid::Ptr g;       ///< optional: absent means the base material's g
  std::string units = "mm";        ///< file metadata "units"
  std::string creator;             ///< file metadata "creator"
};

/// One problem found in a material-set file: "file: grid 'sigma_s' voxel (3,4,5): ...".
struct ValidationProblem {
  std::string message;
};

/// Calls openvdb::initialize() once; every entry point below calls it.
void initializeOpenVdb();

/// Loads and validates; throws InputError with the first problem (file, grid, voxel).
/// Missing, empty, truncated and corrupt files are InputErrors too: the file is parsed
/// in an isolated child process (see volume/vdb_isolated_read.h). Metadata "units"
/// missing means "mm"; any other value than mm, cm, m or in is an error.
std::shared_ptr<const MaterialSet> loadMaterialSet(const std::filesystem::path& file);

/// Every problem in `set` (a missing required grid, σt < 0, σs < 0, σs > σt, |g| >= 1,
/// NaN/Inf), each naming `fileForMessages`, the grid and the voxel in index coordinates
/// plus its world position through the grid's transform; active tiles are named as a
/// tile at its origin. Stops after `maxProblems`.
///
/// Backgrounds are checked with the same rules although the field never reads them
/// (inactive = base): other renderers read the raw grids, where the background is the
/// value outside the active region, so an invalid one marks a broken file.
/// σs <= σt (per channel, relative tolerance 1e-6 for float round-off) is checked only
/// where both grids have an active value at the same index and the two grids share one
/// transform: where one side is inactive the field takes the base material there, which
/// the file alone does not know (the scene's base is checked by the scene loader).
std::vector<ValidationProblem> validateMaterialSet(const MaterialSet& set,
                                                   const std::string& fileForMessages,
                                                   std::size_t maxProblems = 100);

/// Writes the set atomically with metadata units/creator/version ("version" is the
/// material-set format version, an int, currently 1; creator defaults to "sslpv").
/// Does not validate the values, so tests and tools can write invalid files on purpose.
void saveMaterialSet(const MaterialSet& set, const std::filesystem::path& file);

/// A copy with its own grids (deep): painting it leaves `set`, which may be shared, as it was.
std::shared_ptr<MaterialSet> deepCopy(const MaterialSet& set);

/// Human-readable report for `sslpv inspect`: grids, types, active voxel counts, value
/// ranges, transforms, metadata and every validation problem. Returns false when the
/// file has problems (the report then lists them). Throws InputError when unreadable.
bool inspectVdbFile(const std::filesystem::path& file, std::ostream& report);

/// The continuous material field: trilinear between voxel centres (BoxSampler
/// convention) of each grid through its own transform; inactive voxels and anything
/// outside a grid take the base material's value. `worldToRest` maps world points into
/// the grids' (object rest) space. `sigmaScale` multiplies the σ read from the grids to
/// convert the file's units to the scene's (σ is intrinsic: scaling the object does not
/// change it). With `deformation`, `worldToRest` reaches the deformed object space and
/// the deformation's inverse then the rest space the grids live in (volume/deform.h); box
/// averages are then stratified point averages, the map being non-linear.
/// Thread-safe: each thread makes its own Sampler.
class MaterialField {
 public:
  MaterialField(const MaterialSample& base, std::shared_ptr<const MaterialSet> set,
                const glm::dmat4& worldToRest, double sigmaScale,
                std::shared_ptr<const DeformationPose> deformation = nullptr);

  /// Holds ValueAccessors and scratch buffers: cheap to create (one allocation, no tree
  /// traversal), one per thread. Copies share that state: do not use a Sampler and its
  /// copy on two threads. Non-finite points and boxes give the base material.
  class Sampler {
   public:
    /// The field at a world point.
    MaterialSample sample(const glm::dvec3& world) const;
    /// The field averaged over a world-axis-aligned box: exact for the trilinear field
    /// when the grids are axis-aligned in world space, else a dense stratified average.
    MaterialSample boxAverage(const glm::dvec3& worldMin, const glm::dvec3& worldMax) const;

   private:
    friend class MaterialField;
    struct Impl;
    std::shared_ptr<Impl> impl_;
  };

  Sampler sampler() const;
  const MaterialSample& base() const { return base_; }
  bool homogeneous() const { return !set_; }
  /// Painted and posed by deformers: every sample goes back to rest space through their
  /// inverse.
  bool deformed() const { return set_ && deformation_; }

 private:
  MaterialSample base_;
  std::shared_ptr<const MaterialSet> set_;
  glm::dmat4 worldToRest_;
  double sigmaScale_;
  std::shared_ptr<const DeformationPose> deformation_;
  /// Per-grid maps from world to index space and active bounding boxes, computed once
  /// here so that making a Sampler costs no tree traversal.
  struct Prepared;
  std::shared_ptr<const Prepared> prepared_;
};

/// Fills material.sigmaT/sigmaS/g for every cell of `material.frame` with the field
/// box-filtered over the cell (TBB parallel). coverage is left as is.
void resampleMaterial(const MaterialField& field, MaterialGrid& material);

/// Re-resamples only the cells whose box overlaps `worldRegion` (a brush stroke's bounds)
/// and returns them; the whole grid when the material arrays are not yet sized to the
/// frame. The result equals a full resampleMaterial() of the new field.
CellRange resampleMaterialRegion(const MaterialField& field, MaterialGrid& material, const Bounds& worldRegion);

}  // namespace sslpv

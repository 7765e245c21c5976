#pragma once
// Material sets: OpenVDB files with sigma_t, sigma_s (Vec3SGrid) and g (FloatGrid)
// (docs/design.md §4). Sampling them is volume/material/material_field.h.
#include <openvdb/openvdb.h>

#include <filesystem>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <memory>
#include <string>
#include <vector>


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
/// in an isolated child process (see volume/material/vdb_isolated_read.h). Metadata "units"
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

}  // namespace sslpv

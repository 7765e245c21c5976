#pragma once
// Which LPV cells lie inside the mesh, with fractional coverage at the boundary.
#include "volume/lpv_grid.h"
#include "volume/mesh.h"

namespace sslpv {

/// Fills `coverage` (size frame.cellCount()) with the fraction of each cell inside the
/// closed mesh, in [0, 1]: 1 deep inside, 0 outside, fractional across the surface.
/// Handles meshes of millions of triangles in seconds (OpenVDB meshToVolume, TBB).
std::vector<float> voxelizeCoverage(const TriangleMesh& mesh, const GridFrame& frame);

}  // namespace sslpv

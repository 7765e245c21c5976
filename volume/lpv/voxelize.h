#pragma once
// Which LPV cells lie inside the mesh, with fractional coverage at the boundary.
#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"

namespace sslpv {

/// Fills `coverage` (size frame.cellCount()) with the fraction of each cell inside the
/// closed mesh, in [0, 1]: 1 deep inside, 0 outside, fractional across the surface.
/// Handles meshes of millions of triangles in seconds (OpenVDB meshToVolume, TBB).
std::vector<float> voxelizeCoverage(const TriangleMesh& mesh, const GridFrame& frame);

/// Exact fraction of a cube lying behind a plane with unit normal `normal` (pointing out
/// of the solid) that passes at signed distance `distanceCells` from the cube's centre, in
/// cell widths (negative: the centre is inside). The coverage rule voxelizeCoverage uses.
double planeCubeCoverage(double distanceCells, glm::dvec3 normal);

}  // namespace sslpv

#include "volume/lpv/voxelize.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <mutex>

namespace sslpv {
namespace {

// The level set is kept this many cells either side of the surface; the coverage and the
// normal estimate read at most sqrt(3)/2 + 1 cells away from it, so 3 is ample.
constexpr float kBandCells = 3.0f;

void initializeOpenVdbOnce() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

/// Feeds the mesh to meshToVolume in the level set's index space without copying it.
/// Voxel (i,j,k) of the level set is LPV cell (i,j,k): its centre, index point (i,j,k),
/// is world origin + (i + 0.5) * cellSize.
class IndexSpaceMeshAdapter {
 public:
  IndexSpaceMeshAdapter(const TriangleMesh& mesh, const GridFrame& frame)
      : mesh_(mesh), origin_(frame.origin), inverseCellSize_(1.0 / frame.cellSize) {}

  std::size_t polygonCount() const { return mesh_.triangles.size(); }
  std::size_t pointCount() const { return mesh_.positions.size(); }
  std::size_t vertexCount(std::size_t) const { return 3; }
  void getIndexSpacePoint(std::size_t polygon, std::size_t vertex, openvdb::Vec3d& pos) const {
    const glm::dvec3 p = glm::dvec3(mesh_.positions[mesh_.triangles[polygon][int(vertex)]]);
    const glm::dvec3 index = (p - origin_) * inverseCellSize_ - 0.5;
    pos = openvdb::Vec3d(index.x, index.y, index.z);
  }

 private:
  const TriangleMesh& mesh_;
  glm::dvec3 origin_;
  double inverseCellSize_;
};

/// Volume fraction of the unit cube [0,1]^3 below the plane a.v = level, for a with
/// positive components (inclusion-exclusion over the cube's corners of the simplex
/// volume max(0, level - a.corner)^3 / (6 a.x a.y a.z)).
double cubeFractionBelowPlane(const glm::dvec3& a, double level) {
  double sum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 c(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    const double reach = level - glm::dot(a, c);
    if (reach <= 0.0) continue;
    const int parity = (corner & 1) + ((corner >> 1) & 1) + ((corner >> 2) & 1);
    sum += (parity % 2 == 0 ? 1.0 : -1.0) * reach * reach * reach;
  }
  return sum / (6.0 * a.x * a.y * a.z);
}

/// Coverage of a cell the surface passes through, from the signed distance at its centre
/// and the distance gradient there (both in cells). The surface is taken as the plane
/// they define. That is exact wherever the distance field is planar across the cell
/// (faces); at convex edges and corners the field is cylindrical or spherical and the
/// plane over-estimates by up to a quarter cell per cell of edge length. (Averaging
/// half-size sub-cells of the trilinear field was tried and is worse: it picks up the
/// interior kink of min(distance to each face) one cell away from every edge.)
double boundaryCellCoverage(double distanceCells, const glm::dvec3& gradient) {
  const double length = glm::length(gradient);
  // Near a medial axis (thin sheets, sharp creases) the gradient vanishes or is
  // meaningless; fall back to the axis-aligned ramp, which needs no normal.
  if (length > 0.5 && std::isfinite(length)) return planeCubeCoverage(distanceCells, gradient / length);
  return std::clamp(0.5 - distanceCells, 0.0, 1.0);
}

}  // namespace

/// Coverage of a cell whose centre lies at signed distance `distanceCells` (in cells,
/// negative inside) from a locally planar surface with unit normal `normal`: the exact
/// fraction of the cube behind that plane. For an axis-aligned normal this reduces to
/// clamp(0.5 - d, 0, 1); for oblique normals the transition is wider (up to sqrt(3) cells
/// along the diagonal) and the linear ramp would misplace up to ~5% of a cell.
double planeCubeCoverage(double distanceCells, glm::dvec3 normal) {
  // The cube is symmetric under axis flips, so only |n| matters. Tiny components are
  // lifted to keep the 1/(a.x a.y a.z) inclusion-exclusion well conditioned; the shift
  // they cause is below 1e-3 of a cell, far under the level set's own error.
  constexpr double kMinComponent = 1e-3;
  glm::dvec3 a = glm::max(glm::abs(normal), glm::dvec3(kMinComponent));
  const double halfExtent = 0.5 * (a.x + a.y + a.z);
  // Inside is a.u < -d for u in [-0.5,0.5]^3, i.e. a.v < halfExtent - d for v = u + 0.5.
  const double level = halfExtent - distanceCells;
  if (level <= 0.0) return 0.0;
  if (level >= 2.0 * halfExtent) return 1.0;
  // Evaluate the smaller half and mirror it: fewer cancelling terms, better precision.
  const double fraction = level <= halfExtent
                              ? cubeFractionBelowPlane(a, level)
                              : 1.0 - cubeFractionBelowPlane(a, 2.0 * halfExtent - level);
  return std::clamp(fraction, 0.0, 1.0);
}

std::vector<float> voxelizeCoverage(const TriangleMesh& mesh, const GridFrame& frame) {
  std::vector<float> coverage(frame.cellCount(), 0.0f);
  if (coverage.empty() || mesh.triangles.empty() || !(frame.cellSize > 0.0)) return coverage;

  // A mesh whose bounds miss the frame cannot cover any cell of it (the frame may still lie
  // wholly inside a mesh, so only disjoint bounds justify skipping the level set).
  const Bounds meshBounds = mesh.bounds();
  const glm::dvec3 frameMax = frame.origin + frame.cellSize * glm::dvec3(frame.dims);
  if (glm::any(glm::lessThan(meshBounds.max, frame.origin)) ||
      glm::any(glm::greaterThan(meshBounds.min, frameMax)))
    return coverage;

  initializeOpenVdbOnce();
  const IndexSpaceMeshAdapter adapter(mesh, frame);
  // The grid's transform is informational here (we read it in index space), but keep it
  // true to the frame so the grid could be written out for debugging.
  auto transform = openvdb::math::Transform::createLinearTransform(frame.cellSize);
  transform->postTranslate(openvdb::Vec3d(frame.origin.x, frame.origin.y, frame.origin.z) +
                           openvdb::Vec3d(0.5 * frame.cellSize));
  // Narrow band on both sides; the sign flood fill marks the deep interior with
  // -background, so cells far inside read as fully covered without being active.
  const openvdb::FloatGrid::Ptr levelSet =
      openvdb::tools::meshToVolume<openvdb::FloatGrid>(adapter, *transform, kBandCells, kBandCells);
  const float inverseCellSize = float(1.0 / frame.cellSize);  // the grid stores world units
  // Beyond sqrt(3)/2 cells from the plane the cube is wholly on one side for any normal.
  const float wholeCellDistance = 0.8661f;

  tbb::parallel_for(tbb::blocked_range<int>(0, frame.dims.z), [&](const tbb::blocked_range<int>& zs) {
    auto accessor = levelSet->getConstAccessor();
    auto distanceAt = [&](int x, int y, int z) {
      return accessor.getValue(openvdb::Coord(x, y, z)) * inverseCellSize;
    };
    for (int z = zs.begin(); z != zs.end(); ++z)
      for (int y = 0; y < frame.dims.y; ++y)
        for (int x = 0; x < frame.dims.x; ++x) {
          const float d = distanceAt(x, y, z);
          float value;
          if (d <= -wholeCellDistance) {
            value = 1.0f;
          } else if (d >= wholeCellDistance) {
            value = 0.0f;
          } else {
            // Central differences span two cells.
            const glm::dvec3 gradient(distanceAt(x + 1, y, z) - distanceAt(x - 1, y, z),
                                      distanceAt(x, y + 1, z) - distanceAt(x, y - 1, z),
                                      distanceAt(x, y, z + 1) - distanceAt(x, y, z - 1));
            value = float(boundaryCellCoverage(d, 0.5 * gradient));
          }
          coverage[frame.index(x, y, z)] = value;
        }
  });
  return coverage;
}

}  // namespace sslpv

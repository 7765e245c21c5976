#pragma once
// `sslpv export --pbrt`: the scene as a pbrt-v4 scene (same mesh, lights, camera, boundary,
// and the material field sampled into an "rgbgrid" medium), so users can check sslpv
// against an independent renderer. Syntax and unit choices (pbrt-v4 source, lights.cpp,
// media.cpp, film.cpp, cameras.cpp, util/containers.h SampledGrid):
//  - Camera: sslpv is right-handed, pbrt's LookAt gives a left-handed camera whose +x is
//    cross(up, dir), i.e. sslpv's left: "Scale -1 1 1" before LookAt puts world +x on
//    the image's right as in sslpv. pbrt's "fov" spans the SHORTER image axis.
//  - Lights: pbrt-v4 divides an RGB emission by the photometric value of its colour
//    space's (luminance-normalised) illuminant, and the default "cie1931" sensor at
//    iso 100 / exposure 1 has imaging ratio 1, so "rgb I [1 1 1]" renders as sRGB 1: the
//    RGB values are written as they are ("scale" 1, no "power"). Point/spot "I" is
//    radiant intensity (W/sr, radiance I/r² × BRDF), distant "L" is the irradiance on a
//    surface facing the light, exactly sslpv's units. Spot "coneangle" is the HALF angle;
//    "conedeltaangle" 0 makes pbrt's SmoothStep a hard edge, as in sslpv.
//  - Medium: rgbgrid samples sit at cell centres ((i + 0.5) / n of [p0, p1]) and are
//    interpolated trilinearly; beyond the outer sample a lookup blends toward ZERO, so the
//    grid has one margin cell around the object's bounds. Values are x fastest:
//    index (z * ny + y) * nx + x. σ are per scene unit and pbrt coordinates are scene
//    coordinates, so "scale" is 1. One "g" for the whole medium (the object's mean).
//  - Boundary: "dielectric" with "eta" = material.ior, or "interface" when ior is 1 (an
//    invisible boundary that only switches media). Triangles are written counter-clockwise
//    from outside, so pbrt's geometric normal cross(p0 - p2, p1 - p2) points out and
//    MediumInterface "<medium>" "" puts the medium inside.
#include <filesystem>
#include <glm/vec3.hpp>
#include <iosfwd>
#include <string>
#include <vector>

#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"

namespace sslpv {

class SceneObject;

/// Cells along the longest axis of the object's bounds (--grid).
inline constexpr int kDefaultPbrtGrid = 64;
/// Beyond this the text file reaches gigabytes (6 numbers per cell).
inline constexpr int kMaxPbrtGrid = 256;
/// pbrt's rgbgrid has one g: a larger spread of g inside the object gets a warning.
inline constexpr double kPbrtGSpreadTolerance = 0.01;
/// Written into the file; users raise it for a converged image.
inline constexpr int kPbrtPixelSamples = 256;
/// volpath counts every scattering event and boundary crossing as depth; subsurface
/// paths in dense media take thousands, and sslpv's reference tracer has no limit.
inline constexpr int kPbrtMaxDepth = 100000;
inline constexpr const char* kPbrtMediumName = "sslpv_material";

/// The material field sampled at cell centres for pbrt's "rgbgrid" medium.
struct PbrtMedium {
  /// nx, ny, nz = frame.dims; p0 = frame.origin; p1 = p0 + cellSize * dims.
  GridFrame frame;
  std::vector<glm::vec3> sigmaA;  ///< max(σt − σs, 0) per channel, GridFrame::index order
  std::vector<glm::vec3> sigmaS;
  double gMean = 0.0;  ///< coverage-weighted mean over the cells inside the object
  double gMin = 0.0;   ///< over cells partly inside the object
  double gMax = 0.0;
};

/// `grid` cubic cells along the longest axis of `objectBounds`, one margin cell on every
/// side, centred on the bounds. Throws InputError for grid outside [2, kMaxPbrtGrid].
GridFrame pbrtGridFrame(const Bounds& objectBounds, int grid);

/// Samples object.field() at every cell centre of pbrtGridFrame(object.bounds(), grid)
/// (TBB parallel), and g's mean and range over the object (voxelizeCoverage weights).
PbrtMedium samplePbrtMedium(const SceneObject& object, int grid);

/// pbrt's perspective "fov" in degrees: the scene's vertical fov when width >= height,
/// else the horizontal one, 2·atan(tan(fov_y / 2) · width / height).
double pbrtFovDeg(const Camera& camera);

/// Writes the whole scene text. `imageFile` becomes the Film's "filename"; scene.file is
/// named in the header comment.
void writePbrtScene(std::ostream& out, const Scene& scene, const TriangleMesh& mesh, const PbrtMedium& medium,
                    const std::string& imageFile);

struct PbrtExportSummary {
  glm::ivec3 dims{0};
  std::size_t triangles = 0;
  double gMean = 0.0, gMin = 0.0, gMax = 0.0;
  /// gMax - gMin > kPbrtGSpreadTolerance: pbrt will not see the painted g variation.
  bool gVaries() const { return gMax - gMin > kPbrtGSpreadTolerance; }
};

/// Loads the object, samples the medium and writes `output` atomically; the Film writes
/// `output` with its extension replaced by ".exr". InputError for bad scenes, grids and
/// paths; ResourceError when writing fails (disk full) — no partial file either way.
PbrtExportSummary exportPbrtScene(const Scene& scene, const std::filesystem::path& output,
                                  int grid = kDefaultPbrtGrid);

}  // namespace sslpv

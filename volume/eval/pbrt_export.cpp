#include "volume/eval/pbrt_export.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <fstream>
#include <glm/common.hpp>
#include <glm/trigonometric.hpp>
#include <limits>
#include <ostream>
#include <string_view>

#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/material/scene_object.h"
#include "volume/lpv/voxelize.h"
#include "volume/material/material_field.h"
#include "volume/scene/camera_rays.h"

namespace sslpv {
namespace fs = std::filesystem;

namespace {

/// Shortest text that reads back to the same float/double: the file carries exactly the
/// values sslpv uses, and a grid of millions of values stays as small as it can.
template <typename T>
void writeNumber(std::ostream& out, T value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  out.write(text, result.ptr - text);
}

void writeVec3(std::ostream& out, const glm::dvec3& v) {
  writeNumber(out, v.x);
  out << ' ';
  writeNumber(out, v.y);
  out << ' ';
  writeNumber(out, v.z);
}

void writeVec3(std::ostream& out, const glm::vec3& v) {
  writeNumber(out, v.x);
  out << ' ';
  writeNumber(out, v.y);
  out << ' ';
  writeNumber(out, v.z);
}

/// pbrt strings accept backslash escapes; a comment ends at the line's end.
std::string quoted(std::string_view text) {
  std::string s = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') s += '\\';
    s += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return s + '"';
}

std::string commentSafe(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  return text;
}

/// Values of a large array, a fixed count per line so the file stays readable in an editor.
void writeVec3Array(std::ostream& out, const std::vector<glm::vec3>& values) {
  constexpr std::size_t kPerLine = 4;
  for (std::size_t i = 0; i < values.size(); ++i) {
    out << (i % kPerLine == 0 ? "\n    " : "  ");
    writeVec3(out, values[i]);
  }
  out << "\n  ]";
}

void writeCamera(std::ostream& out, const Camera& camera) {
  out << "# sslpv's camera is right-handed; pbrt's LookAt makes a left-handed one whose +x is\n"
         "# sslpv's left. The Scale flips camera x so world +x is on the image's right, as in\n"
         "# sslpv. pbrt's fov spans the SHORTER image axis (sslpv's fov_y_deg is vertical:\n"
      << "# " << camera.fovYDeg << " degrees, " << camera.width << "x" << camera.height << ").\n";
  out << "Scale -1 1 1\nLookAt ";
  writeVec3(out, camera.position);
  out << "  ";
  writeVec3(out, camera.target);
  out << "  ";
  writeVec3(out, camera.up);
  out << "\nCamera \"perspective\" \"float fov\" [ ";
  writeNumber(out, pbrtFovDeg(camera));
  out << " ]\n";
  out << "# A float EXR (\"savefp16\" false): pbrt's default half floats keep only ~3 digits.\n";
  out << "Film \"rgb\" \"integer xresolution\" [ " << camera.width << " ] \"integer yresolution\" [ "
      << camera.height << " ]\n";
}

void writeLights(std::ostream& out, const std::vector<Light>& lights) {
  out << "# Light values are sslpv's RGB as they are (\"scale\" 1): pbrt-v4 divides an RGB emission\n"
         "# by its illuminant's luminance, and the default sensor (cie1931, iso 100, exposure 1)\n"
         "# has imaging ratio 1, so rgb [1 1 1] renders as 1. Point/spot I: W/sr; distant L: the\n"
         "# irradiance on a surface facing the light (per scene unit^2): sslpv's radiance units.\n";
  if (lights.empty()) out << "# (the scene has no lights)\n";
  for (const Light& light : lights) {
    switch (light.type) {
      case Light::Type::Point:
        out << "LightSource \"point\" \"rgb I\" [ ";
        writeVec3(out, light.intensity);
        out << " ] \"point3 from\" [ ";
        writeVec3(out, light.position);
        out << " ]\n";
        break;
      case Light::Type::Spot:
        out << "# spot: sslpv's fov_deg " << light.fovDeg
            << " is the full cone; pbrt's coneangle is the half angle, and\n"
               "# conedeltaangle 0 gives the same hard edge.\n";
        out << "LightSource \"spot\" \"rgb I\" [ ";
        writeVec3(out, light.intensity);
        out << " ]\n  \"point3 from\" [ ";
        writeVec3(out, light.position);
        out << " ] \"point3 to\" [ ";
        writeVec3(out, light.position + light.direction);
        out << " ]\n  \"float coneangle\" [ ";
        writeNumber(out, 0.5 * light.fovDeg);
        out << " ] \"float conedeltaangle\" [ 0 ]\n";
        break;
      case Light::Type::Directional:
        out << "# distant: light travels from \"from\" towards \"to\" (sslpv's direction).\n";
        out << "LightSource \"distant\" \"rgb L\" [ ";
        writeVec3(out, light.irradiance);
        out << " ] \"point3 from\" [ 0 0 0 ] \"point3 to\" [ ";
        writeVec3(out, light.direction);
        out << " ]\n";
        break;
    }
  }
}

void writeMedium(std::ostream& out, const PbrtMedium& medium) {
  const GridFrame& f = medium.frame;
  const glm::dvec3 p1 = f.origin + f.cellSize * glm::dvec3(f.dims);
  out << "# The material field (base material + material set, the function every sslpv stage\n"
         "# samples) at the centres of " << f.dims.x << "x" << f.dims.y << "x" << f.dims.z
      << " cubic cells of " << f.cellSize
      << " units: the object's bounds plus one cell\n"
         "# on every side, because pbrt blends toward zero beyond the outermost samples.\n"
         "# sigma_a = max(sigma_t - sigma_s, 0) per channel. sigma_a and sigma_s are per scene unit and\n"
         "# pbrt coordinates are the scene's world coordinates, so \"scale\" is 1 and nothing is\n"
         "# converted. pbrt turns each RGB sigma into a smooth spectrum, so strongly coloured media\n"
         "# differ a little from sslpv's per-channel transport.\n";
  if (medium.gMax - medium.gMin > kPbrtGSpreadTolerance)
    out << "# g varies from " << medium.gMin << " to " << medium.gMax
        << " inside the object; rgbgrid takes one g: this is the mean.\n";
  out << "MakeNamedMedium " << quoted(kPbrtMediumName) << " \"string type\" [ \"rgbgrid\" ]\n";
  out << "  \"integer nx\" [ " << f.dims.x << " ] \"integer ny\" [ " << f.dims.y << " ] \"integer nz\" [ "
      << f.dims.z << " ]\n  \"point3 p0\" [ ";
  writeVec3(out, f.origin);
  out << " ] \"point3 p1\" [ ";
  writeVec3(out, p1);
  out << " ]\n  \"float scale\" [ 1 ] \"float g\" [ ";
  writeNumber(out, medium.gMean);
  out << " ]\n  \"rgb sigma_a\" [";
  writeVec3Array(out, medium.sigmaA);
  out << "\n  \"rgb sigma_s\" [";
  writeVec3Array(out, medium.sigmaS);
  out << "\n";
}

void writeObject(std::ostream& out, const TriangleMesh& mesh, double ior) {
  out << "AttributeBegin\n  MediumInterface " << quoted(kPbrtMediumName) << " \"\"\n";
  if (ior == 1.0) {
    out << "  # ior 1: an index-matched boundary that only switches media.\n  Material \"interface\"\n";
  } else {
    out << "  Material \"dielectric\" \"float eta\" [ ";
    writeNumber(out, ior);
    out << " ]\n";
  }
  out << "  # World space, counter-clockwise seen from outside (pbrt's normal points out).\n"
         "  Shape \"trianglemesh\"\n  \"point3 P\" [";
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    out << (i % 4 == 0 ? "\n    " : "  ");
    writeVec3(out, mesh.positions[i]);
  }
  out << "\n  ]\n  \"integer indices\" [";
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const glm::uvec3& t = mesh.triangles[i];
    out << (i % 8 == 0 ? "\n    " : "  ") << t.x << ' ' << t.y << ' ' << t.z;
  }
  out << "\n  ]\nAttributeEnd\n";
}

void requirePbrtGrid(int grid) {
  if (grid < 2 || grid > kMaxPbrtGrid)
    throw InputError("pbrt export: the medium grid must have 2 to " + std::to_string(kMaxPbrtGrid) +
                     " cells along the longest axis, got " + std::to_string(grid));
}

}  // namespace

GridFrame pbrtGridFrame(const Bounds& objectBounds, int grid) {
  requirePbrtGrid(grid);
  if (objectBounds.empty()) throw InputError("pbrt export: the object has no extent");
  const glm::dvec3 extent = objectBounds.extent();
  const double longest = std::max({extent.x, extent.y, extent.z});
  if (!(longest > 0.0) || !std::isfinite(longest))
    throw InputError("pbrt export: the object has zero or non-finite extent");
  GridFrame frame;
  frame.cellSize = longest / grid;
  const glm::dvec3 center = 0.5 * (objectBounds.min + objectBounds.max);
  for (int a = 0; a < 3; ++a) {
    // The tolerance keeps the longest axis at exactly `grid` interior cells.
    frame.dims[a] = std::max(1, int(std::ceil(extent[a] / frame.cellSize - 1e-9))) + 2;
    frame.origin[a] = center[a] - 0.5 * frame.dims[a] * frame.cellSize;
  }
  return frame;
}

PbrtMedium samplePbrtMedium(const SceneObject& object, int grid) {
  PbrtMedium medium;
  medium.frame = pbrtGridFrame(object.bounds(), grid);
  const GridFrame& frame = medium.frame;
  const std::size_t cells = frame.cellCount();
  medium.sigmaA.resize(cells);
  medium.sigmaS.resize(cells);
  std::vector<float> g(cells);
  const MaterialField& field = object.field();
  tbb::parallel_for(tbb::blocked_range<int>(0, frame.dims.z), [&](const tbb::blocked_range<int>& zs) {
    const MaterialField::Sampler sampler = field.sampler();
    for (int z = zs.begin(); z != zs.end(); ++z)
      for (int y = 0; y < frame.dims.y; ++y)
        for (int x = 0; x < frame.dims.x; ++x) {
          const std::size_t i = frame.index(x, y, z);
          const MaterialSample s = sampler.sample(frame.cellCenter(x, y, z));
          medium.sigmaS[i] = s.sigmaS;
          // Float round-off can leave σs a hair above σt where the set has albedo 1.
          medium.sigmaA[i] = glm::max(s.sigmaT - s.sigmaS, glm::vec3(0.0f));
          g[i] = s.g;
        }
  });

  // g over the object only: the margin and the air around the mesh never scatter in pbrt.
  const std::vector<float> coverage = voxelizeCoverage(object.mesh(), frame);
  double weighted = 0.0, weight = 0.0;
  double gMin = std::numeric_limits<double>::infinity(), gMax = -gMin;
  for (std::size_t i = 0; i < cells; ++i) {
    if (!(coverage[i] > 0.0f)) continue;
    weighted += double(coverage[i]) * g[i];
    weight += coverage[i];
    gMin = std::min(gMin, double(g[i]));
    gMax = std::max(gMax, double(g[i]));
  }
  if (weight > 0.0) {
    medium.gMean = weighted / weight;
    medium.gMin = gMin;
    medium.gMax = gMax;
  } else {  // cannot happen for a closed mesh spanning >= 2 cells; the base is the honest fallback
    medium.gMean = medium.gMin = medium.gMax = field.base().g;
  }
  return medium;
}

double pbrtFovDeg(const Camera& camera) {
  if (camera.width >= camera.height) return camera.fovYDeg;
  return glm::degrees(2.0 * std::atan(CameraRays(camera).tanHalfX));
}

void writePbrtScene(std::ostream& out, const Scene& scene, const TriangleMesh& mesh, const PbrtMedium& medium,
                    const std::string& imageFile) {
  out << "# pbrt-v4 scene written by `sslpv export --pbrt` from " << commentSafe(scene.file.string())
      << ",\n# to check sslpv against an independent renderer. 1 unit = 1 " << scene.units
      << " (the scene's units).\n\n";
  writeCamera(out, scene.camera);
  out << "  \"string filename\" [ " << quoted(imageFile) << " ] \"bool savefp16\" [ false ]\n";
  out << "# sslpv traces one ray through each pixel centre; a half-pixel box filter is closest.\n";
  out << "PixelFilter \"box\" \"float xradius\" [ 0.5 ] \"float yradius\" [ 0.5 ]\n";
  out << "# Raise pixelsamples for a converged image. volpath counts every scattering event as\n"
         "# depth; sslpv's reference tracer does not limit them.\n";
  out << "Sampler \"zsobol\" \"integer pixelsamples\" [ " << kPbrtPixelSamples << " ]\n";
  out << "Integrator \"volpath\" \"integer maxdepth\" [ " << kPbrtMaxDepth << " ]\n\nWorldBegin\n\n";
  writeLights(out, scene.lights);
  out << "\n";
  writeMedium(out, medium);
  out << "\n";
  writeObject(out, mesh, scene.material.ior);
}

PbrtExportSummary exportPbrtScene(const Scene& scene, const fs::path& output, int grid) {
  // Cheap checks first, so a typo does not cost a mesh load and a grid sampling.
  requirePbrtGrid(grid);
  requireWritableOutput(output);
  const SceneObject object(scene);
  const PbrtMedium medium = samplePbrtMedium(object, grid);
  fs::path image = output.filename();
  image.replace_extension(".exr");
  writeAtomically(output, [&](const fs::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    if (!out) throw InputError(output.string() + ": cannot open for writing");
    writePbrtScene(out, scene, object.mesh(), medium, image.string());
    out.close();
    if (!out) throwWriteFailed(output, errno);
  });
  PbrtExportSummary summary;
  summary.dims = medium.frame.dims;
  summary.triangles = object.mesh().triangles.size();
  summary.gMean = medium.gMean;
  summary.gMin = medium.gMin;
  summary.gMax = medium.gMax;
  return summary;
}

}  // namespace sslpv

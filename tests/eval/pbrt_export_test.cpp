// `sslpv export --pbrt` (volume/eval/pbrt_export.h): the written pbrt-v4 file is read back with
// a small tokenizer and checked against the scene, against sslpv's own material field,
// mesh and camera, and against pbrt-v4's documented conventions re-derived here from its
// source (LookAt's left-handed camera, fov on the shorter axis, rgbgrid samples at cell
// centres in x-fastest order, half-angle spot cones). pbrt itself is not installed here,
// so no test renders the file.
#include "volume/eval/pbrt_export.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cctype>
#include <cmath>
#include <glm/glm.hpp>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"
#include "volume/core/error.h"
#include "volume/material/material_field.h"
#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"
#include "volume/material/scene_object.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;

// --- a tiny pbrt-v4 reader ----------------------------------------------------------------

struct Token {
  enum Kind { Word, String, Number, Open, Close } kind;
  std::string text;
};

std::vector<Token> tokenize(const std::string& text) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (c == '[' || c == ']') {
      tokens.push_back({c == '[' ? Token::Open : Token::Close, std::string(1, c)});
      ++i;
    } else if (c == '"') {
      std::string s;
      for (++i; i < text.size() && text[i] != '"'; ++i) {
        if (text[i] == '\\') ++i;
        s += text[i];
      }
      ++i;
      tokens.push_back({Token::String, s});
    } else {
      const std::size_t start = i;
      while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i])) && text[i] != '[' &&
             text[i] != ']' && text[i] != '"')
        ++i;
      std::string word = text.substr(start, i - start);
      const bool numeric = std::isdigit(static_cast<unsigned char>(word[0])) || word[0] == '-' ||
                           word[0] == '+' || word[0] == '.';
      tokens.push_back({numeric ? Token::Number : Token::Word, word});
    }
  }
  return tokens;
}

struct Param {
  std::string type, name;
  std::vector<Token> values;
};

struct Statement {
  std::string keyword;
  std::vector<Token> args;  ///< positional: strings without a space, numbers
  std::vector<Param> params;

  const Param* find(const std::string& name) const {
    for (const Param& p : params)
      if (p.name == name) return &p;
    return nullptr;
  }
  const Param& param(const std::string& name) const {
    const Param* p = find(name);
    if (!p) throw std::runtime_error(keyword + ": no parameter " + name);
    return *p;
  }
  std::vector<double> numbers(const std::string& name) const {
    std::vector<double> v;
    for (const Token& t : param(name).values) v.push_back(std::stod(t.text));
    return v;
  }
  double number(const std::string& name) const {
    const auto v = numbers(name);
    if (v.size() != 1) throw std::runtime_error(keyword + ": " + name + " is not one number");
    return v[0];
  }
  glm::dvec3 vec3(const std::string& name) const {
    const auto v = numbers(name);
    if (v.size() != 3) throw std::runtime_error(keyword + ": " + name + " is not 3 numbers");
    return {v[0], v[1], v[2]};
  }
  std::string text(const std::string& name) const { return param(name).values.at(0).text; }
  std::vector<double> argNumbers() const {
    std::vector<double> v;
    for (const Token& t : args) v.push_back(std::stod(t.text));
    return v;
  }
};

std::vector<Statement> parsePbrt(const std::string& text) {
  const std::vector<Token> tokens = tokenize(text);
  std::vector<Statement> statements;
  for (std::size_t i = 0; i < tokens.size();) {
    if (tokens[i].kind != Token::Word) throw std::runtime_error("expected a statement at '" + tokens[i].text + "'");
    Statement st;
    st.keyword = tokens[i++].text;
    while (i < tokens.size() && tokens[i].kind != Token::Word) {
      const Token& t = tokens[i];
      const std::size_t space = t.text.find(' ');
      if (t.kind == Token::String && space != std::string::npos) {
        Param p{t.text.substr(0, space), t.text.substr(space + 1), {}};
        ++i;
        if (i < tokens.size() && tokens[i].kind == Token::Open) {
          for (++i; i < tokens.size() && tokens[i].kind != Token::Close; ++i) p.values.push_back(tokens[i]);
          ++i;
        } else {
          p.values.push_back(tokens.at(i++));
        }
        st.params.push_back(p);
      } else {
        st.args.push_back(t);
        ++i;
      }
    }
    statements.push_back(st);
  }
  return statements;
}

std::vector<const Statement*> all(const std::vector<Statement>& sts, const std::string& keyword) {
  std::vector<const Statement*> found;
  for (const Statement& s : sts)
    if (s.keyword == keyword) found.push_back(&s);
  return found;
}

const Statement& one(const std::vector<Statement>& sts, const std::string& keyword) {
  const auto found = all(sts, keyword);
  if (found.size() != 1)
    throw std::runtime_error("expected one " + keyword + ", found " + std::to_string(found.size()));
  return *found[0];
}

std::size_t positionOf(const std::vector<Statement>& sts, const std::string& keyword) {
  for (std::size_t i = 0; i < sts.size(); ++i)
    if (sts[i].keyword == keyword) return i;
  return sts.size();
}

// --- scenes ---------------------------------------------------------------------------------

std::string sceneJson(const std::string& material, const std::string& camera, const std::string& extra = "") {
  return R"({
    "units": "mm",
    "mesh": {"primitive": "box", "min": [-4, -3, -2], "max": [5, 3, 2.5]},
    "transform": {"translate": [1.5, -2, 0.75], "rotate_deg": [10, 35, -20], "scale": 1.25},
    "material": )" + material + R"(,
    "lights": [
      {"type": "point", "position": [20, 30, 40], "intensity": [1000, 1200.5, 800.25]},
      {"type": "spot", "position": [-30, 25, 10], "direction": [0.6, -0.5, -0.6244998],
       "fov_deg": 37, "intensity": [3000, 2900, 2800]},
      {"type": "directional", "direction": [0.0, -0.6, -0.8], "irradiance": [4, 3.5, 3]}
    ],
    "camera": )" + camera + extra + R"(
  })";
}

const std::string kHomogeneous =
    R"({"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.35}, "ior": 1.5})";
const std::string kCamera = R"({"position": [6, 14, 40], "target": [0.5, -1, 0], "up": [0.1, 1, 0],
                                 "fov_y_deg": 35, "width": 64, "height": 48})";

struct Exported {
  Scene scene;
  PbrtExportSummary summary;
  std::string text;
  std::vector<Statement> statements;
};

Exported exportScene(const TempDir& dir, const std::string& json, int grid) {
  writeText(dir / "scene.json", json);
  Exported e;
  e.scene = loadScene(dir / "scene.json");
  e.summary = exportPbrtScene(e.scene, dir / "out.pbrt", grid);
  e.text = readText(dir / "out.pbrt");
  e.statements = parsePbrt(e.text);
  return e;
}

/// A material set in the box's rest space: σt/σs and g vary along x and y over voxels of
/// 0.7 mm offset by half a voxel, so cell centres fall between voxel centres and the
/// trilinear field is exercised, not just voxel values.
void writeVaryingSet(const fs::path& file) {
  openvdb::initialize();
  MaterialSet set;
  set.sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set.sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set.g = openvdb::FloatGrid::create(0.0f);
  set.sigmaT->setName("sigma_t");
  set.sigmaS->setName("sigma_s");
  set.g->setName("g");
  auto transform = openvdb::math::Transform::createLinearTransform(0.7);
  transform->postTranslate(openvdb::Vec3d(0.35, -0.2, 0.1));
  set.sigmaT->setTransform(transform);
  set.sigmaS->setTransform(transform->copy());
  set.g->setTransform(transform->copy());
  auto t = set.sigmaT->getAccessor();
  auto s = set.sigmaS->getAccessor();
  auto g = set.g->getAccessor();
  for (int z = -2; z <= 2; ++z)
    for (int y = -3; y <= 3; ++y)
      for (int x = -5; x <= 5; ++x) {
        const float a = 2.0f + 0.3f * float(x) + 0.1f * float(y * y) + 0.05f * float(z);
        t.setValue(openvdb::Coord(x, y, z), openvdb::Vec3s(a, 1.3f * a, 0.8f * a));
        s.setValue(openvdb::Coord(x, y, z), openvdb::Vec3s(0.9f * a, 1.2f * a, 0.8f * a));  // blue: albedo 1
        g.setValue(openvdb::Coord(x, y, z), 0.05f * float(x));
      }
  saveMaterialSet(set, file);
}

const std::string kVaryingMaterial =
    R"({"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.1}, "vdb": "set.vdb", "ior": 1})";

// --- camera ---------------------------------------------------------------------------------

/// pbrt-v4's camera, as its source builds it: ctm = Scale * LookAt (cameraFromWorld),
/// LookAt's camera x = cross(up, dir), y = cross(dir, x); Perspective(fov) divides by z and
/// by tan(fov/2); the screen window is [-aspect, aspect] x [-1, 1] for aspect > 1, else
/// [-1, 1] x [-1/aspect, 1/aspect]; raster y grows downwards from the window's top.
glm::dvec2 pbrtRaster(const std::vector<Statement>& sts, const glm::dvec3& world) {
  const std::vector<double> la = one(sts, "LookAt").argNumbers();
  const std::vector<double> sc = one(sts, "Scale").argNumbers();
  const glm::dvec3 pos(la[0], la[1], la[2]), look(la[3], la[4], la[5]), up(la[6], la[7], la[8]);
  const glm::dvec3 dir = glm::normalize(look - pos);
  const glm::dvec3 right = glm::normalize(glm::cross(glm::normalize(up), dir));
  const glm::dvec3 newUp = glm::cross(dir, right);
  const glm::dvec3 d = world - pos;
  const glm::dvec3 cam = glm::dvec3(sc[0], sc[1], sc[2]) * glm::dvec3(glm::dot(d, right), glm::dot(d, newUp), glm::dot(d, dir));
  const double fov = one(sts, "Camera").number("fov");
  const Statement& film = one(sts, "Film");
  const double w = film.number("xresolution"), h = film.number("yresolution");
  const double t = std::tan(glm::radians(0.5 * fov));
  const glm::dvec2 screen(cam.x / cam.z / t, cam.y / cam.z / t);
  const double frame = w / h;
  const glm::dvec2 lo = frame > 1.0 ? glm::dvec2(-frame, -1.0) : glm::dvec2(-1.0, -1.0 / frame);
  const glm::dvec2 hi = -lo;
  return {(screen.x - lo.x) / (hi.x - lo.x) * w, (hi.y - screen.y) / (hi.y - lo.y) * h};
}

class PbrtCamera : public ::testing::TestWithParam<std::pair<int, int>> {};

// Physical expectation: pbrt sees the same image as sslpv, so the world point on sslpv's
// ray through pixel centre (x + ½, y + ½) (volume/cpu/shade.cpp's camera) must project through
// the written camera to raster position (x + ½, y + ½) in pbrt, for portrait, landscape
// and square images (portrait needs the fov converted to the horizontal axis).
TEST_P(PbrtCamera, SslpvPixelCentresProjectToTheSamePbrtRasterPositions) {
  const auto [width, height] = GetParam();
  const std::string camera = R"({"position": [6, 14, 40], "target": [0.5, -1, 0], "up": [0.1, 1, 0],
      "fov_y_deg": 35, "width": )" + std::to_string(width) + R"(, "height": )" + std::to_string(height) + "}";
  TempDir dir;
  const Exported e = exportScene(dir, sceneJson(kHomogeneous, camera), 6);
  const Statement& film = one(e.statements, "Film");
  ASSERT_EQ(film.args.at(0).text, "rgb");
  EXPECT_EQ(film.number("xresolution"), width);
  EXPECT_EQ(film.number("yresolution"), height);
  EXPECT_EQ(film.text("filename"), "out.exr");
  EXPECT_EQ(film.text("savefp16"), "false") << "half-float EXRs would round sslpv's comparison";
  ASSERT_EQ(one(e.statements, "Camera").args.at(0).text, "perspective");
  const double fovY = 35.0;
  const double expectedFov = width >= height
                                 ? fovY
                                 : glm::degrees(2.0 * std::atan(std::tan(glm::radians(fovY / 2)) * width / height));
  EXPECT_NEAR(one(e.statements, "Camera").number("fov"), expectedFov, 1e-12);
  // The camera statements precede WorldBegin (pbrt rejects them after it).
  EXPECT_LT(positionOf(e.statements, "Camera"), positionOf(e.statements, "WorldBegin"));
  EXPECT_LT(positionOf(e.statements, "LookAt"), positionOf(e.statements, "Camera"));

  const Camera& c = e.scene.camera;
  const glm::dvec3 forward = glm::normalize(c.target - c.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, c.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tanHalfY = std::tan(glm::radians(0.5 * c.fovYDeg));
  const double tanHalfX = tanHalfY * c.width / c.height;
  for (const auto& [x, y] : std::vector<std::pair<int, int>>{
           {0, 0}, {width - 1, 0}, {0, height - 1}, {width - 1, height - 1}, {width / 3, height / 2}}) {
    const double u = (2.0 * (x + 0.5) / c.width - 1.0) * tanHalfX;
    const double v = (1.0 - 2.0 * (y + 0.5) / c.height) * tanHalfY;
    const glm::dvec3 world = c.position + 17.0 * glm::normalize(forward + u * right + v * up);
    const glm::dvec2 raster = pbrtRaster(e.statements, world);
    EXPECT_NEAR(raster.x, x + 0.5, 1e-6) << "pixel (" << x << ", " << y << ")";
    EXPECT_NEAR(raster.y, y + 0.5, 1e-6) << "pixel (" << x << ", " << y << ")";
  }
}

std::string shapeName(const ::testing::TestParamInfo<std::pair<int, int>>& shape) {
  return std::to_string(shape.param.first) + "x" + std::to_string(shape.param.second);
}

INSTANTIATE_TEST_SUITE_P(Shapes, PbrtCamera,
                         ::testing::Values(std::make_pair(48, 64), std::make_pair(64, 40), std::make_pair(32, 32)),
                         shapeName);

// --- lights ---------------------------------------------------------------------------------

// Units (docs/design.md §6.12): point/spot intensity W/sr and directional irradiance are pbrt's I and
// L unchanged (pbrt-v4 normalises RGB emission to its illuminant's luminance, and the
// default sensor's imaging ratio is 1). Spot: pbrt's coneangle is the half angle, and a
// conedeltaangle of 0 is a hard edge like sslpv's. Distant: light goes from "from" to "to".
TEST(PbrtExport, LightsKeepSslpvValuesWithPbrtGeometry) {
  TempDir dir;
  const Exported e = exportScene(dir, sceneJson(kHomogeneous, kCamera), 6);
  const auto lights = all(e.statements, "LightSource");
  ASSERT_EQ(lights.size(), e.scene.lights.size());
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const Statement& st = *lights[i];
    const Light& light = e.scene.lights[i];
    SCOPED_TRACE("light " + std::to_string(i));
    EXPECT_EQ(st.find("scale"), nullptr) << "a scale would change sslpv's units";
    EXPECT_EQ(st.find("power"), nullptr) << "power would renormalise the emission";
    switch (light.type) {
      case Light::Type::Point:
        EXPECT_EQ(st.args.at(0).text, "point");
        EXPECT_EQ(st.param("I").type, "rgb");
        EXPECT_EQ(st.vec3("I"), glm::dvec3(light.intensity));
        EXPECT_EQ(st.vec3("from"), light.position);
        break;
      case Light::Type::Spot: {
        EXPECT_EQ(st.args.at(0).text, "spot");
        EXPECT_EQ(st.vec3("I"), glm::dvec3(light.intensity));
        EXPECT_EQ(st.vec3("from"), light.position);
        const glm::dvec3 axis = glm::normalize(st.vec3("to") - st.vec3("from"));
        EXPECT_NEAR(glm::dot(axis, glm::normalize(light.direction)), 1.0, 1e-12);
        EXPECT_DOUBLE_EQ(st.number("coneangle"), 18.5);  // fov_deg 37, full cone
        EXPECT_EQ(st.number("conedeltaangle"), 0.0);
        EXPECT_EQ(st.find("conedelta"), nullptr) << "pbrt-v4 calls it conedeltaangle";
        break;
      }
      case Light::Type::Directional: {
        EXPECT_EQ(st.args.at(0).text, "distant");
        EXPECT_EQ(st.param("L").type, "rgb");
        EXPECT_EQ(st.vec3("L"), glm::dvec3(light.irradiance));
        const glm::dvec3 travel = glm::normalize(st.vec3("to") - st.vec3("from"));
        EXPECT_NEAR(glm::dot(travel, glm::normalize(light.direction)), 1.0, 1e-12);
        break;
      }
    }
  }
  EXPECT_GT(positionOf(e.statements, "LightSource"), positionOf(e.statements, "WorldBegin"));
}

// --- medium ---------------------------------------------------------------------------------

// The rgbgrid must hold sslpv's material field: pbrt's sample (i, j, k) sits at
// p0 + (i + ½, j + ½, k + ½)·(p1 − p0)/n and values run x fastest. Every cell's σs and
// σa = max(σt − σs, 0) must equal MaterialField::Sampler::sample at that centre (the field
// every sslpv consumer uses), through the scene's rotation/scale and the set's own
// transform. The cells are cubic, N cells span the longest axis of the object plus one
// margin cell on each side (pbrt fades to zero beyond the outer samples).
TEST(PbrtExport, MediumHoldsTheMaterialFieldAtEveryCellCentre) {
  TempDir dir;
  writeVaryingSet(dir / "set.vdb");
  constexpr int kGrid = 12;
  const Exported e = exportScene(dir, sceneJson(kVaryingMaterial, kCamera), kGrid);
  const Statement& medium = one(e.statements, "MakeNamedMedium");
  EXPECT_EQ(medium.text("type"), "rgbgrid");
  const glm::ivec3 n(int(medium.number("nx")), int(medium.number("ny")), int(medium.number("nz")));
  const glm::dvec3 p0 = medium.vec3("p0"), p1 = medium.vec3("p1");
  EXPECT_EQ(medium.number("scale"), 1.0);
  const std::size_t cells = std::size_t(n.x) * n.y * n.z;
  const std::vector<double> sigmaA = medium.numbers("sigma_a"), sigmaS = medium.numbers("sigma_s");
  ASSERT_EQ(sigmaA.size(), cells * 3);
  ASSERT_EQ(sigmaS.size(), cells * 3);
  EXPECT_EQ(medium.param("sigma_a").type, "rgb");
  EXPECT_EQ(medium.param("sigma_s").type, "rgb");

  const SceneObject object(e.scene);
  const Bounds& b = object.bounds();
  const glm::dvec3 h = (p1 - p0) / glm::dvec3(n);
  EXPECT_NEAR(h.y, h.x, 1e-9 * h.x);
  EXPECT_NEAR(h.z, h.x, 1e-9 * h.x);
  const glm::dvec3 extent = b.extent();
  EXPECT_NEAR(std::max({extent.x, extent.y, extent.z}), kGrid * h.x, 1e-9 * h.x);
  EXPECT_EQ(std::max({n.x, n.y, n.z}), kGrid + 2);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(p0[a] + h.x, b.min[a] + 1e-9) << "axis " << a << ": no margin cell below the object";
    EXPECT_GE(p1[a] - h.x, b.max[a] - 1e-9) << "axis " << a << ": no margin cell above the object";
  }

  const MaterialField::Sampler sampler = object.field().sampler();
  const MaterialSample base = object.field().base();
  std::size_t heterogeneous = 0;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        const std::size_t i = (std::size_t(z) * n.y + y) * n.x + x;
        const glm::dvec3 centre = p0 + (glm::dvec3(x, y, z) + 0.5) * (p1 - p0) / glm::dvec3(n);
        const MaterialSample s = sampler.sample(centre);
        for (int c = 0; c < 3; ++c) {
          const double expectA = std::max(double(s.sigmaT[c]) - double(s.sigmaS[c]), 0.0);
          // The file holds floats; centres differ from the exporter's in the last bits.
          ASSERT_NEAR(sigmaS[3 * i + c], s.sigmaS[c], 1e-5 * (1.0 + s.sigmaS[c])) << x << "," << y << "," << z;
          ASSERT_NEAR(sigmaA[3 * i + c], expectA, 1e-5 * (1.0 + s.sigmaT[c])) << x << "," << y << "," << z;
          ASSERT_GE(sigmaA[3 * i + c], 0.0);
        }
        if (std::abs(s.sigmaS[0] - base.sigmaS[0]) > 0.05f) ++heterogeneous;
      }
  // The set must actually show up, or the comparison above proves nothing about it (its
  // active block is about 10 x 6 x 4 mm of the rotated box's 15 mm bounding cube).
  EXPECT_GT(heterogeneous, 100u) << "only " << heterogeneous << " of " << cells << " cells differ from the base";

  // g: one value for the medium, the object's mean, inside the painted range; the range
  // exceeds 0.01, so the summary reports it (the CLI warns).
  const double g = medium.number("g");
  EXPECT_DOUBLE_EQ(g, e.summary.gMean);
  EXPECT_TRUE(e.summary.gVaries());
  EXPECT_GT(e.summary.gMax - e.summary.gMin, 0.2);
  EXPECT_GT(g, e.summary.gMin);
  EXPECT_LT(g, e.summary.gMax);
}

// A homogeneous object has one g: it is exported exactly and nothing is reported.
TEST(PbrtExport, HomogeneousGIsExportedExactly) {
  TempDir dir;
  const Exported e = exportScene(dir, sceneJson(kHomogeneous, kCamera), 8);
  EXPECT_NEAR(one(e.statements, "MakeNamedMedium").number("g"), 0.35, 1e-7);
  EXPECT_FALSE(e.summary.gVaries());
  const std::vector<double> sigmaS = one(e.statements, "MakeNamedMedium").numbers("sigma_s");
  for (std::size_t i = 0; i < sigmaS.size(); i += 3) {
    ASSERT_FLOAT_EQ(float(sigmaS[i]), 0.9f);
    ASSERT_FLOAT_EQ(float(sigmaS[i + 2]), 1.1f);
  }
}

// --- object -------------------------------------------------------------------------------

// The shape is sslpv's world-space mesh (after the scene transform), every vertex to the
// float, every triangle, wound so that pbrt's geometric normal cross(p0 − p2, p1 − p2)
// points outwards (positive enclosed volume): MediumInterface "<medium>" "" then puts the
// medium inside. The boundary is a dielectric of the scene's ior.
TEST(PbrtExport, ShapeIsTheWorldSpaceMeshInsideADielectric) {
  TempDir dir;
  const Exported e = exportScene(dir, sceneJson(kHomogeneous, kCamera), 6);
  const TriangleMesh mesh = loadMesh(e.scene.mesh, e.scene.transform);
  const Statement& shape = one(e.statements, "Shape");
  EXPECT_EQ(shape.args.at(0).text, "trianglemesh");
  const std::vector<double> p = shape.numbers("P");
  const std::vector<double> idx = shape.numbers("indices");
  EXPECT_EQ(shape.param("P").type, "point3");
  EXPECT_EQ(shape.param("indices").type, "integer");
  ASSERT_EQ(p.size(), mesh.positions.size() * 3);
  ASSERT_EQ(idx.size() / 3, mesh.triangles.size());
  ASSERT_EQ(e.summary.triangles, mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(float(p[3 * i + c]), mesh.positions[i][c]) << "vertex " << i;
  double volume = 0.0;
  for (std::size_t t = 0; t < idx.size(); t += 3) {
    auto vertex = [&](double k) { return glm::dvec3(p[3 * std::size_t(k)], p[3 * std::size_t(k) + 1], p[3 * std::size_t(k) + 2]); };
    const glm::dvec3 a = vertex(idx[t]), b = vertex(idx[t + 1]), c = vertex(idx[t + 2]);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(idx[t + k], mesh.triangles[t / 3][k]);
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  // A 9 x 6 x 4.5 box scaled by 1.25.
  EXPECT_NEAR(volume, 9.0 * 6.0 * 4.5 * std::pow(1.25, 3), 1e-3);

  const Statement& medium = one(e.statements, "MakeNamedMedium");
  const Statement& interface = one(e.statements, "MediumInterface");
  ASSERT_EQ(interface.args.size(), 2u);
  EXPECT_EQ(interface.args[0].text, medium.args.at(0).text) << "the medium must be inside";
  EXPECT_EQ(interface.args[1].text, "") << "outside is vacuum";
  const Statement& material = one(e.statements, "Material");
  EXPECT_EQ(material.args.at(0).text, "dielectric");
  EXPECT_DOUBLE_EQ(material.number("eta"), 1.5);
  // Order: the medium exists before the shape refers to it; the shape's attributes are scoped.
  const std::size_t begin = positionOf(e.statements, "AttributeBegin");
  EXPECT_LT(positionOf(e.statements, "MakeNamedMedium"), begin);
  EXPECT_LT(begin, positionOf(e.statements, "MediumInterface"));
  EXPECT_LT(positionOf(e.statements, "Material"), positionOf(e.statements, "Shape"));
  EXPECT_LT(positionOf(e.statements, "Shape"), positionOf(e.statements, "AttributeEnd"));
  EXPECT_EQ(one(e.statements, "Integrator").args.at(0).text, "volpath");
  EXPECT_GE(one(e.statements, "Integrator").number("maxdepth"), 1000.0);
}

// ior 1 is sslpv's index-matched, invisible boundary: pbrt's "interface" material.
TEST(PbrtExport, IndexMatchedBoundaryIsAnInterface) {
  TempDir dir;
  writeVaryingSet(dir / "set.vdb");
  const Exported e = exportScene(dir, sceneJson(kVaryingMaterial, kCamera), 6);
  const Statement& material = one(e.statements, "Material");
  EXPECT_EQ(material.args.at(0).text, "interface");
  EXPECT_TRUE(material.params.empty());
}

TEST(PbrtExport, GridOutsideTheRangeIsRejectedBeforeAnyWork) {
  TempDir dir;
  writeText(dir / "scene.json", sceneJson(kHomogeneous, kCamera));
  const Scene scene = loadScene(dir / "scene.json");
  EXPECT_THROW(exportPbrtScene(scene, dir / "out.pbrt", 1), InputError);
  EXPECT_THROW(exportPbrtScene(scene, dir / "out.pbrt", kMaxPbrtGrid + 1), InputError);
  EXPECT_FALSE(fs::exists(dir / "out.pbrt"));
}

}  // namespace
}  // namespace sslpv::test

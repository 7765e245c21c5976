// Mesh loading (primitives and files through assimp), welding, transforms, and the
// watertightness checks SSLPV relies on.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <glm/gtc/constants.hpp>
#include <sstream>

#include "test_support.h"
#include "volume/core/error.h"
#include "volume/scene/mesh.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;

// A unit cube [0,1]^3 as OBJ, faces counter-clockwise from outside (1-based indices).
const char* kCubeVertices =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";
const char* kCubeFaces[] = {
    "f 1 5 7 3\n",  // -x
    "f 2 4 8 6\n",  // +x
    "f 1 2 6 5\n",  // -y
    "f 3 7 8 4\n",  // +y
    "f 1 3 4 2\n",  // -z
    "f 5 6 8 7\n",  // +z
};

std::string cubeObj(int skipFace = -1) {
  std::string text = kCubeVertices;
  for (int i = 0; i < 6; ++i)
    if (i != skipFace) text += kCubeFaces[i];
  return text;
}

MeshSource fileSource(const fs::path& path) {
  MeshSource source;
  source.kind = MeshSource::Kind::File;
  source.path = path;
  return source;
}

std::string errorOf(const MeshSource& source, const Transform& transform = {}) {
  try {
    loadMesh(source, transform);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return {};
}

std::string closedError(const TriangleMesh& mesh) {
  try {
    requireClosedMesh(mesh);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return {};
}

bool hasVertexNear(const TriangleMesh& mesh, glm::vec3 p, float tolerance = 1e-5f) {
  for (const auto& v : mesh.positions)
    if (glm::length(v - p) < tolerance) return true;
  return false;
}

TEST(Mesh, BoxIsClosedWithExactVolume) {
  MeshSource box;
  box.kind = MeshSource::Kind::Box;
  box.boxMin = {-1, -2, -3};
  box.boxMax = {1, 0, 1};
  TriangleMesh mesh = loadMesh(box, {});
  EXPECT_EQ(mesh.name, "box");
  EXPECT_EQ(mesh.positions.size(), 8u);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  MeshTopology topology = analyzeTopology(mesh);
  EXPECT_EQ(topology.boundaryEdges, 0u);
  EXPECT_EQ(topology.nonManifoldEdges, 0u);
  EXPECT_EQ(topology.degenerateTriangles, 0u);
  EXPECT_NO_THROW(requireClosedMesh(mesh));
  // Positive volume means every triangle faces outward.
  EXPECT_DOUBLE_EQ(signedVolume(mesh), 2.0 * 2.0 * 4.0);
  Bounds b = mesh.bounds();
  EXPECT_EQ(b.min, glm::dvec3(-1, -2, -3));
  EXPECT_EQ(b.max, glm::dvec3(1, 0, 1));
}

TEST(Mesh, SphereIsClosedWithVolumeNearAnalytic) {
  MeshSource sphere;
  sphere.kind = MeshSource::Kind::Sphere;
  sphere.center = {1, 2, 3};
  sphere.radius = 2.0;
  TriangleMesh mesh = loadMesh(sphere, {});
  EXPECT_GE(mesh.triangles.size(), 15000u);
  EXPECT_LE(mesh.triangles.size(), 30000u);
  EXPECT_EQ(mesh.positions.size(), mesh.triangles.size() / 2 + 2);  // Euler: closed genus 0
  MeshTopology topology = analyzeTopology(mesh);
  EXPECT_EQ(topology.boundaryEdges, 0u);
  EXPECT_EQ(topology.nonManifoldEdges, 0u);
  EXPECT_EQ(topology.degenerateTriangles, 0u);
  EXPECT_NO_THROW(requireClosedMesh(mesh));
  const double exact = 4.0 / 3.0 * glm::pi<double>() * 8.0;
  EXPECT_GT(signedVolume(mesh), 0.0);
  EXPECT_NEAR(signedVolume(mesh), exact, 0.005 * exact);
  for (const auto& p : mesh.positions)
    EXPECT_NEAR(glm::length(glm::dvec3(p) - sphere.center), 2.0, 1e-5);
}

TEST(Mesh, DegeneratePrimitivesAreInputErrors) {
  MeshSource box;
  box.kind = MeshSource::Kind::Box;
  box.boxMin = {0, 0, 0};
  box.boxMax = {1, 0, 1};
  EXPECT_NE(errorOf(box).find("box: "), std::string::npos);
  MeshSource sphere;
  sphere.kind = MeshSource::Kind::Sphere;
  sphere.radius = 0.0;
  EXPECT_NE(errorOf(sphere).find("sphere: radius must be positive"), std::string::npos);
}

TEST(Mesh, TransformScalesRotatesThenTranslates) {
  MeshSource box;
  box.kind = MeshSource::Kind::Box;
  box.boxMin = {0, 0, 0};
  box.boxMax = {1, 1, 1};
  Transform transform;
  transform.scale = 2.0;
  transform.rotateDeg = {0, 0, 90};
  transform.translate = {10, 0, 0};
  TriangleMesh mesh = loadMesh(box, transform);
  // Corner (1,0,0): scaled (2,0,0), rotated about Z to (0,2,0), translated to (10,2,0).
  EXPECT_TRUE(hasVertexNear(mesh, {10, 2, 0}));
  // Corner (1,1,1): (2,2,2) -> (-2,2,2) -> (8,2,2).
  EXPECT_TRUE(hasVertexNear(mesh, {8, 2, 2}));
  EXPECT_FALSE(hasVertexNear(mesh, {1, 0, 0}));
  // A proper similarity keeps the winding outward and scales volume by s^3.
  EXPECT_NEAR(signedVolume(mesh), 8.0, 1e-5);
  EXPECT_NO_THROW(requireClosedMesh(mesh));
}

TEST(Mesh, ObjFileLoadsTriangulatedAndClosed) {
  test::TempDir dir;
  test::writeText(dir / "cube.obj", cubeObj());
  TriangleMesh mesh = loadMesh(fileSource(dir / "cube.obj"), {});
  EXPECT_EQ(mesh.name, (dir / "cube.obj").string());
  EXPECT_EQ(mesh.triangles.size(), 12u);  // six quads triangulated
  EXPECT_EQ(mesh.positions.size(), 8u);
  EXPECT_NO_THROW(requireClosedMesh(mesh));
  EXPECT_NEAR(signedVolume(mesh), 1.0, 1e-6);
}

// An inside-out file rendered black (the shadow maps and shading take "outside" from the
// winding): it is accepted and turned outward.
TEST(Mesh, InsideOutObjIsReorientedOutward) {
  test::TempDir dir;
  std::string text = kCubeVertices;
  // The same faces with reversed winding.
  text += "f 3 7 5 1\nf 6 8 4 2\nf 5 6 2 1\nf 4 8 7 3\nf 2 4 3 1\nf 7 8 6 5\n";
  test::writeText(dir / "inverted.obj", text);
  TriangleMesh mesh = loadMesh(fileSource(dir / "inverted.obj"), {});
  EXPECT_NEAR(signedVolume(mesh), 1.0, 1e-6);
  EXPECT_NO_THROW(requireClosedMesh(mesh));
}

/// Every triangle of a closed mesh faces away from `inside` (a point of a convex part).
std::size_t trianglesFacing(const TriangleMesh& mesh, const glm::dvec3& inside, double sign) {
  std::size_t count = 0;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
    if (sign * glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0 - inside) > 0.0) ++count;
  }
  return count;
}

TriangleMesh boxMesh(const glm::dvec3& lo, const glm::dvec3& hi) {
  MeshSource box;
  box.kind = MeshSource::Kind::Box;
  box.boxMin = lo;
  box.boxMax = hi;
  return loadMesh(box, {});
}

TriangleMesh loadInMemory(const TriangleMesh& mesh) {
  MeshSource source;
  source.kind = MeshSource::Kind::InMemory;
  source.mesh = std::make_shared<const TriangleMesh>(mesh);
  return loadMesh(source, {});
}

// One reversed face of six made a box 35 % darker: faces are made consistent with their
// neighbours across shared edges, then outward by the signed volume.
TEST(Mesh, AReversedFaceIsTurnedToAgreeWithItsNeighbours) {
  TriangleMesh mesh = boxMesh({0, 0, 0}, {2, 2, 2});
  std::swap(mesh.triangles[4].y, mesh.triangles[4].z);
  std::swap(mesh.triangles[5].y, mesh.triangles[5].z);
  ASSERT_EQ(trianglesFacing(mesh, glm::dvec3(1.0), 1.0), 10u);
  const TriangleMesh fixed = loadInMemory(mesh);
  EXPECT_EQ(trianglesFacing(fixed, glm::dvec3(1.0), 1.0), 12u);
  EXPECT_DOUBLE_EQ(signedVolume(fixed), 8.0);
}

// A hollow object: the cavity's surface faces into the cavity (away from the material),
// which a part's own signed volume alone would get wrong; nesting parity keeps it, and
// flips it when it faces the material.
TEST(Mesh, ACavityFacesIntoTheCavity) {
  TriangleMesh outer = boxMesh({0, 0, 0}, {4, 4, 4});
  const TriangleMesh inner = boxMesh({1, 1, 1}, {3, 3, 3});
  const auto base = unsigned(outer.positions.size());
  outer.positions.insert(outer.positions.end(), inner.positions.begin(), inner.positions.end());
  for (glm::uvec3 t : inner.triangles) outer.triangles.emplace_back(t.x + base, t.z + base, t.y + base);  // into the cavity
  const TriangleMesh kept = loadInMemory(outer);
  EXPECT_EQ(kept.triangles, outer.triangles);
  EXPECT_DOUBLE_EQ(signedVolume(kept), 64.0 - 8.0);
  for (std::size_t i = 12; i < 24; ++i) std::swap(outer.triangles[i].y, outer.triangles[i].z);  // toward the material
  const TriangleMesh fixed = loadInMemory(outer);
  EXPECT_DOUBLE_EQ(signedVolume(fixed), 64.0 - 8.0);
}

TEST(Mesh, PlyFileLoads) {
  test::TempDir dir;
  std::ostringstream ply;
  ply << "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
         "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
         "4 0 4 6 2\n4 1 3 7 5\n4 0 1 5 4\n4 2 6 7 3\n4 0 2 3 1\n4 4 5 7 6\n";
  test::writeText(dir / "cube.ply", ply.str());
  TriangleMesh mesh = loadMesh(fileSource(dir / "cube.ply"), {});
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_EQ(mesh.positions.size(), 8u);
  EXPECT_NO_THROW(requireClosedMesh(mesh));
  EXPECT_NEAR(signedVolume(mesh), 1.0, 1e-6);
}

TEST(Mesh, TinyCubeFileStaysClosedAtEverySize) {
  // Closedness is decided by exact vertex identity, not an absolute distance: a 3e-6
  // cube used to have vertices merged across its faces and was refused as not manifold
  // while 1e-5 and 1e-10 passed.
  test::TempDir dir;
  for (const double side : {1e-3, 1e-5, 6e-6, 2e-6, 2e-8, 2e-10}) {
    SCOPED_TRACE(side);
    std::ostringstream obj;
    obj.precision(17);
    for (int i = 0; i < 8; ++i)
      obj << "v " << ((i & 1) ? side : 0.0) << " " << ((i & 2) ? side : 0.0) << " " << ((i & 4) ? side : 0.0) << "\n";
    for (const char* face : kCubeFaces) obj << face;
    test::writeText(dir / "cube.obj", obj.str());
    const TriangleMesh mesh = loadMesh(fileSource(dir / "cube.obj"), {});
    EXPECT_EQ(mesh.positions.size(), 8u);
    EXPECT_NO_THROW(requireClosedMesh(mesh));
  }
}

TEST(Mesh, StlFileIsWeldedIntoAClosedMesh) {
  // STL stores three separate corners per facet; without welding every edge is a boundary.
  const glm::vec3 corner[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const int tris[12][3] = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}, {0, 1, 5}, {0, 5, 4},
                           {2, 6, 7}, {2, 7, 3}, {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};
  std::ostringstream stl;
  stl << "solid cube\n";
  for (const auto& t : tris) {
    glm::vec3 n = glm::normalize(glm::cross(corner[t[1]] - corner[t[0]], corner[t[2]] - corner[t[0]]));
    stl << "facet normal " << n.x << " " << n.y << " " << n.z << "\nouter loop\n";
    for (int k = 0; k < 3; ++k)
      stl << "vertex " << corner[t[k]].x << " " << corner[t[k]].y << " " << corner[t[k]].z << "\n";
    stl << "endloop\nendfacet\n";
  }
  stl << "endsolid cube\n";
  test::TempDir dir;
  test::writeText(dir / "cube.stl", stl.str());
  TriangleMesh mesh = loadMesh(fileSource(dir / "cube.stl"), {});
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_EQ(mesh.positions.size(), 8u);
  EXPECT_NO_THROW(requireClosedMesh(mesh));
  EXPECT_NEAR(signedVolume(mesh), 1.0, 1e-6);
}

TEST(Mesh, FileTransformIsApplied) {
  test::TempDir dir;
  test::writeText(dir / "cube.obj", cubeObj());
  Transform transform;
  transform.scale = 3.0;
  transform.rotateDeg = {90, 0, 0};  // +y goes to +z
  transform.translate = {0, 0, -5};
  TriangleMesh mesh = loadMesh(fileSource(dir / "cube.obj"), transform);
  // Corner (0,1,0): (0,3,0) -> (0,0,3) -> (0,0,-2).
  EXPECT_TRUE(hasVertexNear(mesh, {0, 0, -2}));
  EXPECT_NEAR(signedVolume(mesh), 27.0, 1e-4);
}

TEST(Mesh, GltfNodeTransformsAreBakedAndPartsMerged) {
  // One cube mesh instanced by two nodes, the second moved by +5 in x: the loader must
  // apply each node's transform and return both cubes in one mesh.
  const float corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const std::uint16_t indices[36] = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                                     2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
  test::TempDir dir;
  {
    std::ofstream bin(dir / "cube.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(corners), sizeof corners);
    bin.write(reinterpret_cast<const char*>(indices), sizeof indices);
  }
  test::writeText(dir / "two.gltf", R"({
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [5, 0, 0]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"uri": "cube.bin", "byteLength": 168}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96},
                    {"buffer": 0, "byteOffset": 96, "byteLength": 72}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
       "min": [0, 0, 0], "max": [1, 1, 1]},
      {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}]
  })");
  TriangleMesh mesh = loadMesh(fileSource(dir / "two.gltf"), {});
  EXPECT_EQ(mesh.triangles.size(), 24u);
  EXPECT_EQ(mesh.positions.size(), 16u);
  EXPECT_TRUE(hasVertexNear(mesh, {6, 1, 1}));
  EXPECT_TRUE(hasVertexNear(mesh, {0, 0, 0}));
  EXPECT_NO_THROW(requireClosedMesh(mesh));
  EXPECT_NEAR(signedVolume(mesh), 2.0, 1e-5);
}

TEST(Mesh, OpenMeshNamesBoundaryEdgeCount) {
  test::TempDir dir;
  test::writeText(dir / "open.obj", cubeObj(/*skipFace=*/5));  // no +z face
  TriangleMesh mesh = loadMesh(fileSource(dir / "open.obj"), {});
  EXPECT_EQ(analyzeTopology(mesh).boundaryEdges, 4u);
  std::string message = closedError(mesh);
  EXPECT_EQ(message.rfind((dir / "open.obj").string() + ": mesh is not closed: 4 boundary edges (a hole near (", 0), 0u)
      << message;
  EXPECT_NE(message.find("SSLPV needs a watertight surface"), std::string::npos) << message;
  // The hole is in the z = 1 plane: the named point is there.
  EXPECT_NE(message.find(", 1)"), std::string::npos) << message;
}

TEST(Mesh, NonManifoldEdgeIsRejected) {
  // Two boxes sharing one edge would be fine if welded apart; a fin on a box edge is not.
  MeshSource box;
  box.kind = MeshSource::Kind::Box;
  box.boxMin = {0, 0, 0};
  box.boxMax = {1, 1, 1};
  TriangleMesh mesh = loadMesh(box, {});
  // A double-sided fin on edge 0-1 (corners (0,0,0) and (1,0,0)): that edge gets 4 uses.
  mesh.positions.push_back({0.5f, -1.0f, -1.0f});
  mesh.triangles.push_back({0, 1, 8});
  mesh.triangles.push_back({1, 0, 8});
  MeshTopology topology = analyzeTopology(mesh);
  EXPECT_EQ(topology.nonManifoldEdges, 1u);
  EXPECT_EQ(topology.boundaryEdges, 0u);
  EXPECT_NE(closedError(mesh).find("box: mesh is not manifold: 1 edges"), std::string::npos);
}

TEST(Mesh, DegenerateTrianglesAreCounted) {
  TriangleMesh mesh;
  mesh.name = "flat";
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 0, 3}};
  EXPECT_EQ(analyzeTopology(mesh).degenerateTriangles, 2u);
}

TEST(Mesh, ClosedButFlatMeshHasNoVolume) {
  // Two triangles back to back: every edge used twice, yet nothing enclosed.
  TriangleMesh mesh;
  mesh.name = "sheet";
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 1}};
  EXPECT_EQ(analyzeTopology(mesh).boundaryEdges, 0u);
  EXPECT_NE(closedError(mesh).find("sheet: mesh encloses no volume"), std::string::npos);
  TriangleMesh empty;
  empty.name = "nothing";
  EXPECT_NE(closedError(empty).find("nothing: mesh has no triangles"), std::string::npos);
}

TEST(Mesh, MissingFileIsNamed) {
  test::TempDir dir;
  fs::path missing = dir / "missing.obj";
  EXPECT_EQ(errorOf(fileSource(missing)), missing.string() + ": mesh file not found");
  EXPECT_NE(errorOf(fileSource(dir.path())).find("not a regular file"), std::string::npos);
}

TEST(Mesh, GarbageFileIsAnInputErrorNamingIt) {
  test::TempDir dir;
  std::string garbage;
  for (int i = 0; i < 4096; ++i) garbage += char((i * 7919 + 13) % 256);
  for (const char* name : {"garbage.ply", "garbage.stl", "garbage.xyzformat", "garbage.obj"}) {
    test::writeText(dir / name, garbage);
    std::string message = errorOf(fileSource(dir / name));
    EXPECT_EQ(message.rfind((dir / name).string() + ": ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// Found by fuzz/mesh_fuzz: faces written without their vertex count ("0 2 1" instead of
// "3 0 2 1") made assimp's triangulation fail its internal assertion and abort the whole
// process. The import now runs in a reader child, so the abort is this file's InputError.
TEST(Mesh, PlyThatAbortsAssimpIsAnInputErrorNamingIt) {
  test::TempDir dir;
  const fs::path file = dir / "faces_without_counts.ply";
  test::writeText(file,
                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                  "0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n");
  const std::string message = errorOf(fileSource(file));
  EXPECT_EQ(message.rfind(file.string() + ": corrupt mesh file (the assimp importer crashed with signal 6", 0), 0u)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// Found by fuzz/mesh_fuzz: assimp never returns on this PLY (a property line cut in half),
// so sslpv hung; the reader child is stopped after a few seconds instead.
TEST(Mesh, PlyOnWhichAssimpHangsIsAnInputErrorWithinSeconds) {
  test::TempDir dir;
  const fs::path file = dir / "cut_property.ply";
  test::writeText(file,
                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                  "property floaroperty float z\nelement face 4\nproperty list uchar int vertex_indices\n"
                  " 0 0\n1 0 0\n0 1 0\n0 0 1\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n");
  const auto start = std::chrono::steady_clock::now();
  const std::string message = errorOf(fileSource(file));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(message, file.string() + ": reading did not finish within 5 s; the file looks corrupt");
  EXPECT_LT(seconds, 30.0);
}

TEST(Mesh, FileWithoutTrianglesIsRejected) {
  test::TempDir dir;
  test::writeText(dir / "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  std::string message = errorOf(fileSource(dir / "points.obj"));
  EXPECT_EQ(message.rfind((dir / "points.obj").string() + ": ", 0), 0u) << message;
}

/// A torus of `ring` x `tube` quads: closed, genus 1, 2 * ring * tube triangles.
TriangleMesh makeTorus(int ring, int tube, double major, double minor) {
  TriangleMesh mesh;
  mesh.name = "torus";
  mesh.positions.reserve(std::size_t(ring) * tube);
  for (int i = 0; i < ring; ++i) {
    double u = 2.0 * glm::pi<double>() * i / ring;
    for (int j = 0; j < tube; ++j) {
      double v = 2.0 * glm::pi<double>() * j / tube;
      double r = major + minor * std::cos(v);
      mesh.positions.emplace_back(r * std::cos(u), r * std::sin(u), minor * std::sin(v));
    }
  }
  auto index = [&](int i, int j) { return unsigned((i % ring) * tube + (j % tube)); };
  mesh.triangles.reserve(std::size_t(2) * ring * tube);
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      mesh.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      mesh.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  }
  return mesh;
}

TEST(Mesh, MillionTriangleTopologyCompletes) {
  TriangleMesh torus = makeTorus(1000, 500, 3.0, 1.0);
  ASSERT_EQ(torus.triangles.size(), 1000000u);
  MeshTopology topology = analyzeTopology(torus);
  EXPECT_EQ(topology.boundaryEdges, 0u);
  EXPECT_EQ(topology.nonManifoldEdges, 0u);
  EXPECT_EQ(topology.degenerateTriangles, 0u);
  EXPECT_NO_THROW(requireClosedMesh(torus));
  const double exact = 2.0 * glm::pi<double>() * glm::pi<double>() * 3.0 * 1.0;
  EXPECT_NEAR(std::abs(signedVolume(torus)), exact, 1e-3 * exact);
}

}  // namespace
}  // namespace sslpv

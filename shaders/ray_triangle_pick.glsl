// Which triangle a ray actually crosses, starting from the one the rasterizer found at
// its pixel. The rasterizer snaps vertices (1/256 pixel on llvmpipe), so where a pixel
// centre lies within that snapping of an edge it may report the neighbour of the triangle
// the exact ray crosses (what Embree hits on the CPU); across a crease or on a coarse
// sphere the face normals differ, and with them Fresnel, refraction and shading.
//
// The crossing test itself (rayCrossesTriangle) is shared with the CPU ray caster,
// which refines Embree's hit the same way: device_shared/ray_triangle_test.h.
//
// Needs, declared by the including shader: `positions` (vec4 per vertex), `indices`
// (3 uint per triangle) and `vertexFans` (GpuMesh::vertexFans: vertexCount + 1 offsets
// into the same array, then the triangles around each vertex).
#include "device_shared/ray_triangle_test.h"

uvec3 triangleVertices(uint triangle) {
  return uvec3(indices[3u * triangle], indices[3u * triangle + 1u], indices[3u * triangle + 2u]);
}

/// pickCrossedTriangle found no triangle the ray crosses.
const uint SSLPV_NO_TRIANGLE = 0xffffffffu;

/// The triangle the ray origin + t dir (t > 0) crosses nearest among `raster` and the
/// triangles sharing a vertex with it (which cover every point within the snapping
/// distance of it on a manifold mesh); `raster` itself when it is crossed (the
/// rasterizer's depth test already made it the nearest there). SSLPV_NO_TRIANGLE when
/// none is: a ray that passes just outside the silhouette, which the rasterizer's
/// snapping counted as covered but the CPU's ray caster misses; a grazing sample there
/// would inject light the CPU backend does not.
uint pickCrossedTriangle(vec3 o, vec3 d, uint raster) {
  const uvec3 r = triangleVertices(raster);
  if (rayCrossesTriangle(o, d, r.x, positions[r.x].xyz, r.y, positions[r.y].xyz, r.z, positions[r.z].xyz))
    return raster;
  uint best = SSLPV_NO_TRIANGLE;
  float bestT = 3.0e38;
  for (int k = 0; k < 3; ++k) {
    const uint vertex = r[k], end = vertexFans[vertex + 1u];
    for (uint f = vertexFans[vertex]; f < end; ++f) {
      const uint triangle = vertexFans[f];
      if (triangle == raster) continue;
      const uvec3 w = triangleVertices(triangle);
      const vec3 p0 = positions[w.x].xyz, p1 = positions[w.y].xyz, p2 = positions[w.z].xyz;
      if (!rayCrossesTriangle(o, d, w.x, p0, w.y, p1, w.z, p2)) continue;
      const vec3 ng = cross(p1 - p0, p2 - p0);
      const float t = dot(p0 - o, ng) / dot(d, ng);
      if (t > 0.0 && t < bestT) {
        bestT = t;
        best = triangle;
      }
    }
  }
  return best;
}

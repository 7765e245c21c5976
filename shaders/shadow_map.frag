#version 460
// Shadow-map rasterization: the nearest triangle per texel (1-based; 0 = no surface). The
// resolve (shaders/shadow_map.comp) intersects that triangle with the texel's exact ray.
layout(location = 0) flat in uint triangleId;
layout(location = 0) out uint outTriangle;

void main() { outTriangle = triangleId; }

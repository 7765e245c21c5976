#version 460
// Shading rasterization (visibility): the nearest triangle per pixel, 1-based (0 =
// background). Shading each pixel once in shaders/shade.comp instead of here measured
// about 3x faster on llvmpipe, which shades whole 4x4 blocks for each small triangle.
layout(location = 0) flat in uint triangleId;
layout(location = 0) out uint outTriangle;

void main() { outTriangle = triangleId; }

// Visibility buffer: the prepass stores per pixel the instance and triangle it saw; compute
// passes rebuild the triangle's attributes at the pixel from its three vertices and the pixel
// ray (analytic, perspective-correct barycentrics), with screen derivatives taken exactly as a
// fragment shader's fine dFdx/dFdy take them: differences across the pixel's 2x2 quad, the
// triangle's plane extended to the neighbour as helper invocations extend it.
#ifndef SHADEL_VISIBILITY_GLSL
#define SHADEL_VISIBILITY_GLSL
#include "common/bindless.glsl"
#include "culling/cull.glsl"

// Unsigned view of the bindless sampled-image table (the visibility buffer is R32G32_UINT).
layout(set = 0, binding = 0) uniform utexture2D gUintTextures[];

#define VISIBILITY_NONE 0xFFFFFFFFu // cleared: no geometry at the pixel

uvec2 loadVisibility(uint slot, ivec2 pixel) {
    return texelFetch(gUintTextures[slot], pixel, 0).xy;
}

struct VisTriangle {
    uint v0, v1, v2; // indices into the unified vertex buffer (vertexOffset applied)
    vec3 r0, r1, r2; // rows of the adjugate of M = [clip.xyw of each vertex] (columns)
    bool frontFacing;
};

// Triangle `triangle` of an instance's mesh (the visibility buffer's: numbered from the mesh's
// first index, whatever LOD its draw used; scene/visibility_vertices.h). Homogeneous
// rasterization (Olano & Greer): with M's columns the clip-space (x, y, w) of the vertices, the
// perspective-correct barycentrics at NDC point q are adj(M) (q, 1), normalised to sum 1. No
// division by w, so triangles crossing the camera plane are fine.
VisTriangle loadVisTriangle(FrameConstants f, GpuInstance inst, uint triangle) {
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    IndexBuffer indices = IndexBuffer(f.indices);
    uint first = mesh.firstIndex + 3u * triangle;
    VisTriangle t;
    t.v0 = uint(int(indices.i[first + 0u]) + mesh.vertexOffset);
    t.v1 = uint(int(indices.i[first + 1u]) + mesh.vertexOffset);
    t.v2 = uint(int(indices.i[first + 2u]) + mesh.vertexOffset);
    VertexBuffer vb = VertexBuffer(f.vertices);
    // The same expression as the vertex shader's gl_Position (world first, then viewProj).
    vec4 c0 = f.viewProj * vec4((inst.model * vec4(vb.v[t.v0].position, 1.0)).xyz, 1.0);
    vec4 c1 = f.viewProj * vec4((inst.model * vec4(vb.v[t.v1].position, 1.0)).xyz, 1.0);
    vec4 c2 = f.viewProj * vec4((inst.model * vec4(vb.v[t.v2].position, 1.0)).xyz, 1.0);
    precise vec3 a = c0.xyw, b = c1.xyw, c = c2.xyw;
    precise vec3 r0 = cross(b, c), r1 = cross(c, a), r2 = cross(a, b);
    t.r0 = r0;
    t.r1 = r1;
    t.r2 = r2;
    // det(M) = w0 w1 w2 * (NDC signed area); Vulkan's counter-clockwise front face (y down)
    // is a negative NDC cross product, and a mirroring instance transform turns it clockwise
    // (the raster passes draw such instances with the clockwise front face).
    t.frontFacing = (dot(a, r0) < 0.0) != (determinant(mat3(inst.model)) < 0.0);
    return t;
}

// NDC of a pixel centre (Vulkan viewport: y grows downwards with the pixel row).
vec2 pixelNdc(FrameConstants f, ivec2 pixel) {
    return (vec2(pixel) + 0.5) * f.invViewportSize * 2.0 - 1.0;
}

vec3 visBarycentrics(VisTriangle t, vec2 ndc) {
    precise vec3 q = vec3(ndc, 1.0);
    precise vec3 l = vec3(dot(t.r0, q), dot(t.r1, q), dot(t.r2, q));
    precise float sum = l.x + l.y + l.z;
    if (!(abs(sum) > 1e-30)) return vec3(1.0 / 3.0); // edge-on: no plane to intersect
    precise vec3 bary = l / sum;
    return bary;
}

// Barycentrics at a pixel and their fine screen derivatives (the 2x2 quad's differences).
struct VisBary {
    vec3 center;
    vec3 dx;
    vec3 dy;
};

VisBary visBaryWithDerivatives(FrameConstants f, VisTriangle t, ivec2 pixel) {
    ivec2 quad = pixel & ~1;
    VisBary b;
    b.center = visBarycentrics(t, pixelNdc(f, pixel));
    precise vec3 x0 = visBarycentrics(t, pixelNdc(f, ivec2(quad.x, pixel.y)));
    precise vec3 x1 = visBarycentrics(t, pixelNdc(f, ivec2(quad.x + 1, pixel.y)));
    precise vec3 y0 = visBarycentrics(t, pixelNdc(f, ivec2(pixel.x, quad.y)));
    precise vec3 y1 = visBarycentrics(t, pixelNdc(f, ivec2(pixel.x, quad.y + 1)));
    b.dx = x1 - x0;
    b.dy = y1 - y0;
    return b;
}

// Interpolation of a vertex attribute and of its derivatives (linear in the barycentrics).
vec2 visInterpolate(vec3 w, vec2 a, vec2 b, vec2 c) {
    precise vec2 r = a * w.x + b * w.y + c * w.z;
    return r;
}
vec3 visInterpolate(vec3 w, vec3 a, vec3 b, vec3 c) {
    precise vec3 r = a * w.x + b * w.y + c * w.z;
    return r;
}
vec4 visInterpolate(vec3 w, vec4 a, vec4 b, vec4 c) {
    precise vec4 r = a * w.x + b * w.y + c * w.z;
    return r;
}
#endif

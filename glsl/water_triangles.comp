#version 460
// Beyond the thesis (docs/rendering.md, "Water without the geometry shader"): the geometry shader's choice
// (Section 8.4, water.glsl) for every grid triangle of the drawn quadrants of every cached patch, made from the
// vertex cache on all of the device's threads instead of per triangle on lavapipe's one vertex thread. Invocation
// (q, k) walks quadrant q of drawn patch k in mesh order and lists the triangles that get water, each vertex as
// (mesh vertex << 2 | water kind), in the quadrant's own range of the water indices; then it turns the quadrant's
// indirect draw (which arrives holding the quadrant's grid cells in the mesh) into the draw of that list.
// water_surface.vert places the vertices.
#include "terrain_vertex.glsl"
#include "water.glsl"

layout(local_size_x = 4) in;

// VkDrawIndexedIndirectCommand, four per patch (render/frame/vertex_cache.rs).
struct DrawCommand {
    uint indexCount;
    uint instanceCount;
    uint firstIndex;
    int vertexOffset;
    uint firstInstance;
};
layout(set = 1, binding = 3, std430) buffer WaterDraws { DrawCommand waterDraws[]; };
layout(set = 1, binding = 4, std430) readonly buffer MeshIndices { uint meshIndices[]; };
layout(set = 1, binding = 5, std430) writeonly buffer WaterIndices { uint waterIndices[]; };

void main() {
    uint q = gl_LocalInvocationIndex;
    uint k = gl_WorkGroupID.y;
    PatchInstance p = instances[k];
    DrawCommand grid = waterDraws[k * 4u + q];
    // Every quadrant's list has room for all its grid cells' indices: 6 m^2 for m = (n - 1) / 2 cells a side.
    uint n = uint(frame.planet.y);
    uint m = (n - 1u) / 2u;
    uint first = (k * 4u + q) * 6u * m * m;
    uint count = 0u;
    if ((p.slots.z & (1 << q)) != 0) {
        uint entry = uint(cacheIndex(p)) * n * n;
        for (uint t = grid.firstIndex; t < grid.firstIndex + grid.indexCount; t += 3u) {
            uvec3 id = uvec3(meshIndices[t], meshIndices[t + 1u], meshIndices[t + 2u]);
            uint kind = waterKind(cachedVertices[entry + id.x].surface, cachedVertices[entry + id.y].surface,
                                  cachedVertices[entry + id.z].surface, p.centreDir.w);
            if (kind != WATER_NONE) {
                waterIndices[first + count] = id.x << 2 | kind;
                waterIndices[first + count + 1u] = id.y << 2 | kind;
                waterIndices[first + count + 2u] = id.z << 2 | kind;
                count += 3u;
            }
        }
    }
    waterDraws[k * 4u + q] = DrawCommand(count, count > 0u ? 1u : 0u, first, 0, k);
}

#version 460
// Beyond the thesis (docs/rendering.md, "The vertex cache"): one frame's grid vertices of every drawn patch, as
// terrain.vert and water.vert would compute them (terrain_vertex.glsl), once, on all of the device's threads.
// Workgroup (x, k): grid vertices 64x .. 64x + 63 of drawn patch k, which is instance k (render/frame/draw.rs puts
// the drawn patches first).
#define VERTEX_CACHE_WRITER
#include "terrain_vertex.glsl"

layout(local_size_x = 64) in;

void main() {
    int n = int(frame.planet.y);
    int id = int(gl_GlobalInvocationID.x);
    if (id >= n * n) return;
    PatchInstance p = instances[gl_WorkGroupID.y];
    TerrainVertex v = terrainVertex(p, id);
    storeVertex(uint(cacheIndex(p) * n * n + id), v, shadeVertex(p, v, true));
}

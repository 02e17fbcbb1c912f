#version 460
// Beyond the thesis (docs/rendering.md, "The vertex cache"): one frame's grid vertices of every drawn patch, as
// terrain.vert and water.vert would compute them (terrain_vertex.glsl), once, on all of the device's threads.
// Workgroup (x, k): grid vertices 64x .. 64x + 63 of drawn patch k, which is instance k (render/frame/draw.rs puts
// the drawn patches first). Vertices of quadrants the patch does not draw (covered by finer patches or culled) are
// skipped. water_triangles.comp then finds the water triangles from it.
#define VERTEX_CACHE_WRITER
#include "terrain_vertex.glsl"

layout(local_size_x = 64) in;

// The quadrants (bit 0: +i half, bit 1: +j half, as render/mesh.rs) of the cells around grid point `ij`.
uint quadrantsAround(ivec2 ij, int n) {
    int m = (n - 1) / 2;
    uint bits = 0u;
    for (int dj = -1; dj <= 0; ++dj) {
        for (int di = -1; di <= 0; ++di) {
            ivec2 cell = ij + ivec2(di, dj);
            if (all(greaterThanEqual(cell, ivec2(0))) && all(lessThanEqual(cell, ivec2(n - 2)))) {
                bits |= 1u << (int(cell.x >= m) | (int(cell.y >= m) << 1));
            }
        }
    }
    return bits;
}

void main() {
    int n = int(frame.planet.y);
    int id = int(gl_GlobalInvocationID.x);
    PatchInstance p = instances[gl_WorkGroupID.y];
    int entry = cacheIndex(p);
    // Only the vertices of drawn quadrants' cells (culled quadrants are not drawn, their skirts hang from them).
    uint around = id < n * n ? quadrantsAround(divMod(id, n).yx, n) : 0u;
    if ((around & uint(p.slots.z)) != 0u) {
        TerrainVertex v = terrainVertex(p, id);
        storeVertex(uint(entry * n * n + id), v, shadeVertex(p, v, true));
    }
}

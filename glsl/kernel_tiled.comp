#version 460
// Tiled GPU version (7.3.2): the workgroup stages a tile of samples in shared memory, waits at a barrier, and
// every invocation reads the tile from there; a second barrier guards the next tile's load.
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint TILE_SIZE = 256;
#include "river_kernel.glsl"

shared RiverSample tile[TILE_SIZE];

void main() {
    PatchJob job = jobs[gl_WorkGroupID.y];
    uint vertex = gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    // Inactive invocations still load samples and reach every barrier.
    bool hasVertex = vertex < params.gridSize * params.gridSize;
    uvec2 xy = uvec2(vertex % params.gridSize, vertex / params.gridSize);
    vec2 v = vec2(xy) * job.spacing;
    Accumulators acc = initAccumulators();
    for (uint base = 0; base < job.sampleCount; base += TILE_SIZE) {
        uint count = min(TILE_SIZE, job.sampleCount - base);
        for (uint k = gl_LocalInvocationID.x; k < count; k += gl_WorkGroupSize.x) {
            tile[k] = samples[job.sampleOffset + base + k];
        }
        barrier();
        if (hasVertex) {
            for (uint k = 0; k < count; ++k) accumulateSample(acc, v, tile[k]);
        }
        barrier();
    }
    if (hasVertex) storeHeight(acc, job, xy);
}

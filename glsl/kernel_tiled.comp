#version 460
// Tiled GPU version (7.3.2): the workgroup stages a tile of samples in shared memory, waits at a barrier, and
// every invocation reads the tile from there; a barrier guards the next tile's load.
//
// Beyond the thesis (docs/kernel.md): a workgroup is a square block of the patch's vertices (x, y from the
// workgroup id; z selects the patch), and staging keeps only the samples within reach of the block's bounding
// box, compacted in their original order. Every invocation then loops over the in-reach samples only, with a
// trip count that is uniform across the group. Order is preserved, so the sums equal the simple kernel's.
layout(local_size_x_id = 0, local_size_y_id = 1) in;
layout(constant_id = 2) const uint TILE_SIZE = 256;
// Invocations per workgroup (x * y of the block), for the size of the offsets array.
layout(constant_id = 3) const uint GROUP_SIZE = 32;
#include "river_kernel.glsl"

// The staged samples as arrays of vec4 and vec2 (24 bytes a sample; faster than an array of structs on
// lavapipe, and 1024 of them fit 32 KiB of shared memory).
shared vec4 tilePositionDerivative[TILE_SIZE];
shared vec2 tileHeightWidth[TILE_SIZE];
// Per invocation: how many samples of its chunk are in reach, then the exclusive prefix sum of those counts.
shared uint chunkOffset[GROUP_SIZE];
shared uint tileCount;

void main() {
    PatchJob job = jobs[gl_WorkGroupID.z];
    uint n = params.gridSize;
    uvec2 first = gl_WorkGroupID.xy * gl_WorkGroupSize.xy;
    uvec2 last = min(first + gl_WorkGroupSize.xy, uvec2(n)) - 1;
    uvec2 xy = first + gl_LocalInvocationID.xy;
    // Invocations beyond the grid still stage samples and reach every barrier.
    bool hasVertex = xy.x < n && xy.y < n;
    vec2 v = vec2(xy) * job.spacing;
    vec2 boxMin = vec2(first) * job.spacing;
    vec2 boxMax = vec2(last) * job.spacing;
    float reach = params.influenceDistance * 1.0001 + 1e-4;
    uint lane = gl_LocalInvocationIndex;
    uint groupSize = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
    // Each invocation stages a contiguous chunk of at most 32 samples of a tile (a bit mask remembers which).
    uint chunk = (TILE_SIZE + groupSize - 1) / groupSize;

    Accumulators acc = initAccumulators();
    for (uint base = 0; base < job.sampleCount; base += TILE_SIZE) {
        uint count = min(TILE_SIZE, job.sampleCount - base);
        uint begin = min(lane * chunk, count);
        uint end = min(begin + chunk, count);
        uint inReach = 0;
        for (uint k = begin; k < end; ++k) {
            vec2 p = samples[job.sampleOffset + base + k].positionDerivative.xy;
            if (length(p - clamp(p, boxMin, boxMax)) <= reach) inReach |= 1u << (k - begin);
        }
        chunkOffset[lane] = bitCount(inReach);
        barrier();
        if (lane == 0) {
            uint sum = 0;
            for (uint i = 0; i < groupSize; ++i) {
                uint c = chunkOffset[i];
                chunkOffset[i] = sum;
                sum += c;
            }
            tileCount = sum;
        }
        barrier();
        uint at = chunkOffset[lane];
        for (uint k = begin; k < end; ++k) {
            if ((inReach & (1u << (k - begin))) != 0) {
                RiverSample s = samples[job.sampleOffset + base + k];
                tilePositionDerivative[at] = s.positionDerivative;
                tileHeightWidth[at] = s.heightWidth.xy;
                ++at;
            }
        }
        barrier();
        uint staged = tileCount;
        if (hasVertex) {
            for (uint k = 0; k < staged; ++k) {
                accumulateSample(acc, v, RiverSample(tilePositionDerivative[k], vec4(tileHeightWidth[k], 0.0, 0.0)));
            }
        }
        barrier();
    }
    if (hasVertex) storeHeight(acc, job, xy);
}

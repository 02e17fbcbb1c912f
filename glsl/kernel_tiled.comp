#version 460
// Tiled GPU version (7.3.2): the workgroup stages a tile of samples in shared memory, waits at a barrier, and
// every invocation reads the tile from there; a barrier guards the next tile's load.
//
// Beyond the thesis (docs/kernel.md):
// - a workgroup is a block of a row's vertices (x, y from the workgroup id; z selects the row), its
//   invocations laid out in Morton order, so that every subgroup covers a compact square of vertices;
// - staging copies only the samples that the reach masks of kernel_reach.comp mark for this block, compacted in
//   their original order (a subgroup scan of the mask words' bit counts gives each word its place);
// - every invocation loops over the staged samples only, with a trip count uniform across the group. Each
//   lane of a subgroup reads a different staged sample and the subgroup shares them by broadcast: one
//   shared-memory read per sample and subgroup instead of one per invocation.
// The order of summation is the sample order, so the sums equal the simple kernel's.
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
// Invocations per workgroup: BLOCK_X x BLOCK_Y, a multiple of the subgroup size (full subgroups are required).
layout(local_size_x_id = 0) in;
// The vertex block: powers of two, square or twice as wide as high (for the Morton layout).
layout(constant_id = 1) const uint BLOCK_X = 8;
layout(constant_id = 2) const uint BLOCK_Y = 8;
// Samples per tile: a multiple of 32 (one mask word covers 32 samples), at most 32 x the invocations.
layout(constant_id = 3) const uint TILE_SIZE = 1024;
// The subgroup size the pipeline requires (gl_SubgroupSize): a constant lets the broadcast loop be unrolled,
// which on lavapipe turns every broadcast into a register shuffle.
layout(constant_id = 4) const uint SUBGROUP_SIZE = 8;
#include "river_kernel.glsl"
#include "kernel_blocks.glsl"

// The staged samples, prepared (prepareSample), as arrays of vec4, vec2 and vec2: 32 bytes a sample, faster
// than an array of structs on lavapipe; 992 of them fit 32 KiB of shared memory with the counts.
shared vec4 tilePositionDerivative[TILE_SIZE];
shared vec2 tileHeightHalfWidth[TILE_SIZE];
shared vec2 tileReachRiver[TILE_SIZE];
// In-reach samples of a chunk counted by each subgroup (at most one subgroup per invocation), in two rows.
const uint MAX_SUBGROUPS = BLOCK_X * BLOCK_Y;
const uint TILE_WORDS = TILE_SIZE / 32;
shared uint subgroupCounts[2 * MAX_SUBGROUPS];

// The even bits of `i`, packed: one coordinate of a Morton index.
uint evenBits(uint i) {
    i &= 0x55555555u;
    i = (i | (i >> 1)) & 0x33333333u;
    i = (i | (i >> 2)) & 0x0f0f0f0fu;
    i = (i | (i >> 4)) & 0x00ff00ffu;
    return (i | (i >> 8)) & 0x0000ffffu;
}

// The vertex of the block that invocation `i` computes: Morton order within BLOCK_Y x BLOCK_Y squares, squares
// side by side along x.
uvec2 vertexInBlock(uint i) {
    uint square = BLOCK_Y * BLOCK_Y;
    uint j = i % square;
    return uvec2(evenBits(j) + (i / square) * BLOCK_Y, evenBits(j >> 1));
}

// Procedure 4 over the first `staged` samples of the tile. Each lane of a subgroup reads one staged sample and
// the subgroup shares them by broadcast.
void accumulateTile(inout Accumulators acc, vec2 v, uint staged) {
    for (uint first = 0; first < staged; first += SUBGROUP_SIZE) {
        uint mine = min(first + gl_SubgroupInvocationID, staged - 1);
        vec4 positionDerivative = tilePositionDerivative[mine];
        vec2 heightHalfWidth = tileHeightHalfWidth[mine];
        vec2 reachRiver = tileReachRiver[mine];
        uint sharing = min(SUBGROUP_SIZE, staged - first);
        for (uint from = 0; from < SUBGROUP_SIZE; ++from) {
            if (from >= sharing) break;
            PreparedSample s = PreparedSample(subgroupBroadcast(positionDerivative, from),
                subgroupBroadcast(heightHalfWidth.x, from), subgroupBroadcast(heightHalfWidth.y, from),
                subgroupBroadcast(reachRiver.x, from), subgroupBroadcast(reachRiver.y, from));
            accumulateSample(acc, v, s);
        }
    }
}

void main() {
    PatchJob job = jobs[params.firstJob + gl_WorkGroupID.z];
    uvec2 size = uvec2(BLOCK_X, BLOCK_Y);
    uvec2 count = blockCount(job, size);
    // The dispatch covers the largest lattice of its rows; a smaller one leaves whole workgroups idle.
    if (any(greaterThanEqual(gl_WorkGroupID.xy, count))) return;
    uint block = gl_WorkGroupID.y * count.x + gl_WorkGroupID.x;
    uint lane = gl_LocalInvocationIndex;
    uvec2 xy = gl_WorkGroupID.xy * size + vertexInBlock(lane);
    // Invocations beyond the lattice take part in staging and in the subgroup broadcasts, and store nothing.
    bool hasVertex = all(lessThan(xy, latticeSize(job)));
    if (job.parentPlace != NO_PARENT) {
        if (hasVertex) copyFromParent(job, xy);
        return;
    }
    uvec2 vertex = patchVertex(job, xy);
    // Precise: the vertex position enters the decisions of accumulateSample, which must not fuse it.
    precise vec2 v = vec2(vertex) * job.spacing;
    uint words = wordsOf(job);

    // The patch's mask words are read in chunks of TILE_WORDS (invocation i holds word i of the chunk); the
    // in-reach samples of each chunk are appended to the tile, which is consumed whenever the next chunk might
    // not fit and at the end. A block within reach of few samples thus stages them all in one tile, however
    // many samples its patch has.
    Accumulators acc = initAccumulators();
    uint filled = 0;
    for (uint chunk = 0; chunk * TILE_WORDS < words; ++chunk) {
        uint word = chunk * TILE_WORDS + lane;
        uint bits = lane < TILE_WORDS && word < words ? reachMasks[reachMaskIndex(job, block, word)] : 0;
        uint at = subgroupExclusiveAdd(bitCount(bits));
        // Counts alternate between two rows, so a chunk's counts are never overwritten before every invocation
        // has read them (the next chunk's barrier comes first).
        uint row = (chunk % 2) * MAX_SUBGROUPS;
        if (gl_SubgroupInvocationID == gl_SubgroupSize - 1) subgroupCounts[row + gl_SubgroupID] = at + bitCount(bits);
        barrier();
        uint found = 0;
        for (uint i = 0; i < gl_NumSubgroups; ++i) {
            uint c = subgroupCounts[row + i];
            at += i < gl_SubgroupID ? c : 0;
            found += c;
        }
        if (filled + found > TILE_SIZE) {
            accumulateTile(acc, v, filled);
            barrier();
            filled = 0;
        }
        at += filled;
        while (bits != 0) {
            uint k = word * 32 + uint(findLSB(bits));
            bits &= bits - 1;
            PreparedSample s = prepareSample(samples[job.sampleOffset + k]);
            tilePositionDerivative[at] = s.positionDerivative;
            tileHeightHalfWidth[at] = vec2(s.height, s.halfWidth);
            tileReachRiver[at] = vec2(s.reach, s.river);
            ++at;
        }
        filled += found;
    }
    // The staging of the last chunks is ordered before the body by this barrier; earlier staging by the next
    // chunk's barrier, which comes before any flush.
    barrier();
    accumulateTile(acc, v, filled);
    if (hasVertex) storeHeight(acc, job, vertex);
}

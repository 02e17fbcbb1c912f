#version 460
// Simple GPU version (7.3.1): one invocation per vertex, every sample read from the storage buffer.
// Workgroups: x covers a row's vertices, y selects the row in the job table (from params.firstJob).
layout(local_size_x_id = 0) in;
#include "river_kernel.glsl"

void main() {
    PatchJob job = jobs[params.firstJob + gl_WorkGroupID.y];
    uvec2 size = latticeSize(job);
    uint index = gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    if (index >= size.x * size.y) return;
    uvec2 xy = uvec2(index % size.x, index / size.x);
    if (job.parentPlace != NO_PARENT) {
        copyFromParent(job, xy);
        return;
    }
    uvec2 vertex = patchVertex(job, xy);
    // Precise: the vertex position enters the decisions of accumulateSample, which must not fuse it.
    precise vec2 v = vec2(vertex) * job.spacing;
    Accumulators acc = initAccumulators();
    for (uint k = 0; k < job.sampleCount; ++k) {
        accumulateSample(acc, v, prepareSample(samples[job.sampleOffset + k]));
    }
    storeHeight(acc, job, vertex);
}

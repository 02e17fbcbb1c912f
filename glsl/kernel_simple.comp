#version 460
// Simple GPU version (7.3.1): one invocation per vertex, every sample read from the storage buffer.
// Workgroups: x covers a patch's vertices, y selects the patch in the job table.
layout(local_size_x_id = 0) in;
#include "river_kernel.glsl"

void main() {
    PatchJob job = jobs[gl_WorkGroupID.y];
    uint vertex = gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    if (vertex >= params.gridSize * params.gridSize) return;
    uvec2 xy = uvec2(vertex % params.gridSize, vertex / params.gridSize);
    vec2 v = vec2(xy) * job.spacing;
    Accumulators acc = initAccumulators();
    for (uint k = 0; k < job.sampleCount; ++k) {
        accumulateSample(acc, v, prepareSample(samples[job.sampleOffset + k]));
    }
    storeHeight(acc, job, xy);
}

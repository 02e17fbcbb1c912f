// The river-height kernel body (Procedures 3-5, Sections 6.5-6.6), shared by kernel_simple.comp (7.3.1) and
// kernel_tiled.comp (7.3.2). Mirrors src/kernel/cpu.rs operation for operation; see docs/kernel.md.
#extension GL_EXT_nonuniform_qualifier : require

// Position (xy) and first derivative (zw); height (x) and full width (y).
struct RiverSample {
    vec4 positionDerivative;
    vec4 heightWidth;
};

// One patch of the dispatch: its grid spacing, its range of samples, its bindless slot.
struct PatchJob {
    float spacing;
    uint sampleOffset;
    uint sampleCount;
    uint slot;
};

// Layer 0: terrain height, lerp factor, water height, signed minimum distance. Layer 1: river half width.
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2DArray riverImages[];
layout(set = 1, binding = 0, std430) readonly buffer Samples { RiverSample samples[]; };
layout(set = 1, binding = 1, std430) readonly buffer Jobs { PatchJob jobs[]; };

layout(push_constant) uniform KernelParams {
    float influenceDistance;
    float basinDepth;
    float seaLevel;
    float basinWaterOffset;
    uint gridSize;
} params;

// The accumulators of Procedure 4.
struct Accumulators {
    float heightSum;
    float weightSum;
    float basinSum;
    float widthSum;
    bool inRiver;
    float inRiverSum;
    float inRiverWSum;
    float minDistance;
};

Accumulators initAccumulators() {
    return Accumulators(0.0, 0.0, 0.0, 0.0, false, 0.0, 0.0, 3.402823466e38);
}

// Procedure 3 for one sample, accumulated as in Procedure 4. On SIMD hardware the body runs under a mask for the
// whole subgroup when any lane is in reach; lavapipe runs it under a mask always (measured: 0.7 ms for the
// distance tests of a workload alone, 43 ms with the masked body), which is why the tiled kernel culls samples
// per workgroup with a workgroup-uniform test.
void accumulateSample(inout Accumulators acc, vec2 v, RiverSample s) {
    vec2 p = s.positionDerivative.xy;
    vec2 d = s.positionDerivative.zw;
    float dist = length(v - p);
    if (dist <= params.influenceDistance) {
        float halfWidth = s.heightWidth.y * 0.5;
        vec2 n = vec2(d.y, -d.x);
        float nn = n.x * n.x + n.y * n.y;
        float t = nn > 0.0 ? ((v.x - p.x) * n.x + (v.y - p.y) * n.y) / nn : 0.0;
        vec2 vn = p + t * n;
        float projectionDistance = length(vn - v);
        float normalDistance = length(p - vn);
        float wDist = 1.0 - dist / params.influenceDistance;
        float basinDepth = wDist * params.basinDepth;
        acc.heightSum += wDist * s.heightWidth.x;
        acc.weightSum += wDist;
        acc.basinSum += basinDepth;
        acc.widthSum += wDist * halfWidth;
        if (projectionDistance < halfWidth && normalDistance <= halfWidth) {
            float normalFactor = normalDistance / halfWidth;
            float factor = normalFactor * normalFactor * normalFactor;
            float wRiver = 1.0 - projectionDistance / halfWidth;
            acc.inRiver = true;
            acc.inRiverSum += wRiver * factor * basinDepth;
            acc.inRiverWSum += wRiver;
        }
        float side = d.x * (v.y - p.y) - d.y * (v.x - p.x);
        float signedDist = side > 0.0 ? -dist : dist;
        if (abs(signedDist) < abs(acc.minDistance)) acc.minDistance = signedDist;
    }
}

// Procedure 5: the five outputs of one vertex, written to the patch's slot.
void storeHeight(Accumulators acc, PatchJob job, uvec2 xy) {
    vec4 heights = vec4(0.0, 1.0, params.seaLevel, params.influenceDistance);
    float riverWidth = 0.0;
    if (acc.weightSum > 0.0) {
        float height = acc.heightSum / acc.weightSum;
        float basin = acc.basinSum / acc.weightSum;
        riverWidth = acc.widthSum / acc.weightSum;
        if (acc.inRiver) {
            float inRiverBasin = acc.inRiverSum / acc.inRiverWSum;
            float heightOffset = basin - params.basinWaterOffset;
                    heights = vec4(height + inRiverBasin, 0.0, max(params.seaLevel, height + heightOffset), acc.minDistance);
        } else {
            float terrainHeight = height + basin;
            float divisor = params.influenceDistance - riverWidth;
            float lerpFactor = divisor > 0.0 ? clamp((abs(acc.minDistance) - riverWidth) / divisor, 0.0, 1.0) : 0.0;
                    heights = vec4(terrainHeight, lerpFactor, max(params.seaLevel, terrainHeight - params.basinWaterOffset),
                        acc.minDistance);
        }
    }
    imageStore(riverImages[nonuniformEXT(job.slot)], ivec3(xy, 0), heights);
    imageStore(riverImages[nonuniformEXT(job.slot)], ivec3(xy, 1), vec4(riverWidth, 0.0, 0.0, 0.0));
}

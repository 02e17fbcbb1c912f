// The river-height kernel body (Procedures 3-5, Sections 6.5-6.6), shared by kernel_simple.comp (7.3.1) and
// kernel_tiled.comp (7.3.2). Mirrors src/kernel/cpu.rs operation for operation; see docs/kernel.md.
#extension GL_EXT_nonuniform_qualifier : require
#include "slot_layers.glsl"

// Position (xy) and first derivative (zw); height (x), full width (y) and, beyond the thesis, the sample's own
// influence distance (z; 0: the kernel's, which bounds it) and its river's number (w).
struct RiverSample {
    vec4 positionDerivative;
    vec4 heightWidth;
};

// One row of the dispatch: a patch's grid spacing, its range of samples, its river texture's place (a slot and
// layer: slot_layers.glsl), where its reach
// masks start (in words; used by the tiled kernel only, see kernel_blocks.glsl), and which of its vertices the row
// covers. A patch computed from scratch is one row over all its vertices. A patch that takes river data from its
// parent (10.2, docs/kernel.md) is four rows, one per vertex parity: the even vertices copied from the parent's
// quadrant, and the three other lattices of every second vertex computed.
struct PatchJob {
    float spacing;
    uint sampleOffset;
    uint sampleCount;
    uint place;
    uint maskOffset;
    // Stride (bits 0-7) and the parity of the first vertex along x (bits 8-15) and y (16-23).
    uint lattice;
    // The place of the parent's river texture to copy from, or NO_PARENT.
    uint parentPlace;
    // The parent vertex of the row's first vertex: x (bits 0-15), y (16-31).
    uint parentOffset;
};

const uint NO_PARENT = 0xffffffffu;
// The half width a lake's vertices report (LAKE_HALF_WIDTH in src/kernel/cpu.rs).
const float LAKE_HALF_WIDTH = 1e9;

// Layer 0: terrain height, lerp factor, water height, signed minimum distance. Layer 1: river half width, flow.
// Layer 2 (beyond the thesis): the second river's signed distance and half width, the nearest sample's half
// width, the rivers' order (src/kernel/mod.rs, RiverTexel).
// Read as well as written: rows that copy from the parent read its texture.
layout(set = 0, binding = 0, rgba32f) uniform image2DArray riverImages[];
layout(set = 1, binding = 0, std430) readonly buffer Samples { RiverSample samples[]; };
layout(set = 1, binding = 1, std430) readonly buffer Jobs { PatchJob jobs[]; };

layout(push_constant) uniform KernelParams {
    float influenceDistance;
    float basinDepth;
    float seaLevel;
    float basinWaterOffset;
    uint gridSize;
    // Row of the job table that workgroup index 0 computes: rows are dispatched in groups of the same lattice.
    uint firstJob;
    // Beyond the thesis: the least distance between samples, in vertex spacings (0: none; signedWidth).
    float sampleFloor;
} params;

uint latticeStride(PatchJob job) {
    return job.lattice & 0xffu;
}

uvec2 latticeParity(PatchJob job) {
    return uvec2((job.lattice >> 8) & 0xffu, (job.lattice >> 16) & 0xffu);
}

// Vertices of the row's lattice along x and y.
uvec2 latticeSize(PatchJob job) {
    uint stride = latticeStride(job);
    return (uvec2(params.gridSize) - latticeParity(job) + stride - 1) / stride;
}

// The patch vertex of lattice point `xy`.
uvec2 patchVertex(PatchJob job, uvec2 xy) {
    return xy * latticeStride(job) + latticeParity(job);
}

// A row that copies its lattice (every second vertex, from the first) from the parent's quadrant.
void copyFromParent(PatchJob job, uvec2 xy) {
    ivec2 from = ivec2(xy + uvec2(job.parentOffset & 0xffffu, job.parentOffset >> 16));
    ivec2 to = ivec2(patchVertex(job, xy));
    for (int layer = 0; layer < 3; ++layer) {
        ivec3 target = ivec3(to, int(layerOf(job.place)) + layer);
        ivec3 source = ivec3(from, int(layerOf(job.parentPlace)) + layer);
        imageStore(riverImages[slotOf(job.place)], target, imageLoad(riverImages[slotOf(job.parentPlace)], source));
    }
}

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
    // Its square: the nearest sample is chosen on it.
    float minDistance2;
    // The influence distance of the nearest sample: the lerp factor reaches 1 there.
    float nearestReach;
    // The half width of the nearest sample.
    float nearestHalfWidth;
    // Beyond the thesis: the nearest sample's river number (-1 before any) and how far along its flow the vertex
    // lies (along2 over scale2, as src/kernel/cpu.rs), and the nearest sample of another river: its signed
    // distance, the square of it, its half width, river number and the same along the flow.
    float nearestRiver;
    vec2 nearestAlong;
    float secondDistance;
    float secondDistance2;
    float secondHalfWidth;
    float secondRiver;
    vec2 secondAlong;
    // Beyond the thesis: the highest level of the lakes whose samples reach the vertex (-FLT_MAX: none).
    float lakeLevel;
    // Beyond the thesis: how far into that lake's reach the vertex lies from the lake's nearest sample, as the
    // squared share of the reach (0 on the lake's line, towards 1 at the reach's edge).
    float lakeOffset2;
    // Beyond the thesis: the unit directions (downstream) of the samples whose river covers the vertex, weighted
    // as their river depth (the water's flow).
    vec2 flowSum;
};

Accumulators initAccumulators() {
    return Accumulators(0.0, 0.0, 0.0, 0.0, false, 0.0, 0.0, 3.402823466e38, 3.402823466e38,
                        params.influenceDistance, 0.0, -1.0, vec2(0.0, 1.0), 3.402823466e38, 3.402823466e38, 0.0,
                        -1.0, vec2(0.0, 1.0), -3.402823466e38, 1.0, vec2(0.0));
}

// A sample with what does not depend on the vertex computed once: the tiled kernel prepares each sample when it
// stages it, the simple kernel on every read.
struct PreparedSample {
    vec4 positionDerivative;
    float height;
    float halfWidth;
    // The sample's influence distance.
    float reach;
    // Its river's number.
    float river;
};

PreparedSample prepareSample(RiverSample s) {
    float reach = s.heightWidth.z > 0.0 ? s.heightWidth.z : params.influenceDistance;
    return PreparedSample(s.positionDerivative, s.heightWidth.x, s.heightWidth.y * 0.5, reach, s.heightWidth.w);
}

// Procedure 3 for one sample, accumulated as in Procedure 4: the CPU reference's quantities
// (src/kernel/cpu.rs), operation for operation.
//
// Decisions every device takes alike (docs/kernel.md): whether the sample is relevant, whether its basin holds the
// vertex, which side of its line the vertex lies on and which sample is nearest are decided on squared distances,
// dot and cross products. Vulkan rounds additions and multiplications correctly, and `precise` forbids fusing them
// (a driver that contracted d.x * r.y - d.y * r.x into one FMA flipped the sign of the distance of vertices on a
// sample's line: 39.6 = 2 x 19.8 on NVIDIA), so these equal the CPU's bit for bit. The weights are written to be
// positive whenever the decision says so; only they carry the rounding of square roots and divisions.
//
// On SIMD hardware the body runs under a mask for the whole subgroup when any lane is in reach; lavapipe runs it
// under a mask always, which is why the tiled kernel stages only the samples within reach of its vertex block.
void accumulateSample(inout Accumulators acc, vec2 v, PreparedSample s) {
    vec2 p = s.positionDerivative.xy;
    vec2 d = s.positionDerivative.zw;
    precise vec2 r = v - p;
    precise float dist2 = r.x * r.x + r.y * r.y;
    // A lake's sample (negative width): its level reaches the vertices within half its width, and it takes no
    // part in Procedure 3.
    if (s.halfWidth < 0.0) {
        precise float lakeReach2 = s.halfWidth * s.halfWidth;
        if (dist2 < lakeReach2) {
            float offset2 = dist2 / lakeReach2;
            if (s.height > acc.lakeLevel) {
                acc.lakeLevel = s.height;
                acc.lakeOffset2 = offset2;
            } else if (s.height == acc.lakeLevel) {
                acc.lakeOffset2 = min(acc.lakeOffset2, offset2);
            }
        }
        return;
    }
    float reach = s.reach;
    precise float reach2 = reach * reach;
    if (dist2 < reach2) {
        float dist = sqrt(dist2);
        // 1 - dist / reach, positive for every relevant sample.
        float wDist = (reach2 - dist2) / (reach * (reach + dist));
        float basinDepth = wDist * params.basinDepth;
        acc.heightSum += wDist * s.height;
        acc.weightSum += wDist;
        acc.basinSum += basinDepth;
        acc.widthSum += wDist * s.halfWidth;
        bool zero = d == vec2(0.0);
        precise float dot_ = r.x * d.x + r.y * d.y;
        precise float along2 = zero ? dist2 : dot_ * dot_;
        float along = zero ? dist : abs(dot_);
        precise float halfWidth2 = s.halfWidth * s.halfWidth;
        precise float dd = d.x * d.x + d.y * d.y;
        precise float limit2 = zero ? halfWidth2 : halfWidth2 * dd;
        precise float side = d.x * r.y - d.y * r.x;
        precise float side2 = side * side;
        // projection distance < half width and normal distance <= half width.
        if (along2 < limit2 && side2 <= limit2) {
            // 1 / (halfWidth x |derivative|): turns the unnormalised distances along and across the flow into the
            // fractions of the half width that Procedure 3 uses. 1 / halfWidth for a zero derivative.
            float inverseScale = 1.0 / (s.halfWidth * (zero ? 1.0 : sqrt(dd)));
            float normalFactor = abs(side) * inverseScale;
            float factor = normalFactor * normalFactor * normalFactor;
            // 1 - along / limit, positive in the basin.
            float wRiver = (limit2 - along2) * (inverseScale * inverseScale) / (1.0 + along * inverseScale);
            acc.inRiver = true;
            acc.inRiverSum += wRiver * factor * basinDepth;
            acc.inRiverWSum += wRiver;
            // d / |d| without another square root: inverseScale x halfWidth = 1 / |d| (and d = 0 stays 0).
            acc.flowSum += wRiver * (d * (inverseScale * s.halfWidth));
        }
        // Beyond the thesis: the nearest sample, and the nearest of another river.
        float signedDist = side > 0.0 ? -dist : dist;
        vec2 alongScale = vec2(along2, zero ? 1.0 : dd);
        if (dist2 < acc.minDistance2) {
            if (s.river != acc.nearestRiver) {
                acc.secondDistance = acc.minDistance;
                acc.secondDistance2 = acc.minDistance2;
                acc.secondHalfWidth = acc.nearestHalfWidth;
                acc.secondRiver = acc.nearestRiver;
                acc.secondAlong = acc.nearestAlong;
            }
            acc.minDistance2 = dist2;
            acc.minDistance = signedDist;
            acc.nearestReach = reach;
            acc.nearestHalfWidth = s.halfWidth;
            acc.nearestRiver = s.river;
            acc.nearestAlong = alongScale;
        } else if (s.river != acc.nearestRiver && dist2 < acc.secondDistance2) {
            acc.secondDistance = signedDist;
            acc.secondDistance2 = dist2;
            acc.secondHalfWidth = s.halfWidth;
            acc.secondRiver = s.river;
            acc.secondAlong = alongScale;
        }
    }
}

// Beyond the thesis: a half width made negative where the vertex lies beyond the end of its river (`along`: how
// far along the flow from the river's nearest sample, as along2 and scale2), as beyond_end in src/kernel/cpu.rs.
float signedWidth(float halfWidth, vec2 along, float spacing) {
    float limit = max(params.sampleFloor * spacing, halfWidth);
    precise float bound = limit * limit * along.y;
    return along.x > bound ? -halfWidth : halfWidth;
}

// Procedure 5: the five outputs of one vertex (patch vertex `xy`), written to the patch's slot.
void storeHeight(Accumulators acc, PatchJob job, uvec2 xy) {
    vec4 heights = vec4(0.0, 1.0, params.seaLevel, params.influenceDistance);
    float riverWidth = 0.0;
    vec2 flow = vec2(0.0);
    // Beyond the thesis: the second river's signed distance and half width, the nearest sample's half width and
    // the rivers' order (1: the nearest's number below the second's, -1 above, 0 no second).
    vec4 second = vec4(params.influenceDistance, 0.0, 0.0, 0.0);
    if (acc.weightSum > 0.0) {
        bool other = acc.secondRiver >= 0.0;
        second = vec4(other ? acc.secondDistance : params.influenceDistance,
                      other ? signedWidth(acc.secondHalfWidth, acc.secondAlong, job.spacing) : 0.0,
                      signedWidth(acc.nearestHalfWidth, acc.nearestAlong, job.spacing),
                      other ? (acc.nearestRiver < acc.secondRiver ? 1.0 : -1.0) : 0.0);
        float height = acc.heightSum / acc.weightSum;
        float basin = acc.basinSum / acc.weightSum;
        // Beyond the thesis: a vertex nearest to a sample with its own, shorter reach (a finer level's stream) has
        // that stream's width, not the mean with the wide river whose valley it runs down.
        riverWidth = acc.nearestReach < params.influenceDistance ? acc.nearestHalfWidth : acc.widthSum / acc.weightSum;
        if (acc.inRiver) {
            flow = acc.flowSum / acc.inRiverWSum;
            float inRiverBasin = acc.inRiverSum / acc.inRiverWSum;
            float heightOffset = basin - params.basinWaterOffset;
            heights = vec4(height + inRiverBasin, 0.0, max(params.seaLevel, height + heightOffset), acc.minDistance);
        } else {
            float terrainHeight = height + basin;
            float divisor = acc.nearestReach - riverWidth;
            float lerpFactor = divisor > 0.0 ? clamp((abs(acc.minDistance) - riverWidth) / divisor, 0.0, 1.0) : 0.0;
            heights = vec4(terrainHeight, lerpFactor, max(params.seaLevel, terrainHeight - params.basinWaterOffset),
                           acc.minDistance);
        }
    }
    // Beyond the thesis: a vertex a lake reaches, outside every river's basin, gets the lake's level as its
    // water, a distance of 0 and the lake half width, which the shaders read as a basin whose water the mesh shows
    // where the terrain lies below it, and its rivers' terrain above the level brought down to it as an inflow's
    // water is; in a river's basin, an inflow's water above the level comes down to it across the lake's reach,
    // its bed with it (src/kernel/cpu.rs, with_lake).
    if (acc.lakeLevel > -3.402823466e38) {
        if (acc.inRiver) {
            float excess = heights.z - acc.lakeLevel;
            if (excess > 0.0) {
                precise float drop = excess * (1.0 - acc.lakeOffset2);
                heights.z -= drop;
                heights.x -= drop;
            }
        } else {
            float excess = heights.x - acc.lakeLevel;
            if (excess > 0.0) {
                precise float drop = excess * (1.0 - acc.lakeOffset2);
                heights.x -= drop;
            }
            heights.z = acc.lakeLevel;
            heights.w = 0.0;
            riverWidth = LAKE_HALF_WIDTH;
            second.zw = vec2(0.0);
        }
    }
    uint slot = slotOf(job.place);
    int layer = int(layerOf(job.place));
    imageStore(riverImages[slot], ivec3(xy, layer), heights);
    imageStore(riverImages[slot], ivec3(xy, layer + 1), vec4(riverWidth, flow, 0.0));
    imageStore(riverImages[slot], ivec3(xy, layer + 2), second);
}

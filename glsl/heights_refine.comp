#version 460
// Base heights on demand (Sections 3.6 and 4.2): one diamond-square step per patch. Workgroup k turns the heights
// of job k's parent (a bindless sampled texture) into those of the child (a bindless storage image), border
// included. The CPU reference is src/planet/detail.rs (refine); this shader computes the same bits: the same
// 32-bit hash, exact scalings, sorted four-value averages and `precise` arithmetic (no fused or reordered
// operations). docs/planet.md explains the border, the folding across face edges and the cube corners.
#extension GL_EXT_nonuniform_qualifier : require
#include "slot_layers.glsl"
layout(local_size_x = 64) in;

layout(constant_id = 0) const int CELLS = 32;      // cells per patch edge (vertices - 1)
const int BORDER = 2;                              // planet::detail::BORDER
const int SIDE = CELLS + 1 + 2 * BORDER;           // stored points per row
const int REACH = BORDER + 1;                      // diamond centres are needed one point beyond the border
const int SPAN = (CELLS + 2 * REACH) / 2 + 1;      // diamond centres per row

layout(set = 0, binding = 0, r32f) uniform writeonly image2DArray heightImages[];
layout(set = 0, binding = 1) uniform sampler2DArray patchTextures[];

struct RefineJob {
    int childPlace;  // the places of the child's and the parent's heights (slot_layers.glsl)
    int parentPlace;
    int face;
    int level;      // the child's
    ivec2 patchXY;  // the child's position in its level's grid
    int rangeIndex; // where the child's lowest and highest height go in `ranges`
    int unused;
};
layout(set = 1, binding = 0, std430) readonly buffer Jobs { RefineJob jobs[]; };
// Lowest and highest height of every refined patch (border included), read back by the renderer for its level of
// detail and culling bounds.
layout(set = 1, binding = 1, std430) writeonly buffer Ranges { vec2 ranges[]; };

layout(push_constant) uniform Push {
    uint seed;
    float amplitude;  // detail-amplitude: the displacement of level 0
    float flatShare;  // DetailRule::flat_share: the displacement's share on level ground
    float spreadGain; // DetailRule::spread_gain
} push;

shared float centres[SPAN * SPAN];
shared vec2 laneRanges[64];

const ivec3 FACE_NORMAL[6] = ivec3[](ivec3(1, 0, 0), ivec3(-1, 0, 0), ivec3(0, 1, 0), ivec3(0, -1, 0), ivec3(0, 0, 1), ivec3(0, 0, -1));
const ivec3 FACE_U[6] = ivec3[](ivec3(0, 0, -1), ivec3(0, 0, 1), ivec3(1, 0, 0), ivec3(1, 0, 0), ivec3(1, 0, 0), ivec3(-1, 0, 0));
const ivec3 FACE_V[6] = ivec3[](ivec3(0, 1, 0), ivec3(0, 1, 0), ivec3(0, 0, -1), ivec3(0, 0, 1), ivec3(0, 1, 0), ivec3(0, 1, 0));

RefineJob job;
int cells;            // lattice cells per face edge at the child's level
ivec2 origin;         // the child's vertex (0, 0) in face-lattice coordinates of its level
ivec2 parentOrigin;   // the parent's, at the parent's level

int outside(int g) { return g < 0 ? -1 : (g > cells ? 1 : 0); }

bool inCornerQuadrant(ivec2 g) { return outside(g.x) != 0 && outside(g.y) != 0; }

// planet::detail::key: the cube key of a point of the face or of the strip beyond one edge (folded).
uvec3 latticeKey(ivec2 g) {
    ivec3 n = FACE_NORMAL[job.face];
    ivec2 c = clamp(g, ivec2(0), ivec2(cells));
    int over = abs(g.x - c.x) + abs(g.y - c.y);
    int h = cells / 2;
    return uvec3((n + 1) * h + FACE_U[job.face] * (c.x - h) + FACE_V[job.face] * (c.y - h) - n * over);
}

// planet::detail::unfold_neighbour: a neighbour in a corner quadrant turned about the cube corner.
ivec2 unfoldNeighbour(ivec2 p, ivec2 q) {
    int sx = outside(q.x), sy = outside(q.y);
    if (sx == 0 || sy == 0) return q;
    ivec2 corner = ivec2(sx < 0 ? 0 : cells, sy < 0 ? 0 : cells);
    int a = (q.x - corner.x) * sx;
    int b = (q.y - corner.y) * sy;
    ivec2 ab = outside(p.x) != 0 ? ivec2(-b, a) : ivec2(b, -a);
    return corner + ab * ivec2(sx, sy);
}

uint mix32(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    return x ^ (x >> 16);
}

uint latticeHash(uint level, uvec3 key) {
    uint h = mix32(push.seed ^ 0x9e3779b9u);
    h = mix32(h ^ (level + 0x9e3779b9u));
    h = mix32(h ^ (key.x + 0x9e3779b9u));
    h = mix32(h ^ (key.y + 0x9e3779b9u));
    return mix32(h ^ (key.z + 0x9e3779b9u));
}

// The four values in ascending order, summed left to right: their average, and the highest less the lowest.
vec2 sortedAverageAndSpread(vec4 v) {
    float a = min(v.x, v.y), b = max(v.x, v.y), c = min(v.z, v.w), d = max(v.z, v.w);
    float s0 = min(a, c), t = max(a, c), u = min(b, d), s3 = max(b, d);
    float s1 = min(t, u), s2 = max(t, u);
    precise float sum = ((s0 + s1) + s2) + s3;
    precise float average = sum * 0.25;
    precise float spread = s3 - s0;
    return vec2(average, spread);
}

// The point between the four heights `around` (DetailRule::displaced): their average plus its displacement, the
// level's amplitude times its share (the flat share, growing with the spread), or the bare average in a corner
// quadrant.
float displaced(vec4 around, ivec2 g) {
    vec2 averageAndSpread = sortedAverageAndSpread(around);
    if (inCornerQuadrant(g)) return averageAndSpread.x;
    uint level = uint(job.level);
    uint h = latticeHash(level, latticeKey(g));
    precise float unit = float(h >> 8) * (1.0 / 16777216.0) * 2.0 - 1.0;
    precise float amplitude = push.amplitude * uintBitsToFloat((127u - min(level, 126u)) << 23);
    precise float levels = uintBitsToFloat((127u + min(level, 127u)) << 23);
    precise float share = min(push.flatShare + (averageAndSpread.y * levels) * push.spreadGain, 1.0);
    precise float value = averageAndSpread.x + unit * (amplitude * share);
    return value;
}

// A point of the parent's lattice (even child coordinates).
float parentAt(ivec2 g) {
    ivec2 texel = g / 2 - parentOrigin + BORDER;
    return texelFetch(patchTextures[nonuniformEXT(slotOf(job.parentPlace))], ivec3(texel, layerOf(job.parentPlace)), 0).r;
}

// A parent point or a diamond centre.
float valueAt(ivec2 g) {
    if ((g.x & 1) == 0) return parentAt(g);
    ivec2 c = (g - origin + REACH) / 2;
    return centres[c.y * SPAN + c.x];
}

void main() {
    job = jobs[gl_WorkGroupID.x];
    cells = CELLS << job.level;
    origin = job.patchXY * CELLS;
    parentOrigin = (job.patchXY >> 1) * CELLS;
    uint lane = gl_LocalInvocationIndex;

    // Diamond step: cell centres of the parent's lattice, one point beyond the border on each side.
    for (uint k = lane; k < SPAN * SPAN; k += gl_WorkGroupSize.x) {
        ivec2 g = origin - REACH + 2 * ivec2(k % SPAN, k / SPAN);
        vec4 corners = vec4(parentAt(g + ivec2(-1, -1)), parentAt(g + ivec2(1, -1)), parentAt(g + ivec2(-1, 1)),
                            parentAt(g + ivec2(1, 1)));
        centres[k] = displaced(corners, g);
    }
    barrier();

    // Every stored point: the parent's, a centre, or the square step of an edge midpoint.
    vec2 range = vec2(3.4e38, -3.4e38);
    for (uint k = lane; k < SIDE * SIDE; k += gl_WorkGroupSize.x) {
        ivec2 texel = ivec2(k % SIDE, k / SIDE);
        ivec2 g = origin + texel - BORDER;
        float value;
        if (inCornerQuadrant(g)) {
            value = parentAt(clamp(g, ivec2(0), ivec2(cells)));
        } else if (((g.x ^ g.y) & 1) == 0) {
            value = valueAt(g);
        } else {
            vec4 around = vec4(valueAt(unfoldNeighbour(g, g + ivec2(-1, 0))), valueAt(unfoldNeighbour(g, g + ivec2(1, 0))),
                               valueAt(unfoldNeighbour(g, g + ivec2(0, -1))), valueAt(unfoldNeighbour(g, g + ivec2(0, 1))));
            value = displaced(around, g);
        }
        imageStore(heightImages[nonuniformEXT(slotOf(job.childPlace))], ivec3(texel, layerOf(job.childPlace)), vec4(value));
        range = vec2(min(range.x, value), max(range.y, value));
    }

    // The patch's height range: a tree reduction over the workgroup.
    laneRanges[lane] = range;
    barrier();
    for (uint stride = gl_WorkGroupSize.x / 2; stride > 0; stride /= 2) {
        if (lane < stride) {
            vec2 other = laneRanges[lane + stride];
            laneRanges[lane] = vec2(min(laneRanges[lane].x, other.x), max(laneRanges[lane].y, other.y));
        }
        barrier();
    }
    if (lane == 0) ranges[job.rangeIndex] = laneRanges[0];
}

// Shared by terrain.vert, water.vert and vertex_cache.comp (Section 8.2): a patch vertex's base height and river
// data, blended by the lerp factor and morphed towards the parent, placed on the sphere relative to the camera;
// its normal and the air in front of it; and the vertex cache that holds all of it for a frame.
#include "terrain_common.glsl"
#include "atmosphere.glsl"

// Texture coordinates of a grid position in the base-height texture, which has a border of HEIGHT_BORDER points
// (planet::detail::BORDER) on each side.
const float HEIGHT_BORDER = 2.0;
vec2 baseCoord(vec2 t) {
    float n = frame.planet.y;
    return (t + 0.5 + HEIGHT_BORDER) / (n + 2.0 * HEIGHT_BORDER);
}

// The unit direction at a grid position minus the patch centre's, to f32 precision relative to the patch's size
// at any depth. With q = c + d (c: the centre on the cube, d: the offset within the patch on the cube),
// q/|q| - c/|c| = d/|q| - c e / ((|c| + |q|) |q| |c|), where e = |q|^2 - |c|^2 = 2 c.d + d.d comes from per-patch
// dot products; nothing subtracts two nearly equal large numbers.
vec3 directionOffset(PatchInstance p, vec2 grid) {
    float n = frame.planet.y;
    vec2 st = grid / (n - 1.0) - 0.5;
    vec3 d = st.x * p.axisU.xyz + st.y * p.axisV.xyz;
    float e = st.x * p.axisU.w + st.y * p.axisV.w + dot(d, d);
    float c = p.cubeCentre.w;
    float q = sqrt(c * c + e);
    return d / q - p.cubeCentre.xyz * (e / ((c + q) * q * c));
}

float baseAt(PatchInstance p, vec2 grid) {
    vec2 t = p.texRect.xy + grid * p.texRect.z;
    int place = p.slots.x;
    return textureLod(patchTextures[nonuniformEXT(slotOf(place))], vec3(baseCoord(t), layerOf(place)), 0.0).r;
}

// One layer of the river data at a grid position, blended by the morph factor into the parent's river data at
// the same place.
vec4 riverLayerAt(PatchInstance p, vec2 grid, float morph, float layer) {
    float n = frame.planet.y;
    vec3 uv = vec3((p.texRect.xy + grid * p.texRect.z + 0.5) / n, float(layerOf(p.slots.y)) + layer);
    vec4 data = textureLod(patchTextures[nonuniformEXT(slotOf(p.slots.y))], uv, 0.0);
    if (morph > 0.0 && p.slots.w >= 0) {
        vec3 parentUv = vec3((p.morph.zw + grid * 0.5 + 0.5) / n, float(layerOf(p.slots.w)) + layer);
        data = mix(data, textureLod(patchTextures[nonuniformEXT(slotOf(p.slots.w))], parentUv, 0.0), morph);
    }
    return data;
}

// River data at a grid position (layer 0: terrain height, lerp factor, water height, signed distance; layer 1: the
// half width and the flow in the patch frame), blended as riverLayerAt blends.
vec4 riverAt(PatchInstance p, vec2 grid, float morph, out vec3 widthFlow) {
    widthFlow = riverLayerAt(p, grid, morph, 1.0).rgb;
    return riverLayerAt(p, grid, morph, 0.0);
}

// The blended terrain height at a grid position (for normals).
float heightAt(PatchInstance p, vec2 grid, float morph) {
    float base = baseAt(p, grid);
    if (p.slots.y < 0) return base;
    vec3 widthFlow;
    vec4 river = riverAt(p, grid, morph, widthFlow);
    return mix(river.x, base, river.y);
}

// A river pair's slot without a river (see riverPairAt).
const vec2 NO_RIVER = vec2(FAR_FROM_RIVERS, 0.0);
// The share of its half width a vertex beyond its river's end draws (see surfaceAt).
const float BEYOND_END_WIDTH = 1e-3;

// Beyond the thesis (docs/rendering.md, "The two nearest rivers"): the two nearest rivers at a grid position,
// signed distance and half width each, in the rivers' order (the lower number first), so that the vertices of a
// triangle between two rivers agree on which slot holds which; a slot no river fills is NO_RIVER, a river the
// vertex lies beyond the end of has half width 0 (the kernel's negative half width), so that it narrows to
// nothing there. From layer 2 of the river data (the second river, the nearest sample's half width, the order) and
// the nearest distance; `beyondEnd`: whether the vertex lies beyond the nearest river's end.
vec4 riverPairAt(PatchInstance p, vec2 grid, float morph, float nearestDistance, out bool beyondEnd) {
    vec4 second = riverLayerAt(p, grid, morph, 2.0);
    beyondEnd = second.z < 0.0;
    vec2 nearest = second.z != 0.0 ? vec2(nearestDistance, max(second.z, 0.0)) : NO_RIVER;
    vec2 other = second.w != 0.0 ? vec2(second.x, max(second.y, 0.0)) : NO_RIVER;
    return second.w < 0.0 ? vec4(other, nearest) : vec4(nearest, other);
}

// Terrain height, water height, signed distance and half width at a grid position, from the patch's (or its
// stand-in's) textures; `flow`: the water's flow in the patch frame; `pair`: riverPairAt.
vec4 surfaceAt(PatchInstance p, vec2 grid, float morph, out vec2 flow, out vec4 pair) {
    float base = baseAt(p, grid);
    flow = vec2(0.0);
    pair = vec4(NO_RIVER, NO_RIVER);
    if (p.slots.y < 0) return vec4(base, frame.sun.w, FAR_FROM_RIVERS, 0.0);
    vec3 widthFlow;
    vec4 river = riverAt(p, grid, morph, widthFlow);
    flow = widthFlow.yz;
    bool beyondEnd;
    pair = riverPairAt(p, grid, morph, river.w, beyondEnd);
    // Beyond the thesis: beyond its river's end a vertex draws the river narrowed to nothing (a thousandth of its
    // width, so that it still counts as reached by a river), or the river's band would run on between it and the
    // vertices beside the river (docs/rendering.md, "The two nearest rivers").
    if (beyondEnd) widthFlow.x *= BEYOND_END_WIDTH;
    // Section 8.2: blend the river terrain into the base terrain by the lerp factor.
    float height = mix(river.x, base, river.y);
    return vec4(height, max(river.z, frame.sun.w), river.w, widthFlow.x);
}

// Beyond the thesis (CDLOD, Strugar 2009): how far a vertex has morphed towards its parent's mesh, from its
// distance to the camera: 0 inside the morph band's start, 1 from the switch distance at its grid position on.
// The switch distance is bilinear between the patch's corners, written as a(1 - t) + bt so that an edge's
// vertices take the same value in both patches that share it (runtime/error_field.rs).
float switchDistance(PatchInstance p, vec2 grid) {
    vec2 t = grid / (frame.planet.y - 1.0);
    vec4 d = p.switchDistances;
    float low = d.x * (1.0 - t.x) + d.y * t.x;
    float high = d.z * (1.0 - t.x) + d.w * t.x;
    return low * (1.0 - t.y) + high * t.y;
}
float morphFactor(PatchInstance p, vec2 grid, float distance) {
    return clamp((distance / switchDistance(p, grid) - p.morph.x) * p.morph.y, 0.0, 1.0);
}

// Camera-relative position: the patch centre relative to the camera (f64 on the CPU), plus the small offset of the
// grid position on the sphere, plus the height along the direction.
vec3 positionAt(PatchInstance p, float height, vec3 offset) {
    float radius = frame.planet.x;
    return p.centreRel.xyz + p.centreDir.xyz * height + offset * (radius + height);
}

// The flow in the patch frame as a world tangent: the frame's axes are the face's u and v (the grid's i and j),
// taken into the tangent plane.
vec3 flowTangent(PatchInstance p, vec2 flow, vec3 direction) {
    vec3 tangentU = normalize(p.axisU.xyz - direction * dot(p.axisU.xyz, direction));
    vec3 tangentV = normalize(p.axisV.xyz - direction * dot(p.axisV.xyz, direction));
    return flow.x * tangentU + flow.y * tangentV;
}

// One vertex of the patch mesh, before normals and atmosphere.
struct TerrainVertex {
    vec3 position;   // camera-relative
    vec3 local;      // position - centreRel: small, the ground detail's coordinates build on it
    vec3 direction;  // unit direction from the planet centre
    vec4 surface;    // final height, water height, signed distance, river half width
    vec4 pair;       // the two nearest rivers in their order (riverPairAt)
    vec3 flow;       // the water's flow: a world tangent, unit length where the samples agree
    vec2 grid;       // (i, j) within the patch, unmorphed
    vec2 morphed;    // the grid position morphed towards the parent's mesh
    float morph;
    vec3 offset;     // directionOffset at the morphed grid position
    int edge;        // -1 surface, 0-3 edge skirts, 4-5 midline skirts
};

// (a / n, a % n) for the mesh's small non-negative indices, through a float division: lavapipe runs an integer
// division of a vector lane by lane. Exact while a < 2^20: the quotient's error stays far below 1 / (2n).
ivec2 divMod(int a, int n) {
    int q = int((float(a) + 0.5) / float(n));
    return ivec2(q, a - q * n);
}

// The grid point of mesh vertex `id` (render/mesh.rs: the grid, then six skirts of n vertices) and its skirt.
ivec2 meshGrid(int id, out int edge) {
    int n = int(frame.planet.y);
    edge = -1;
    if (id < n * n) return divMod(id, n).yx;
    ivec2 skirt = divMod(id - n * n, n);
    edge = skirt.x;
    int k = skirt.y;
    int m = (n - 1) / 2;
    ivec2 along[6] = ivec2[](ivec2(k, 0), ivec2(k, n - 1), ivec2(0, k), ivec2(n - 1, k), ivec2(m, k), ivec2(k, m));
    return along[edge];
}

// Morph: odd grid coordinates slide towards the even neighbour below, so that fully morphed the mesh is the
// parent's (whose points keep their heights at every level).
vec2 morphedGrid(vec2 grid, float morph) { return grid - mod(grid, 2.0) * morph; }

// Beyond the thesis (docs/rendering.md, "Water in the terrain mesh"): the height at which the mesh places a
// vertex of `surface` (terrain height, water height, signed distance, half width). With the water in the mesh,
// a vertex under the sea, or in a river basin whose water the mesh shows (not painted), lies on the water's
// surface, so that the terrain pass draws the water where it is and writes its depth; else on the terrain. Only
// the vertex's own data decide, so the vertices patches share are placed alike.
float placedHeight(vec4 surface) {
    float height = surface.x;
    if (!waterInMesh()) return height;
    height = max(height, frame.sun.w);
    if (waterMode() != WATER_PAINTED && inRiverBasin(surface)) height = max(height, surface.y);
    return height;
}

// Places a vertex of `v.surface` at the morphed grid position (offset: directionOffset there), at placedHeight;
// skirts hang texRect.w below.
void place(PatchInstance p, inout TerrainVertex v) {
    v.direction = normalize(p.centreDir.xyz + v.offset);
    float placed = placedHeight(v.surface);
    if (v.edge >= 0) {
        v.surface.x -= p.texRect.w;
        placed -= p.texRect.w;
    }
    v.position = positionAt(p, placed, v.offset);
    v.local = p.centreDir.xyz * placed + v.offset * (frame.planet.x + placed);
}

// Mesh vertex `id` of `p`, computed from the patch textures.
TerrainVertex terrainVertex(PatchInstance p, int id) {
    TerrainVertex v;
    v.grid = vec2(meshGrid(id, v.edge));
    // The morph distance is the unmorphed vertex's, from its base height, which neighbouring patches share bit for
    // bit.
    v.morph = morphFactor(p, v.grid, length(positionAt(p, baseAt(p, v.grid), directionOffset(p, v.grid))));
    v.morphed = morphedGrid(v.grid, v.morph);
    vec2 flow;
    v.surface = surfaceAt(p, v.morphed, v.morph, flow, v.pair);
    v.offset = directionOffset(p, v.morphed);
    place(p, v);
    v.flow = flowTangent(p, flow, v.direction);
    return v;
}

// What a vertex's passes need beyond its place: its normal and the air between the eye and it.
struct VertexShading {
    vec3 normal;
    vec3 sunlight;       // the sunlight that reaches the vertex
    vec3 inscatter;      // display value of the radiance the air scatters towards the eye (inscatteredColour)
    vec3 transmittance;  // what the air between the eye and the vertex lets through
};

// Normal from the four neighbours (one parent spacing apart when fully morphed); at the patch edges the neighbour
// outside is the base texture's border point (the neighbouring patch's vertex, same bits), so both sides of a seam
// get the same normal; without `withNormal`, the direction. The atmosphere from atmosphere.glsl.
VertexShading shadeVertex(PatchInstance p, TerrainVertex v, bool withNormal) {
    VertexShading s;
    s.normal = v.direction;
    if (withNormal) {
        vec3 neighbour[4];
        vec2 offsets[4] = vec2[](vec2(1, 0), vec2(-1, 0), vec2(0, 1), vec2(0, -1));
        for (int k = 0; k < 4; ++k) {
            vec2 g = v.morphed + offsets[k] * (1.0 + v.morph);
            neighbour[k] = positionAt(p, heightAt(p, g, v.morph), directionOffset(p, g));
        }
        s.normal = normalize(cross(neighbour[0] - neighbour[1], neighbour[2] - neighbour[3]));
        if (dot(s.normal, v.direction) < 0.0) s.normal = -s.normal;
    }
    s.sunlight = vec3(1.0);
    s.inscatter = vec3(0.0);
    s.transmittance = vec3(1.0);
    if (atmosphereOn()) {
        Scattering air = airTo(v.position, v.surface.x, v.direction, s.sunlight);
        // The phase functions and the tone map per vertex: the angle between the view ray and the sun and the air
        // in front change slowly across a triangle (and the cache computes them once per grid point, not per
        // drawn vertex or per pixel).
        float c = dot(normalize(v.position), normalize(frame.sun.xyz));
        s.inscatter = inscatteredColour(air.rayleigh, air.mie, c);
        s.transmittance = air.transmittance;
    }
    return s;
}

// Beyond the thesis (docs/rendering.md, "The vertex cache"): every grid vertex of every drawn patch, computed once
// a frame by vertex_cache.comp, which lavapipe runs on all its threads, and read by both passes' vertex shaders,
// which it runs on one. Skirts read their grid point's. The normal, the height and the river in f32, the rest in
// f16 pairs.
struct CachedVertex {
    vec4 normalMorph;  // the normal; the morph factor
    vec4 surface;      // height (of the grid point), water height, signed distance, half width
    uvec4 shading;     // flow.xy, flow.z and sunlight.r, sunlight.gb, inscatter.rg
    uvec4 air;         // inscatter.b and transmittance.r, transmittance.gb; the river pair (distances within f16)
};

// The largest distance the cache's f16 river pair holds (FAR_FROM_RIVERS comes back as this).
const float PAIR_LIMIT = 60000.0;

#ifdef VERTEX_CACHE_WRITER
layout(set = 1, binding = 2, std430) writeonly buffer VertexCache { CachedVertex cachedVertices[]; };
#else
layout(set = 1, binding = 2, std430) readonly buffer VertexCache { CachedVertex cachedVertices[]; };
#endif

// The cache index of instance `p` (instance.detail.w), or -1 where its vertices are computed in the vertex shader.
int cacheIndex(PatchInstance p) { return int(p.detail.w); }

#ifdef VERTEX_CACHE_WRITER
void storeVertex(uint index, TerrainVertex v, VertexShading s) {
    CachedVertex c;
    c.normalMorph = vec4(s.normal, v.morph);
    c.surface = v.surface;
    c.shading = uvec4(packHalf2x16(v.flow.xy), packHalf2x16(vec2(v.flow.z, s.sunlight.r)), packHalf2x16(s.sunlight.gb),
                      packHalf2x16(s.inscatter.rg));
    vec4 pair = clamp(v.pair, -PAIR_LIMIT, PAIR_LIMIT);
    c.air = uvec4(packHalf2x16(vec2(s.inscatter.b, s.transmittance.r)), packHalf2x16(s.transmittance.gb),
                  packHalf2x16(pair.xy), packHalf2x16(pair.zw));
    cachedVertices[index] = c;
}
#else
// Mesh vertex `id` of `p` from the cache: its grid point's, placed as terrainVertex places it.
void loadVertex(PatchInstance p, int id, out TerrainVertex v, out VertexShading s) {
    v.grid = vec2(meshGrid(id, v.edge));
    int n = int(frame.planet.y);
    CachedVertex c = cachedVertices[cacheIndex(p) * n * n + int(v.grid.y) * n + int(v.grid.x)];
    v.morph = c.normalMorph.w;
    v.morphed = morphedGrid(v.grid, v.morph);
    v.offset = directionOffset(p, v.morphed);
    v.surface = c.surface;
    v.pair = vec4(unpackHalf2x16(c.air.z), unpackHalf2x16(c.air.w));
    place(p, v);
    vec2 flowZSunR = unpackHalf2x16(c.shading.y);
    vec2 inscatterBTransmittanceR = unpackHalf2x16(c.air.x);
    v.flow = vec3(unpackHalf2x16(c.shading.x), flowZSunR.x);
    s.normal = c.normalMorph.xyz;
    s.sunlight = vec3(flowZSunR.y, unpackHalf2x16(c.shading.z));
    s.inscatter = vec3(unpackHalf2x16(c.shading.w), inscatterBTransmittanceR.x);
    s.transmittance = vec3(inscatterBTransmittanceR.y, unpackHalf2x16(c.air.y));
}

// Mesh vertex `id` of `p` and its shading: from the cache where the patch has an entry, else computed here (the
// thesis's way, Section 8.2), with the normal if `withNormal`.
void meshVertex(PatchInstance p, int id, bool withNormal, out TerrainVertex v, out VertexShading s) {
    if (cacheIndex(p) >= 0) {
        loadVertex(p, id, v, s);
    } else {
        v = terrainVertex(p, id);
        s = shadeVertex(p, v, withNormal);
    }
}
#endif

// Shared by terrain.vert and water.vert (Section 8.2): a patch vertex's base height and river data, blended by
// the lerp factor and morphed towards the parent, placed on the sphere relative to the camera.
#include "terrain_common.glsl"

// Texture coordinates of a grid position in the base-height texture, which has a border of HEIGHT_BORDER points
// (planet::detail::BORDER) on each side.
const float HEIGHT_BORDER = 2.0;
vec3 baseCoord(vec2 t) {
    float n = frame.planet.y;
    return vec3((t + 0.5 + HEIGHT_BORDER) / (n + 2.0 * HEIGHT_BORDER), 0.0);
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
    return textureLod(patchTextures[nonuniformEXT(p.slots.x)], baseCoord(t), 0.0).r;
}

// River data at a grid position (layer 0: terrain height, lerp factor, water height, signed distance; layer 1: the
// half width and the flow in the patch frame), blended by the morph factor into the parent's river data at the
// same place.
vec4 riverAt(PatchInstance p, vec2 grid, float morph, out vec3 widthFlow) {
    float n = frame.planet.y;
    vec3 uv = vec3((p.texRect.xy + grid * p.texRect.z + 0.5) / n, 0.0);
    vec4 river = textureLod(patchTextures[nonuniformEXT(p.slots.y)], uv, 0.0);
    widthFlow = textureLod(patchTextures[nonuniformEXT(p.slots.y)], uv + vec3(0, 0, 1), 0.0).rgb;
    if (morph > 0.0 && p.slots.w >= 0) {
        vec3 parentUv = vec3((p.morph.zw + grid * 0.5 + 0.5) / n, 0.0);
        river = mix(river, textureLod(patchTextures[nonuniformEXT(p.slots.w)], parentUv, 0.0), morph);
        widthFlow = mix(widthFlow,
                        textureLod(patchTextures[nonuniformEXT(p.slots.w)], parentUv + vec3(0, 0, 1), 0.0).rgb, morph);
    }
    return river;
}

// The blended terrain height at a grid position (for normals).
float heightAt(PatchInstance p, vec2 grid, float morph) {
    float base = baseAt(p, grid);
    if (p.slots.y < 0) return base;
    vec3 widthFlow;
    vec4 river = riverAt(p, grid, morph, widthFlow);
    return mix(river.x, base, river.y);
}

// Terrain height, water height, signed distance and half width at a grid position, from the patch's (or its
// stand-in's) textures; `flow`: the water's flow in the patch frame.
vec4 surfaceAt(PatchInstance p, vec2 grid, float morph, out vec2 flow) {
    float base = baseAt(p, grid);
    flow = vec2(0.0);
    if (p.slots.y < 0) return vec4(base, frame.sun.w, 1e9, 0.0);
    vec3 widthFlow;
    vec4 river = riverAt(p, grid, morph, widthFlow);
    flow = widthFlow.yz;
    // Section 8.2: blend the river terrain into the base terrain by the lerp factor.
    float height = mix(river.x, base, river.y);
    return vec4(height, max(river.z, frame.sun.w), river.w, widthFlow.x);
}

// Beyond the thesis (CDLOD, Strugar 2009): how far a vertex has morphed towards its parent's mesh, from its
// distance to the camera: 0 inside the morph band's start, 1 from the patch level's switch distance on.
float morphFactor(PatchInstance p, float distance) {
    return clamp((distance - p.morph.x) * p.morph.y, 0.0, 1.0);
}

// Camera-relative position: the patch centre relative to the camera (f64 on the CPU), plus the small offset of the
// grid position on the sphere, plus the height along the direction.
vec3 positionAt(PatchInstance p, float height, vec3 offset) {
    float radius = frame.planet.x;
    return p.centreRel.xyz + p.centreDir.xyz * height + offset * (radius + height);
}

// One vertex of the patch mesh (gl_VertexIndex of instance gl_InstanceIndex), before normals and atmosphere.
struct TerrainVertex {
    vec3 position;   // camera-relative
    vec3 local;      // from the patch centre (centreRel), small: the ground detail's coordinates build on it
    vec3 direction;  // unit direction from the planet centre
    vec4 surface;    // final height, water height, signed distance, river half width
    vec2 flow;       // the water's flow in the patch frame
    vec2 grid;       // (i, j) within the patch, unmorphed
    vec2 morphed;    // the grid position morphed towards the parent's mesh
    float morph;
    vec3 offset;     // directionOffset at the morphed grid position
    int edge;        // -1 surface, 0-3 edge skirts, 4-5 midline skirts
};

TerrainVertex terrainVertex(PatchInstance p) {
    int n = int(frame.planet.y);
    int id = gl_VertexIndex;
    ivec2 ij;
    TerrainVertex v;
    v.edge = -1;
    if (id < n * n) {
        ij = ivec2(id % n, id / n);
    } else {
        v.edge = (id - n * n) / n;
        int k = (id - n * n) % n;
        int m = (n - 1) / 2;
        ivec2 along[6] = ivec2[](ivec2(k, 0), ivec2(k, n - 1), ivec2(0, k), ivec2(n - 1, k), ivec2(m, k), ivec2(k, m));
        ij = along[v.edge];
    }
    v.grid = vec2(ij);
    // Morph: odd grid coordinates slide towards the even neighbour below, so that fully morphed the mesh is the
    // parent's (whose points keep their heights at every level); the distance is the unmorphed vertex's, from its
    // base height, which neighbouring patches share bit for bit.
    v.morph = morphFactor(p, length(positionAt(p, baseAt(p, v.grid), directionOffset(p, v.grid))));
    v.morphed = v.grid - mod(v.grid, 2.0) * v.morph;
    v.surface = surfaceAt(p, v.morphed, v.morph, v.flow);
    v.offset = directionOffset(p, v.morphed);
    v.direction = normalize(p.centreDir.xyz + v.offset);
    if (v.edge >= 0) v.surface.x -= p.texRect.w;
    float height = v.surface.x;
    v.position = positionAt(p, height, v.offset);
    v.local = p.centreDir.xyz * height + v.offset * (frame.planet.x + height);
    return v;
}

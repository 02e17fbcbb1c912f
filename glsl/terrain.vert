#version 460
// Section 8.2: per vertex, the base height and the river data of the patch, blended by the lerp factor, projected
// onto the sphere; normals from neighbouring heights; skirts below the patch edges close cracks between levels.
#include "terrain_common.glsl"
#include "atmosphere.glsl"

layout(constant_id = 0) const uint WATER_PASS = 0;

// Locations 0-5 and 9 are what the fragment shader reads (directly in the terrain pass, through the geometry
// shader in the water pass); 6-8 are for the geometry shader.
layout(location = 0) out vec3 vPosition;    // camera-relative
layout(location = 1) out vec3 vNormal;
layout(location = 2) out vec4 vRiver;       // final height, water height, signed distance, river half width
layout(location = 3) flat out int vRiverWater;
layout(location = 4) flat out float vLevel;
layout(location = 5) out vec3 vDirection;   // unit direction from the planet centre
layout(location = 6) out vec2 vGrid;        // (i, j) within the patch
layout(location = 7) flat out int vInstance;
layout(location = 8) flat out int vSkirt;   // -1 surface, 0-3 edge skirts, 4-5 midline skirts
layout(location = 9) flat out float vSpacing;
// The atmosphere between the camera and the vertex (atmosphere.glsl); the water pass uses the terrain vertex's (the
// water lies a little higher: the difference does not show).
layout(location = 10) out vec3 vInscatterRayleigh;
layout(location = 11) out vec3 vInscatterMie;
layout(location = 12) out vec3 vTransmittance;
layout(location = 13) out vec3 vSunlight;   // the sunlight that reaches the vertex
layout(location = 14) out vec3 vFlow;       // the river's flow: a tangent, unit length where the samples agree
layout(location = 15) out vec3 vDetail;     // world position modulo DETAIL_PERIOD, precise near the camera

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

void main() {
    PatchInstance p = instances[gl_InstanceIndex];
    int n = int(frame.planet.y);
    int id = gl_VertexIndex;
    bool skirt = id >= n * n;
    ivec2 ij;
    int edge = -1;
    if (!skirt) {
        ij = ivec2(id % n, id / n);
    } else {
        edge = (id - n * n) / n;
        int k = (id - n * n) % n;
        int m = (n - 1) / 2;
        ivec2 along[6] = ivec2[](ivec2(k, 0), ivec2(k, n - 1), ivec2(0, k), ivec2(n - 1, k), ivec2(m, k), ivec2(k, m));
        ij = along[edge];
    }
    vec2 grid = vec2(ij);
    // Morph: odd grid coordinates slide towards the even neighbour below, so that fully morphed the mesh is the
    // parent's (whose points keep their heights at every level); the distance is the unmorphed vertex's, from its
    // base height, which neighbouring patches share bit for bit.
    float morph = morphFactor(p, length(positionAt(p, baseAt(p, grid), directionOffset(p, grid))));
    vec2 morphed = grid - mod(grid, 2.0) * morph;
    vec2 flow;
    vec4 surface = surfaceAt(p, morphed, morph, flow);
    vec3 offset = directionOffset(p, morphed);
    vec3 direction = normalize(p.centreDir.xyz + offset);
    float height = surface.x;
    if (skirt) height -= p.texRect.w;
    vec3 position = positionAt(p, height, offset);

    // Normal from the four neighbours (one parent spacing apart when fully morphed); at the patch edges the
    // neighbour outside is the base texture's border point (the neighbouring patch's vertex, same bits), so both
    // sides of a seam get the same normal. The water pass needs none: water is level.
    vec3 normal = direction;
    if (WATER_PASS == 0) {
        vec3 neighbour[4];
        vec2 offsets[4] = vec2[](vec2(1, 0), vec2(-1, 0), vec2(0, 1), vec2(0, -1));
        for (int k = 0; k < 4; ++k) {
            vec2 g = morphed + offsets[k] * (1.0 + morph);
            neighbour[k] = positionAt(p, heightAt(p, g, morph), directionOffset(p, g));
        }
        normal = normalize(cross(neighbour[0] - neighbour[1], neighbour[2] - neighbour[3]));
        if (dot(normal, direction) < 0.0) normal = -normal;
    }

    if (WATER_PASS == 0 && frame.extra.w > 0.5) {
        captured[gl_InstanceIndex * (n * n + 6 * n) + gl_VertexIndex] = vec4(position, 1.0 + morph);
    }

    vPosition = position;
    // The patch centre's world position (mod the period, from f64) plus the vertex's small offset from it.
    vDetail = p.detail.xyz + p.centreDir.xyz * height + offset * (frame.planet.x + height);
    vNormal = normal;
    vDirection = direction;
    vRiver = vec4(height, surface.y, surface.z, surface.w);
    vGrid = grid;
    vInstance = gl_InstanceIndex;
    vSkirt = edge;
    vRiverWater = 0;
    vLevel = p.centreRel.w;
    vSpacing = p.centreDir.w;
    // The patch frame's axes are the face's u and v (the grid's i and j), taken into the tangent plane.
    vec3 tangentU = normalize(p.axisU.xyz - direction * dot(p.axisU.xyz, direction));
    vec3 tangentV = normalize(p.axisV.xyz - direction * dot(p.axisV.xyz, direction));
    vFlow = flow.x * tangentU + flow.y * tangentV;
    vInscatterRayleigh = vec3(0.0);
    vInscatterMie = vec3(0.0);
    vTransmittance = vec3(1.0);
    vSunlight = vec3(1.0);
    if (atmosphereOn()) {
        Scattering s = airTo(position, height, direction, vSunlight);
        vInscatterRayleigh = s.rayleigh;
        vInscatterMie = s.mie;
        vTransmittance = s.transmittance;
    }
    gl_Position = frame.viewProjection * vec4(position, 1.0);
}

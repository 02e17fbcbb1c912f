#version 460
// Section 8.2: per vertex, the base height and the river data of the patch, blended by the lerp factor, projected
// onto the sphere; normals from neighbouring heights; skirts below the patch edges close cracks between levels.
#include "terrain_common.glsl"

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

// The blended terrain height at a grid position (for normals: two texture reads).
float heightAt(PatchInstance p, vec2 grid) {
    float n = frame.planet.y;
    vec2 t = p.texRect.xy + grid * p.texRect.z;
    float base = textureLod(patchTextures[nonuniformEXT(p.slots.x)], baseCoord(t), 0.0).r;
    if (p.slots.y < 0) return base;
    vec2 river = textureLod(patchTextures[nonuniformEXT(p.slots.y)], vec3((t + 0.5) / n, 0.0), 0.0).xy;
    return mix(river.x, base, river.y);
}

// River data and base height at a grid position, read from the patch's (or its stand-in's) textures.
vec4 surfaceAt(PatchInstance p, vec2 grid, out float baseHeight) {
    float n = frame.planet.y;
    vec2 t = p.texRect.xy + grid * p.texRect.z;
    baseHeight = textureLod(patchTextures[nonuniformEXT(p.slots.x)], baseCoord(t), 0.0).r;
    if (p.slots.y < 0) return vec4(baseHeight, frame.sun.w, 1e9, 0.0);
    vec2 uv = (t + 0.5) / n;
    vec4 river = textureLod(patchTextures[nonuniformEXT(p.slots.y)], vec3(uv, 0.0), 0.0);
    float halfWidth = textureLod(patchTextures[nonuniformEXT(p.slots.y)], vec3(uv, 1.0), 0.0).r;
    // Section 8.2: blend the river terrain into the base terrain by the lerp factor.
    float height = mix(river.x, baseHeight, river.y);
    return vec4(height, max(river.z, frame.sun.w), river.w, halfWidth);
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
    float base;
    vec4 surface = surfaceAt(p, grid, base);
    vec3 offset = directionOffset(p, grid);
    vec3 direction = normalize(p.centreDir.xyz + offset);
    float height = surface.x;
    if (skirt) height -= frame.extra.x * p.centreDir.w;
    vec3 position = positionAt(p, height, offset);

    // Normal from the four neighbours (clamped to the patch; the base texture's border keeps edges smooth). The
    // water pass needs none: water is level.
    vec3 normal = direction;
    if (WATER_PASS == 0) {
        vec3 neighbour[4];
        vec2 offsets[4] = vec2[](vec2(1, 0), vec2(-1, 0), vec2(0, 1), vec2(0, -1));
        for (int k = 0; k < 4; ++k) {
            vec2 g = clamp(grid + offsets[k], vec2(0.0), vec2(n - 1));
            neighbour[k] = positionAt(p, heightAt(p, g), directionOffset(p, g));
        }
        normal = normalize(cross(neighbour[0] - neighbour[1], neighbour[2] - neighbour[3]));
        if (dot(normal, direction) < 0.0) normal = -normal;
    }

    vPosition = position;
    vNormal = normal;
    vDirection = direction;
    vRiver = vec4(height, surface.y, surface.z, surface.w);
    vGrid = grid;
    vInstance = gl_InstanceIndex;
    vSkirt = edge;
    vRiverWater = 0;
    vLevel = p.centreRel.w;
    vSpacing = p.centreDir.w;
    gl_Position = frame.viewProjection * vec4(position, 1.0);
}

// Shared by terrain.vert, terrain.geom and terrain.frag (Chapter 8): per-frame push constants, the per-patch
// instance table, and the bindless patch textures.
#extension GL_EXT_nonuniform_qualifier : require

layout(push_constant) uniform FramePush {
    // Camera-relative world -> clip (the camera sits at the origin; see docs/rendering.md).
    mat4 viewProjection;
    // xyz: unit direction towards the sun; w: sea level.
    vec4 sun;
    // x: radius; y: vertices per patch edge; z: water mode (0 auto, 1 geometry, 2 painted) + 4 x view (0 shaded,
    // 1 level-of-detail colours, 2 painted rivers shown red) + 16 if the water is still + 32 if the water is part
    // of the terrain mesh + 64 x (the lake map's slot + 1, 0 without lakes; below 2^14) + 2^20 x log2 of the lake
    // map's cells per face edge; w: the lowest height any terrain can have.
    vec4 planet;
    // x: the atmosphere's transmittance table slot, or -1 without atmosphere; y: time in seconds (the water's
    // flow); z: height unit of the colour bands (max-mountain-height / 16, so that Appendix A's planet, whose
    // mountains are 16 high, is coloured as before); w: 1 to capture vertices.
    vec4 extra;
    // xyz: the camera from the planet's centre; w: atmosphere-height.
    vec4 camera;
} frame;

uint waterMode() { return uint(frame.planet.z) & 3u; }
uint viewMode() { return (uint(frame.planet.z) >> 2) & 3u; }
bool stillWater() { return (uint(frame.planet.z) & 16u) != 0u; }
// Beyond the thesis (docs/rendering.md, "Water in the terrain mesh"): the terrain pass draws the water, its
// vertices under water raised to the water's surface; no water pass.
bool waterInMesh() { return (uint(frame.planet.z) & 32u) != 0u; }
// Beyond the thesis (docs/rendering.md, "Lakes from afar"): the slot of the lakes' depth map, or -1.
int lakeMapSlot() { return int((uint(frame.planet.z) >> 6) & 0x3fffu) - 1; }
float lakeMapCells() { return float(1u << (uint(frame.planet.z) >> 20)); }

const uint WATER_AUTO = 0;
const uint WATER_GEOMETRY = 1;
const uint WATER_PAINTED = 2;

// One drawn patch (or the part of an ancestor standing in for a patch whose data has not arrived). Positions are
// built relative to the camera from f64 values the CPU computed per patch, so precision does not depend on the
// planet's size or the patch's depth (docs/rendering.md, "Precision").
struct PatchInstance {
    vec4 centreRel;   // xyz: radius * centre direction - camera (computed in f64); w: level
    vec4 centreDir;   // xyz: unit centre direction; w: world distance between neighbouring vertices
    vec4 cubeCentre;  // xyz: the patch centre on the cube; w: its length
    vec4 axisU;       // xyz: cube-space step across the whole patch along i; w: 2 cubeCentre . axisU
    vec4 axisV;       // xyz: the same along j; w: 2 cubeCentre . axisV
    vec4 texRect;     // xy: source texel of vertex (0, 0); z: source texels per vertex; w: skirt length
    ivec4 slots;      // places (slot_layers.glsl) x: base heights; y: river data or -1; z: drawn quadrants (not a
                      // place); w: the parent's river data or -1
    vec4 morph;       // x: share of the switch distance where morphing towards the parent starts; y: 1 / the
                      // morph band's share; zw: the patch's vertex (0, 0) in its parent's river texture
    vec4 switchDistances; // at the corners (0, 0), (n-1, 0), (0, n-1), (n-1, n-1); bilinear between them
    vec4 detail;      // xyz: the patch centre's world position modulo 65536 (computed in f64; render/frame/shader_data.rs)
};

// Beyond the thesis: a vertex a lake reaches reports a half width of 1e9 (docs/kernel.md, "Lakes"), so a triangle
// with one has an interpolated half width far above any river's.
const float LAKE_HALF_WIDTH_FLOOR = 1e6;
// The signed distance of a point no river reaches.
const float FAR_FROM_RIVERS = 1e9;

// Whether a vertex of `surface` (terrain height, water height, signed distance, half width) lies in a river's
// basin: |signed distance| < half width (Section 8.4; false where no river reaches, half width 0).
bool inRiverBasin(vec4 surface) { return abs(surface.z) < surface.w; }

// smoothstep with the division by the band's width written as a product, so that constant edges fold to one
// constant factor (lavapipe runs a division per lane, several times slower than a product); the same curve.
float smoothBand(float e0, float e1, float x) {
    float t = clamp((x - e0) * (1.0 / (e1 - e0)), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// The ground detail's lattices repeat every 256 units, which divides the period of its coordinates (fDetail,
// render/frame/shader_data.rs, DETAIL_PERIOD).
const float GROUND_DETAIL_PERIOD = 256.0;

layout(set = 1, binding = 0, std430) readonly buffer Instances { PatchInstance instances[]; };
// Where the terrain pass puts every vertex when frame.extra.w is 1 (tests): per instance and mesh vertex, the
// camera-relative position and 1 + morph factor.
layout(set = 1, binding = 1, std430) writeonly buffer Captured { vec4 captured[]; };

// Every patch texture is layers of a 2D array image (slot_layers.glsl): base heights (1 layer, with a border of two
// texels), river data (3 layers).
#include "slot_layers.glsl"
layout(set = 0, binding = 1) uniform sampler2DArray patchTextures[];

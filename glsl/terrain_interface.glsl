// What terrain.frag reads, written by terrain.vert (terrain pass) and terrain.geom (water pass), packed into nine
// vec4 slots: lavapipe's draw module and triangle setup work per slot, per vertex and per triangle, on one thread
// (docs/rendering.md, "The patch mesh and the shaders"). Writers define TERRAIN_WRITER before including it.

#include "noise.glsl"

// Beyond the thesis: 1 where <terrain-colours> is `climate` (docs/rendering.md, "Climate"), 0 for Fig. 8.2's
// height bands (every stage of the terrain's pipelines gets the same specialization constants).
layout(constant_id = 2) const uint CLIMATE = 0;

#ifdef TERRAIN_WRITER
#define TERRAIN_IO out
#else
#define TERRAIN_IO in
#endif

layout(location = 0) TERRAIN_IO vec4 ioPositionFlowX;   // camera-relative position; the flow's x
layout(location = 1) TERRAIN_IO vec4 ioNormalFlowY;     // the surface normal; the flow's y
layout(location = 2) TERRAIN_IO vec4 ioRiver;           // final height, water height, signed distance, half width
layout(location = 3) TERRAIN_IO vec4 ioDirectionFlowZ;  // unit direction from the planet centre; the flow's z
layout(location = 4) TERRAIN_IO vec4 ioDetailSunR;      // world position mod DETAIL_PERIOD; the sunlight's red
layout(location = 5) TERRAIN_IO vec4 ioInscatterSunG;   // the air's inscattered light (display value); sunlight green
layout(location = 6) TERRAIN_IO vec4 ioTransmittanceSunB; // the air's transmittance from the eye; sunlight blue
// The water pass: river water (1) or not (0); the terrain pass: the distance to the banks of the river the vertex
// measured (`bank`). Twice the level plus whether the vertex lies in a river basin (1) or not (0): the level is the
// same at a triangle's three vertices, so the interpolated sum splits again. The vertex spacing (the same at a
// triangle's three vertices, so interpolated, not flat, to share the slot). The climate's moisture (0.5 without
// CLIMATE).
layout(location = 7) TERRAIN_IO vec4 ioKindLevelBasinSpacingMoisture;
// Beyond the thesis: the two nearest rivers in their order, signed distance and half width each (riverPairAt in
// terrain_vertex.glsl); the terrain pass paints their union where a triangle's vertices agree on them.
layout(location = 8) TERRAIN_IO vec4 ioRiverPair;

// One vertex of what terrain.frag reads.
struct SurfaceVertex {
    vec3 position;
    vec3 normal;
    vec4 river;
    vec3 direction;
    vec3 detail;
    vec3 flow;            // the river's flow: a tangent, unit length where the samples agree
    vec3 sunlight;        // the sunlight that reaches the vertex
    vec3 inscatter;       // display value of the radiance the air scatters towards the eye
    vec3 transmittance;   // what the air between the eye and the vertex lets through
    bool riverWater;      // the water pass only
    float bank;           // the terrain pass only: |signed distance| - half width (negative in the river)
    vec4 pair;            // the terrain pass only: the two nearest rivers in their order
    float level;
    float spacing;
    bool inBasin;         // |signed distance| < half width
};

#ifdef TERRAIN_WRITER
void writeSurface(SurfaceVertex v) {
    ioPositionFlowX = vec4(v.position, v.flow.x);
    ioNormalFlowY = vec4(v.normal, v.flow.y);
    ioRiver = v.river;
    ioDirectionFlowZ = vec4(v.direction, v.flow.z);
    ioDetailSunR = vec4(v.detail, v.sunlight.r);
    ioInscatterSunG = vec4(v.inscatter, v.sunlight.g);
    ioTransmittanceSunB = vec4(v.transmittance, v.sunlight.b);
    ioKindLevelBasinSpacingMoisture = vec4(v.riverWater ? 1.0 : v.bank, 2.0 * v.level + (v.inBasin ? 1.0 : 0.0),
                                           v.spacing, CLIMATE == 1u ? moistureAt(v.direction) : 0.5);
    ioRiverPair = v.pair;
}
#else
#define fPosition ioPositionFlowX.xyz
#define fNormal ioNormalFlowY.xyz
#define fRiver ioRiver
#define fDirection ioDirectionFlowZ.xyz
#define fDetail ioDetailSunR.xyz
#define fFlow vec3(ioPositionFlowX.w, ioNormalFlowY.w, ioDirectionFlowZ.w)
#define fSunlight vec3(ioDetailSunR.w, ioInscatterSunG.w, ioTransmittanceSunB.w)
#define fInscatter ioInscatterSunG.xyz
#define fTransmittance ioTransmittanceSunB.xyz
#define fRiverWater ioKindLevelBasinSpacingMoisture.x
#define fBank ioKindLevelBasinSpacingMoisture.x
// The interpolation may miss the level's exact double by a few ulps either way.
#define fLevel floor(ioKindLevelBasinSpacingMoisture.y * 0.5 + 0.25)
#define fSpacing ioKindLevelBasinSpacingMoisture.z
#define fMoisture ioKindLevelBasinSpacingMoisture.w
// Above 0 where any vertex of the triangle lies in a river basin (the water pass's choice of river triangles), less
// a thousandth for the level's rounding (at level 24 a few millionths).
#define fNearBasin (ioKindLevelBasinSpacingMoisture.y - 2.0 * fLevel - 1e-3)
#define fRiverPair ioRiverPair
#endif

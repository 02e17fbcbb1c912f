#version 460
// Section 8.4: a real geometry shader that spawns water. For every terrain triangle of a drawn quadrant it emits
// a water triangle at the computed water heights when any vertex lies in a river basin (|signed distance| < half
// width) or below sea level. River water the mesh is too coarse for is left to the fragment shader to paint.
// (The terrain itself is drawn without a geometry shader, per quadrant: docs/rendering.md says why.)
#include "terrain_common.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

layout(location = 0) in vec3 vPosition[];
layout(location = 1) in vec3 vNormal[];
layout(location = 2) in vec4 vRiver[];
layout(location = 5) in vec3 vDirection[];
layout(location = 6) in vec2 vGrid[];
layout(location = 7) flat in int vInstance[];
layout(location = 8) flat in int vSkirt[];
layout(location = 10) in vec3 vInscatterRayleigh[];
layout(location = 11) in vec3 vInscatterMie[];
layout(location = 12) in vec3 vTransmittance[];
layout(location = 13) in vec3 vSunlight[];
layout(location = 14) in vec3 vFlow[];
layout(location = 15) in vec3 vDetail[];

layout(location = 0) out vec3 fPosition;
layout(location = 1) out vec3 fNormal;
layout(location = 2) out vec4 fRiver;
layout(location = 3) flat out int fRiverWater;
layout(location = 4) flat out float fLevel;
layout(location = 5) out vec3 fDirection;
layout(location = 9) flat out float fSpacing;
layout(location = 10) out vec3 fInscatterRayleigh;
layout(location = 11) out vec3 fInscatterMie;
layout(location = 12) out vec3 fTransmittance;
layout(location = 13) out vec3 fSunlight;
layout(location = 14) out vec3 fFlow;
layout(location = 15) out vec3 fDetail;

void main() {
    if (vSkirt[0] >= 0 || vSkirt[1] >= 0 || vSkirt[2] >= 0) return;
    PatchInstance p = instances[vInstance[0]];
    float middle = 0.5 * (frame.planet.y - 1.0);
    vec2 middleOfTriangle = (vGrid[0] + vGrid[1] + vGrid[2]) / 3.0;
    int quadrant = int(middleOfTriangle.x >= middle) | (int(middleOfTriangle.y >= middle) << 1);
    if ((p.slots.z & (1 << quadrant)) == 0) return;

    float spacing = p.centreDir.w;
    float seaLevel = frame.sun.w;
    uint mode = waterMode();
    bool inBasin = false;
    bool belowSea = false;
    float widest = 0.0;
    for (int k = 0; k < 3; ++k) {
        inBasin = inBasin || abs(vRiver[k].z) < vRiver[k].w;
        belowSea = belowSea || vRiver[k].x < seaLevel;
        widest = max(widest, vRiver[k].w);
    }
    // The thesis's rule: the mesh shows a river only if its vertices are closer than half the river's width.
    bool paint = mode == WATER_PAINTED || (mode == WATER_AUTO && spacing >= widest);
    bool riverWater = inBasin && !paint;
    if (!riverWater && !belowSea) return;
    for (int k = 0; k < 3; ++k) {
        float water = riverWater ? vRiver[k].y : seaLevel;
        // Up from the terrain vertex to the water (a small difference: precise at any planet size).
        vec3 position = vPosition[k] + vDirection[k] * (water - vRiver[k].x);
        fPosition = position;
        fNormal = vDirection[k];
        fRiver = vec4(vRiver[k].x, water, vRiver[k].z, vRiver[k].w);
        // River water (not sea) is clipped to the basin in the fragment shader.
        fRiverWater = riverWater && !belowSea ? 1 : 0;
        fLevel = p.centreRel.w;
        fDirection = vDirection[k];
        fSpacing = spacing;
        fInscatterRayleigh = vInscatterRayleigh[k];
        fInscatterMie = vInscatterMie[k];
        fTransmittance = vTransmittance[k];
        fSunlight = vSunlight[k];
        fFlow = vFlow[k];
        fDetail = vDetail[k];
        gl_Position = frame.viewProjection * vec4(position, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}

#version 460
// Section 8.4: a real geometry shader that spawns water. For every terrain triangle of a drawn quadrant it emits
// a water triangle at the computed water heights when any vertex lies in a river basin (|signed distance| < half
// width) or below sea level. River water the mesh is too coarse for is left to the fragment shader to paint.
// (The terrain itself is drawn without a geometry shader, per quadrant: docs/rendering.md says why.)
#include "terrain_common.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

// water.vert's packed outputs.
layout(location = 0) in vec4 vLocalInstance[];
layout(location = 1) in vec4 vRiver[];
layout(location = 2) in vec4 vDirectionEdge[];
layout(location = 3) in vec4 vGridFlow[];
layout(location = 4) in vec4 vRayleighSunR[];
layout(location = 5) in vec4 vMieSunG[];
layout(location = 6) in vec4 vTransmittanceSunB[];

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
    if (vDirectionEdge[0].w >= 0.0 || vDirectionEdge[1].w >= 0.0 || vDirectionEdge[2].w >= 0.0) return;
    PatchInstance p = instances[int(vLocalInstance[0].w)];
    float middle = 0.5 * (frame.planet.y - 1.0);
    vec2 middleOfTriangle = (vGridFlow[0].xy + vGridFlow[1].xy + vGridFlow[2].xy) / 3.0;
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
        vec3 direction = vDirectionEdge[k].xyz;
        // Up from the terrain vertex to the water (a small difference: precise at any planet size).
        vec3 local = vLocalInstance[k].xyz + direction * (water - vRiver[k].x);
        vec3 position = p.centreRel.xyz + local;
        fPosition = position;
        fNormal = direction;
        fRiver = vec4(vRiver[k].x, water, vRiver[k].z, vRiver[k].w);
        // River water (not sea) is clipped to the basin in the fragment shader.
        fRiverWater = riverWater && !belowSea ? 1 : 0;
        fLevel = p.centreRel.w;
        fDirection = direction;
        fSpacing = spacing;
        fInscatterRayleigh = vRayleighSunR[k].xyz;
        fInscatterMie = vMieSunG[k].xyz;
        fTransmittance = vTransmittanceSunB[k].xyz;
        fSunlight = vec3(vRayleighSunR[k].w, vMieSunG[k].w, vTransmittanceSunB[k].w);
        fFlow = flowTangent(p, vGridFlow[k].zw, direction);
        fDetail = p.detail.xyz + local;
        gl_Position = frame.viewProjection * vec4(position, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}

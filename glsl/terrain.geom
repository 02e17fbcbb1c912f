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
layout(location = 3) in vec4 vGridFlowXY[];
layout(location = 4) in vec4 vInscatterSunR[];
layout(location = 5) in vec4 vTransmittanceSunG[];
layout(location = 6) in vec2 vSunBFlowZ[];

#define TERRAIN_WRITER
#include "terrain_interface.glsl"

void main() {
    if (vDirectionEdge[0].w >= 0.0 || vDirectionEdge[1].w >= 0.0 || vDirectionEdge[2].w >= 0.0) return;
    PatchInstance p = instances[int(vLocalInstance[0].w)];
    float middle = 0.5 * (frame.planet.y - 1.0);
    vec2 middleOfTriangle = (vGridFlowXY[0].xy + vGridFlowXY[1].xy + vGridFlowXY[2].xy) / 3.0;
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
        SurfaceVertex s;
        s.position = position;
        s.normal = direction;
        s.river = vec4(vRiver[k].x, water, vRiver[k].z, vRiver[k].w);
        s.direction = direction;
        s.detail = p.detail.xyz + local;
        s.flow = vec3(vGridFlowXY[k].zw, vSunBFlowZ[k].y);
        s.sunlight = vec3(vInscatterSunR[k].w, vTransmittanceSunG[k].w, vSunBFlowZ[k].x);
        s.inscatter = vInscatterSunR[k].xyz;
        s.transmittance = vTransmittanceSunG[k].xyz;
        // River water (not sea) is clipped to the basin in the fragment shader.
        s.riverWater = riverWater && !belowSea;
        s.level = p.centreRel.w;
        s.spacing = spacing;
        writeSurface(s);
        gl_Position = frame.viewProjection * vec4(position, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}

#version 460
// Section 8.4: a real geometry shader that spawns water. For every terrain triangle of a drawn quadrant it emits
// a water triangle at the computed water heights when any vertex lies in a river basin (|signed distance| < half
// width) or below sea level (water.glsl). River water the mesh is too coarse for is left to the fragment shader to
// paint. Beyond the thesis, patches in the vertex cache skip it (water_triangles.comp).
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
#include "water.glsl"

void main() {
    if (vDirectionEdge[0].w >= 0.0 || vDirectionEdge[1].w >= 0.0 || vDirectionEdge[2].w >= 0.0) return;
    PatchInstance p = instances[int(vLocalInstance[0].w)];
    float middle = 0.5 * (frame.planet.y - 1.0);
    vec2 middleOfTriangle = (vGridFlowXY[0].xy + vGridFlowXY[1].xy + vGridFlowXY[2].xy) / 3.0;
    int quadrant = int(middleOfTriangle.x >= middle) | (int(middleOfTriangle.y >= middle) << 1);
    if ((p.slots.z & (1 << quadrant)) == 0) return;

    uint kind = waterKind(vRiver[0], vRiver[1], vRiver[2], p.centreDir.w);
    if (kind == WATER_NONE) return;
    for (int k = 0; k < 3; ++k) {
        SurfaceVertex s = waterVertex(p, kind, vLocalInstance[k].xyz, vRiver[k], vDirectionEdge[k].xyz);
        s.flow = vec3(vGridFlowXY[k].zw, vSunBFlowZ[k].y);
        s.sunlight = vec3(vInscatterSunR[k].w, vTransmittanceSunG[k].w, vSunBFlowZ[k].x);
        s.inscatter = vInscatterSunR[k].xyz;
        s.transmittance = vTransmittanceSunG[k].xyz;
        writeSurface(s);
        gl_Position = frame.viewProjection * vec4(s.position, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}

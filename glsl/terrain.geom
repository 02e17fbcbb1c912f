#version 460
// Section 8.4: a real geometry shader. The terrain pass passes the terrain triangles of the drawn quadrants
// through and decides whether a river there must be painted (mesh too coarse for its width). The water pass emits
// a water triangle at the computed water heights where any vertex lies in a river basin or below sea level.
#include "terrain_common.glsl"

layout(constant_id = 0) const uint WATER_PASS = 0;

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

layout(location = 0) in vec3 vPosition[];
layout(location = 1) in vec3 vNormal[];
layout(location = 2) in vec3 vDirection[];
layout(location = 3) in vec4 vRiver[];
layout(location = 4) in vec2 vGrid[];
layout(location = 5) flat in int vInstance[];
layout(location = 6) flat in int vSkirt[];

layout(location = 0) out vec3 fPosition;
layout(location = 1) out vec3 fNormal;
layout(location = 2) out vec4 fRiver;
layout(location = 3) flat out int fPaint;
layout(location = 4) flat out float fLevel;
layout(location = 5) out vec3 fDirection;

void main() {
    PatchInstance p = instances[vInstance[0]];
    float middle = 0.5 * (frame.planet.y - 1.0);
    vec2 middleOfTriangle = (vGrid[0] + vGrid[1] + vGrid[2]) / 3.0;
    int quadrant = int(middleOfTriangle.x >= middle) | (int(middleOfTriangle.y >= middle) << 1);
    int skirt = max(max(vSkirt[0], vSkirt[1]), vSkirt[2]);
    if (skirt >= 4) {
        // A midline skirt: drawn beside a drawn quadrant that borders an undrawn one (where a finer patch is).
        // The midline lies on the boundary, so the two quadrants beside it differ in bit 0 (vertical midline) or
        // bit 1 (horizontal midline).
        int bit = skirt == 4 ? 1 : 2;
        bool a = (p.slots.z & (1 << (quadrant | bit))) != 0;
        bool b = (p.slots.z & (1 << (quadrant & ~bit))) != 0;
        if (a == b || WATER_PASS == 1) return;
    } else if ((p.slots.z & (1 << quadrant)) == 0) {
        return;
    }

    float spacing = p.centreDir.w;
    float seaLevel = frame.sun.w;
    uint mode = uint(frame.planet.z);
    bool inBasin = false;
    bool belowSea = false;
    float widest = 0.0;
    for (int k = 0; k < 3; ++k) {
        inBasin = inBasin || abs(vRiver[k].z) < vRiver[k].w;
        belowSea = belowSea || vRiver[k].x < seaLevel;
        widest = max(widest, vRiver[k].w);
    }
    // The thesis's rule: the mesh shows a river only if its vertices are closer than half the river's width.
    bool coarse = spacing >= widest;
    bool paint = mode == WATER_PAINTED || (mode == WATER_AUTO && coarse);

    if (WATER_PASS == 0) {
        for (int k = 0; k < 3; ++k) {
            fPosition = vPosition[k];
            fNormal = vNormal[k];
            fRiver = vRiver[k];
            fPaint = paint ? 1 : 0;
            fLevel = p.centreRel.w;
            fDirection = vDirection[k];
            gl_Position = gl_in[k].gl_Position;
            EmitVertex();
        }
        EndPrimitive();
        return;
    }

    bool riverWater = inBasin && !paint;
    if (!riverWater && !belowSea) return;
    float radius = frame.planet.x;
    for (int k = 0; k < 3; ++k) {
        float water = riverWater ? vRiver[k].y : seaLevel;
        vec3 position = p.centreRel.xyz + (vDirection[k] - p.centreDir.xyz) * radius + vDirection[k] * water;
        fPosition = position;
        fNormal = vDirection[k];
        fRiver = vec4(vRiver[k].x, water, vRiver[k].z, vRiver[k].w);
        // River water (not sea) is clipped to the basin in the fragment shader.
        fPaint = riverWater && !belowSea ? 1 : 0;
        fLevel = p.centreRel.w;
        fDirection = vDirection[k];
        gl_Position = frame.viewProjection * vec4(position, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}

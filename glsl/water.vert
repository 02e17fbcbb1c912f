#version 460
// Section 8.4: the water pass's vertex, handed to the geometry shader (terrain.geom) that spawns the water
// triangles. Packed into few vec4s: Mesa's draw module looks up every geometry-shader input of every vertex of every
// triangle by a linear search over the vertex outputs, which made the unpacked interface the largest cost of the
// frame on lavapipe (docs/rendering.md, "The patch mesh and the shaders").
#include "terrain_vertex.glsl"

layout(location = 0) out vec4 vLocalInstance;    // xyz: TerrainVertex.local; w: the instance
layout(location = 1) out vec4 vRiver;            // final height, water height, signed distance, river half width
layout(location = 2) out vec4 vDirectionEdge;    // xyz: unit direction from the planet centre; w: TerrainVertex.edge
layout(location = 3) out vec4 vGridFlowXY;       // xy: (i, j) within the patch; zw: the flow's x and y
// The atmosphere between the camera and the terrain vertex (the water lies a little higher: the difference does
// not show), as in terrain.vert: in-scattered light and transmittance, with the sunlight and the flow's z.
layout(location = 4) out vec4 vInscatterSunR;
layout(location = 5) out vec4 vTransmittanceSunG;
layout(location = 6) out vec2 vSunBFlowZ;

void main() {
    PatchInstance p = instances[gl_InstanceIndex];
    TerrainVertex v;
    VertexShading s;
    meshVertex(p, gl_VertexIndex, false, v, s);
    vLocalInstance = vec4(v.local, float(gl_InstanceIndex));
    vRiver = v.surface;
    vDirectionEdge = vec4(v.direction, float(v.edge));
    vGridFlowXY = vec4(v.grid, v.flow.xy);
    vInscatterSunR = vec4(s.inscatter, s.sunlight.r);
    vTransmittanceSunG = vec4(s.transmittance, s.sunlight.g);
    vSunBFlowZ = vec2(s.sunlight.b, v.flow.z);
    gl_Position = frame.viewProjection * vec4(v.position, 1.0);
}

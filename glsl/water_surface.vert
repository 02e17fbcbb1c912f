#version 460
// Beyond the thesis (docs/rendering.md, "Water without the geometry shader"): the water pass's vertex for patches
// in the vertex cache. The index is a mesh vertex and the water kind that water_triangles.comp chose for its
// triangle (mesh vertex << 2 | kind); the vertex is placed as the geometry shader places it (water.glsl).
#include "terrain_vertex.glsl"

#define TERRAIN_WRITER
#include "terrain_interface.glsl"
#include "water.glsl"

void main() {
    PatchInstance p = instances[gl_InstanceIndex];
    TerrainVertex v;
    VertexShading shading;
    loadVertex(p, gl_VertexIndex >> 2, v, shading);
    SurfaceVertex s = waterVertex(p, uint(gl_VertexIndex) & 3u, v.local, v.surface, v.direction);
    s.flow = v.flow;
    s.sunlight = shading.sunlight;
    s.inscatter = shading.inscatter;
    s.transmittance = shading.transmittance;
    writeSurface(s);
    gl_Position = frame.viewProjection * vec4(s.position, 1.0);
}

#version 460
// Section 8.2: the terrain pass's vertex: the base height and the river data of the patch, blended by the lerp
// factor, projected onto the sphere, with its normal from neighbouring heights and the air in front of it
// (terrain_vertex.glsl: from the vertex cache, or computed here); skirts below the patch edges close cracks between
// levels. The water pass has its own (water.vert).
#include "terrain_vertex.glsl"

#define TERRAIN_WRITER
#include "terrain_interface.glsl"

void main() {
    PatchInstance p = instances[gl_InstanceIndex];
    TerrainVertex v;
    VertexShading shading;
    meshVertex(p, gl_VertexIndex, true, v, shading);

    if (frame.extra.w > 0.5) {
        int n = int(frame.planet.y);
        captured[gl_InstanceIndex * (n * n + 6 * n) + gl_VertexIndex] = vec4(v.position, 1.0 + v.morph);
    }

    SurfaceVertex s;
    s.position = v.position;
    s.normal = shading.normal;
    s.river = v.surface;
    // A vertex no river sample reaches (half width 0) holds the influence distance, whatever side it lies on; for
    // painting it is far from every river (as a patch without rivers, terrain_vertex.glsl), so that a triangle
    // reaching it paints no river between its vertices (terrain.frag, distanceSlope).
    if (v.surface.w == 0.0) s.river.z = FAR_FROM_RIVERS;
    s.inBasin = inRiverBasin(v.surface);
    s.pair = v.pair;
    // How far the vertex lies from the banks of the river it measured (negative inside; with no river, the
    // influence distance: at least that far from any), for painting where a triangle's vertices measured different
    // rivers (terrain.frag). A lake's vertex counts as one spacing outside: lakes are drawn from their own data.
    s.bank = v.surface.w > LAKE_HALF_WIDTH_FLOOR ? p.centreDir.w : abs(v.surface.z) - v.surface.w;
    s.direction = v.direction;
    // The patch centre's world position (mod the period, from f64) plus the vertex's small offset from it.
    s.detail = p.detail.xyz + v.local;
    s.flow = v.flow;
    s.sunlight = shading.sunlight;
    s.inscatter = shading.inscatter;
    s.transmittance = shading.transmittance;
    s.riverWater = false;
    s.level = p.centreRel.w;
    s.spacing = p.centreDir.w;
    writeSurface(s);
    gl_Position = frame.viewProjection * vec4(v.position, 1.0);
}

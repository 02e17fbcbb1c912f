#version 460
// Section 8.2: the terrain pass's vertex: per vertex, the base height and the river data of the patch, blended by
// the lerp factor, projected onto the sphere (terrain_vertex.glsl); normals from neighbouring heights; skirts below
// the patch edges close cracks between levels. The water pass has its own (water.vert).
#include "terrain_vertex.glsl"
#include "atmosphere.glsl"

#define TERRAIN_WRITER
#include "terrain_interface.glsl"

void main() {
    PatchInstance p = instances[gl_InstanceIndex];
    TerrainVertex v = terrainVertex(p);

    // Normal from the four neighbours (one parent spacing apart when fully morphed); at the patch edges the
    // neighbour outside is the base texture's border point (the neighbouring patch's vertex, same bits), so both
    // sides of a seam get the same normal.
    vec3 neighbour[4];
    vec2 offsets[4] = vec2[](vec2(1, 0), vec2(-1, 0), vec2(0, 1), vec2(0, -1));
    for (int k = 0; k < 4; ++k) {
        vec2 g = v.morphed + offsets[k] * (1.0 + v.morph);
        neighbour[k] = positionAt(p, heightAt(p, g, v.morph), directionOffset(p, g));
    }
    vec3 normal = normalize(cross(neighbour[0] - neighbour[1], neighbour[2] - neighbour[3]));
    if (dot(normal, v.direction) < 0.0) normal = -normal;

    if (frame.extra.w > 0.5) {
        int n = int(frame.planet.y);
        captured[gl_InstanceIndex * (n * n + 6 * n) + gl_VertexIndex] = vec4(v.position, 1.0 + v.morph);
    }

    SurfaceVertex s;
    s.position = v.position;
    s.normal = normal;
    s.river = v.surface;
    s.direction = v.direction;
    // The patch centre's world position (mod the period, from f64) plus the vertex's small offset from it.
    s.detail = p.detail.xyz + v.local;
    s.flow = flowTangent(p, v.flow, v.direction);
    s.sunlight = vec3(1.0);
    s.air = Scattering(vec3(0.0), vec3(0.0), vec3(1.0));
    if (atmosphereOn()) s.air = airTo(v.position, v.surface.x, v.direction, s.sunlight);
    s.riverWater = false;
    s.level = p.centreRel.w;
    s.spacing = p.centreDir.w;
    writeSurface(s);
    gl_Position = frame.viewProjection * vec4(v.position, 1.0);
}

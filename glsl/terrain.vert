#version 460
// Section 8.2: the terrain pass's vertex: per vertex, the base height and the river data of the patch, blended by
// the lerp factor, projected onto the sphere (terrain_vertex.glsl); normals from neighbouring heights; skirts below
// the patch edges close cracks between levels. The water pass has its own (water.vert).
#include "terrain_vertex.glsl"
#include "atmosphere.glsl"

// What terrain.frag reads (the geometry shader writes the same locations in the water pass).
layout(location = 0) out vec3 vPosition;    // camera-relative
layout(location = 1) out vec3 vNormal;
layout(location = 2) out vec4 vRiver;       // final height, water height, signed distance, river half width
layout(location = 3) flat out int vRiverWater;
layout(location = 4) flat out float vLevel;
layout(location = 5) out vec3 vDirection;   // unit direction from the planet centre
layout(location = 9) flat out float vSpacing;
// The atmosphere between the camera and the vertex (atmosphere.glsl).
layout(location = 10) out vec3 vInscatterRayleigh;
layout(location = 11) out vec3 vInscatterMie;
layout(location = 12) out vec3 vTransmittance;
layout(location = 13) out vec3 vSunlight;   // the sunlight that reaches the vertex
layout(location = 14) out vec3 vFlow;       // the river's flow: a tangent, unit length where the samples agree
layout(location = 15) out vec3 vDetail;     // world position modulo DETAIL_PERIOD, precise near the camera

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

    vPosition = v.position;
    // The patch centre's world position (mod the period, from f64) plus the vertex's small offset from it.
    vDetail = p.detail.xyz + v.local;
    vNormal = normal;
    vDirection = v.direction;
    vRiver = v.surface;
    vRiverWater = 0;
    vLevel = p.centreRel.w;
    vSpacing = p.centreDir.w;
    vFlow = flowTangent(p, v.flow, v.direction);
    vInscatterRayleigh = vec3(0.0);
    vInscatterMie = vec3(0.0);
    vTransmittance = vec3(1.0);
    vSunlight = vec3(1.0);
    if (atmosphereOn()) {
        Scattering s = airTo(v.position, v.surface.x, v.direction, vSunlight);
        vInscatterRayleigh = s.rayleigh;
        vInscatterMie = s.mie;
        vTransmittance = s.transmittance;
    }
    gl_Position = frame.viewProjection * vec4(v.position, 1.0);
}

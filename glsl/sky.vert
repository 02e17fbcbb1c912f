#version 460
// Beyond the thesis: the sky dome's vertex, marched by sky_dome.comp this frame. Drawn at the far plane (depth 0
// with reversed Z), so only pixels no surface covered pass the depth test; directions outside the dome keep the
// clear colour (space, and holes in the surface stay visible for bench::holes).
#include "terrain_common.glsl"
#include "atmosphere.glsl"
#include "sky_vertex.glsl"

layout(set = 1, binding = 6, std430) readonly buffer Dome { SkyVertex dome[]; };

layout(location = 0) out vec3 vView;
layout(location = 1) out vec3 vRayleigh;
layout(location = 2) out vec3 vMie;
layout(location = 3) out vec3 vTransmittance;
layout(location = 4) out vec3 vSky;

void main() {
    SkyVertex v = dome[gl_VertexIndex];
    vView = v.direction.xyz;
    vRayleigh = v.rayleigh.xyz;
    vMie = v.mie.xyz;
    vTransmittance = v.transmittance.xyz;
    // The sky's colour with the phase functions of the vertex's own angle to the sun: away from the sun they
    // change slowly across a quad of the dome (sky.frag evaluates them per pixel near it).
    vSky = inscatteredColour(v.rayleigh.xyz, v.mie.xyz, dot(v.direction.xyz, normalize(frame.sun.xyz)));
    // A direction (w = 0) projects to depth 0 with the infinite reversed-Z projection.
    gl_Position = frame.viewProjection * vec4(v.direction.xyz, 0.0);
}

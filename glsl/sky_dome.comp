#version 460
// Beyond the thesis: the sky dome's vertices with the scattering marched per vertex (O'Neil 2005, GPU Gems 2
// ch. 16, with the transmittance table of atmosphere.glsl): about five thousand vertices instead of a march per
// sky pixel, once a frame on all of the device's threads (lavapipe runs vertex shaders on one; sky.vert reads
// them). The rings span the directions that can show air, from the sphere of the lowest terrain through the horizon
// of sea level (where they crowd, the limb and the bright horizon band change fastest) to the top of the shell (or
// the zenith from inside it). Invocation k: vertex k = ring * (SEGMENTS + 1) + segment.
#include "terrain_common.glsl"
#include "atmosphere.glsl"
#include "sky_vertex.glsl"

layout(local_size_x = 64) in;

layout(constant_id = 0) const uint RINGS = 48;
layout(constant_id = 1) const uint SEGMENTS = 96;
const int SKY_STEPS = 16;

layout(set = 1, binding = 6, std430) writeonly buffer Dome { SkyVertex dome[]; };

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= (RINGS + 1u) * (SEGMENTS + 1u)) return;
    uint ring = k / (SEGMENTS + 1u);
    uint segment = k % (SEGMENTS + 1u);
    Air a = air();
    vec3 eye = frame.camera.xyz;
    float r = length(eye);
    vec3 down = -eye / r;
    // Angles from the nadir: the lowest terrain's sphere, the horizon of sea level, the top of the shell.
    float thetaInner = asin(min((frame.planet.x + frame.planet.w) / r, 1.0));
    float thetaHorizon = asin(min(a.bottom / r, 1.0));
    float thetaTop = r > a.top ? asin(a.top / r) : PI;
    float x = float(max(ring, 1u) - 1u) / float(RINGS - 1u);
    // Ring 0 lies far enough out that its chords stay outside the lowest terrain's sphere.
    float theta = ring == 0u ? atan(tan(thetaInner) / cos(PI / float(SEGMENTS))) : mix(thetaHorizon, thetaTop, x * x);
    float phi = 2.0 * PI * float(segment) / float(SEGMENTS);
    vec3 e1 = normalize(cross(down, abs(down.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
    vec3 e2 = cross(down, e1);
    vec3 dir = down * cos(theta) + (e1 * cos(phi) + e2 * sin(phi)) * sin(theta);
    // A ray into the sea-level sphere stops there.
    float b = dot(eye, dir);
    float disc = b * b - (r * r - a.bottom * a.bottom);
    float ground = disc > 0.0 ? -b - sqrt(disc) : -1.0;
    Scattering s = scatter(a, eye, dir, ground > 0.0 ? ground : 1e30, SKY_STEPS, false);
    dome[k] = SkyVertex(vec4(dir, 0.0), vec4(s.rayleigh, 0.0), vec4(s.mie, 0.0), vec4(s.transmittance, 0.0));
}

#version 460
// Beyond the thesis: the sky and the glow of the limb from the dome's per-vertex scattering (sky.vert), with the
// phase functions per pixel near the sun so that its aureole stays round (elsewhere the vertices' colour, whose
// phase functions change slowly across a quad of the dome); the sun's disc; added to the clear colour that the
// air lets through.
#include "terrain_common.glsl"
#include "atmosphere.glsl"

// Covered pixels are rejected before shading.
layout(early_fragment_tests) in;

layout(location = 0) in vec3 vView;
layout(location = 1) in vec3 vRayleigh;
layout(location = 2) in vec3 vMie;
layout(location = 3) in vec3 vTransmittance;
layout(location = 4) in vec3 vSky;
layout(location = 0) out vec4 outColor;

// The sun's angular radius, widened to a few pixels at typical fields of view.
const float SUN_COS = 0.99985;

// The aureole: per pixel within 15 degrees of the sun, blended into the vertices' colour out to 25 (where the Mie
// phase's change across a quad of the dome is a percent or two of it). Lavapipe skips the branch for blocks of
// pixels that are all farther.
const float AUREOLE_INNER_COS = 0.9659258;
const float AUREOLE_OUTER_COS = 0.9063078;

void main() {
    vec3 dir = normalize(vView);
    float c = dot(dir, normalize(frame.sun.xyz));
    vec3 sky = vSky;
    if (c > AUREOLE_OUTER_COS) {
        vec3 aureole = inscatteredColour(vRayleigh, vMie, c);
        sky = mix(vSky, aureole, smoothBand(AUREOLE_OUTER_COS, AUREOLE_INNER_COS, c));
    }
    float sun = smoothBand(SUN_COS, 1.0 - 0.25 * (1.0 - SUN_COS), c);
    sky += sun * vTransmittance * (1.0 - sky);
    // Blend::Transmit: result = sky + clear colour x the air's (grey) transmittance.
    outColor = vec4(sky, dot(vTransmittance, vec3(1.0 / 3.0)) * (1.0 - sun));
}

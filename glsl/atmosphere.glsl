// Beyond the thesis (docs/rendering.md, "Atmosphere"): single Rayleigh and Mie scattering in the shell of
// atmosphere-height (Table 6.1) after Bruneton and Neyret 2008, section 4: the light scattered towards the eye
// along a view segment, marched with the sunlight that reaches each step read from the transmittance table
// (src/planet/atmosphere.rs, which computes it with the same air). The air's numbers (RAYLEIGH_OPTICAL_DEPTH and the
// others) come from src/planet/air.rs through build.rs. Needs terrain_common.glsl.

const float PI = 3.14159265;

// Whether this frame draws an atmosphere: extra.x is the transmittance table's slot, or -1.
bool atmosphereOn() { return frame.extra.x >= 0.0; }

struct Air {
    float bottom;         // radius of sea level
    float top;            // radius of the top of the shell
    float rayleighHeight;
    float mieHeight;
    vec3 rayleigh;        // scattering = extinction per unit length at the bottom
    float mieScattering;
    float mieExtinction;
};

Air air() {
    float height = frame.camera.w;
    Air a;
    a.bottom = frame.planet.x + frame.sun.w;
    a.top = a.bottom + height;
    a.rayleighHeight = height * RAYLEIGH_HEIGHT_FRACTION;
    a.mieHeight = a.rayleighHeight * MIE_HEIGHT_RATIO;
    a.rayleigh = RAYLEIGH_OPTICAL_DEPTH / a.rayleighHeight;
    a.mieScattering = MIE_OPTICAL_DEPTH / a.mieHeight;
    a.mieExtinction = a.mieScattering * MIE_EXTINCTION_RATIO;
    return a;
}

// The sunlight that reaches radius r from the direction at cosine mu of the zenith: the table's transmittance to
// the top of the shell (Bruneton 2017's coordinates, as Atmosphere::table_uv), and the planet's shadow below the
// horizon, softened over about the sun's diameter.
vec3 sunTransmittance(Air a, float r, float mu) {
    r = clamp(r, a.bottom, a.top);
    float horizon = sqrt(a.top * a.top - a.bottom * a.bottom);
    float rho = sqrt(max(r * r - a.bottom * a.bottom, 0.0));
    float d = max(-r * mu + sqrt(max(r * r * (mu * mu - 1.0) + a.top * a.top, 0.0)), 0.0);
    float dMin = a.top - r;
    float dMax = rho + horizon;
    float xMu = clamp((d - dMin) / max(dMax - dMin, 1e-6), 0.0, 1.0);
    float xR = rho / horizon;
    vec2 size = vec2(TRANSMITTANCE_WIDTH, TRANSMITTANCE_HEIGHT);
    vec2 uv = 0.5 / size + vec2(xMu, xR) * (1.0 - 1.0 / size);
    vec3 t = textureLod(patchTextures[int(frame.extra.x)], vec3(uv, 0.0), 0.0).rgb;
    float s = a.bottom / r;
    float horizonMu = -sqrt(max(1.0 - s * s, 0.0));
    return t * smoothBand(-0.01, 0.01, mu - horizonMu);
}

float rayleighPhase(float c) { return 3.0 / (16.0 * PI) * (1.0 + c * c); }

// Cornette-Shanks.
float miePhase(float c) {
    float g = MIE_G;
    float g2 = g * g;
    // k^1.5 as k sqrt(k): lavapipe runs pow as a logarithm and an exponential per lane.
    float k = 1.0 + g2 - 2.0 * g * c;
    return 3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + c * c) / ((2.0 + g2) * k * sqrt(k));
}

// Single scattering along a view segment, before the phase functions (they depend on the angle to the sun only,
// so vertex shaders can march and fragment shaders apply them), and the segment's transmittance.
struct Scattering {
    vec3 rayleigh;
    vec3 mie;
    vec3 transmittance;
};

// The segment from `origin` (from the planet's centre) along the unit `dir` up to `tMax`, clipped to the shell,
// by the midpoint rule with `steps` steps. With `sunAtEnds`, the sunlight is read from the table at the segment's
// two ends only and interpolated linearly between them: close for segments whose altitude changes one way (from
// the eye to the ground), two table reads instead of one per step and no transcendental more.
Scattering scatter(Air a, vec3 origin, vec3 dir, float tMax, int steps, bool sunAtEnds) {
    Scattering s;
    s.rayleigh = vec3(0.0);
    s.mie = vec3(0.0);
    s.transmittance = vec3(1.0);
    float b = dot(origin, dir);
    float disc = b * b - (dot(origin, origin) - a.top * a.top);
    if (disc <= 0.0) return s;
    float q = sqrt(disc);
    float t0 = max(-b - q, 0.0);
    float t1 = min(-b + q, tMax);
    if (t1 <= t0) return s;
    vec3 sun = normalize(frame.sun.xyz);
    float dt = (t1 - t0) / float(steps);
    vec3 depth = vec3(0.0);
    vec3 sunFirst = vec3(0.0);
    vec3 sunLast = vec3(0.0);
    if (sunAtEnds) {
        vec3 p0 = origin + dir * t0;
        vec3 p1 = origin + dir * t1;
        sunFirst = sunTransmittance(a, length(p0), dot(p0, sun) / length(p0));
        sunLast = sunTransmittance(a, length(p1), dot(p1, sun) / length(p1));
    }
    for (int k = 0; k < steps; ++k) {
        vec3 p = origin + dir * (t0 + (float(k) + 0.5) * dt);
        float r = length(p);
        float h = max(r - a.bottom, 0.0);
        float rayleighDensity = exp(-h / a.rayleighHeight);
        float mieDensity = exp(-h / a.mieHeight);
        vec3 extinction = a.rayleigh * rayleighDensity + a.mieExtinction * mieDensity;
        float f = (float(k) + 0.5) / float(steps);
        vec3 sunlight = sunAtEnds ? mix(sunFirst, sunLast, f) : sunTransmittance(a, r, dot(p, sun) / r);
        vec3 light = exp(-(depth + 0.5 * dt * extinction)) * sunlight * dt;
        depth += extinction * dt;
        s.rayleigh += light * rayleighDensity;
        s.mie += light * mieDensity;
    }
    s.rayleigh *= a.rayleigh;
    s.mie *= a.mieScattering;
    s.transmittance = exp(-depth);
    return s;
}

// The air between the eye and a surface point at camera-relative `position`, `height` above the radius along the
// unit `up`, marched with few steps (per vertex: it changes slowly across a triangle, and lavapipe shades many more
// fragments than it transforms vertices); `sunlight` is the sunlight that reaches the point.
const int SURFACE_STEPS = 6;
Scattering airTo(vec3 position, float height, vec3 up, out vec3 sunlight) {
    Air a = air();
    float distance = length(position);
    sunlight = sunTransmittance(a, frame.planet.x + height, dot(up, normalize(frame.sun.xyz)));
    return scatter(a, frame.camera.xyz, position / max(distance, 1e-6), distance, SURFACE_STEPS, true);
}

// The display value (tone-mapped at exposure 1) of the radiance scattered towards the eye, `c` the cosine of the
// angle between the view ray and the sun: what every caller draws (surfaces per vertex, the sky per vertex and
// near the sun per pixel).
vec3 inscatteredColour(vec3 rayleigh, vec3 mie, float c) {
    vec3 radiance = SUN_INTENSITY * (rayleigh * rayleighPhase(c) + mie * miePhase(c));
    return 1.0 - exp(-radiance);
}

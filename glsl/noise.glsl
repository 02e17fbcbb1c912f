// Value noise shared by the terrain's shaders (no external assets): the ground detail and the ripples in
// terrain.frag, the climate's moisture field per vertex (terrain_interface.glsl). Needs nothing else.
#ifndef NOISE_GLSL
#define NOISE_GLSL

// The hash of a lattice point is
// fract(x * y * z * (x + y + z)) of its coordinates, each scrambled alone (`scramble`), so a cell's eight corners
// scramble six coordinates, not twenty-four (docs/rendering.md, "Cheaper pixels").
vec3 scramble(vec3 p) { return fract(p * 0.3183099 + 0.1) * 17.0; }

float hashScrambled(float x, float y, float z) { return fract(x * y * z * (x + y + z)); }

// The hashes of a cell's eight corners from its scrambled low (`a`) and high (`b`) coordinates, corner k at
// (k & 1, (k >> 1) & 1, k >> 2).
void cornerHashes(vec3 a, vec3 b, out float c[8]) {
    c[0] = hashScrambled(a.x, a.y, a.z);
    c[1] = hashScrambled(b.x, a.y, a.z);
    c[2] = hashScrambled(a.x, b.y, a.z);
    c[3] = hashScrambled(b.x, b.y, a.z);
    c[4] = hashScrambled(a.x, a.y, b.z);
    c[5] = hashScrambled(b.x, a.y, b.z);
    c[6] = hashScrambled(a.x, b.y, b.z);
    c[7] = hashScrambled(b.x, b.y, b.z);
}

// Value noise whose lattice repeats every `period` cells.
float periodicNoise(vec3 x, float period) {
    vec3 i = floor(x);
    vec3 f = fract(x);
    f = f * f * (3.0 - 2.0 * f);
    float c[8];
    cornerHashes(scramble(mod(i, period)), scramble(mod(i + 1.0, period)), c);
    return mix(mix(mix(c[0], c[1], f.x), mix(c[2], c[3], f.x), f.y), mix(mix(c[4], c[5], f.x), mix(c[6], c[7], f.x), f.y),
               f.z);
}

// Beyond the thesis (docs/rendering.md, "Climate"): the large-scale field of moisture that winds and mountains
// bring or keep away, in [0, 1] around 0.5, over the unit `direction`: two octaves of value noise, about a third
// and a ninth of a radius across (thousands of kilometres on Earth). Smooth at the scale of a patch's vertices, so
// they compute it and the fragments interpolate it.
float moistureAt(vec3 direction) {
    return 0.65 * periodicNoise(direction * 3.0 + 11.0, 64.0) + 0.35 * periodicNoise(direction * 9.0 + 5.0, 64.0);
}

#endif

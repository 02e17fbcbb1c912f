// One vertex of the sky dome, written by sky_dome.comp and read by sky.vert: its direction and the single
// scattering along it before the phase functions, with the air's transmittance (std430, w unused).
struct SkyVertex {
    vec4 direction;
    vec4 rayleigh;
    vec4 mie;
    vec4 transmittance;
};

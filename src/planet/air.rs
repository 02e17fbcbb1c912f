//! The air of the atmosphere shell, beyond the thesis (which reads `atmosphere-height`, Table 6.1, and draws no
//! atmosphere): an exponential Rayleigh and Mie atmosphere after Bruneton and Neyret 2008, scaled to the shell.
//! Dependency-free, because build.rs includes this file to hand the same numbers to the shaders
//! (`glsl/atmosphere.glsl`) as macro definitions: one source for the CPU's transmittance table and the GPU's march.
//!
//! The air is given by Earth's vertical optical depths, not by per-metre coefficients, so that a planet of any
//! size (Appendix A's is 1024 units across with a 32-unit shell) looks like Earth from its ground; the scale
//! heights are fractions of `atmosphere-height` (docs/rendering.md, "Atmosphere", says why these fractions).

/// Rayleigh scale height as a fraction of the shell's height: eight scale heights fit in the shell, so the air at
/// its top is e^-8 of the air at sea level (Earth: 8 km of a 100 km shell, 12.5 %).
pub const RAYLEIGH_HEIGHT_FRACTION: f64 = 0.125;
/// Mie (aerosol) scale height as a fraction of the Rayleigh one (Earth: 1.2 km / 8 km).
pub const MIE_HEIGHT_RATIO: f64 = 0.15;
/// Earth's vertical Rayleigh optical depth at 680, 550 and 440 nm (scattering 5.8, 13.5, 33.1 per 1e6 m times
/// its 8 km scale height; Bruneton and Neyret 2008, Table 1).
pub const RAYLEIGH_OPTICAL_DEPTH: [f64; 3] = [0.0464, 0.1080, 0.2648];
/// Earth's vertical Mie scattering optical depth (21 per 1e6 m times 1.2 km; Bruneton and Neyret 2008).
pub const MIE_OPTICAL_DEPTH: f64 = 0.0252;
/// Mie extinction over scattering (absorption by aerosols; Bruneton and Neyret 2008: 1 / 0.9).
pub const MIE_EXTINCTION_RATIO: f64 = 1.11;
/// Asymmetry of the Cornette-Shanks Mie phase function.
pub const MIE_G: f64 = 0.76;
/// Sun irradiance in the renderer's units: an overhead sun makes the zenith sky about as bright as sunlit grass.
pub const SUN_INTENSITY: f64 = 20.0;
/// Size of the transmittance table (Bruneton 2017's parametrisation: view zenith across, altitude down).
pub const TRANSMITTANCE_SIZE: [u32; 2] = [256, 64];

//! The atmosphere shell (beyond the thesis, see `air`): its geometry and air, and the transmittance table the
//! shaders read for the sunlight that reaches any point (Bruneton and Neyret 2008, section 4; the table's
//! parametrisation is Bruneton's 2017 reference implementation, which spends its texels near the horizon).

use rayon::prelude::*;

use super::air;

/// An exponential atmosphere around a sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atmosphere {
    /// Radius of the bottom of the air: the planet's radius plus its sea level.
    pub bottom: f64,
    /// Radius of the top of the shell.
    pub top: f64,
    /// Scale heights of the molecules' and the aerosols' density (which falls by e over each).
    pub rayleigh_height: f64,
    /// See `rayleigh_height`.
    pub mie_height: f64,
    /// Rayleigh scattering (= extinction) per unit length at the bottom, for red, green and blue.
    pub rayleigh: [f64; 3],
    /// Mie scattering per unit length at the bottom.
    pub mie_scattering: f64,
    /// Mie extinction per unit length at the bottom.
    pub mie_extinction: f64,
}

/// The transmittance from every altitude along every direction to the top of the shell (zero where the ray meets
/// the ground), RGBA32F texels (alpha 1), row-major, [`air::TRANSMITTANCE_SIZE`].
pub struct TransmittanceTable {
    /// Texels across (directions) and down (altitudes).
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// The texels, row-major.
    pub texels: Vec<[f32; 4]>,
}

/// Steps of the numerical integral per table texel.
const TABLE_STEPS: usize = 500;

impl Atmosphere {
    /// The atmosphere of a planet of `radius` with air from `sea_level` up to `height` above it; `None` where
    /// `height` is 0 (Table 6.1 allows a planet without air).
    pub fn new(radius: f64, sea_level: f64, height: f64) -> Option<Self> {
        if height <= 0.0 {
            return None;
        }
        let rayleigh_height = height * air::RAYLEIGH_HEIGHT_FRACTION;
        let mie_height = rayleigh_height * air::MIE_HEIGHT_RATIO;
        let mie_scattering = air::MIE_OPTICAL_DEPTH / mie_height;
        Some(Self {
            bottom: radius + sea_level,
            top: radius + sea_level + height,
            rayleigh_height,
            mie_height,
            rayleigh: air::RAYLEIGH_OPTICAL_DEPTH.map(|tau| tau / rayleigh_height),
            mie_scattering,
            mie_extinction: mie_scattering * air::MIE_EXTINCTION_RATIO,
        })
    }

    /// Extinction per unit length at radius `r` (below the bottom, the bottom's).
    pub fn extinction(&self, r: f64) -> [f64; 3] {
        let h = (r - self.bottom).max(0.0);
        let rayleigh = (-h / self.rayleigh_height).exp();
        let mie = (-h / self.mie_height).exp() * self.mie_extinction;
        self.rayleigh.map(|b| b * rayleigh + mie)
    }

    /// Whether the ray from radius `r` with cosine `mu` of its zenith angle meets the ground.
    pub fn meets_ground(&self, r: f64, mu: f64) -> bool {
        mu < 0.0 && r * r * (mu * mu - 1.0) + self.bottom * self.bottom > 0.0
    }

    /// Distance from radius `r` along `mu` to the top of the shell.
    pub fn distance_to_top(&self, r: f64, mu: f64) -> f64 {
        let discriminant = r * r * (mu * mu - 1.0) + self.top * self.top;
        (-r * mu + discriminant.max(0.0).sqrt()).max(0.0)
    }

    /// Transmittance from radius `r` along `mu` to the top of the shell, by the midpoint rule with `steps` steps;
    /// zero where the ray meets the ground.
    pub fn transmittance(&self, r: f64, mu: f64, steps: usize) -> [f64; 3] {
        if self.meets_ground(r, mu) {
            return [0.0; 3];
        }
        let length = self.distance_to_top(r, mu);
        let dt = length / steps as f64;
        let mut depth = [0.0; 3];
        for k in 0..steps {
            let t = (k as f64 + 0.5) * dt;
            // Radius at distance t along the ray (law of cosines).
            let radius = (r * r + t * t + 2.0 * r * mu * t).sqrt();
            let e = self.extinction(radius);
            for c in 0..3 {
                depth[c] += e[c] * dt;
            }
        }
        depth.map(|d| (-d).exp())
    }

    /// The texture coordinates of (r, mu) in the transmittance table (Bruneton 2017,
    /// `GetTransmittanceTextureUvFromRMu`; `glsl/atmosphere.glsl` has the same mapping).
    pub fn table_uv(&self, r: f64, mu: f64) -> [f64; 2] {
        let horizon = (self.top * self.top - self.bottom * self.bottom).sqrt();
        let rho = (r * r - self.bottom * self.bottom).max(0.0).sqrt();
        let d = self.distance_to_top(r, mu);
        let (d_min, d_max) = (self.top - r, rho + horizon);
        let x_mu = (d - d_min) / (d_max - d_min);
        let x_r = rho / horizon;
        let [w, h] = air::TRANSMITTANCE_SIZE;
        [texel_from_unit(x_mu, w), texel_from_unit(x_r, h)]
    }

    /// The (r, mu) at a table texture coordinate: the inverse of [`Self::table_uv`].
    pub fn table_r_mu(&self, uv: [f64; 2]) -> (f64, f64) {
        let [w, h] = air::TRANSMITTANCE_SIZE;
        let (x_mu, x_r) = (unit_from_texel(uv[0], w), unit_from_texel(uv[1], h));
        let horizon = (self.top * self.top - self.bottom * self.bottom).sqrt();
        let rho = horizon * x_r;
        let r = (rho * rho + self.bottom * self.bottom).sqrt();
        let (d_min, d_max) = (self.top - r, rho + horizon);
        let d = d_min + x_mu * (d_max - d_min);
        let mu = if d == 0.0 {
            1.0
        } else {
            ((horizon * horizon - rho * rho - d * d) / (2.0 * r * d)).clamp(-1.0, 1.0)
        };
        (r, mu)
    }

    /// The transmittance table: every texel centre's transmittance to the top of the shell.
    pub fn transmittance_table(&self) -> TransmittanceTable {
        let [width, height] = air::TRANSMITTANCE_SIZE;
        let texels = (0..width * height)
            .into_par_iter()
            .map(|k| {
                let uv = [
                    ((k % width) as f64 + 0.5) / width as f64,
                    ((k / width) as f64 + 0.5) / height as f64,
                ];
                let (r, mu) = self.table_r_mu(uv);
                // Texels of rays that graze the ground keep their value above it: the shader decides the ground.
                let t = self.transmittance(r, mu.max(self.horizon_mu(r)), TABLE_STEPS);
                [t[0] as f32, t[1] as f32, t[2] as f32, 1.0]
            })
            .collect();
        TransmittanceTable {
            width,
            height,
            texels,
        }
    }

    /// Cosine of the zenith angle of the horizon (the ray that touches the bottom sphere) at radius `r`.
    pub fn horizon_mu(&self, r: f64) -> f64 {
        let s = (self.bottom / r.max(self.bottom)).min(1.0);
        -(1.0 - s * s).sqrt()
    }
}

/// Texture coordinate in [0.5 / n, 1 - 0.5 / n] of x in [0, 1], so that the ends fall on texel centres.
fn texel_from_unit(x: f64, n: u32) -> f64 {
    0.5 / n as f64 + x * (1.0 - 1.0 / n as f64)
}

fn unit_from_texel(u: f64, n: u32) -> f64 {
    (u - 0.5 / n as f64) / (1.0 - 1.0 / n as f64)
}

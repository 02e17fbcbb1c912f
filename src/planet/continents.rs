//! Continents (Section 4.1): continental feature points on the sphere, water feature points placed as the thesis
//! places them, a weighted Voronoi diagram whose continental weight yields the requested landmass share, and a
//! perturbation of the coasts. Or continents read from an equirectangular image.

use std::path::Path;

use glam::DVec3;

use crate::rng::Rng;

/// Stream tags for [`Rng`]: every random decision of the planet has its own stream.
const STREAM_CONTINENTS: u64 = 0xC0_0001;
const STREAM_PERTURB: u64 = 0xC0_0002;

/// Errors of continent generation from an image.
#[derive(Debug, thiserror::Error)]
pub enum ContinentError {
    /// The image is missing or cannot be decoded.
    #[error("cannot read continents image {path}: {message}")]
    Unreadable {
        /// The image.
        path: String,
        /// The decoder's message.
        message: String,
    },
    /// Not twice as wide as high, or too small.
    #[error(
        "continents image {path} is {width}x{height}; an equirectangular image must be twice as wide as high \
         (e.g. 2048x1024) and at least 8x4"
    )]
    WrongSize {
        /// The image.
        path: String,
        /// Its pixels across.
        width: u32,
        /// Its pixels down.
        height: u32,
    },
    /// All land or all sea.
    #[error(
        "continents image {path} is all {what}: land is brighter than middle grey, sea darker, and a planet needs \
         both"
    )]
    Uniform {
        /// The image.
        path: String,
        /// "land" or "sea".
        what: &'static str,
    },
}

/// The Voronoi feature points of Section 4.1.
#[derive(Clone, Debug)]
pub struct FeaturePoints {
    /// The continents' centres: land is nearer one of them than the water points (by the weight).
    pub continental: Vec<DVec3>,
    /// The water points between them.
    pub water: Vec<DVec3>,
}

/// Continental points, uniformly random on the sphere and at least a minimum angle apart (the angle shrinks if
/// the points do not fit after many tries, so any count succeeds).
pub fn continental_points(seed: u64, count: usize) -> Vec<DVec3> {
    let mut rng = Rng::new(seed, &[STREAM_CONTINENTS]);
    // Spherical caps of equal area for `count` points have angular radius ~ sqrt(4/count); keep 0.8 of that apart.
    let mut min_angle = 0.8
        * (4.0 / count.max(1) as f64)
            .sqrt()
            .min(std::f64::consts::FRAC_PI_2);
    let mut points: Vec<DVec3> = Vec::with_capacity(count);
    let mut failures = 0;
    while points.len() < count {
        let p = random_direction(&mut rng);
        if points.iter().all(|q| p.angle_between(*q) >= min_angle) {
            points.push(p);
        } else {
            failures += 1;
            if failures % 200 == 0 {
                min_angle *= 0.9;
            }
        }
    }
    points
}

/// A uniformly distributed unit vector.
pub fn random_direction(rng: &mut Rng) -> DVec3 {
    let z = rng.range_f64(-1.0, 1.0);
    let phi = rng.range_f64(0.0, std::f64::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Water points exactly as Section 4.1 places them: one opposite a single continent; otherwise four per pair of
/// continental points: their midpoint, its negative, their cross product, and its negative.
pub fn water_points(continental: &[DVec3]) -> Vec<DVec3> {
    if continental.len() == 1 {
        return vec![-continental[0]];
    }
    let mut water = Vec::new();
    for (i, a) in continental.iter().enumerate() {
        for b in &continental[i + 1..] {
            let sum = *a + *b;
            // Antipodal pair: any direction perpendicular to both is a midpoint.
            let mid = if sum.length() > 1e-9 {
                sum.normalize()
            } else {
                a.any_orthonormal_vector()
            };
            let cross = a.cross(*b);
            let cross = if cross.length() > 1e-9 {
                cross.normalize()
            } else {
                mid.cross(*a).normalize()
            };
            water.extend([mid, -mid, cross, -cross]);
        }
    }
    water
}

impl FeaturePoints {
    /// The feature points of the planet of `seed` with `continents` continents.
    pub fn generate(seed: u64, continents: usize) -> Self {
        let continental = continental_points(seed, continents);
        let water = water_points(&continental);
        Self { continental, water }
    }

    /// The ratio (nearest continental angle) / (nearest water angle): a point is land when
    /// `weight * continental < water`, i.e. when this ratio is below 1 / weight (weighted Voronoi, 3.5.1).
    pub fn ratio(&self, p: DVec3) -> f64 {
        let nearest = |set: &[DVec3]| {
            set.iter()
                .map(|q| p.angle_between(*q))
                .fold(f64::MAX, f64::min)
        };
        nearest(&self.continental) / nearest(&self.water).max(1e-12)
    }
}

/// Smooth 3D value noise with three independent channels, for the coast perturbation.
fn value_noise3(seed: u64, p: DVec3) -> DVec3 {
    let cell = p.floor();
    let f = p - cell;
    let s = f * f * (DVec3::splat(3.0) - 2.0 * f);
    let mut out = DVec3::ZERO;
    for corner in 0..8u32 {
        let o = DVec3::new(
            (corner & 1) as f64,
            ((corner >> 1) & 1) as f64,
            (corner >> 2) as f64,
        );
        let c = cell + o;
        let key = [
            STREAM_PERTURB,
            c.x as i64 as u64,
            c.y as i64 as u64,
            c.z as i64 as u64,
        ];
        let mut rng = Rng::new(seed, &key);
        let value = DVec3::new(
            rng.range_f64(-1.0, 1.0),
            rng.range_f64(-1.0, 1.0),
            rng.range_f64(-1.0, 1.0),
        );
        let w = (if o.x > 0.0 { s.x } else { 1.0 - s.x })
            * (if o.y > 0.0 { s.y } else { 1.0 - s.y })
            * (if o.z > 0.0 { s.z } else { 1.0 - s.z });
        out += value * w;
    }
    out
}

/// The perturbation filter of Section 4.1: each point takes the classification of a point a random distance
/// away in a random direction. The displacement is a smooth noise field (as in Musgrave's perturbation), so
/// coasts become irregular without speckle. `amplitude` is the largest displacement in radians.
pub fn perturb(seed: u64, p: DVec3, amplitude: f64) -> DVec3 {
    if amplitude <= 0.0 {
        return p;
    }
    // Three octaves, the coarsest with features about a tenth of the sphere wide.
    let mut d = DVec3::ZERO;
    let mut scale = 6.0;
    let mut weight = 0.6;
    for octave in 0..3u64 {
        d += value_noise3(seed.wrapping_add(octave), p * scale) * weight;
        scale *= 2.3;
        weight *= 0.5;
    }
    (p + d * amplitude).normalize()
}

/// The weight that makes the land share of `ratios` (with area `weights`) as close as possible to `target`
/// (a fraction): the weighted quantile of the ratios, so no iterative search is needed.
pub fn weight_for_share(ratios: &[f64], weights: &[f64], target: f64) -> f64 {
    let mut order: Vec<usize> = (0..ratios.len()).collect();
    order.sort_by(|&a, &b| ratios[a].total_cmp(&ratios[b]));
    let total: f64 = weights.iter().sum();
    let mut acc = 0.0;
    for (k, &i) in order.iter().enumerate() {
        acc += weights[i];
        if acc >= target * total {
            // Threshold halfway to the next ratio, so that exactly the points so far are land.
            let next = order.get(k + 1).map_or(ratios[i] * 1.01, |&j| ratios[j]);
            return 2.0 / (ratios[i] + next).max(1e-12);
        }
    }
    1e-12
}

/// Land or sea from an equirectangular image: bright is land (luminance above the middle grey).
pub struct ContinentImage {
    width: u32,
    height: u32,
    land: Vec<bool>,
}

impl ContinentImage {
    /// Reads `path` and checks it is an equirectangular image with land and sea.
    pub fn load(path: &Path) -> Result<Self, ContinentError> {
        let unreadable = |message: String| ContinentError::Unreadable {
            path: path.display().to_string(),
            message,
        };
        let image = image::ImageReader::open(path)
            .map_err(|e| unreadable(e.to_string()))?
            .with_guessed_format()
            .map_err(|e| unreadable(e.to_string()))?
            .decode()
            .map_err(|e| unreadable(e.to_string()))?
            .into_luma16();
        let (width, height) = image.dimensions();
        if width != 2 * height || height < 4 {
            return Err(ContinentError::WrongSize {
                path: path.display().to_string(),
                width,
                height,
            });
        }
        let land: Vec<bool> = image.pixels().map(|p| p.0[0] > u16::MAX / 2).collect();
        if land.iter().all(|&l| l) || !land.iter().any(|&l| l) {
            return Err(ContinentError::Uniform {
                path: path.display().to_string(),
                what: if land[0] { "land" } else { "sea" },
            });
        }
        Ok(Self {
            width,
            height,
            land,
        })
    }

    /// Whether the direction `p` falls on a land pixel (longitude from +X towards -Z... see docs/planet.md).
    pub fn is_land(&self, p: DVec3) -> bool {
        let (lon, lat) = crate::planet::lon_lat(p);
        let x = ((lon + 180.0) / 360.0 * self.width as f64).floor() as i64;
        let y = ((90.0 - lat) / 180.0 * self.height as f64).floor() as i64;
        let x = x.rem_euclid(self.width as i64) as u32;
        let y = y.clamp(0, self.height as i64 - 1) as u32;
        self.land[(y * self.width + x) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn water_points_follow_the_thesis() {
        let c = [DVec3::X, DVec3::Y];
        let w = water_points(&c);
        assert_eq!(w.len(), 4);
        let mid = DVec3::new(1.0, 1.0, 0.0).normalize();
        assert!(w[0].abs_diff_eq(mid, 1e-12) && w[1].abs_diff_eq(-mid, 1e-12));
        assert!(w[2].abs_diff_eq(DVec3::Z, 1e-12) && w[3].abs_diff_eq(DVec3::NEG_Z, 1e-12));
        assert_eq!(water_points(&[DVec3::Z]), vec![DVec3::NEG_Z]);
        assert_eq!(water_points(&continental_points(1, 5)).len(), 4 * 10);
    }

    #[test]
    fn continental_points_keep_apart() {
        let p = continental_points(3, 5);
        for (i, a) in p.iter().enumerate() {
            assert!((a.length() - 1.0).abs() < 1e-12);
            for b in &p[i + 1..] {
                assert!(a.angle_between(*b) > 0.5, "{a} {b}");
            }
        }
    }

    #[test]
    fn weight_for_share_hits_the_quantile() {
        let ratios: Vec<f64> = (0..1000).map(|i| i as f64 / 1000.0 + 0.01).collect();
        let weights = vec![1.0; 1000];
        let w = weight_for_share(&ratios, &weights, 0.3);
        let share = ratios.iter().filter(|r| **r * w < 1.0).count();
        assert_eq!(share, 300);
    }
}

//! The planet measured with geomorphology's own statistics (beyond the thesis; docs/geomorphology.md): coasts
//! (box-counting dimension, straight runs), hypsometry (land heights by band, mean land height), rivers
//! (sinuosity, slope-area concavity) and lakes. `generate` writes them in stats.json next to the drainage
//! model's Horton and Hack measures, so every change to how the world is made can be scored.

pub mod coast;
pub mod profiles;

use serde::Serialize;

use crate::{
    drainage::Drainage,
    planet::heights::{area_weight, FaceLattice},
};
pub use coast::{CoastMeasures, LandMask};

/// Land-height bands: upper edges as fractions of `max-mountain-height` (Earth's 0-1, 1-2, 2-3 and above 3 km
/// with an 8 km range, the scale config/earth.xml uses).
pub const BAND_EDGES: [f64; 3] = [0.125, 0.25, 0.375];

/// What stats.json reports of a planet's form.
#[derive(Clone, Debug, Default, Serialize)]
pub struct WorldMeasures {
    /// The coast's measures.
    #[serde(flatten)]
    pub coast: CoastMeasures,
    /// Share of the land area (percent) whose height above sea level lies in each band of
    /// `land_height_band_edges`: below the first, between, above the last.
    pub land_height_bands: Vec<f64>,
    /// The bands' edges in height units above sea level.
    pub land_height_band_edges: Vec<f64>,
    /// Area-weighted mean height of the land above sea level, in height units.
    pub mean_land_height: f64,
    /// Median sinuosity of the streams of Strahler order 3 and more along their base courses, as the base network
    /// (and `rivers.geojson`) holds them (drainage model; NaN otherwise). `generate` adds the sinuosity of the
    /// courses as drawn, with the meanders below the base lattice (`stream_sinuosity_median`).
    #[serde(serialize_with = "finite_or_null")]
    pub stream_sinuosity_median_base: f64,
    /// Slope-area concavity of the rivers' profiles (drainage model; NaN otherwise).
    #[serde(serialize_with = "finite_or_null")]
    pub concavity: f64,
    /// Share of the land area under lakes (drainage model).
    pub lake_land_share: f64,
}

fn finite_or_null<S: serde::Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    match x.is_finite() {
        true => s.serialize_f64(*x),
        false => s.serialize_none(),
    }
}

/// Measures a planet: `lattice` the precomputed heights, `land` whether a direction is land on them.
pub fn measure(
    lattice: &FaceLattice,
    land: impl Fn(glam::DVec3) -> bool + Sync,
    (sea_level, max_mountain_height, radius): (f64, f64, f64),
    drainage: Option<&Drainage>,
) -> WorldMeasures {
    let edges: Vec<f64> = BAND_EDGES
        .iter()
        .map(|e| e * (max_mountain_height - sea_level))
        .collect();
    let (bands, mean, land_area) = hypsometry(lattice, sea_level, &edges);
    let (sinuosity, concavity, lakes) = match drainage {
        Some(d) => (
            profiles::sinuosity_median(&d.reaches, |k| profiles::course_length(&d.reaches[k])),
            profiles::concavity(&d.reaches, radius),
            d.lakes.iter().map(|l| l.area).sum::<f64>() / (land_area * radius * radius),
        ),
        None => (f64::NAN, f64::NAN, 0.0),
    };
    WorldMeasures {
        coast: LandMask::new(land).measure(),
        land_height_bands: bands,
        land_height_band_edges: edges,
        mean_land_height: mean,
        stream_sinuosity_median_base: sinuosity,
        concavity,
        lake_land_share: lakes,
    }
}

/// Land area per band (percent of the land), the mean land height above sea level, and the land's area on the
/// unit sphere, area-weighted over the lattice's points (a point shared by faces counts once per face, with its
/// share of the area on each).
fn hypsometry(lattice: &FaceLattice, sea_level: f64, edges: &[f64]) -> (Vec<f64>, f64, f64) {
    let c = lattice.cells;
    let mut bands = vec![0.0; edges.len() + 1];
    let (mut sum, mut area, mut total) = (0.0, 0.0, 0.0);
    for face in 0..crate::planet::cube::FACES {
        for j in 0..=c {
            for i in 0..=c {
                let w = area_weight(c, i, j);
                total += w;
                let h = lattice.get(face, i, j) as f64 - sea_level;
                if h > 0.0 {
                    bands[edges.iter().filter(|&&e| h >= e).count()] += w;
                    sum += w * h;
                    area += w;
                }
            }
        }
    }
    let area = area.max(f64::MIN_POSITIVE);
    (
        bands.iter().map(|b| 100.0 * b / area).collect(),
        sum / area,
        area / total * 4.0 * std::f64::consts::PI,
    )
}

//! River measures of geomorphology over the drainage model's reaches (docs/geomorphology.md): the sinuosity of
//! large streams and the slope-area concavity of river profiles.

use crate::drainage::ReachPath;

/// Streams of this Strahler order and more are measured for sinuosity (smaller ones run a few lattice steps).
pub const SINUOUS_ORDER: u32 = 3;
/// Drainage-area bins per decade of the slope-area fit.
const BINS_PER_DECADE: f64 = 5.0;

/// Chains of reaches of one Strahler order, each from its uppermost reach down to where it meets a higher order
/// or ends: the streams of Strahler's ordering, as polylines of reach indices.
pub fn streams(reaches: &[ReachPath]) -> Vec<Vec<usize>> {
    let continues = |i: usize| {
        reaches[i]
            .downstream
            .filter(|&d| reaches[d].strahler == reaches[i].strahler)
    };
    let mut fed = vec![false; reaches.len()];
    for i in 0..reaches.len() {
        if let Some(d) = continues(i) {
            fed[d] = true;
        }
    }
    (0..reaches.len())
        .filter(|&i| !fed[i])
        .map(|first| {
            let mut chain = vec![first];
            while let Some(next) = continues(*chain.last().expect("not empty")) {
                chain.push(next);
            }
            chain
        })
        .collect()
}

/// Median over the streams of order [`SINUOUS_ORDER`] and more of path length over the chord between its ends
/// (1 for a straight stream; Leopold and Wolman call a river meandering from 1.5). `length(k)` gives the length
/// (radians) of reach `k` as it is drawn, e.g. [`course_length`]. NaN without such streams.
pub fn sinuosity_median(reaches: &[ReachPath], length: impl Fn(usize) -> f64) -> f64 {
    let mut ratios: Vec<f64> = streams(reaches)
        .iter()
        .filter(|chain| reaches[chain[0]].strahler >= SINUOUS_ORDER)
        .filter_map(|chain| {
            let first = reaches[chain[0]].points.first()?;
            let last = reaches[*chain.last()?].points.last()?;
            let chord = first.angle_between(*last);
            (chord > 1e-9).then(|| chain.iter().map(|&r| length(r)).sum::<f64>() / chord)
        })
        .collect();
    median(&mut ratios)
}

/// The length (radians) of a reach along its points.
pub fn course_length(reach: &ReachPath) -> f64 {
    reach
        .points
        .windows(2)
        .map(|w| w[0].angle_between(w[1]))
        .sum()
}

/// The slope-area concavity theta of S ~ A^-theta: minus the least-squares slope of the mean ln(slope) in bins of
/// ln(drainage area), over every step of every reach whose bed falls (Flint's law; Mudd et al. 2018 find a
/// median of 0.43 over the world's basins). `radius` turns angles into lengths. NaN with fewer than two bins.
pub fn concavity(reaches: &[ReachPath], radius: f64) -> f64 {
    let mut bins: std::collections::BTreeMap<i64, (f64, f64, usize)> = Default::default();
    for reach in reaches {
        for i in 0..reach.points.len().saturating_sub(1) {
            let drop = (reach.beds[i] - reach.beds[i + 1]) as f64;
            let run = reach.points[i].angle_between(reach.points[i + 1]) * radius;
            if drop <= 0.0 || run <= 0.0 || reach.areas[i] <= 0.0 {
                continue;
            }
            let ln_area = reach.areas[i].ln();
            let bin = (ln_area / std::f64::consts::LN_10 * BINS_PER_DECADE).floor() as i64;
            let entry = bins.entry(bin).or_default();
            entry.0 += ln_area;
            entry.1 += (drop / run).ln();
            entry.2 += 1;
        }
    }
    let points: Vec<(f64, f64)> = bins
        .values()
        .filter(|b| b.2 >= 3)
        .map(|&(a, s, n)| (a / n as f64, s / n as f64))
        .collect();
    if points.len() < 2 {
        return f64::NAN;
    }
    -crate::drainage::rivers::slope(&points)
}

/// The median of `values` (NaN when empty).
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n % 2 {
        1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn reach(points: Vec<DVec3>, beds: Vec<f32>, areas: Vec<f64>, strahler: u32) -> ReachPath {
        ReachPath {
            points,
            beds,
            areas,
            strahler,
            downstream: None,
        }
    }

    #[test]
    fn a_profile_with_slope_as_a_power_of_area_gives_its_exponent() {
        // Steps of equal length whose slope falls as area^-0.45 while area doubles each step.
        let step = 0.001;
        let n: usize = 200;
        let points: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new((i as f64 * step).cos(), (i as f64 * step).sin(), 0.0))
            .collect();
        let areas: Vec<f64> = (0..n).map(|i| 1e-6 * 1.05f64.powi(i as i32)).collect();
        let mut beds = vec![10.0f32];
        for i in 0..n - 1 {
            let slope = 0.5 * areas[i].powf(-0.45) * 1e-3;
            beds.push(beds[i] - (slope * step) as f32);
        }
        let theta = concavity(&[reach(points, beds, areas, 1)], 1.0);
        assert!((theta - 0.45).abs() < 0.03, "{theta}");
    }

    #[test]
    fn a_straight_stream_has_sinuosity_one_and_a_zigzag_more() {
        let straight: Vec<DVec3> = (0..10)
            .map(|i| DVec3::new(1.0, i as f64 * 0.01, 0.0).normalize())
            .collect();
        let zigzag: Vec<DVec3> = (0..10)
            .map(|i| DVec3::new(1.0, i as f64 * 0.01, (i % 2) as f64 * 0.01).normalize())
            .collect();
        let reaches = [reach(straight, vec![0.0; 10], vec![1.0; 10], 3)];
        assert!((sinuosity_median(&reaches, |k| course_length(&reaches[k])) - 1.0).abs() < 1e-9);
        let reaches = [reach(zigzag, vec![0.0; 10], vec![1.0; 10], 3)];
        assert!(sinuosity_median(&reaches, |k| course_length(&reaches[k])) > 1.3);
        // Order 2 is not measured.
        let reaches = [reach(
            vec![DVec3::X, DVec3::Y],
            vec![0.0; 2],
            vec![1.0; 2],
            2,
        )];
        assert!(sinuosity_median(&reaches, |k| course_length(&reaches[k])).is_nan());
    }
}

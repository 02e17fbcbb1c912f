//! Coastlines measured as geomorphology measures them (docs/geomorphology.md): the box-counting dimension of the
//! coast (Mandelbrot 1967: Britain's west coast 1.25, Norway's 1.52, a circle 1.0) and the longest straight run
//! of coast, on an equirectangular land mask between 60 degrees south and north.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::{drainage::rivers::slope, planet::direction_at};

/// Width of the mask (pixels; height half of it): a pixel is 0.088 degrees, half the precomputed lattice's cell.
pub const MASK_WIDTH: usize = 4096;
/// Latitudes measured: the equirectangular mask stretches the poles.
pub const LATITUDE_BAND: f64 = 60.0;
/// Box sizes of the count, in pixels of a [`MASK_WIDTH`] mask (0.18 to 5.6 degrees): single pixels are left out,
/// as a digitised curve undercounts at its own resolution.
const BOX_SIZES: [usize; 6] = [2, 4, 8, 16, 32, 64];
/// A stretch of coast counts as straight while no point of it stands further from the great circle through its
/// ends than this many pixels (the mask's staircase stands half a pixel off a straight coast).
const STRAIGHT_TOLERANCE_PIXELS: f64 = 1.5;

/// The measures of one planet's coasts.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct CoastMeasures {
    /// Box-counting dimension: minus the least-squares slope of ln(boxes holding coast) over ln(box size).
    pub coast_dimension: f64,
    /// The longest stretch of coast that stays within the tolerance of a great circle, as a share of the
    /// circumference.
    pub longest_straight_coast: f64,
}

/// A land mask of `MASK_WIDTH` x `MASK_WIDTH / 2` pixels over longitude and latitude, row 0 at the north.
pub struct LandMask {
    width: usize,
    height: usize,
    land: Vec<bool>,
}

impl LandMask {
    /// Samples `is_land` at every pixel centre.
    pub fn new(is_land: impl Fn(DVec3) -> bool + Sync) -> Self {
        Self::with_width(MASK_WIDTH, is_land)
    }

    /// Samples `is_land` at every pixel centre of a mask `width` pixels wide (and half as high).
    pub fn with_width(width: usize, is_land: impl Fn(DVec3) -> bool + Sync) -> Self {
        let height = width / 2;
        let mut mask = Self {
            width,
            height,
            land: vec![false; width * height],
        };
        // Only the rows measured are sampled; the sines and cosines of each column's longitude and each row's
        // latitude are taken once (the same products as `direction_at`, so the same directions).
        let rows = mask.rows();
        let angles = |degrees: f64| degrees.to_radians().sin_cos();
        let columns: Vec<(f64, f64)> = (0..width)
            .map(|x| angles(Self::lon_lat(width, x as f64 + 0.5, 0.0).0))
            .collect();
        mask.land[rows.start * width..rows.end * width]
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(row, land)| {
                let y = (row + rows.start) as f64 + 0.5;
                let (sin_lat, cos_lat) = angles(Self::lon_lat(width, 0.0, y).1);
                for (land, &(sin_lon, cos_lon)) in land.iter_mut().zip(&columns) {
                    *land = is_land(DVec3::new(cos_lat * cos_lon, sin_lat, -cos_lat * sin_lon));
                }
            });
        mask
    }

    fn lon_lat(width: usize, x: f64, y: f64) -> (f64, f64) {
        (
            x / width as f64 * 360.0 - 180.0,
            90.0 - y / (width / 2) as f64 * 180.0,
        )
    }

    fn at(&self, x: usize, y: usize) -> bool {
        self.land[y * self.width + x % self.width]
    }

    /// The rows inside the latitude band.
    fn rows(&self) -> std::ops::Range<usize> {
        let margin = ((90.0 - LATITUDE_BAND) / 180.0 * self.height as f64).round() as usize;
        margin..self.height - margin
    }

    /// The coast's box-counting dimension and longest straight run (docs/geomorphology.md).
    pub fn measure(&self) -> CoastMeasures {
        CoastMeasures {
            coast_dimension: self.box_dimension(),
            longest_straight_coast: self.longest_straight_run(),
        }
    }

    /// Minus the slope of ln(boxes with a coast pixel) over ln(box size); coast pixels are land pixels beside sea
    /// (4-neighbours, wrapping in longitude). NaN without coast.
    pub fn box_dimension(&self) -> f64 {
        let rows = self.rows();
        let w = self.width;
        let coast: Vec<(usize, usize)> = rows
            .clone()
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                self.at(x, y)
                    && (!self.at(x + 1, y)
                        || !self.at(x + w - 1, y)
                        || (y > rows.start && !self.at(x, y - 1))
                        || (y + 1 < rows.end && !self.at(x, y + 1)))
            })
            .collect();
        let points: Vec<(f64, f64)> = BOX_SIZES
            .iter()
            .map(|&s| {
                let s = (s * self.width / MASK_WIDTH).max(1);
                let mut boxes: Vec<usize> =
                    coast.iter().map(|&(x, y)| (y / s) * w + x / s).collect();
                boxes.sort_unstable();
                boxes.dedup();
                ((s as f64).ln(), (boxes.len() as f64).ln())
            })
            .collect();
        -slope(&points)
    }

    /// The coastlines as closed or open polylines of unit directions (marching squares on the mask; a line ends
    /// where it leaves the latitude band).
    pub fn coastlines(&self) -> Vec<Vec<DVec3>> {
        let (w, rows) = (self.width, self.rows());
        // Edge ids: 2 (y w + x) for the edge from pixel (x, y) to (x + 1, y), + 1 for (x, y) to (x, y + 1).
        let h_edge = |x: usize, y: usize| 2 * (y * w + x % w);
        let v_edge = |x: usize, y: usize| 2 * (y * w + x % w) + 1;
        let mut links: HashMap<usize, Vec<usize>> = HashMap::new();
        let mut link = |a: usize, b: usize| {
            links.entry(a).or_default().push(b);
            links.entry(b).or_default().push(a);
        };
        for y in rows.start..rows.end - 1 {
            for x in 0..w {
                let corners = [
                    self.at(x, y),
                    self.at(x + 1, y),
                    self.at(x, y + 1),
                    self.at(x + 1, y + 1),
                ];
                let (top, bottom, left, right) = (
                    h_edge(x, y),
                    h_edge(x, y + 1),
                    v_edge(x, y),
                    v_edge(x + 1, y),
                );
                let crossed: Vec<usize> = [
                    (corners[0] != corners[1], top),
                    (corners[1] != corners[3], right),
                    (corners[2] != corners[3], bottom),
                    (corners[0] != corners[2], left),
                ]
                .iter()
                .filter(|(c, _)| *c)
                .map(|&(_, e)| e)
                .collect();
                match crossed.len() {
                    2 => link(crossed[0], crossed[1]),
                    // A saddle: the corner (x, y) is cut off from the opposite one.
                    4 => {
                        link(top, left);
                        link(bottom, right);
                    }
                    _ => {}
                }
            }
        }
        let position = |e: usize| {
            let (p, vertical) = (e / 2, e % 2 == 1);
            let (x, y) = ((p % w) as f64 + 0.5, (p / w) as f64 + 0.5);
            let (x, y) = if vertical { (x, y + 0.5) } else { (x + 0.5, y) };
            let (lon, lat) = Self::lon_lat(w, x, y);
            direction_at(lon, lat)
        };
        let mut visited: HashMap<usize, bool> = HashMap::new();
        let mut lines = Vec::new();
        // Open lines from their ends first, then the closed ones.
        let mut starts: Vec<usize> = links
            .iter()
            .filter(|(_, l)| l.len() == 1)
            .map(|(&e, _)| e)
            .collect();
        let mut rest: Vec<usize> = links.keys().copied().collect();
        starts.sort_unstable();
        rest.sort_unstable();
        starts.extend(rest);
        for start in starts {
            if visited.contains_key(&start) {
                continue;
            }
            let mut line = vec![position(start)];
            visited.insert(start, true);
            let mut at = start;
            while let Some(&next) = links[&at].iter().find(|e| !visited.contains_key(e)) {
                visited.insert(next, true);
                line.push(position(next));
                at = next;
            }
            if links[&at].contains(&start) && line.len() > 2 {
                line.push(line[0]);
            }
            lines.push(line);
        }
        lines
    }

    /// The longest straight stretch of any coastline, as a share of the circumference: the longest segment of
    /// the coastlines simplified by Douglas-Peucker with the straightness tolerance.
    pub fn longest_straight_run(&self) -> f64 {
        let tolerance = STRAIGHT_TOLERANCE_PIXELS * std::f64::consts::TAU / MASK_WIDTH as f64;
        self.coastlines()
            .par_iter()
            .map(|line| longest_straight(line, tolerance))
            .reduce(|| 0.0, f64::max)
            / std::f64::consts::TAU
    }
}

/// The longest segment (radians) of `line` simplified by Douglas-Peucker with `tolerance` (radians): a stretch
/// whose every point lies within the tolerance of the great circle through its ends.
pub fn longest_straight(line: &[DVec3], tolerance: f64) -> f64 {
    if line.len() < 2 {
        return 0.0;
    }
    let mut longest: f64 = 0.0;
    let mut stack = vec![(0usize, line.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        let (pa, pb) = (line[a], line[b]);
        let normal = pa.cross(pb);
        // Distance from the great circle through the ends, or from the end itself when the ends meet.
        let off = |q: DVec3| match normal.length() > 1e-12 {
            true => q.dot(normal / normal.length()).abs().asin(),
            false => pa.angle_between(q),
        };
        let farthest = (a + 1..b)
            .map(|i| (off(line[i]), i))
            .fold((0.0, a), |m, x| if x.0 > m.0 { x } else { m });
        if farthest.0 > tolerance {
            stack.push((a, farthest.1));
            stack.push((farthest.1, b));
        } else {
            longest = longest.max(pa.angle_between(pb));
        }
    }
    longest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_round_island_has_dimension_one_and_no_straight_coast() {
        let centre = direction_at(10.0, 5.0);
        let wide = LandMask::with_width(2048, |d| d.angle_between(centre) < 0.8);
        // Boxes a sixteenth of the island wide round a smooth curve's count down a little.
        let dimension = wide.box_dimension();
        assert!((0.88..1.05).contains(&dimension), "{dimension}");
        let mask = LandMask::with_width(2048, |d| d.angle_between(centre) < 0.3);
        let m = mask.measure();
        // A circle of 0.3 rad: chords within 3 pixels (0.0046 rad) of it are about 0.105 rad long, 1.7 % of the
        // circumference.
        assert!(m.longest_straight_coast < 0.02, "{m:?}");
    }

    #[test]
    fn a_straight_coast_is_found_and_measured() {
        // Land south of the great circle through the poles at longitude 0 and 180... i.e. a half sphere: its
        // coast is two meridians, each running the whole band (120 degrees, a third of the circumference).
        let mask = LandMask::with_width(2048, |d| d.z < 0.0);
        let m = mask.measure();
        assert!((m.longest_straight_coast - 1.0 / 3.0).abs() < 0.01, "{m:?}");
        assert!((m.coast_dimension - 1.0).abs() < 0.05, "{m:?}");
    }

    #[test]
    fn a_rough_coast_has_a_dimension_above_one() {
        // Land where fractal noise with a rough spectrum stands above zero: its coasts are rough at every scale.
        let mask = LandMask::with_width(2048, |d| {
            let mut sum = 0.0;
            let mut amplitude = 1.0;
            let mut f = 3.0;
            for octave in 0..9u64 {
                sum += amplitude * crate::planet::noise::value(octave, d * f);
                amplitude *= 0.65;
                f *= 2.0;
            }
            sum > 0.0
        });
        let m = mask.measure();
        assert!(m.coast_dimension > 1.12, "{m:?}");
    }
}

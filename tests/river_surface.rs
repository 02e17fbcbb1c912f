//! Rivers lie in their valleys as drawn: along every river of the drainage model at level 6, the surface the
//! renderer draws (the kernel's river terrain blended into the base heights by the lerp factor, Section 8.2)
//! beside the river is nowhere more than a stated tolerance below the river's water, and the water does not rise
//! downstream. The thesis's model, whose rivers are random walks over the relief, fails the first check.

use std::path::Path;

use glam::DVec2;
use riverplanet::{
    config::{Config, RiverModel},
    kernel::{cpu::calculate_height, KernelParams},
    planet::cube::PatchId,
    river::samples::{patch_samples, PatchFrame},
    world::World,
};

const LEVEL: u8 = 6;

/// How far the water may stand above the drawn terrain beside it, in height units. The kernel averages the river
/// bed over the influence distance (Procedures 4-5), so where a river falls steeply its water at the centre stands
/// above banks a few units up- or downstream. On config/planet.xml seed 1 (eroded relief, whose heads are steep,
/// as concave profiles are) that is at most 0.90, at fewer than one point in ten thousand (0.17 at the 99.99th
/// percentile, 0.11 at the 99.9th); the carved relief measured 0.49 at most. The thesis's rivers, which cross the
/// relief, stand up to 2.88 above their banks on the same planet.
const BANK_TOLERANCE: f64 = 1.0;
/// The 99.9th percentile of the same, at most.
const BANK_TOLERANCE_999: f64 = 0.2;
/// How much the water may rise from one checked point to the next downstream (the kernel's averaging over
/// samples of falling beds; 0.198 at most measured on the eroded relief's steep heads, 0.056 on the carved).
const RISE_TOLERANCE: f64 = 0.25;

struct Findings {
    /// The largest height of water above the drawn terrain beside the river.
    worst_excess: f64,
    /// The largest rise of the water from one checked point to the next downstream one along a segment.
    worst_rise: f64,
    /// River centres whose flow (the kernel's weighted sample direction) does not point downstream, the way the
    /// water falls (within 60 degrees of the segment's direction of increasing t), of `centres`.
    upstream_flows: usize,
    centres: usize,
    checked: usize,
    /// Every checked height of the water above the drawn terrain beside the river.
    excesses: Vec<f64>,
}

/// Checks the middle of every segment of every river at [`LEVEL`].
fn survey(world: &World) -> Findings {
    let n = world.config.rendering.vertices;
    let params = KernelParams::from_config(&world.config);
    let sea = world.planet.sea_level as f64;
    let mut findings = Findings {
        worst_excess: f64::MIN,
        worst_rise: f64::MIN,
        upstream_flows: 0,
        centres: 0,
        checked: 0,
        excesses: Vec::new(),
    };
    for system in &world.network.systems {
        // Lakes are surveyed by lakes_are_drawn_as_water_at_their_level.
        for segment in system.segments.iter().filter(|s| !s.lake) {
            let mut previous_water: Option<f64> = None;
            for t in [0.3, 0.5, 0.7] {
                let on = system.frame.to_sphere(segment.curve.point(t));
                let patch = PatchId::containing(on, LEVEL);
                let frame = PatchFrame::new(patch, world.planet.radius, n);
                let samples = patch_samples(&world.network, &frame).samples;
                let heights = world.planet.patch_heights(patch);
                let spacing = frame.spacing();
                let extent = spacing * (n - 1) as f64;
                // The river at this level: the sample nearest the point.
                let at = frame.to_patch(on);
                let Some(sample) = samples.iter().filter(|s| s.width > 0.0).min_by(|a, b| {
                    let d = |s: &riverplanet::kernel::RiverSample| {
                        DVec2::from(s.position.map(|x| x as f64)).distance(at)
                    };
                    d(a).total_cmp(&d(b))
                }) else {
                    continue;
                };
                let centre = DVec2::from(sample.position.map(|x| x as f64));
                let inside = |q: DVec2| q.min_element() >= 0.0 && q.max_element() <= extent;
                if !inside(centre) {
                    continue;
                }
                let kernel = |q: DVec2| {
                    calculate_height([q.x as f32, q.y as f32], &samples, spacing as f32, &params)
                };
                let texel = kernel(centre);
                let water = texel.water_height as f64;
                if water <= sea + 1e-6 {
                    continue;
                }
                if let Some(before) = previous_water {
                    findings.worst_rise = findings.worst_rise.max(water - before);
                }
                previous_water = Some(water);
                let base = |q: DVec2| {
                    let (x, y) = (q.x / spacing, q.y / spacing);
                    let (i, j) = (x.floor() as i64, y.floor() as i64);
                    let (fx, fy) = (x - i as f64, y - j as f64);
                    let h = |di, dj| heights.get(i + di, j + dj) as f64;
                    (h(0, 0) * (1.0 - fx) + h(1, 0) * fx) * (1.0 - fy)
                        + (h(0, 1) * (1.0 - fx) + h(1, 1) * fx) * fy
                };
                let d = DVec2::from(sample.derivative.map(|x| x as f64)).normalize();
                findings.centres += 1;
                if DVec2::from(texel.flow.map(|x| x as f64)).dot(d) < 0.5 {
                    findings.upstream_flows += 1;
                }
                let across = d.perp();
                let half = sample.width as f64 * 0.5;
                let reach = params.influence_distance as f64;
                for k in 0..=8 {
                    let s = half + (reach - half) * k as f64 / 8.0;
                    for side in [-1.0, 1.0] {
                        let q = centre + across * s * side;
                        if !inside(q) {
                            continue;
                        }
                        let r = kernel(q);
                        // A point much nearer another river is that river's bank (at a confluence, the tributary's
                        // water stands above the main river's valley, as it must).
                        if (r.min_distance.abs() as f64) < 0.75 * s {
                            continue;
                        }
                        let surface = r.terrain_height as f64
                            + (base(q) - r.terrain_height as f64) * r.lerp_factor as f64;
                        // Below the sea level the bank is the sea's surface, which the water pass draws.
                        if surface <= sea {
                            continue;
                        }
                        findings.worst_excess = findings.worst_excess.max(water - surface);
                        findings.excesses.push(water - surface);
                        findings.checked += 1;
                    }
                }
            }
        }
    }
    findings
}

fn world(model: RiverModel) -> World {
    let mut config =
        Config::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("config/planet.xml")).unwrap();
    config.river.model = model;
    World::build(&config, 1).unwrap()
}

#[test]
fn drained_rivers_run_below_their_banks_never_rise_and_flow_downstream_at_level_6() {
    let world = world(RiverModel::Drainage);
    let mut f = survey(&world);
    f.excesses.sort_by(f64::total_cmp);
    let quantile = |q: f64| f.excesses[((f.excesses.len() - 1) as f64 * q) as usize];
    println!(
        "{} points beside rivers: water at most {:.4} above the drawn terrain, rising at most {:.4}; {} of {} \
         centres flow otherwise than downstream",
        f.checked, f.worst_excess, f.worst_rise, f.upstream_flows, f.centres
    );
    assert!(f.checked > 10_000);
    // Where rivers meet or run side by side the flow mixes them: 88 of 14,322 centres (0.6 %) measured.
    assert!(
        f.upstream_flows * 100 <= f.centres,
        "{} of {} river centres flow otherwise than downstream",
        f.upstream_flows,
        f.centres
    );
    println!(
        "water above its banks: {:.4} at the 99.9th percentile, {:.4} at the 99.99th",
        quantile(0.999),
        quantile(0.9999)
    );
    assert!(
        f.worst_excess <= BANK_TOLERANCE,
        "water {} above its banks",
        f.worst_excess
    );
    assert!(
        quantile(0.999) <= BANK_TOLERANCE_999,
        "water {} above its banks at the 99.9th percentile",
        quantile(0.999)
    );
    assert!(
        f.worst_rise <= RISE_TOLERANCE,
        "water rises by {} downstream",
        f.worst_rise
    );
}

#[test]
fn the_thesis_rivers_fail_the_bank_check() {
    let world = world(RiverModel::Thesis);
    let f = survey(&world);
    println!(
        "thesis: water at most {:.4} above the drawn terrain",
        f.worst_excess
    );
    assert!(f.worst_excess > BANK_TOLERANCE);
}

/// Lake water at every lake point: at the lake's level, also in the basin of a river flowing in, whose water comes
/// down to the level across the lake's reach (0.0000 measured at config/planet.xml seed 1's 386 lake points;
/// before, an inflow's water stood up to 0.315 above the level a cell before its mouth, and 0.65 with a steeper
/// relief tried in docs/geomorphology.md).
const LAKE_TOLERANCE: f64 = 0.01;
/// The drawn ground at a lake point above the lake's water, at most: a river's valley blended into the basin near
/// an inflow (0.098 measured, at 4 of 386 points).
const LAKE_GROUND_TOLERANCE: f64 = 0.15;
/// The median lake point's water from the level, at most (0.005 measured).
const LAKE_MEDIAN_TOLERANCE: f64 = 0.01;

#[test]
fn lakes_are_drawn_as_water_at_their_level() {
    let world = world(RiverModel::Drainage);
    let drainage = world.planet.drainage.as_ref().unwrap();
    assert!(!drainage.lakes.is_empty());
    let n = world.config.rendering.vertices;
    let params = KernelParams::from_config(&world.config);
    let (mut deviations, mut grounds) = (Vec::new(), Vec::new());
    for lake in &drainage.lakes {
        for &p in &lake.points {
            let patch = PatchId::containing(p, LEVEL);
            let frame = PatchFrame::new(patch, world.planet.radius, n);
            let samples = patch_samples(&world.network, &frame).samples;
            let at = frame.to_patch(p);
            let t = calculate_height(
                [at.x as f32, at.y as f32],
                &samples,
                frame.spacing() as f32,
                &params,
            );
            // The water stands over the drawn ground: the planet's own, blended into a river's valley near one.
            let base = world.planet.height_at(p);
            let ground = t.terrain_height + (base - t.terrain_height) * t.lerp_factor;
            grounds.push(ground as f64 - t.water_height as f64);
            deviations.push((t.water_height as f64 - lake.level as f64).abs());
        }
    }
    deviations.sort_by(f64::total_cmp);
    grounds.sort_by(f64::total_cmp);
    let dry = grounds.iter().filter(|g| **g > 0.0).count();
    assert!(
        grounds[grounds.len() - 1] <= LAKE_GROUND_TOLERANCE && dry * 20 <= grounds.len(),
        "the ground stands above a lake's water at {dry} points, up to {}",
        grounds[grounds.len() - 1]
    );
    println!(
        "ground above the water at {dry} of {} lake points, at most {:.4}; median ground {:.4} below the water",
        grounds.len(),
        grounds[grounds.len() - 1],
        -grounds[grounds.len() / 2]
    );
    let (median, worst) = (
        deviations[deviations.len() / 2],
        deviations[deviations.len() - 1],
    );
    println!(
        "{} lake points: water {median:.4} from the level at the median, {worst:.4} at most",
        deviations.len()
    );
    assert!(
        median <= LAKE_MEDIAN_TOLERANCE,
        "lake water {median} off its level at the median"
    );
    assert!(worst <= LAKE_TOLERANCE, "lake water {worst} off its level");
}

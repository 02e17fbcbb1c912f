//! Rivers and lakes from a routing: lakes where depressions are deep enough, river nodes where drainage area
//! passes a threshold, and the river nodes cut into reaches between heads, confluences and mouths, each with its
//! Strahler order and the reach it flows into.

use serde::Serialize;

use super::{
    grid::SphereGrid,
    junctions::split_junctions,
    routing::{Routing, NONE},
};

/// A stretch of river between a head or confluence and the next confluence or mouth.
#[derive(Clone, Debug)]
pub struct Reach {
    /// Nodes in flow order. The first is a head or a confluence; the last is the confluence it joins, or its mouth
    /// (a sea or lake node).
    pub nodes: Vec<u32>,
    /// Strahler order: 1 for a reach from a head, the larger of the joining orders below a confluence, plus one
    /// when two of the largest meet.
    pub strahler: u32,
    /// The reach this one flows into; `None` at a mouth.
    pub downstream: Option<usize>,
}

/// A depression deep enough to hold water.
#[derive(Clone, Debug)]
pub struct Lake {
    /// The grid nodes under its water.
    pub nodes: Vec<u32>,
    /// The water level: the depression's spill height.
    pub level: f64,
}

/// The statistics the issue asks `generate` to report (docs/rivers.md).
#[derive(Clone, Debug, Default, Serialize)]
pub struct DrainageMeasures {
    /// River systems: reaches that end at a mouth.
    pub rivers: usize,
    /// Stretches between heads, confluences and mouths.
    pub reaches: usize,
    /// River nodes where two rivers or more meet.
    pub confluences: usize,
    /// Confluences where three rivers or more meet (D8 lets up to seven drain into one node; real junctions are
    /// binary): wide rivers meeting at one point are drawn as one blob of water (docs/geomorphology.md).
    pub multiple_junctions: usize,
    /// Depressions kept as lakes.
    pub lakes: usize,
    /// The highest Strahler order.
    pub strahler_max: u32,
    /// Strahler streams of each order (index 0: order 1) in the basins of order [`HORTON_BASIN_ORDER`] and more.
    pub streams_per_order: Vec<usize>,
    /// Horton's bifurcation ratio: exp(-slope) of the least-squares lines through ln(streams of order w) over w
    /// within each basin of order [`HORTON_BASIN_ORDER`] and more, one slope shared by all of them.
    pub bifurcation_ratio: f64,
    /// Hack's exponent: least-squares slope of ln(main-stream length) over ln(drainage area) at the lower end of
    /// every reach.
    pub hack_exponent: f64,
    /// Share of the land area that drains through a river or a lake.
    pub drained_land_fraction: f64,
    /// Steps along a reach where the bed rises downstream.
    pub uphill_steps: usize,
    /// Lattice quads whose two diagonals both carry a river (two rivers crossing).
    pub crossings: usize,
}

/// Basins of this outlet order and more are pooled for Horton's bifurcation ratio.
pub const HORTON_BASIN_ORDER: u32 = 3;

/// What the routing makes of a planet's heights.
pub struct DrainageNetwork {
    /// Every reach, upstream first.
    pub reaches: Vec<Reach>,
    /// The lakes.
    pub lakes: Vec<Lake>,
    /// Per node: the lake it belongs to.
    pub lake_of: Vec<Option<u32>>,
    /// The network's statistics.
    pub measures: DrainageMeasures,
}

/// Thresholds of extraction, in units of the unit sphere.
#[derive(Clone, Copy, Debug)]
pub struct Thresholds {
    /// Drainage area at which a river starts.
    pub river_area: f64,
    /// Depth a depression needs to be kept as a lake.
    pub lake_depth: f64,
}

/// Extracts rivers and lakes from `routing` over `heights` (the unfilled heights; nodes at or below `sea_level`
/// are sea), after splitting the junctions of three rivers or more in `routing` ([`split_junctions`]).
pub fn extract(
    grid: &SphereGrid,
    routing: &mut Routing,
    heights: &[f64],
    sea_level: f64,
    thresholds: Thresholds,
) -> DrainageNetwork {
    let n = grid.len();
    let sea = |k: usize| heights[k] <= sea_level;
    let (lakes, lake_of) = lakes(grid, routing, heights, sea_level, thresholds.lake_depth);
    let channel = |k: usize| !sea(k) && lake_of[k].is_none();
    split_junctions(grid, routing, channel, thresholds.river_area);
    let routing = &*routing;
    let river: Vec<bool> = (0..n)
        .map(|k| !sea(k) && lake_of[k].is_none() && routing.area[k] >= thresholds.river_area)
        .collect();
    let mut donors = vec![0u32; n];
    for (k, &r) in routing.receiver.iter().enumerate() {
        if river[k] && r != NONE {
            donors[r as usize] += 1;
        }
    }
    // Reaches start at heads and confluences, upstream first, so a reach comes after every reach that joins it.
    let mut reaches: Vec<Reach> = Vec::new();
    let mut starting_at = vec![u32::MAX; n];
    for &k in &routing.upstream_first {
        let k = k as usize;
        if !river[k] || donors[k] == 1 {
            continue;
        }
        let mut nodes = vec![k as u32];
        let mut at = k;
        loop {
            let r = routing.receiver[at];
            if r == NONE {
                break;
            }
            nodes.push(r);
            at = r as usize;
            if !river[at] || donors[at] >= 2 {
                break;
            }
        }
        starting_at[k] = reaches.len() as u32;
        reaches.push(Reach {
            nodes,
            strahler: 1,
            downstream: None,
        });
    }
    // Links and Strahler orders.
    for reach in reaches.iter_mut() {
        let end = *reach.nodes.last().unwrap() as usize;
        let below = starting_at[end];
        if below != u32::MAX && river[end] {
            reach.downstream = Some(below as usize);
        }
    }
    let downstream: Vec<Option<usize>> = reaches.iter().map(|r| r.downstream).collect();
    let ordering = order(&downstream);
    for (reach, &strahler) in reaches.iter_mut().zip(&ordering.strahler) {
        reach.strahler = strahler;
    }
    let measures = measure(
        grid, routing, heights, sea_level, &reaches, &ordering, &river, &lake_of,
    );
    DrainageNetwork {
        measures: DrainageMeasures {
            lakes: lakes.len(),
            confluences: donors
                .iter()
                .zip(&river)
                .filter(|(&d, &r)| r && d >= 2)
                .count(),
            multiple_junctions: donors
                .iter()
                .zip(&river)
                .filter(|(&d, &r)| r && d >= 3)
                .count(),
            ..measures
        },
        reaches,
        lakes,
        lake_of,
    }
}

/// Depressions the filling raised by more than `depth` somewhere: connected land nodes raised at all, kept when
/// the deepest is at least `depth`.
fn lakes(
    grid: &SphereGrid,
    routing: &Routing,
    heights: &[f64],
    sea_level: f64,
    depth: f64,
) -> (Vec<Lake>, Vec<Option<u32>>) {
    let n = grid.len();
    // Raised by more than the epsilon slope could have done: filled water.
    let raised = |k: usize| heights[k] > sea_level && routing.filled[k] - heights[k] > depth * 1e-3;
    let mut lake_of = vec![None; n];
    let mut seen = vec![false; n];
    let mut lakes = Vec::new();
    for start in 0..n {
        if seen[start] || !raised(start) {
            continue;
        }
        let mut nodes = vec![start as u32];
        seen[start] = true;
        let mut k = 0;
        while k < nodes.len() {
            for &next in grid.neighbours(nodes[k]) {
                if !seen[next as usize] && raised(next as usize) {
                    seen[next as usize] = true;
                    nodes.push(next);
                }
            }
            k += 1;
        }
        let deepest = nodes
            .iter()
            .map(|&k| routing.filled[k as usize] - heights[k as usize])
            .fold(0.0, f64::max);
        if deepest >= depth {
            let level = nodes
                .iter()
                .map(|&k| routing.filled[k as usize])
                .fold(f64::MIN, f64::max);
            for &k in &nodes {
                lake_of[k as usize] = Some(lakes.len() as u32);
            }
            lakes.push(Lake { nodes, level });
        }
    }
    (lakes, lake_of)
}

/// Least-squares slope of y over x (NaN with fewer than two distinct x).
pub fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    if points.len() < 2 || sxx == 0.0 {
        f64::NAN
    } else {
        sxy / sxx
    }
}

/// The least-squares slope of y over x shared by several groups of points, each with its own intercept (the
/// slope fitted within groups): Horton's law holds within a basin, N_w = R^(order - w), so basins of different
/// orders are not pooled into one line (pooling counts every basin's top stream as if all had the same order).
fn within_basin_slope(groups: &[Vec<(f64, f64)>]) -> f64 {
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for g in groups.iter().filter(|g| g.len() >= 2) {
        let n = g.len() as f64;
        let (mx, my) = g
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        for (x, y) in g {
            sxy += (x - mx) * (y - my);
            sxx += (x - mx) * (x - mx);
        }
    }
    if sxx == 0.0 {
        f64::NAN
    } else {
        sxy / sxx
    }
}

#[allow(clippy::too_many_arguments)]
fn measure(
    grid: &SphereGrid,
    routing: &Routing,
    heights: &[f64],
    sea_level: f64,
    reaches: &[Reach],
    ordering: &Ordering,
    river: &[bool],
    lake_of: &[Option<u32>],
) -> DrainageMeasures {
    let n = grid.len();
    // Hack: the longest flow path above each node (to the divide), upstream first.
    let mut longest = vec![0.0f64; n];
    for &k in &routing.upstream_first {
        let r = routing.receiver[k as usize];
        if r != NONE {
            let length = longest[k as usize] + grid.angle(k, r);
            longest[r as usize] = longest[r as usize].max(length);
        }
    }
    let hack: Vec<(f64, f64)> = reaches
        .iter()
        .filter_map(|reach| {
            // The last river node of the reach (its mouth node may be sea).
            let last = reach.nodes.iter().rev().find(|&&k| river[k as usize])?;
            let (l, a) = (longest[*last as usize], routing.area[*last as usize]);
            (l > 0.0).then(|| (a.ln(), l.ln()))
        })
        .collect();
    // Drained land: land whose water reaches a river or a lake, downstream first.
    let mut drained = vec![false; n];
    let (mut land, mut drained_land) = (0.0, 0.0);
    for &k in routing.upstream_first.iter().rev() {
        let k = k as usize;
        if heights[k] <= sea_level {
            continue;
        }
        let r = routing.receiver[k];
        drained[k] = river[k] || lake_of[k].is_some() || (r != NONE && drained[r as usize]);
        land += grid.areas[k];
        if drained[k] {
            drained_land += grid.areas[k];
        }
    }
    let uphill_steps = reaches
        .iter()
        .flat_map(|r| r.nodes.windows(2))
        .filter(|w| routing.filled[w[1] as usize] > routing.filled[w[0] as usize])
        .count();
    let river_edge = |a: u32, b: u32| {
        let flows = |x: u32, y: u32| river[x as usize] && routing.receiver[x as usize] == y;
        flows(a, b) || flows(b, a)
    };
    let crossings = grid
        .quads()
        .filter(|&[a, b, c, d]| river_edge(a, d) && river_edge(b, c))
        .count();
    DrainageMeasures {
        rivers: reaches.iter().filter(|r| r.downstream.is_none()).count(),
        reaches: reaches.len(),
        confluences: 0,
        multiple_junctions: 0,
        lakes: 0,
        strahler_max: ordering.strahler_max,
        streams_per_order: ordering.streams_per_order.clone(),
        bifurcation_ratio: ordering.bifurcation_ratio,
        hack_exponent: slope(&hack),
        drained_land_fraction: if land > 0.0 { drained_land / land } else { 0.0 },
        uphill_steps,
        crossings,
    }
}

/// Strahler orders and Horton's stream counts of a forest of reaches.
#[derive(Clone, Debug, Default)]
pub struct Ordering {
    /// Per reach: 1 from a head, the larger of the joining orders below a confluence, plus one when two of the
    /// largest meet.
    pub strahler: Vec<u32>,
    /// The highest of them.
    pub strahler_max: u32,
    /// Strahler streams of each order (index 0: order 1) in the basins of order [`HORTON_BASIN_ORDER`] and more.
    pub streams_per_order: Vec<usize>,
    /// Horton's bifurcation ratio over those basins ([`DrainageMeasures::bifurcation_ratio`]).
    pub bifurcation_ratio: f64,
}

/// Orders the forest whose reach `r` flows into `downstream[r]` (in any order; every link leads to a mouth). Horton:
/// a stream of order w starts where a reach of order w has no incoming reach of order w; streams are counted in the
/// basins whose outlet has order [`HORTON_BASIN_ORDER`] or more (all basins if none has): Horton's law describes
/// branched networks, and a coast's first- and second-order creeks have no branching to measure.
pub fn order(downstream: &[Option<usize>]) -> Ordering {
    let n = downstream.len();
    let mut incoming: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (r, d) in downstream.iter().enumerate() {
        if let Some(d) = *d {
            incoming[d].push(r);
        }
    }
    // Upstream first: a reach once every reach that joins it is ordered.
    let mut waiting: Vec<usize> = incoming.iter().map(Vec::len).collect();
    let mut ready: Vec<usize> = (0..n).filter(|&r| waiting[r] == 0).collect();
    let mut upstream_first = Vec::with_capacity(n);
    let mut strahler = vec![1u32; n];
    while let Some(r) = ready.pop() {
        upstream_first.push(r);
        if let Some(top) = incoming[r].iter().map(|&u| strahler[u]).max() {
            let ties = incoming[r].iter().filter(|&&u| strahler[u] == top).count();
            strahler[r] = if ties >= 2 { top + 1 } else { top };
        }
        if let Some(d) = downstream[r] {
            waiting[d] -= 1;
            if waiting[d] == 0 {
                ready.push(d);
            }
        }
    }
    debug_assert_eq!(upstream_first.len(), n, "the reaches' links form a cycle");
    let mut outlet: Vec<usize> = (0..n).collect();
    for &r in upstream_first.iter().rev() {
        if let Some(d) = downstream[r] {
            outlet[r] = outlet[d];
        }
    }
    let strahler_max = strahler.iter().copied().max().unwrap_or(0);
    let basin_order = HORTON_BASIN_ORDER.min(strahler_max);
    let mut streams = vec![0usize; strahler_max as usize + 1];
    // Streams per order in each basin (by its outlet reach).
    let mut per_basin: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for r in 0..n {
        let starts = !incoming[r].iter().any(|&u| strahler[u] == strahler[r]);
        if starts && strahler[outlet[r]] >= basin_order {
            streams[strahler[r] as usize] += 1;
            let basin = per_basin
                .entry(outlet[r])
                .or_insert_with(|| vec![0; strahler_max as usize + 1]);
            basin[strahler[r] as usize] += 1;
        }
    }
    let horton: Vec<Vec<(f64, f64)>> = per_basin
        .values()
        .map(|counts| {
            (1..=strahler_max)
                .filter(|&w| counts[w as usize] > 0)
                .map(|w| (w as f64, (counts[w as usize] as f64).ln()))
                .collect()
        })
        .collect();
    Ordering {
        strahler,
        strahler_max,
        streams_per_order: streams.get(1..).unwrap_or_default().to_vec(),
        bifurcation_ratio: (-within_basin_slope(&horton)).exp(),
    }
}

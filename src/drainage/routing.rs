//! Flow routing over the sphere: depressions filled by Priority-Flood + epsilon (Barnes, Lehman and Mulla 2014,
//! Algorithm 3), then every land node drains to its steepest lower neighbour (D8 on the filled surface), and
//! drainage area accumulates downstream.

use std::{cmp::Reverse, collections::BinaryHeap};

use super::grid::{Ordered, SphereGrid};

/// `receiver` of a node that drains nowhere (the sea).
pub const NONE: u32 = u32::MAX;

/// Where the water of every node goes.
pub struct Routing {
    /// Heights with every depression filled to its spill level, plus a tiny rise per step over flats, so that every
    /// land node has a strictly lower neighbour (the epsilon of Priority-Flood + epsilon).
    pub filled: Vec<f64>,
    /// The node each node drains to ([`NONE`] for sea nodes).
    pub receiver: Vec<u32>,
    /// Every node before the node it drains to (upstream first).
    pub upstream_first: Vec<u32>,
    /// Drainage area on the unit sphere: a node's own area plus the area of everything that drains through it.
    pub area: Vec<f64>,
    /// Quads of the lattice where two diagonal flows would have crossed and one was turned (see
    /// `uncross_diagonals`).
    pub turned: usize,
    /// Quads where two diagonal flows still cross: no lower alternative was left.
    pub crossing: usize,
}

/// Routes `heights` (one per grid node) to the sea: nodes at or below `sea_level` are outlets.
pub fn route(grid: &SphereGrid, heights: &[f64], sea_level: f64) -> Routing {
    let n = grid.len();
    let span = heights
        .iter()
        .fold(0.0f64, |m, h| m.max((h - sea_level).abs()));
    // Small enough to leave real slopes alone, large enough to stay exact over the longest flat.
    let epsilon = (span + 1.0) * 1e-9;
    let mut filled = heights.to_vec();
    let mut closed = vec![false; n];
    let mut open = BinaryHeap::new();
    // Sea nodes drain nowhere; only those beside land need to enter the queue.
    let mut downstream_first = Vec::with_capacity(n);
    for k in 0..n {
        if heights[k] <= sea_level {
            closed[k] = true;
            let coast = grid
                .neighbours(k as u32)
                .iter()
                .any(|&j| heights[j as usize] > sea_level);
            match coast {
                true => open.push(Reverse((Ordered(heights[k]), k as u32))),
                false => downstream_first.push(k as u32),
            }
        }
    }
    // Nodes leave the queue in order of their filled height, so every node comes after the nodes below it.
    while let Some(Reverse((Ordered(h), node))) = open.pop() {
        downstream_first.push(node);
        for &next in grid.neighbours(node) {
            if !closed[next as usize] {
                closed[next as usize] = true;
                let f = heights[next as usize].max(h + epsilon);
                filled[next as usize] = f;
                open.push(Reverse((Ordered(f), next)));
            }
        }
    }
    let receiver: Vec<u32> = (0..n as u32)
        .map(|k| match heights[k as usize] <= sea_level {
            true => NONE,
            false => steepest_lower(grid, &filled, k, &[]),
        })
        .collect();
    let mut routing = Routing {
        filled,
        receiver,
        upstream_first: downstream_first.into_iter().rev().collect(),
        area: Vec::new(),
        turned: 0,
        crossing: 0,
    };
    uncross_diagonals(grid, &mut routing);
    routing.area = accumulate(grid, &routing);
    routing
}

/// Drainage area on the unit sphere: each node's own area plus everything that drains through it.
pub fn accumulate(grid: &SphereGrid, routing: &Routing) -> Vec<f64> {
    let mut area = grid.areas.clone();
    for &k in &routing.upstream_first {
        let r = routing.receiver[k as usize];
        if r != NONE {
            area[r as usize] += area[k as usize];
        }
    }
    area
}

/// The neighbour of `node` with the steepest descent on `filled` (drop over angle), leaving out `except`;
/// [`NONE`] if no neighbour is lower.
fn steepest_lower(grid: &SphereGrid, filled: &[f64], node: u32, except: &[u32]) -> u32 {
    let h = filled[node as usize];
    let mut best = (0.0, NONE);
    for (next, angle) in grid.steps(node) {
        let drop = h - filled[next as usize];
        if drop > 0.0 && !except.contains(&next) {
            let slope = drop / angle;
            if slope > best.0 {
                best = (slope, next);
            }
        }
    }
    best.1
}

/// D8 lets the two diagonals of one lattice quad both carry water, which would make two rivers cross. Where they
/// do, the node with the gentler diagonal drains to its next steepest lower neighbour off that diagonal instead;
/// repeated until no quad has two (or no alternative is left, counted in `crossing`).
fn uncross_diagonals(grid: &SphereGrid, routing: &mut Routing) {
    let flows = |r: &[u32], a: u32, b: u32| r[a as usize] == b || r[b as usize] == a;
    for _ in 0..8 {
        let mut changed = false;
        routing.crossing = 0;
        for [a, b, c, d] in grid.quads() {
            let r = &routing.receiver;
            if !(flows(r, a, d) && flows(r, b, c)) {
                continue;
            }
            // The diagonal's upper end, and the drop along it.
            let upper = |x: u32, y: u32| if r[x as usize] == y { x } else { y };
            let (p, q) = (upper(a, d), upper(b, c));
            let drop = |x: u32| routing.filled[x as usize] - routing.filled[r[x as usize] as usize];
            let gentle = if drop(p) <= drop(q) { p } else { q };
            let other = steepest_lower(grid, &routing.filled, gentle, &[r[gentle as usize]]);
            if other == NONE {
                routing.crossing += 1;
            } else {
                routing.receiver[gentle as usize] = other;
                routing.turned += 1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

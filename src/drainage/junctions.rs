//! Binary confluences (beyond the thesis; docs/geomorphology.md, `multiple_junctions`): D8 lets up to seven
//! neighbours drain into one node, so three or four rivers often meet at one lattice point, where real junctions
//! are binary (Shreve 1966). Wide rivers meeting at one point are drawn as one blob of water. Here, at a node
//! where three rivers or more meet, every river but the two largest is turned to another lower neighbour of its
//! last node, one where at most one river arrives so far: the sea, a lake, or a river it then joins one lattice
//! step up- or downstream. Every turn stays downhill on the filled surface (so the routing stays a forest in the
//! same upstream-first order) and never crosses another flow's diagonal.

use super::{
    grid::SphereGrid,
    routing::{accumulate, Routing, NONE},
};

/// Passes over the junctions: a turn can leave another node with three rivers, which the next pass splits.
const PASSES: usize = 4;

/// Splits the junctions of three rivers or more in `routing` where a lower neighbour allows it, and accumulates
/// the drainage area anew. `channel(k)` says whether node `k` can hold a river (land outside lakes); a channel
/// node is a river where at least `river_area` drains. Returns the turned rivers.
pub fn split_junctions(
    grid: &SphereGrid,
    routing: &mut Routing,
    channel: impl Fn(usize) -> bool,
    river_area: f64,
) -> usize {
    let n = grid.len();
    let mut turned = 0;
    for _ in 0..PASSES {
        let river: Vec<bool> = (0..n)
            .map(|k| channel(k) && routing.area[k] >= river_area)
            .collect();
        let mut arriving = vec![0u32; n];
        for k in (0..n).filter(|&k| river[k]) {
            if let Some(r) = receiver(routing, k) {
                arriving[r] += 1;
            }
        }
        let mut changed = false;
        for &junction in &routing.upstream_first {
            let junction = junction as usize;
            if !river[junction] || arriving[junction] < 3 {
                continue;
            }
            let mut donors: Vec<u32> = grid
                .neighbours(junction as u32)
                .iter()
                .copied()
                .filter(|&d| river[d as usize] && receiver(routing, d as usize) == Some(junction))
                .collect();
            // The largest two stay; the smallest is turned first.
            donors.sort_by(|a, b| routing.area[*b as usize].total_cmp(&routing.area[*a as usize]));
            for &donor in donors[2..].iter().rev() {
                let accepts = |x: u32| {
                    !channel(x as usize) || (river[x as usize] && arriving[x as usize] < 2)
                };
                if let Some(to) = turn(grid, routing, donor, junction as u32, accepts) {
                    routing.receiver[donor as usize] = to;
                    arriving[junction] -= 1;
                    arriving[to as usize] += 1;
                    turned += 1;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
        routing.area = accumulate(grid, routing);
    }
    turned
}

fn receiver(routing: &Routing, k: usize) -> Option<usize> {
    let r = routing.receiver[k];
    (r != NONE).then_some(r as usize)
}

/// The steepest lower neighbour of `donor` other than `junction` that `accepts` the river and whose step crosses
/// no flow along the lattice quad's other diagonal.
fn turn(
    grid: &SphereGrid,
    routing: &Routing,
    donor: u32,
    junction: u32,
    accepts: impl Fn(u32) -> bool,
) -> Option<u32> {
    let h = routing.filled[donor as usize];
    let mut best: Option<(f64, u32)> = None;
    for (next, angle) in grid.steps(donor) {
        let drop = h - routing.filled[next as usize];
        if next == junction || drop <= 0.0 || !accepts(next) || crosses(grid, routing, donor, next)
        {
            continue;
        }
        let slope = drop / angle;
        if best.is_none_or(|(s, _)| slope > s) {
            best = Some((slope, next));
        }
    }
    best.map(|(_, next)| next)
}

/// Whether a step from `a` to `b` along a quad's diagonal would cross a flow along its other diagonal: the two
/// nodes beside both ends (a diagonal step has exactly two) draining one into the other.
fn crosses(grid: &SphereGrid, routing: &Routing, a: u32, b: u32) -> bool {
    let beside: Vec<u32> = grid
        .neighbours(a)
        .iter()
        .copied()
        .filter(|x| grid.neighbours(b).contains(x))
        .collect();
    let [p, q] = beside[..] else {
        return false;
    };
    routing.receiver[p as usize] == q || routing.receiver[q as usize] == p
}

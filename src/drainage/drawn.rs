//! The network as drawn (beyond the thesis; docs/geomorphology.md, "The network as drawn"): the base lattice's
//! rivers with the streams of the finer levels joining them along their length, as a user descending sees them.
//! The base network's orders measure one scale; a stream that joins a first-order river halfway down makes it
//! second order below the junction, as Strahler (1957) counts on a map that shows that stream.

use serde::Serialize;

use super::{
    rivers::{order, Ordering},
    streams::Junction,
};

/// Strahler's and Horton's measures of the drawn network.
#[derive(Clone, Debug, Default, Serialize)]
pub struct DrawnMeasures {
    /// Reaches between junctions: the drawn reaches cut where streams join them.
    pub reaches: usize,
    /// The highest Strahler order drawn.
    pub strahler_max: u32,
    /// Strahler streams of each order (index 0: order 1) in the basins of order 3 and more.
    pub streams_per_order: Vec<usize>,
    /// Horton's bifurcation ratio of the drawn network (as [`super::rivers::DrainageMeasures::bifurcation_ratio`]).
    pub bifurcation_ratio: f64,
}

/// The ordering of drawn reaches whose reach `r` flows out at `outlets[r]`: onto a place along another (the head
/// of the reach below is its place 0), or nowhere (a mouth in the sea or a lake). A reach that others join along
/// its length is cut into pieces there, each flowing into the next.
pub fn ordering(outlets: &[Option<Junction>]) -> Ordering {
    let n = outlets.len();
    let mut splits: Vec<Vec<f64>> = vec![Vec::new(); n];
    for junction in outlets.iter().flatten() {
        if junction.at > 0.0 {
            splits[junction.reach].push(junction.at);
        }
    }
    let mut first = Vec::with_capacity(n);
    let mut pieces = 0;
    for places in &mut splits {
        places.sort_by(f64::total_cmp);
        places.dedup();
        first.push(pieces);
        pieces += places.len() + 1;
    }
    // The piece that begins at a junction (the first piece for the head).
    let piece_at =
        |j: &Junction| first[j.reach] + splits[j.reach].partition_point(|&at| at <= j.at);
    let mut downstream = vec![None; pieces];
    for r in 0..n {
        let last = first[r] + splits[r].len();
        for (piece, below) in downstream[first[r]..last].iter_mut().zip(first[r] + 1..) {
            *piece = Some(below);
        }
        downstream[last] = outlets[r].as_ref().map(piece_at);
    }
    order(&downstream)
}

/// The measures of [`ordering`].
pub fn measure(outlets: &[Option<Junction>]) -> DrawnMeasures {
    let ordering = ordering(outlets);
    DrawnMeasures {
        reaches: ordering.strahler.len(),
        strahler_max: ordering.strahler_max,
        streams_per_order: ordering.streams_per_order,
        bifurcation_ratio: ordering.bifurcation_ratio,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn into(reach: usize, at: f64) -> Option<Junction> {
        Some(Junction { reach, at })
    }

    #[test]
    fn streams_joining_along_first_order_rivers_raise_the_orders_below_them() {
        // Rivers 0 and 1 meet at the head of 2, which reaches the sea: orders 1, 1, 2.
        let rivers = vec![into(2, 0.0), into(2, 0.0), None];
        assert_eq!(ordering(&rivers).strahler, vec![1, 1, 2]);
        // A stream joining each of 0 and 1 halfway down: both second order below, the river below them third.
        let mut drawn = rivers.clone();
        drawn.extend([into(0, 1.5), into(1, 2.5)]);
        let o = ordering(&drawn);
        assert_eq!(o.strahler_max, 3);
        // Pieces: 0 above and below its junction, 1 likewise, 2, and the two streams.
        assert_eq!(o.strahler, vec![1, 2, 1, 2, 3, 1, 1]);
        // A stream joining the second-order river adds no order.
        let mut one = rivers.clone();
        one.push(into(2, 3.0));
        assert_eq!(ordering(&one).strahler_max, 2);
    }

    #[test]
    fn streams_joining_at_one_place_join_one_piece() {
        // Two streams join river 0 at the same place, a third further down.
        let drawn = vec![None, into(0, 2.0), into(0, 2.0), into(0, 4.0)];
        let o = ordering(&drawn);
        // River 0: above the first junction (1), below it (two first-order streams and the river: 2), below the
        // second (2).
        assert_eq!(o.strahler, vec![1, 2, 2, 1, 1, 1]);
    }
}

//! The sphere as one graph for flow routing: the lattice points of the six cube faces at one resolution, each
//! point once (a point on a face border or cube corner is shared by the faces that hold it, found by its integer
//! cube key), linked to its eight neighbours on every face that holds it. Flow thus crosses face borders like
//! any other step, with no seam.

use std::{cmp::Reverse, collections::BinaryHeap, collections::HashMap};

use rayon::prelude::*;

use glam::{DVec3, I64Vec3};

use crate::planet::{
    cube::FACES,
    heights::{area_weight, FaceLattice},
};

/// Lattice points of the sphere and their neighbours.
pub struct SphereGrid {
    /// Cells per face edge of the lattice the grid was made from.
    pub cells: u32,
    /// Unit direction of each node.
    pub directions: Vec<DVec3>,
    /// Area on the unit sphere each node stands for (summed over the faces that share it: 4 pi in all).
    pub areas: Vec<f64>,
    /// Node of each lattice point, indexed as [`FaceLattice::index`].
    node_of: Vec<u32>,
    /// Neighbours of node k: `neighbours[offsets[k]..offsets[k + 1]]`, without repeats, and the angle to each.
    offsets: Vec<u32>,
    neighbours: Vec<u32>,
    angles: Vec<f64>,
}

impl SphereGrid {
    /// The grid of `lattice`'s points (its heights are not read).
    pub fn new(lattice: &FaceLattice) -> Self {
        let c = lattice.cells;
        let mut ids: HashMap<I64Vec3, u32> = HashMap::new();
        let mut directions = Vec::new();
        let mut areas: Vec<f64> = Vec::new();
        let mut node_of = vec![0u32; lattice.data.len()];
        for face in 0..FACES {
            for j in 0..=c {
                for i in 0..=c {
                    let key = lattice.key(face, i, j);
                    let mut add = || {
                        directions.push(lattice.direction(key));
                        areas.push(0.0);
                        directions.len() as u32 - 1
                    };
                    // Only points on a face's border are shared with another face.
                    let border = i == 0 || j == 0 || i == c || j == c;
                    let id = if border {
                        *ids.entry(key).or_insert_with(add)
                    } else {
                        add()
                    };
                    areas[id as usize] += area_weight(c, i, j);
                    node_of[lattice.index(face, i, j)] = id;
                }
            }
        }
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); directions.len()];
        for face in 0..FACES {
            for j in 0..=c {
                for i in 0..=c {
                    let a = node_of[lattice.index(face, i, j)];
                    for (di, dj) in NEIGHBOURS {
                        let (ni, nj) = (i as i64 + di, j as i64 + dj);
                        if (0..=c as i64).contains(&ni) && (0..=c as i64).contains(&nj) {
                            lists[a as usize]
                                .push(node_of[lattice.index(face, ni as u32, nj as u32)]);
                        }
                    }
                }
            }
        }
        let mut offsets = Vec::with_capacity(lists.len() + 1);
        let mut neighbours = Vec::new();
        offsets.push(0);
        for mut list in lists {
            list.sort_unstable();
            list.dedup();
            neighbours.extend(list);
            offsets.push(neighbours.len() as u32);
        }
        let angles = (0..directions.len())
            .into_par_iter()
            .flat_map_iter(|k| {
                let range = offsets[k] as usize..offsets[k + 1] as usize;
                let here = directions[k];
                let (neighbours, directions) = (&neighbours, &directions);
                range.map(move |e| {
                    crate::planet::cube::angle(here, directions[neighbours[e] as usize])
                })
            })
            .collect();
        Self {
            cells: c,
            directions,
            areas,
            node_of,
            offsets,
            neighbours,
            angles,
        }
    }

    /// Nodes in the grid (lattice points shared by faces counted once).
    pub fn len(&self) -> usize {
        self.directions.len()
    }

    /// Whether the grid has no node.
    pub fn is_empty(&self) -> bool {
        self.directions.is_empty()
    }

    /// The node of lattice point (i, j) of `face`.
    pub fn node(&self, lattice: &FaceLattice, face: usize, i: u32, j: u32) -> u32 {
        self.node_of[lattice.index(face, i, j)]
    }

    /// The nodes beside `node`: its eight lattice neighbours (seven at a cube corner), across face edges.
    pub fn neighbours(&self, node: u32) -> &[u32] {
        let k = node as usize;
        &self.neighbours[self.offsets[k] as usize..self.offsets[k + 1] as usize]
    }

    /// The neighbours of `node` with the angle to each (radians on the unit sphere).
    pub fn steps(&self, node: u32) -> impl Iterator<Item = (u32, f64)> + '_ {
        let k = node as usize;
        let range = self.offsets[k] as usize..self.offsets[k + 1] as usize;
        self.neighbours[range.clone()]
            .iter()
            .copied()
            .zip(self.angles[range].iter().copied())
    }

    /// The angle between two nodes (radians on the unit sphere).
    pub fn angle(&self, a: u32, b: u32) -> f64 {
        crate::planet::cube::angle(self.directions[a as usize], self.directions[b as usize])
    }

    /// One value per node from a lattice (the value of a shared point is the first face's).
    pub fn values(&self, lattice: &FaceLattice) -> Vec<f64> {
        let mut out = vec![0.0; self.len()];
        for (k, &node) in self.node_of.iter().enumerate().rev() {
            out[node as usize] = lattice.data[k] as f64;
        }
        out
    }

    /// For every node, the angle to the nearest of `sources` along the grid (Dijkstra over neighbour steps) and
    /// which source that is; `f64::INFINITY` and `u32::MAX` beyond `limit`.
    pub fn nearest(&self, sources: &[u32], limit: f64) -> (Vec<f64>, Vec<u32>) {
        let mut distance = vec![f64::INFINITY; self.len()];
        let mut from = vec![u32::MAX; self.len()];
        let mut open = BinaryHeap::new();
        for &s in sources {
            distance[s as usize] = 0.0;
            from[s as usize] = s;
            open.push(Reverse((Ordered(0.0), s)));
        }
        while let Some(Reverse((Ordered(d), node))) = open.pop() {
            if d > distance[node as usize] {
                continue;
            }
            for (next, step) in self.steps(node) {
                let nd = d + step;
                if nd < distance[next as usize] && nd <= limit {
                    distance[next as usize] = nd;
                    from[next as usize] = from[node as usize];
                    open.push(Reverse((Ordered(nd), next)));
                }
            }
        }
        (distance, from)
    }

    /// Every quad of every face as its nodes: (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1).
    pub fn quads(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        let (c, side) = (self.cells as usize, self.cells as usize + 1);
        (0..FACES).flat_map(move |face| {
            (0..c).flat_map(move |j| {
                (0..c).map(move |i| {
                    let at = |di: usize, dj: usize| {
                        self.node_of[face * side * side + (j + dj) * side + i + di]
                    };
                    [at(0, 0), at(1, 0), at(0, 1), at(1, 1)]
                })
            })
        })
    }

    /// Writes one value per node back into every lattice point that holds the node.
    pub fn write(&self, values: &[f64], lattice: &mut FaceLattice) {
        for (k, &node) in self.node_of.iter().enumerate() {
            lattice.data[k] = values[node as usize] as f32;
        }
    }
}

/// The eight neighbours of a lattice point on its face.
const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// A finite f64 ordered for a priority queue.
#[derive(PartialEq)]
pub struct Ordered(pub f64);
impl Eq for Ordered {}
impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}
impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

//! The planet as a cube of six quadtrees projected onto a sphere (Section 3.1).
//!
//! Face f spans `normal + u * u_axis + v * v_axis` for u, v in [-1, 1] on the cube of half-size 1, with
//! `u_axis x v_axis = normal` (outward, counter-clockwise seen from outside). Normalising a cube point gives the
//! sphere point; scaling by the radius gives the planet. The orientation of every face is in docs/planet.md.

use glam::DVec3;

use crate::fast_hash::FastMap;

/// The six faces: +X, -X, +Y, -Y, +Z, -Z.
pub const FACES: usize = 6;

/// (normal, u axis, v axis) of each face.
pub const FACE_AXES: [(DVec3, DVec3, DVec3); FACES] = [
    (DVec3::X, DVec3::NEG_Z, DVec3::Y),
    (DVec3::NEG_X, DVec3::Z, DVec3::Y),
    (DVec3::Y, DVec3::X, DVec3::NEG_Z),
    (DVec3::NEG_Y, DVec3::X, DVec3::Z),
    (DVec3::Z, DVec3::X, DVec3::Y),
    (DVec3::NEG_Z, DVec3::NEG_X, DVec3::Y),
];

/// The point of face `face` at (u, v) in [-1, 1]^2 on the cube of half-size 1.
pub fn cube_point(face: usize, u: f64, v: f64) -> DVec3 {
    let (n, a, b) = FACE_AXES[face];
    n + a * u + b * v
}

/// The unit-sphere point above (u, v) of `face`.
pub fn sphere_point(face: usize, u: f64, v: f64) -> DVec3 {
    cube_point(face, u, v).normalize()
}

/// The face a direction points through, and its (u, v) there. Ties on an edge or corner go to the lowest face
/// index, so every direction has exactly one answer.
pub fn face_of(direction: DVec3) -> (usize, f64, f64) {
    let a = direction.abs();
    let face = if a.x >= a.y && a.x >= a.z {
        if direction.x >= 0.0 {
            0
        } else {
            1
        }
    } else if a.y >= a.z {
        if direction.y >= 0.0 {
            2
        } else {
            3
        }
    } else if direction.z >= 0.0 {
        4
    } else {
        5
    };
    let (n, u_axis, v_axis) = FACE_AXES[face];
    let p = direction / direction.dot(n);
    (face, p.dot(u_axis), p.dot(v_axis))
}

/// A map keyed by patch, hashed by [`FastHasher`](crate::fast_hash::FastHasher): the caches are looked up for
/// every patch the level of detail visits and every quadrant culled, each frame.
pub type PatchMap<V> = FastMap<PatchId, V>;

/// The angle between two directions, accurate for tiny angles too (atan2 of the cross and dot products; the
/// arc cosine of the dot product loses all precision below about 1e-7 rad, the size of a level-20 patch).
pub fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// An edge of a face, named by where it lies in (u, v).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Edge {
    /// u = -1
    West,
    /// u = +1
    East,
    /// v = -1
    South,
    /// v = +1
    North,
}

/// The four edges, in the order the code enumerates them.
pub const EDGES: [Edge; 4] = [Edge::West, Edge::East, Edge::South, Edge::North];

impl Edge {
    /// The point of this edge at parameter s in [-1, 1] (s runs along u for South/North, along v for West/East).
    pub fn point(self, face: usize, s: f64) -> DVec3 {
        match self {
            Edge::West => cube_point(face, -1.0, s),
            Edge::East => cube_point(face, 1.0, s),
            Edge::South => cube_point(face, s, -1.0),
            Edge::North => cube_point(face, s, 1.0),
        }
    }

    fn of(u: f64, v: f64) -> Edge {
        let candidates = [
            (Edge::West, u + 1.0),
            (Edge::East, 1.0 - u),
            (Edge::South, v + 1.0),
            (Edge::North, 1.0 - v),
        ];
        candidates
            .into_iter()
            .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            .map(|c| c.0)
            .unwrap_or(Edge::West)
    }
}

/// Which edge of which face meets `edge` of `face`, and whether the edge parameter runs the other way there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Adjacency {
    /// The neighbouring face.
    pub face: usize,
    /// Its edge that meets ours.
    pub edge: Edge,
    /// Whether the edge parameter runs the other way there.
    pub reversed: bool,
}

/// The face across `edge` of `face` (derived from the geometry, listed in docs/planet.md and tested for all 24
/// edges).
pub fn adjacent(face: usize, edge: Edge) -> Adjacency {
    // Step just beyond the middle of the edge, onto the neighbouring face.
    let mid = edge.point(face, 0.0);
    let (n, _, _) = FACE_AXES[face];
    let beyond = mid - n * 1e-6;
    let (other, u, v) = face_of(beyond);
    let other_edge = Edge::of(u, v);
    // Compare the direction of the edge parameter on both sides.
    let a0 = edge.point(face, -1.0);
    let param_there = |p: DVec3| {
        let (_, u, v) = face_of_on(other, p);
        match other_edge {
            Edge::West | Edge::East => v,
            Edge::South | Edge::North => u,
        }
    };
    Adjacency {
        face: other,
        edge: other_edge,
        reversed: param_there(a0) > 0.0,
    }
}

/// (u, v) of a cube point on the plane of `face` (the point need not lie on that face's square).
pub fn face_of_on(face: usize, p: DVec3) -> (usize, f64, f64) {
    let (n, u_axis, v_axis) = FACE_AXES[face];
    let q = p / p.dot(n);
    (face, q.dot(u_axis), q.dot(v_axis))
}

/// A quadtree patch: face, level (0 = the whole face) and position in the level's 2^level x 2^level grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PatchId {
    /// The cube face, 0 to 5.
    pub face: u8,
    /// The quadtree level.
    pub level: u8,
    /// Column in the level's grid (along u).
    pub x: u32,
    /// Row in the level's grid (along v).
    pub y: u32,
}

impl PatchId {
    /// The patch covering the whole of `face`.
    pub fn root(face: usize) -> Self {
        Self {
            face: face as u8,
            level: 0,
            x: 0,
            y: 0,
        }
    }

    /// Patches per face edge at this level.
    pub fn count(self) -> u32 {
        1 << self.level
    }

    /// Its place among the patches of its level, faces in order and each row-major: the index of per-patch
    /// tables of one level.
    pub fn index(self) -> usize {
        let count = self.count() as usize;
        (self.face as usize * count + self.y as usize) * count + self.x as usize
    }

    /// Side length in (u, v) units.
    pub fn size(self) -> f64 {
        2.0 / self.count() as f64
    }

    /// (u, v) of the patch's corner at its minimum u and v.
    pub fn origin(self) -> (f64, f64) {
        (
            -1.0 + self.x as f64 * self.size(),
            -1.0 + self.y as f64 * self.size(),
        )
    }

    /// (u, v) of the point at fraction (s, t) in [0, 1]^2 across the patch.
    pub fn uv(self, s: f64, t: f64) -> (f64, f64) {
        let (u0, v0) = self.origin();
        (u0 + s * self.size(), v0 + t * self.size())
    }

    /// The unit-sphere point at fraction (s, t) across the patch.
    pub fn sphere_point(self, s: f64, t: f64) -> DVec3 {
        let (u, v) = self.uv(s, t);
        sphere_point(self.face as usize, u, v)
    }

    /// The projected centre of the patch on the unit sphere (used by Eq. 6.1).
    pub fn center(self) -> DVec3 {
        self.sphere_point(0.5, 0.5)
    }

    /// Angular radius of the patch around its centre: the spherical cap of this radius contains the patch (its
    /// edges are great-circle arcs between the corners).
    pub fn cap_angle(self) -> f64 {
        let centre = self.center();
        self.corners()
            .iter()
            .map(|c| angle(*c, centre))
            .fold(0.0, f64::max)
    }

    /// The four corners on the unit sphere: (0,0), (1,0), (0,1), (1,1).
    pub fn corners(self) -> [DVec3; 4] {
        [
            self.sphere_point(0.0, 0.0),
            self.sphere_point(1.0, 0.0),
            self.sphere_point(0.0, 1.0),
            self.sphere_point(1.0, 1.0),
        ]
    }

    /// Child `q` (bit 0: +x half, bit 1: +y half).
    pub fn child(self, q: u32) -> Self {
        Self {
            face: self.face,
            level: self.level + 1,
            x: self.x * 2 + (q & 1),
            y: self.y * 2 + (q >> 1),
        }
    }

    /// The patch of `level` that `direction` points through (on the face [`face_of`] names).
    pub fn containing(direction: DVec3, level: u8) -> Self {
        let (face, u, v) = face_of(direction);
        let count = 1u64 << level;
        let cell = |t: f64| (((t + 1.0) * 0.5 * count as f64) as u64).min(count - 1) as u32;
        Self {
            face: face as u8,
            level,
            x: cell(u),
            y: cell(v),
        }
    }

    /// The patch one level up that contains this one (`None` for a root).
    pub fn parent(self) -> Option<Self> {
        (self.level > 0).then(|| Self {
            face: self.face,
            level: self.level - 1,
            x: self.x / 2,
            y: self.y / 2,
        })
    }

    /// The same-level patch across `edge`, on this face or the adjacent one.
    pub fn neighbour(self, edge: Edge) -> Self {
        let n = self.count() as i64;
        let (dx, dy) = match edge {
            Edge::West => (-1, 0),
            Edge::East => (1, 0),
            Edge::South => (0, -1),
            Edge::North => (0, 1),
        };
        let (x, y) = (self.x as i64 + dx, self.y as i64 + dy);
        if (0..n).contains(&x) && (0..n).contains(&y) {
            return Self {
                x: x as u32,
                y: y as u32,
                ..self
            };
        }
        // Across the face border: the point of the edge beside the patch centre, pushed just over the edge. The
        // edge is a line shared by both faces, so the position along it is preserved exactly.
        let (u, v) = self.uv(0.5 + 0.5 * dx as f64, 0.5 + 0.5 * dy as f64);
        let p = cube_point(
            self.face as usize,
            u + dx as f64 * 1e-9,
            v + dy as f64 * 1e-9,
        );
        let (face, u, v) = face_of(p);
        let size = self.size();
        let clamp = |c: f64| (((c + 1.0) / size).floor() as i64).clamp(0, n - 1) as u32;
        Self {
            face: face as u8,
            level: self.level,
            x: clamp(u),
            y: clamp(v),
        }
    }
}

//! The one patch mesh (Section 3.3): an n x n grid of vertices, two triangles per cell, plus skirts: strips hanging
//! below the four edges and the two midlines that hide cracks between patches of different levels. Vertices carry
//! no attributes: the vertex shader derives (i, j) from the index (grid vertices first, then n skirt vertices for
//! each of: south, north, west, east edge, vertical midline, horizontal midline).
//!
//! Indices are grouped by quadrant, so that the terrain pass draws each quadrant as its own instanced range (only
//! the instances that draw that quadrant) without a geometry shader. A midline skirt segment belongs to both
//! quadrants beside it: it closes the crack towards finer patches on the other side, and hides under the surface
//! when both sides are drawn.
//!
//! Also the sky dome's grid (beyond the thesis, glsl/sky.vert), and the upload of an index buffer.

use std::ops::Range;

use crate::gpu::{Access, Buffer, BufferDesc, Context, GpuError, MemoryLocation};

/// The index ranges of one quadrant, laid out as grid cells, edge skirts, then the two midline skirts.
#[derive(Clone, Debug, Default)]
pub struct QuadrantMesh {
    /// Its grid cells only: what the water pass's geometry shader turns into water (it drops skirts).
    pub grid: Range<u32>,
    /// Its grid cells and the skirts below the patch's edges: what the terrain pass always draws.
    pub core: Range<u32>,
    /// The skirt below the midline towards quadrant `q ^ 1` (the vertical midline) and towards `q ^ 2` (the
    /// horizontal one): needed only where that quadrant is not drawn, i.e. covered by finer patches.
    pub across: [Range<u32>; 2],
}

/// The index buffer and the ranges of each quadrant in it (bit 0: +i half, bit 1: +j half). The whole buffer is
/// every triangle at least once (midline skirts twice).
pub struct PatchMesh {
    /// Every quadrant's indices, one after the other.
    pub indices: Vec<u32>,
    /// Where each quadrant's cells and skirts lie in `indices`.
    pub quadrants: [QuadrantMesh; 4],
}

/// Builds the mesh for `n x n` vertices (n = 2^k + 1).
pub fn patch_mesh(n: u32) -> PatchMesh {
    let grid = |i: u32, j: u32| j * n + i;
    let skirt = |edge: u32, k: u32| n * n + edge * n + k;
    let m = (n - 1) / 2;
    let half = |k: u32| (k >= m) as u32;
    // Per quadrant: grid cells, edge skirts, the skirt towards q ^ 1, the skirt towards q ^ 2.
    let mut lists: [[Vec<u32>; 4]; 4] = Default::default();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                grid(i, j),
                grid(i + 1, j),
                grid(i, j + 1),
                grid(i + 1, j + 1),
            );
            lists[(half(i) | half(j) << 1) as usize][0].extend_from_slice(&[a, b, d, a, d, c]);
        }
    }
    for k in 0..n - 1 {
        // (first vertex, second vertex, skirt edge, list, the quadrants it belongs to with whether its winding is
        // reversed there). As built, a segment along +i faces +j and one along +j faces -i; every skirt must face
        // away from its quadrant, so that back faces can be culled (the surface with its skirts is closed).
        let segments = [
            (grid(k, 0), grid(k + 1, 0), 0, 1, vec![(half(k), true)]),
            (
                grid(k, n - 1),
                grid(k + 1, n - 1),
                1,
                1,
                vec![(half(k) | 2, false)],
            ),
            (
                grid(0, k),
                grid(0, k + 1),
                2,
                1,
                vec![(half(k) << 1, false)],
            ),
            (
                grid(n - 1, k),
                grid(n - 1, k + 1),
                3,
                1,
                vec![(1 | half(k) << 1, true)],
            ),
            (
                grid(m, k),
                grid(m, k + 1),
                4,
                2,
                vec![(half(k) << 1, true), (1 | half(k) << 1, false)],
            ),
            (
                grid(k, m),
                grid(k + 1, m),
                5,
                3,
                vec![(half(k), false), (half(k) | 2, true)],
            ),
        ];
        for (a, b, edge, list, quadrants) in segments {
            let (sa, sb) = (skirt(edge, k), skirt(edge, k + 1));
            for (q, reversed) in quadrants {
                let triangles = if reversed {
                    [b, a, sa, b, sa, sb]
                } else {
                    [a, b, sb, a, sb, sa]
                };
                lists[q as usize][list].extend_from_slice(&triangles);
            }
        }
    }
    let mut indices: Vec<u32> = Vec::new();
    let quadrants = lists.map(|parts| {
        let ranges = parts.map(|part| {
            let start = indices.len() as u32;
            indices.extend(part);
            start..indices.len() as u32
        });
        QuadrantMesh {
            grid: ranges[0].clone(),
            core: ranges[0].start..ranges[1].end,
            across: [ranges[2].clone(), ranges[3].clone()],
        }
    });
    PatchMesh { indices, quadrants }
}

/// The sky dome's triangles: `rings` bands of `segments` quads, vertex `ring * (segments + 1) + segment`.
pub fn dome_mesh(rings: u32, segments: u32) -> Vec<u32> {
    let vertex = |ring: u32, segment: u32| ring * (segments + 1) + segment;
    (0..rings)
        .flat_map(|ring| {
            (0..segments).flat_map(move |s| {
                [
                    vertex(ring, s),
                    vertex(ring + 1, s),
                    vertex(ring, s + 1),
                    vertex(ring, s + 1),
                    vertex(ring + 1, s),
                    vertex(ring + 1, s + 1),
                ]
            })
        })
        .collect()
}

/// `indices` in a device-local index buffer (which compute shaders may read, as water_triangles.comp does).
pub fn index_buffer(ctx: &Context, name: &str, indices: &[u32]) -> Result<Buffer, GpuError> {
    let buffer = ctx.create_buffer(&BufferDesc {
        name,
        size: std::mem::size_of_val(indices) as u64,
        uses: &[
            Access::IndexRead,
            Access::ComputeRead,
            Access::TransferWrite,
        ],
        location: MemoryLocation::GpuOnly,
    })?;
    ctx.run_and_wait(name, |rec| {
        rec.upload_buffer(&buffer, 0, bytemuck::cast_slice(indices))
    })?;
    Ok(buffer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrants_cover_the_grid_once_and_every_vertex_is_used() {
        let n = 33;
        let mesh = patch_mesh(n);
        let count = n * n + 6 * n;
        assert!(mesh.indices.iter().all(|&i| i < count));
        let mut used = vec![false; count as usize];
        for &i in &mesh.indices {
            used[i as usize] = true;
        }
        assert!(used.iter().all(|u| *u));
        // Grid cells once, outer skirts once, midline skirts twice.
        assert_eq!(
            mesh.indices.len() as u32,
            (n - 1) * (n - 1) * 6 + 4 * (n - 1) * 6 + 2 * 2 * (n - 1) * 6
        );
        assert_eq!(mesh.quadrants[0].grid.start, 0);
        assert_eq!(mesh.quadrants[3].across[1].end, mesh.indices.len() as u32);
        let slice = |r: &Range<u32>| &mesh.indices[r.start as usize..r.end as usize];
        for quadrant in &mesh.quadrants {
            // The grid range holds the quadrant's 16 x 16 cells and nothing else; the core adds its two edges.
            assert_eq!(quadrant.grid.len() as u32, (n - 1) * (n - 1) / 4 * 6);
            assert!(slice(&quadrant.grid).iter().all(|&v| v < n * n));
            assert_eq!(quadrant.core.start, quadrant.grid.start);
            assert_eq!(
                quadrant.core.len() - quadrant.grid.len(),
                2 * (n as usize - 1) / 2 * 6
            );
            // A midline skirt hangs from the midline between q and its neighbour across it.
            for (axis, across) in quadrant.across.iter().enumerate() {
                let midline_edge = 4 + axis as u32;
                assert_eq!(across.len() as u32, (n - 1) / 2 * 6);
                assert!(slice(across)
                    .iter()
                    .all(|&v| v < n * n || (v - n * n) / n == midline_edge));
            }
        }
        // Every grid cell's triangles sit in the quadrant of the cell.
        for (q, quadrant) in mesh.quadrants.iter().enumerate() {
            let range = quadrant.core.start..quadrant.across[1].end;
            for tri in mesh.indices[range.start as usize..range.end as usize].chunks(3) {
                if let Some(&v) = tri
                    .iter()
                    .find(|&&v| v < n * n && tri.iter().all(|&w| w < n * n))
                {
                    let (ci, cj) = (
                        tri.iter().map(|v| v % n).sum::<u32>(),
                        tri.iter().map(|v| v / n).sum::<u32>(),
                    );
                    let quadrant = ((ci * 2 >= 3 * (n - 1)) as usize)
                        | (((cj * 2 >= 3 * (n - 1)) as usize) << 1);
                    assert_eq!(quadrant, q, "triangle with vertex {v}");
                }
            }
        }
    }

    /// The terrain pass culls back faces: every triangle must face outwards, grid cells up (counter-clockwise
    /// seen from outside, i x j = up) and skirts away from their quadrant, or a crack would show through.
    #[test]
    fn every_triangle_faces_outwards() {
        let n = 33;
        let mesh = patch_mesh(n);
        // Grid vertices at (i, j, 0), skirt vertices below their edge's grid points at z = -1.
        let m = (n - 1) / 2;
        let position = |v: u32| -> [f64; 3] {
            if v < n * n {
                return [(v % n) as f64, (v / n) as f64, 0.0];
            }
            let (edge, k) = ((v - n * n) / n, ((v - n * n) % n) as f64);
            let (i, j) = match edge {
                0 => (k, 0.0),
                1 => (k, (n - 1) as f64),
                2 => (0.0, k),
                3 => ((n - 1) as f64, k),
                4 => (m as f64, k),
                _ => (k, m as f64),
            };
            [i, j, -1.0]
        };
        for (q, quadrant) in mesh.quadrants.iter().enumerate() {
            let centre = [
                (m as f64) * (0.5 + (q & 1) as f64),
                (m as f64) * (0.5 + (q >> 1) as f64),
            ];
            let range = quadrant.core.start as usize..quadrant.across[1].end as usize;
            for tri in mesh.indices[range].chunks(3) {
                let [a, b, c] = [0, 1, 2].map(|k| position(tri[k]));
                let (e, f) = (
                    [0, 1, 2].map(|k| b[k] - a[k]),
                    [0, 1, 2].map(|k| c[k] - a[k]),
                );
                let normal = [
                    e[1] * f[2] - e[2] * f[1],
                    e[2] * f[0] - e[0] * f[2],
                    e[0] * f[1] - e[1] * f[0],
                ];
                if tri.iter().all(|&v| v < n * n) {
                    assert!(normal[2] > 0.0, "grid triangle {tri:?} faces down");
                } else {
                    let middle = [0, 1].map(|k| (a[k] + b[k] + c[k]) / 3.0 - centre[k]);
                    let away = normal[0] * middle[0] + normal[1] * middle[1];
                    assert!(
                        away > 0.0,
                        "skirt triangle {tri:?} of quadrant {q} faces inwards"
                    );
                }
            }
        }
    }
}

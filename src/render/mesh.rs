//! The one patch mesh (Section 3.3): an n x n grid of vertices, two triangles per cell, plus a skirt along each
//! edge (a strip hanging below the edge) that hides cracks between patches of different levels. Vertices carry no
//! attributes: the vertex shader derives (i, j) from the index (grid vertices first, then 4 x n skirt vertices:
//! south, north, west, east edges, then 2 x n skirt vertices along the vertical and horizontal midlines). The
//! midline skirts close the cracks between a patch's drawn quadrants and the finer patches beside them; the
//! geometry shader draws them only beside a drawn quadrant.

/// Indices of the grid and skirt triangles.
pub fn patch_indices(n: u32) -> Vec<u32> {
    let grid = |i: u32, j: u32| j * n + i;
    let skirt = |edge: u32, k: u32| n * n + edge * n + k;
    let m = (n - 1) / 2;
    let mut out = Vec::with_capacity(((n - 1) * (n - 1) * 6 + 6 * (n - 1) * 6) as usize);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                grid(i, j),
                grid(i + 1, j),
                grid(i, j + 1),
                grid(i + 1, j + 1),
            );
            out.extend_from_slice(&[a, b, d, a, d, c]);
        }
    }
    for k in 0..n - 1 {
        let edges = [
            (grid(k, 0), grid(k + 1, 0), 0),
            (grid(k, n - 1), grid(k + 1, n - 1), 1),
            (grid(0, k), grid(0, k + 1), 2),
            (grid(n - 1, k), grid(n - 1, k + 1), 3),
            (grid(m, k), grid(m, k + 1), 4),
            (grid(k, m), grid(k + 1, m), 5),
        ];
        for (a, b, edge) in edges {
            let (sa, sb) = (skirt(edge, k), skirt(edge, k + 1));
            out.extend_from_slice(&[a, b, sb, a, sb, sa]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_index_is_a_vertex_and_every_vertex_is_used() {
        let n = 33;
        let indices = patch_indices(n);
        let count = n * n + 6 * n;
        assert!(indices.iter().all(|&i| i < count));
        let mut used = vec![false; count as usize];
        for &i in &indices {
            used[i as usize] = true;
        }
        assert!(used.iter().all(|u| *u));
        assert_eq!(indices.len() as u32, (n - 1) * (n - 1) * 6 + 6 * (n - 1) * 6);
    }
}

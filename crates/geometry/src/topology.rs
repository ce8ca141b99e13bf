//! The edge topology of a triangle mesh as read from a file: whether it is closed (every edge
//! in exactly two faces), how many boundary edges it has (edges in one face), and its shells
//! (faces joined through shared edges).
//!
//! Written here rather than with numpy and scipy (sorted int64 edge keys, an argsort, a sparse
//! face graph and `connected_components`) because that was half of reading a large mesh in a
//! fresh process, where every temporary array is memory faulted in: one counting sort of the
//! sides by their lower vertex (as the hierarchy's edge normals) and a union–find over the
//! faces (docs/environment.md, session 19).

/// Closedness, boundary edges and shells of a mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Topology {
    /// Every edge in exactly two faces.
    pub watertight: bool,
    /// Number of edges in exactly one face.
    pub boundary: usize,
    /// Per face its shell, numbered in the order of each shell's first face.
    pub shell: Vec<u32>,
    /// Number of shells.
    pub shells: usize,
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up; // path halving
        x = up;
    }
    x
}

/// The sides of `faces` (side 3 t + k: edge k of triangle t, from corner k to corner k + 1)
/// bucketed by their lower vertex with a counting sort, in increasing side order within a
/// bucket: (bucket starts per vertex (n_vertices + 1), per side (other vertex, side)).
pub(crate) fn sides_by_lower_vertex(
    n_vertices: usize,
    faces: &[[u32; 3]],
) -> (Vec<u32>, Vec<(u32, u32)>) {
    let n_sides = 3 * faces.len();
    let ends = |side: usize| {
        let f = &faces[side / 3];
        let (a, b) = (f[side % 3], f[(side + 1) % 3]);
        (a.min(b), a.max(b))
    };
    let mut start = vec![0u32; n_vertices + 1];
    for side in 0..n_sides {
        start[ends(side).0 as usize + 1] += 1;
    }
    for v in 0..n_vertices {
        start[v + 1] += start[v];
    }
    let mut other = vec![(0u32, 0u32); n_sides];
    let mut next = start.clone();
    for side in 0..n_sides {
        let (lo, hi) = ends(side);
        let at = &mut next[lo as usize];
        other[*at as usize] = (hi, side as u32);
        *at += 1;
    }
    (start, other)
}

/// The topology of `faces` (vertex indices below `n_vertices`, checked by the caller).
pub fn topology(n_vertices: usize, faces: &[[u32; 3]]) -> Topology {
    // sides bucketed by lower vertex, each bucket's by other vertex: an edge's sides together
    let (start, mut other) = sides_by_lower_vertex(n_vertices, faces);
    let mut parent: Vec<u32> = (0..faces.len() as u32).collect();
    let (mut watertight, mut boundary) = (true, 0);
    for v in 0..n_vertices {
        let bucket = &mut other[start[v] as usize..start[v + 1] as usize];
        bucket.sort_unstable();
        for edge in bucket.chunk_by(|x, y| x.0 == y.0) {
            watertight &= edge.len() == 2;
            boundary += (edge.len() == 1) as usize;
            // the faces of an edge in one shell
            for pair in edge.windows(2) {
                let face = |i: usize| pair[i].1 / 3;
                let (a, b) = (find(&mut parent, face(0)), find(&mut parent, face(1)));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
    }
    // shells numbered by their first face
    let mut label = vec![u32::MAX; faces.len()];
    let mut shell = Vec::with_capacity(faces.len());
    let mut shells = 0;
    for f in 0..faces.len() as u32 {
        let root = find(&mut parent, f) as usize;
        if label[root] == u32::MAX {
            label[root] = shells;
            shells += 1;
        }
        shell.push(label[root]);
    }
    Topology {
        watertight,
        boundary,
        shell,
        shells: shells as usize,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_tetrahedra_an_open_strip_and_a_fin() {
        // two closed tetrahedra: watertight, two shells in the order of their first faces
        let tet = |o: u32| {
            [
                [o, o + 2, o + 1],
                [o, o + 1, o + 3],
                [o + 1, o + 2, o + 3],
                [o, o + 3, o + 2],
            ]
        };
        let mut f: Vec<[u32; 3]> = tet(4).to_vec();
        f.extend(tet(0));
        let t = topology(8, &f);
        assert_eq!(
            t,
            Topology {
                watertight: true,
                boundary: 0,
                shell: vec![0, 0, 0, 0, 1, 1, 1, 1],
                shells: 2
            }
        );
        // an open strip of two triangles: 4 boundary edges, one shell
        let t = topology(4, &[[0, 1, 2], [2, 1, 3]]);
        assert!(!t.watertight);
        assert_eq!((t.boundary, t.shells), (4, 1));
        // a fin: a third face on one edge of a tetrahedron (not watertight, one shell, the
        // fin's two free edges on the boundary)
        let mut f = tet(0).to_vec();
        f.push([0, 2, 4]);
        let t = topology(5, &f);
        assert!(!t.watertight);
        assert_eq!((t.boundary, t.shells, t.shell[4]), (2, 1, 0));
        // faces sharing only a vertex are apart
        let t = topology(5, &[[0, 1, 2], [0, 3, 4]]);
        assert_eq!((t.shells, t.shell.clone()), (2, vec![0, 1]));
    }
}

//! Welding the vertices of a triangle soup: an STL file repeats each shared vertex once per
//! triangle, and CAD exports leave float noise at seams.
//!
//! Written here rather than with numpy (`np.unique` on a 64-bit hash of the rounded rows, then
//! an order-restoring argsort) because that was the largest part of reading a big mesh; one
//! pass with a hash map keeps the first appearance's order directly (reading a 1 M-triangle
//! STL, `load_mesh`: 0.61 → 0.46 s warm; docs/environment.md).
use rustc_hash::FxHashMap;

/// The merge key of a vertex: its coordinates rounded to integers of 1e-8 (8 decimals of the
/// file's unit, as trimesh merges), ties to even as numpy's `rint`; with `exact`, the bit
/// patterns of the coordinates (−0 as +0).
#[inline]
fn key(v: &[f64; 3], exact: bool) -> [i64; 3] {
    if exact {
        v.map(|x| (x + 0.0).to_bits() as i64)
    } else {
        v.map(|x| (x * 1e8).round_ties_even() as i64)
    }
}

/// Merges the vertices whose coordinates agree to 8 decimals (beyond ±9e10, where that
/// overflows 64-bit integers, the equal ones), keeping the order and the coordinates of their
/// first appearance, and re-indexes `faces` to the merged vertices. The vertices must be
/// finite and every face index in `0..vertices.len()` (`Err` names the first that is not).
pub fn weld_vertices(
    vertices: &[[f64; 3]],
    faces: &mut [[i64; 3]],
) -> Result<Vec<[f64; 3]>, String> {
    if let Some(i) = vertices
        .iter()
        .position(|v| !v.iter().all(|x| x.is_finite()))
    {
        return Err(format!(
            "vertex {i} has non-finite coordinates {:?}",
            vertices[i]
        ));
    }
    let n = vertices.len() as i64;
    for (f, face) in faces.iter().enumerate() {
        if let Some(&i) = face.iter().find(|&&i| i < 0 || i >= n) {
            return Err(format!(
                "face {f} indexes vertex {i}, out of the {n} vertices"
            ));
        }
    }
    let exact = vertices.iter().flatten().any(|x| x.abs() >= 9e10);
    let mut index: FxHashMap<[i64; 3], u32> = FxHashMap::default();
    index.reserve(vertices.len() / 4);
    let mut merged = Vec::with_capacity(vertices.len() / 4);
    let remap: Vec<u32> = vertices
        .iter()
        .map(|v| {
            *index.entry(key(v, exact)).or_insert_with(|| {
                merged.push(*v);
                (merged.len() - 1) as u32
            })
        })
        .collect();
    for face in faces.iter_mut() {
        for i in face.iter_mut() {
            *i = remap[*i as usize] as i64;
        }
    }
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merges_within_eight_decimals_in_order_of_first_appearance() {
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0 + 4e-9, 0.0, -0.0], // the same as vertex 1 to 8 decimals
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0 + 6e-9, 0.0, 0.0], // rounds to the next 1e-8: another vertex
        ];
        let mut f = [[0, 1, 3], [4, 2, 3], [0, 5, 3]];
        let merged = weld_vertices(&v, &mut f).unwrap();
        assert_eq!(merged, vec![v[0], v[1], v[3], v[5]]);
        assert_eq!(f, [[0, 1, 2], [0, 1, 2], [0, 3, 2]]);
    }

    #[test]
    fn huge_coordinates_merge_when_equal_and_bad_input_is_named() {
        let v = [[1e11, 0.0, 0.0], [1e11, 0.0, -0.0], [1e11 + 1e-4, 0.0, 0.0]];
        let mut f = [[0, 1, 2]];
        assert_eq!(weld_vertices(&v, &mut f).unwrap().len(), 2);
        let mut f = [[0, 1, 3]];
        let e = weld_vertices(&v, &mut f).unwrap_err();
        assert!(e.contains("face 0 indexes vertex 3"), "{e}");
        let e = weld_vertices(&[[f64::NAN, 0.0, 0.0]], &mut []).unwrap_err();
        assert!(e.contains("vertex 0"), "{e}");
    }
}

//! Triangle meshes as contact obstacles (docs/contact.md): the [`Shape`] of contact answered by
//! the bounding volume hierarchy of the surroundings' geometry crate.
//!
//! Signed distance and normal come from [`Surface::project_point`] (sign by the angle-weighted
//! pseudo-normal). Derivatives are exact where they exist: with the closest point inside a face
//! the normal is the face normal and the distance's Hessian is 0; on an edge or a vertex the
//! distance is that to a point, Hessian (I − n nᵀ)/d, or to the edge's line, Hessian
//! (I − n nᵀ − l lᵀ)/d with l the edge direction (the distance does not change along it).
//!
//! Warm start: each query starts the hierarchy search from the triangle the previous query of
//! this obstacle found (the samples of a cable are visited in order along it, so the previous
//! sample's triangle is near), held in an atomic so that the shape stays `Sync`.
use crate::contact::{PointQuery, Shape};
use geometry::closest::{point_triangle, Feature};
use geometry::{Surface, TriMesh, V3};
use nalgebra::{Matrix3, Vector3};
use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// A closed triangle mesh (solid inside), in its own frame.
pub struct MeshShape {
    mesh: Arc<TriMesh>,
    /// Largest distance of a vertex from the local origin.
    radius: f64,
    /// The triangle of the last query (warm start).
    hint: AtomicUsize,
}

impl MeshShape {
    pub fn new(mesh: TriMesh, vertices: &[V3]) -> Self {
        let radius = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        MeshShape {
            mesh: Arc::new(mesh),
            radius,
            hint: AtomicUsize::new(usize::MAX),
        }
    }

    pub fn n_triangles(&self) -> usize {
        self.mesh.n_triangles()
    }
}

impl fmt::Debug for MeshShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "MeshShape({} triangles)", self.mesh.n_triangles())
    }
}

impl Shape for MeshShape {
    fn query(&self, p: &Vector3<f64>) -> PointQuery {
        let hint = self.hint.load(Ordering::Relaxed);
        let pr = self
            .mesh
            .project_point(p, f64::INFINITY, hint)
            .expect("a mesh has triangles: an unbounded query finds one");
        self.hint.store(pr.feature, Ordering::Relaxed);
        let d = pr.distance;
        let n = pr.normal;
        let face_n = self.mesh.face_normal(pr.feature);
        // On a face (also: on a face's edge or vertex with p straight above the face) the
        // normal is the face's: flat.
        if d == 0.0 || n.dot(&face_n).abs() >= 1.0 - 1e-12 {
            return PointQuery {
                distance: d,
                normal: n,
                hessian: Matrix3::zeros(),
            };
        }
        let proj = Matrix3::identity() - n * n.transpose();
        let hessian = match self.feature(p, pr.feature) {
            Feature::Edge(k) => {
                let tri = self.triangle(pr.feature);
                let l = (tri[(k as usize + 1) % 3] - tri[k as usize]).normalize();
                (proj - l * l.transpose()) / d
            }
            _ => proj / d,
        };
        PointQuery {
            distance: d,
            normal: n,
            hessian,
        }
    }
    fn distance_within(&self, p: &Vector3<f64>, bound: f64) -> f64 {
        let hint = self.hint.load(Ordering::Relaxed);
        match self.mesh.project_point(p, bound, hint) {
            Some(pr) => {
                self.hint.store(pr.feature, Ordering::Relaxed);
                pr.distance
            }
            None => f64::INFINITY,
        }
    }
    fn min_radius(&self) -> f64 {
        0.0 // sharp edges
    }
    fn bounding_radius(&self) -> f64 {
        self.radius
    }
    fn clone_box(&self) -> Box<dyn Shape> {
        Box::new(MeshShape {
            mesh: self.mesh.clone(),
            radius: self.radius,
            hint: AtomicUsize::new(self.hint.load(Ordering::Relaxed)),
        })
    }
}

impl MeshShape {
    fn triangle(&self, t: usize) -> [V3; 3] {
        self.mesh.triangle(t)
    }
    fn feature(&self, p: &V3, t: usize) -> Feature {
        let [a, b, c] = self.triangle(t);
        point_triangle(p, &a, &b, &c).1
    }
}

/// A box with half extents `half` about the origin as a closed 12-triangle mesh (tests).
pub fn box_mesh(half: Vector3<f64>) -> MeshShape {
    let mut v = Vec::new();
    for k in 0..8 {
        v.push(Vector3::new(
            if k & 1 == 0 { -half.x } else { half.x },
            if k & 2 == 0 { -half.y } else { half.y },
            if k & 4 == 0 { -half.z } else { half.z },
        ));
    }
    // Outward-facing (counter-clockwise seen from outside).
    let f: Vec<[u32; 3]> = vec![
        [0, 2, 3],
        [0, 3, 1], // z−
        [4, 5, 7],
        [4, 7, 6], // z+
        [0, 1, 5],
        [0, 5, 4], // y−
        [2, 6, 7],
        [2, 7, 3], // y+
        [0, 4, 6],
        [0, 6, 2], // x−
        [1, 3, 7],
        [1, 7, 5], // x+
    ];
    MeshShape::new(TriMesh::new(&v, &f).unwrap(), &v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Cuboid;

    /// The mesh of a box answers as the box primitive (distance, normal, Hessian) in every
    /// region: faces, edges, vertices, inside.
    #[test]
    fn box_mesh_matches_the_box_primitive() {
        let half = Vector3::new(0.03, 0.04, 0.05);
        let mesh = box_mesh(half);
        let cuboid = Cuboid { half };
        let mut k = 0;
        for i in -3..=3 {
            for j in -3..=3 {
                for l in -3..=3 {
                    let p = Vector3::new(0.021 * i as f64, 0.027 * j as f64, 0.033 * l as f64)
                        + Vector3::new(1e-4, 2e-4, 3e-4);
                    let (a, b) = (mesh.query(&p), cuboid.query(&p));
                    assert!((a.distance - b.distance).abs() < 1e-14, "{p}");
                    assert!((a.normal - b.normal).norm() < 1e-12, "{p}");
                    if a.distance > 0.0 {
                        assert!(
                            (a.hessian - b.hessian).amax() < 1e-9 * (1.0 + b.hessian.amax()),
                            "{p}: {} vs {}",
                            a.hessian,
                            b.hessian
                        );
                    }
                    k += 1;
                }
            }
        }
        assert_eq!(k, 343);
    }
}

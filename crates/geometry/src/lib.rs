//! Distance queries against the surroundings of a cable: triangle meshes (with a bounding
//! volume hierarchy) and analytic primitives (plane, box, cylinder, sphere).
//!
//! Every shape answers two queries through the [`Surface`] trait, the extension point that
//! contact and clearance share:
//! - [`Surface::project_point`]: signed distance (negative inside), closest surface point and
//!   outward normal;
//! - [`Surface::closest_to_segment`]: unsigned distance of a segment, closest points on both,
//!   and the normal at the surface point.
//!
//! Both take a distance bound (nothing farther is searched) and a warm-start hint (the
//! feature found by the previous query of the same point or segment: with a moving cable,
//! consecutive steps are close, so its distance prunes the hierarchy at once).
//! [`clearance`] evaluates the clearance of cables over saved steps against parts moving
//! rigidly with their bodies.

pub mod clearance;
pub mod closest;
pub mod mesh;
pub mod primitives;
pub mod topology;
pub mod weld;
mod wide;

use nalgebra::Vector3;

pub type V3 = Vector3<f64>;

pub use clearance::{clearance, Clearance, ClearanceError, Control, Part, RigidMap};
pub use mesh::{MeshError, TriMesh};
pub use primitives::{Cuboid, Cylinder, HalfSpace, Sphere};
pub use topology::{topology, Topology};
pub use weld::weld_vertices;

/// Closest point of a surface to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointProjection {
    /// Signed distance: positive outside, negative inside (m).
    pub distance: f64,
    /// Closest point on the surface.
    pub point: V3,
    /// Outward unit normal at `point` (for a point off the surface: ±(p − point)/|p − point|).
    pub normal: V3,
    /// Feature index (triangle of a mesh; 0 for primitives): the warm-start hint.
    pub feature: usize,
}

/// Closest points of a segment and a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentProjection {
    /// Unsigned distance between the segment and the surface (0 if they cross) (m).
    pub distance: f64,
    /// Parameter of the closest point on the segment a + t (b − a), t in [0, 1].
    pub t: f64,
    /// Closest point on the segment.
    pub on_segment: V3,
    /// Closest point on the surface.
    pub on_surface: V3,
    /// Outward unit normal of the surface at `on_surface`.
    pub normal: V3,
    /// Feature index (triangle of a mesh; 0 for primitives).
    pub feature: usize,
}

/// A surface that answers closest-point queries. `max_distance` bounds the search: `None` when
/// nothing is closer (for points: in unsigned distance). `hint` is a feature index from a
/// previous query (`usize::MAX` for none); it only speeds the search up.
pub trait Surface: Send + Sync {
    fn project_point(&self, p: &V3, max_distance: f64, hint: usize) -> Option<PointProjection>;
    fn closest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        max_distance: f64,
        hint: usize,
    ) -> Option<SegmentProjection>;
}

/// Any shape of the surroundings.
pub enum Shape {
    Mesh(TriMesh),
    HalfSpace(HalfSpace),
    Cuboid(Cuboid),
    Cylinder(Cylinder),
    Sphere(Sphere),
}

impl Shape {
    fn surface(&self) -> &dyn Surface {
        match self {
            Shape::Mesh(s) => s,
            Shape::HalfSpace(s) => s,
            Shape::Cuboid(s) => s,
            Shape::Cylinder(s) => s,
            Shape::Sphere(s) => s,
        }
    }
}

impl Surface for Shape {
    #[inline]
    fn project_point(&self, p: &V3, max_distance: f64, hint: usize) -> Option<PointProjection> {
        self.surface().project_point(p, max_distance, hint)
    }
    #[inline]
    fn closest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        max_distance: f64,
        hint: usize,
    ) -> Option<SegmentProjection> {
        self.surface().closest_to_segment(a, b, max_distance, hint)
    }
}

/// A height-field surface z = h(x, y) over [0, 1]² (n × n quads, 2 n² triangles, normals
/// up): vertices and triangles. The benchmarks' and tests' bumpy surfaces.
pub fn height_field(n: usize, h: impl Fn(f64, f64) -> f64) -> (Vec<V3>, Vec<[u32; 3]>) {
    let mut v = Vec::with_capacity((n + 1) * (n + 1));
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            v.push(V3::new(x, y, h(x, y)));
        }
    }
    let mut f = Vec::with_capacity(2 * n * n);
    for i in 0..n {
        for j in 0..n {
            let a = (i * (n + 1) + j) as u32;
            let (b, c, d) = (a + n as u32 + 1, a + 1, a + n as u32 + 2);
            f.push([a, b, d]);
            f.push([a, d, c]);
        }
    }
    (v, f)
}

/// Uniform numbers in [0, 1) from a 64-bit linear congruential generator (Knuth's MMIX
/// constants): the tests' reproducible random points and segments.
#[cfg(test)]
pub(crate) fn test_random(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

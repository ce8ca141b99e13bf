//! Contact of the cable with rigid surroundings (docs/contact.md): obstacles answer
//! closest-point queries (signed distance, outward normal and its gradient), and the contact
//! term adds a smooth barrier on the gap between the cable surface and the obstacle, with
//! smoothed Coulomb friction, to the assembly.
//!
//! Gap at a point x of the centreline: g = φ(x) − r (φ the obstacle's signed distance, r the
//! cable radius). Energy per edge: κ Σ_k w_k b(g(x_k)) over sample points x_k = (1−t_k)a + t_k b
//! of the edge (composite trapezoid rule, w_k the arc-length weights), with the IPC barrier
//! b(g) = −(g − d̂)² ln(g/d̂) on (0, d̂), zero beyond d̂, continued below g_s = d̂/1000 by its
//! second-order Taylor polynomial (C², defined for any gap: a penetrated start, a predictor or a
//! moving obstacle never make it undefined).
//!
//! Friction (smoothed Coulomb, IPC's f₁ with a stick zone of width ε): per sample the force
//! μ λ f₁(|u_T|) u_T/|u_T| opposes the tangential displacement u_T = (I − n nᵀ)(x − x_ref) since
//! the start of the step (statics: since the last equilibrium, ε = `stick_distance`; dynamics:
//! within the time step, ε = `stick_velocity` · h), with λ = −κ w b'(g) the sample's normal force
//! and n the normal, both at the current iterate (not lagged; the Jacobian is exact and
//! non-symmetric). Contact with a rigid obstacle couples only the two nodes of an edge: the
//! block-tridiagonal structure stays.
use crate::assembly::{Eval, KinkAt, Part, Term, Workspace};
use crate::friction::{f1_over, stick_cut};
use crate::model::{NodeKind, Pose, Rod};
use crate::rotation::rotation_matrix;
use crate::state::State;
use geometry::primitives;
use nalgebra::{Matrix3, Vector3};
use std::fmt;

/// Signed distance of a point to a shape, its gradient (the outward normal) and the gradient of
/// the normal (the Hessian of the distance; zero on flat parts): the geometry crate's, whose
/// primitives' distance code contact and clearance share.
pub type PointQuery = geometry::primitives::PointDistance;

/// Closest points between a segment and a shape.
#[derive(Clone, Copy, Debug)]
pub struct SegmentQuery {
    /// Signed distance of the segment to the surface (negative: the segment penetrates).
    pub distance: f64,
    /// Parameter of the segment's closest point, in [0, 1].
    pub t: f64,
    pub point: Vector3<f64>,
    /// Closest point on the surface and outward normal there.
    pub closest: Vector3<f64>,
    pub normal: Vector3<f64>,
}

/// A solid convex shape in its own frame: the geometry an obstacle answers queries with.
/// Meshes implement this too (after the merge with the mesh-distance crate).
pub trait Shape: Send + Sync + fmt::Debug {
    /// Signed distance (positive outside), normal and its gradient at a point (local frame).
    fn query(&self, p: &Vector3<f64>) -> PointQuery;
    /// The signed distance alone (broad phase).
    fn distance(&self, p: &Vector3<f64>) -> f64 {
        self.query(p).distance
    }
    /// Broad phase: the signed distance if the point is within `bound` of the surface, else
    /// the exact distance or ∞ (a mesh prunes its hierarchy with the bound and answers ∞; a
    /// point deeper than `bound` inside a mesh also reads as far).
    fn distance_within(&self, p: &Vector3<f64>, _bound: f64) -> f64 {
        self.distance(p)
    }
    /// The smallest radius of curvature of the surface that a cable can touch (0: sharp
    /// edges, ∞: flat); it sets the sample spacing along the edges.
    fn min_radius(&self) -> f64;
    /// A bound on the distance from the local origin to any surface point (∞: unbounded).
    fn bounding_radius(&self) -> f64;
    fn clone_box(&self) -> Box<dyn Shape>;
}

impl Clone for Box<dyn Shape> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// Half-space below the plane z = 0 of its frame (normal +z).
#[derive(Clone, Copy, Debug)]
pub struct Plane;

/// Sphere of a radius about the origin.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub radius: f64,
}

/// Solid cylinder about the z axis, centred at the origin, with flat caps at z = ±length/2
/// (length = ∞: infinite, no caps).
#[derive(Clone, Copy, Debug)]
pub struct Cylinder {
    pub radius: f64,
    pub length: f64,
}

/// Box with half extents along the axes, centred at the origin.
#[derive(Clone, Copy, Debug)]
pub struct Cuboid {
    pub half: Vector3<f64>,
}

impl Shape for Plane {
    fn query(&self, p: &Vector3<f64>) -> PointQuery {
        primitives::half_space_local(p)
    }
    fn distance(&self, p: &Vector3<f64>) -> f64 {
        primitives::half_space_local(p).distance
    }
    fn min_radius(&self) -> f64 {
        f64::INFINITY
    }
    fn bounding_radius(&self) -> f64 {
        f64::INFINITY
    }
    fn clone_box(&self) -> Box<dyn Shape> {
        Box::new(*self)
    }
}

impl Shape for Sphere {
    fn query(&self, p: &Vector3<f64>) -> PointQuery {
        primitives::sphere_local(self.radius, p, true)
    }
    fn distance(&self, p: &Vector3<f64>) -> f64 {
        primitives::sphere_local(self.radius, p, false).distance
    }
    fn min_radius(&self) -> f64 {
        self.radius
    }
    fn bounding_radius(&self) -> f64 {
        self.radius
    }
    fn clone_box(&self) -> Box<dyn Shape> {
        Box::new(*self)
    }
}

impl Shape for Cylinder {
    fn distance(&self, p: &Vector3<f64>) -> f64 {
        primitives::cylinder_local_distance(self.radius, 0.5 * self.length, p)
    }
    fn query(&self, p: &Vector3<f64>) -> PointQuery {
        primitives::cylinder_local(self.radius, 0.5 * self.length, p, true)
    }
    fn min_radius(&self) -> f64 {
        if self.length.is_finite() {
            0.0 // sharp rims
        } else {
            self.radius
        }
    }
    fn bounding_radius(&self) -> f64 {
        (self.radius * self.radius + 0.25 * self.length * self.length).sqrt()
    }
    fn clone_box(&self) -> Box<dyn Shape> {
        Box::new(*self)
    }
}

impl Shape for Cuboid {
    fn distance(&self, p: &Vector3<f64>) -> f64 {
        primitives::cuboid_local_distance(&self.half, p)
    }
    fn query(&self, p: &Vector3<f64>) -> PointQuery {
        primitives::cuboid_local(&self.half, p, true)
    }
    fn min_radius(&self) -> f64 {
        0.0
    }
    fn bounding_radius(&self) -> f64 {
        self.half.norm()
    }
    fn clone_box(&self) -> Box<dyn Shape> {
        Box::new(*self)
    }
}

/// A shape on a body, placed by a pose (its frame in the global frame), with its friction
/// coefficient.
#[derive(Clone, Debug)]
pub struct Obstacle {
    pub name: String,
    /// Index of the body that carries it (for the per-body force totals).
    pub body: usize,
    pub shape: Box<dyn Shape>,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    position: Vector3<f64>,
    rotation: Matrix3<f64>,
    moved: bool,
    /// Counts the pose changes (the contact's cached queries are of one pose).
    pose_version: u64,
    /// The rotation is the identity (most parts: global at the reference, on a fixed body):
    /// queries skip the transforms.
    unrotated: bool,
    /// The shape's `bounding_radius` (∞: unbounded).
    bounding_radius: f64,
    /// Added to every signed distance: the solid shrunk by this much (0: as given). The
    /// push-out continuation of a start inside the geometry (`Contact::set_shrink`).
    shrink: f64,
}

impl Obstacle {
    pub fn new(name: &str, body: usize, shape: Box<dyn Shape>, friction: f64, pose: &Pose) -> Self {
        let rotation = rotation_matrix(&pose.orientation);
        Obstacle {
            name: name.into(),
            body,
            bounding_radius: shape.bounding_radius(),
            shape,
            friction,
            position: pose.position,
            rotation,
            moved: true,
            pose_version: 0,
            unrotated: rotation == Matrix3::identity(),
            shrink: 0.0,
        }
    }

    /// Moves the obstacle rigidly (the pose of its frame in the global frame).
    pub fn set_pose(&mut self, pose: &Pose) {
        let rotation = rotation_matrix(&pose.orientation);
        if pose.position != self.position || rotation != self.rotation {
            self.moved = true;
            self.pose_version += 1;
        }
        self.position = pose.position;
        self.rotation = rotation;
        self.unrotated = rotation == Matrix3::identity();
    }

    /// Signed distance, outward normal and its gradient at a global point.
    #[inline]
    pub fn query(&self, p: &Vector3<f64>) -> PointQuery {
        let q = self.shape.query(&self.local(p));
        if self.unrotated {
            return PointQuery {
                distance: q.distance + self.shrink,
                ..q
            };
        }
        PointQuery {
            distance: q.distance + self.shrink,
            normal: self.rotation * q.normal,
            hessian: if q.hessian == Matrix3::zeros() {
                q.hessian
            } else {
                self.rotation * q.hessian * self.rotation.transpose()
            },
        }
    }

    /// Signed distance at a global point (broad phase).
    #[inline]
    pub fn distance(&self, p: &Vector3<f64>) -> f64 {
        self.shape.distance(&self.local(p)) + self.shrink
    }

    /// A global point in the obstacle's frame.
    #[inline]
    fn local(&self, p: &Vector3<f64>) -> Vector3<f64> {
        if self.unrotated {
            p - self.position
        } else {
            self.rotation.transpose() * (p - self.position)
        }
    }

    /// Signed distance at a global point if within `bound` of the surface, else the exact
    /// distance or ∞ (broad phase; [`Shape::distance_within`]).
    #[inline]
    pub fn distance_within(&self, p: &Vector3<f64>, bound: f64) -> f64 {
        self.shape
            .distance_within(&self.local(p), bound - self.shrink)
            + self.shrink
    }

    /// Closest points between the segment [a, b] and the obstacle: the least signed distance
    /// along the segment (convex for convex shapes; `primitives::minimise_along_segment`, which
    /// for a mesh finds a local minimum).
    pub fn segment_query(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> SegmentQuery {
        let d = b - a;
        let slope = |t: f64| {
            let q = self.query(&(a + t * d));
            (q.distance, q.normal.dot(&d))
        };
        let t = primitives::minimise_along_segment(slope, d.norm(), a.norm(), false);
        let point = a + t * (b - a);
        let q = self.query(&point);
        SegmentQuery {
            distance: q.distance,
            t,
            point,
            closest: q.closest_point(&point),
            normal: q.normal,
        }
    }
}

/// Parameters of the contact term (docs/contact.md).
#[derive(Clone, Debug)]
pub struct ContactOptions {
    /// Cable radius r, m.
    pub radius: f64,
    /// Activation distance d̂ of the barrier, m (the gap stays in (0, d̂) in contact).
    pub distance: f64,
    /// Barrier stiffness κ, N/m² (≤ 0: automatic, from the cable's weight per length).
    pub stiffness: f64,
    /// Width of the stick zone of static and quasistatic friction, m.
    pub stick_distance: f64,
    /// Width of the stick zone of dynamic friction, m/s.
    pub stick_velocity: f64,
    /// Largest number of sample intervals per edge (on curved and sharp geometry).
    pub max_samples: usize,
    /// Normal damping of dynamic contact, s: a Kelvin–Voigt time constant τ_c on the barrier's
    /// stiffness (the normal force gains τ_c κ w b''(g) ġ, ġ the gap's rate relative to the
    /// geometry over the step), so a contact oscillation of frequency f has the damping ratio
    /// π f τ_c. 0: an elastic contact (it rings on the barrier).
    pub damping: f64,
}

impl ContactOptions {
    /// Defaults for a cable of radius r: d̂ = 1 % of r, ε_x = 0.1 % of r, ε_v = 0.1 mm/s.
    pub fn for_radius(radius: f64) -> Self {
        ContactOptions {
            radius,
            distance: 0.01 * radius,
            stiffness: 0.0,
            stick_distance: 1e-3 * radius,
            stick_velocity: 1e-3,
            max_samples: 8,
            damping: 5e-4,
        }
    }
}

/// The contact's normal damping coefficient saturates at its value at this fraction of d̂:
/// it is κ w φ(g) τ_c/h times the harmonic mean of b''(g) and b''(d̂ · this), ≈ b''(g) well
/// above it.
pub const DAMPING_SATURATION: f64 = 1e-2;

/// b''(g) at the damping's saturation gap `DAMPING_SATURATION` · d̂ (`sample_terms`' `floor`).
pub fn damping_floor(dhat: f64) -> f64 {
    barrier(DAMPING_SATURATION * dhat, dhat).2
}

/// The fade φ(g) of the contact's normal damping and φ'(g): 1 up to 3/4 of d̂, then
/// 1 − ((g − ¾d̂)/(¼d̂))² down to 0 at d̂ (C¹ at both ends, so the damping coefficient
/// κ w b''(g) φ(g) has a continuous slope where samples enter the barrier).
#[inline]
pub fn damping_fade(g: f64, dhat: f64) -> (f64, f64) {
    let g1 = 0.75 * dhat;
    if g <= g1 {
        (1.0, 0.0)
    } else if g >= dhat {
        (0.0, 0.0)
    } else {
        let w = dhat - g1;
        let u = (g - g1) / w;
        (1.0 - u * u, -2.0 * u / w)
    }
}

/// g_s: below it the barrier is its C² Taylor polynomial from there.
#[inline]
fn continuation_gap(dhat: f64) -> f64 {
    1e-3 * dhat
}

/// b'''(g) of `barrier` (0 on the quadratic continuation below g_s and beyond d̂).
#[inline]
pub fn barrier_third(g: f64, dhat: f64) -> f64 {
    if g >= dhat || g < continuation_gap(dhat) {
        return 0.0;
    }
    let d = g - dhat;
    -6.0 / g + 6.0 * d / (g * g) - 2.0 * d * d / (g * g * g)
}

/// Barrier b(g), b'(g), b''(g) (times κ elsewhere), zero beyond d̂, C² Taylor continuation
/// below g_s = d̂/1000.
#[inline]
pub fn barrier(g: f64, dhat: f64) -> (f64, f64, f64) {
    if g >= dhat {
        return (0.0, 0.0, 0.0);
    }
    let gs = continuation_gap(dhat);
    let exact = |g: f64| {
        let d = g - dhat;
        let l = (g / dhat).ln();
        (
            -d * d * l,
            -2.0 * d * l - d * d / g,
            -2.0 * l - 4.0 * d / g + d * d / (g * g),
        )
    };
    if g >= gs {
        exact(g)
    } else {
        let (b, b1, b2) = exact(gs);
        let dg = g - gs;
        (b + b1 * dg + 0.5 * b2 * dg * dg, b1 + b2 * dg, b2)
    }
}

/// Per node: no contact, sticking (tangential motion within the stick zone), slipping.
pub const NO_CONTACT: u8 = 0;
pub const STICK: u8 = 1;
pub const SLIP: u8 = 2;

/// Residual, Jacobian and energy contributions of one sample point of an edge.
#[derive(Clone, Copy, Debug)]
pub struct SampleTerms {
    pub energy: f64,
    /// Contact force gradient (∂E/∂x) and the friction force (as a gradient: the force on the
    /// cable is minus these).
    pub normal_grad: Vector3<f64>,
    pub friction_grad: Vector3<f64>,
    /// ∂(normal_grad + friction_grad)/∂x.
    pub jac: Matrix3<f64>,
    /// Tangential displacement |u_T| relative to the stick width.
    pub slip_ratio: f64,
    /// Work of friction and of the normal damping over the step (≥ 0).
    pub friction_work: f64,
}

/// The contact term at a point x with weight w (arc length, m), reference x_ref (the point at
/// the step's start, carried with the geometry), obstacle query q: barrier, normal damping
/// (`damping_rate` = τ_c/h, 0 in statics; `gap_ref` the gap of x_ref; `floor` =
/// [`damping_floor`] of d̂) and friction (μ, stick width ε).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn sample_terms(
    q: &PointQuery,
    x: &Vector3<f64>,
    x_ref: &Vector3<f64>,
    w: f64,
    radius: f64,
    dhat: f64,
    kappa: f64,
    mu: f64,
    eps: f64,
    damping_rate: f64,
    gap_ref: f64,
    floor: f64,
    want_jac: bool,
) -> Option<SampleTerms> {
    let g = q.distance - radius;
    if g >= dhat {
        return None;
    }
    let (b, b1, b2) = barrier(g, dhat);
    let kw = kappa * w;
    let n = q.normal;
    let mut normal_grad = kw * b1 * n;
    let mut jac = if want_jac {
        kw * (b2 * n * n.transpose() + b1 * q.hessian)
    } else {
        Matrix3::zeros()
    };
    let mut damping_work = 0.0;
    if damping_rate > 0.0 {
        // Normal damping: c Δg n with c = (τ_c/h) κ w b''(g) and Δg = g − g_ref the gap's
        // change over the step relative to the geometry (Δg/h the backward-difference gap
        // rate; a point sliding along a curved surface keeps its gap).
        let dg = g - gap_ref;
        // Faded out towards d̂ (C¹ there: b'' alone would switch its slope b''' on at d̂,
        // and Newton stalls on samples that enter and leave).
        let (phi, dphi) = damping_fade(g, dhat);
        // Saturated towards its value at d̂/100: b'' grows as 1/g², and a sample a clip drives
        // into the geometry (its node prescribed) would meet a damping force without bound that
        // no free node can balance (bench_harness --contact: Newton stalled at 100 N). Smoothly:
        // the harmonic mean of b''(g) and b''(d̂/100), below both, with a continuous slope (the
        // former hard cap's kink at d̂/100 made Newton cycle at impacts; docs/contact.md).
        let b2c = 1.0 / (1.0 / b2 + 1.0 / floor);
        let b3c = barrier_third(g, dhat) * (b2c / b2) * (b2c / b2);
        let c = damping_rate * kw * b2c * phi;
        normal_grad += c * dg * n;
        damping_work = c * dg * dg;
        if want_jac {
            // ∂c/∂x = (τ_c/h) κ w (b''' φ + b'' φ') n;  ∂Δg/∂x = n;  ∂n/∂x = H.
            let c3 = damping_rate * kw * (b3c * phi + b2c * dphi);
            jac += (c3 * dg + c) * n * n.transpose() + c * dg * q.hessian;
        }
    }
    let mut friction_grad = Vector3::zeros();
    let mut slip_ratio = 0.0;
    let mut friction_work = 0.0;
    if mu > 0.0 {
        let lambda = -kw * b1; // ≥ 0
        let u = x - x_ref;
        let un = n.dot(&u);
        let wt = u - un * n;
        let s = wt.norm();
        slip_ratio = s / eps;
        let (phi, dphi) = f1_over(s, eps);
        friction_grad = mu * lambda * phi * wt;
        friction_work = friction_grad.dot(&u);
        if want_jac {
            // ∂w_T/∂x = T − n (H u)ᵀ − (n·u) H;  ∂λ/∂x = −κ w b'' nᵀ.
            let t = Matrix3::identity() - n * n.transpose();
            let dw = t - n * (q.hessian * u).transpose() - un * q.hessian;
            let mut dphiw = phi * Matrix3::identity();
            if s > 0.0 {
                dphiw += (dphi / s) * wt * wt.transpose();
            }
            jac += mu * lambda * dphiw * dw + (mu * phi * (-kw * b2)) * wt * n.transpose();
        }
    }
    Some(SampleTerms {
        energy: kw * b,
        normal_grad,
        friction_grad,
        jac,
        slip_ratio,
        friction_work: friction_work + damping_work,
    })
}

/// The contact term of one cable: obstacles, parameters, the friction reference and the
/// outputs of the last full assembly.
#[derive(Clone, Debug)]
pub struct Contact {
    pub obstacles: Vec<Obstacle>,
    pub opts: ContactOptions,
    /// κ given (`ContactOptions::stiffness`) or automatic (the weight per length at about
    /// d̂/2), N/m²: the start of every obstacle's stiffness.
    pub kappa: f64,
    /// κ in use per obstacle, N/m²: `kappa`, raised where the contact load far exceeds the
    /// weight the automatic stiffness is set for (`adapt_stiffness`).
    pub obstacle_kappa: Vec<f64>,
    /// Per obstacle: the smallest sample gap of the last full assembly (`min_gap`), and the
    /// smallest of the full assemblies since `begin_solve` (∞: no sample within reach).
    obstacle_gap: Vec<f64>,
    lowest_gap: Vec<f64>,
    /// Node positions at the start of the step (friction and damping reference).
    reference: Vec<Vector3<f64>>,
    /// Per obstacle: its pose (position, rotation) when the reference was taken, that pose
    /// before the current step (restored by `rollback_step`), and the rigid motion x ↦ R x + t
    /// of the obstacle since the reference was taken (the reference is carried with it).
    reference_pose: Vec<(Vector3<f64>, Matrix3<f64>)>,
    reference_pose_n: Vec<(Vector3<f64>, Matrix3<f64>)>,
    transport: Vec<(Matrix3<f64>, Vector3<f64>)>,
    /// Per sample (as `cache_samples`): the gap of its reference point, queried once per step
    /// when the sample first needs it (NaN: not yet).
    reference_gap: Vec<f64>,
    /// `damping_floor` of the barrier's reach d̂.
    damping_floor: f64,
    /// Stick width of the current step (m) and the step duration (dynamics).
    eps: f64,
    step: Option<f64>,
    /// Sample intervals per edge for each obstacle.
    samples: Vec<usize>,
    /// Outputs of the last assembly of the whole cable: forces of the geometry on the cable
    /// per node (global, N), split into normal and friction parts, node states, totals per body.
    pub normal_force: Vec<Vector3<f64>>,
    pub friction_force: Vec<Vector3<f64>>,
    pub node_state: Vec<u8>,
    pub body_force: Vec<Vector3<f64>>,
    /// Samples inside the barrier (gap below d̂) in the last assembly.
    pub active: usize,
    /// Edges (per obstacle: k · edges + e) whose broad phase uses exact signed distances (a
    /// start inside the geometry being resolved: a point deeper inside a mesh than the
    /// barrier's reach reads as far otherwise).
    deep: Vec<bool>,
    /// Samples along a Newton correction (`line_search`): κ·weight, gap, approach.
    line: Vec<(f64, f64, f64)>,
    /// The queries of the last assembly, per obstacle k and edge e (index k · edges + e): the
    /// edge's end points, the exact distance at its midpoint (∞: not queried), the obstacle's
    /// position and rotation, and per sample (stride `max_samples` + 1) distance and normal.
    /// `step_bound` and `line_search` at the same positions reuse them instead of querying
    /// the geometry again.
    cache_edges: Vec<CachedEdge>,
    cache_samples: Vec<(f64, Vector3<f64>)>,
}

/// An edge's queries of the last assembly against one obstacle (`Contact::edge_samples`).
#[derive(Clone, Debug)]
struct CachedEdge {
    /// The edge's end points when queried.
    a: Vector3<f64>,
    b: Vector3<f64>,
    /// Exact distance at the midpoint; ∞: not queried.
    d_mid: f64,
    /// An edge the assembly found beyond the barrier's reach: a lower bound of the gap of every
    /// point of it at `a`, `b` (−∞: none known). Every point of the edge moves at most as far as
    /// one of its ends, so at other end points the bound less that motion still holds: an edge
    /// moved less than `far_gap` − d̂ since is not queried again.
    far_gap: f64,
    /// The obstacle's `pose_version` when queried.
    pose: u64,
}

impl CachedEdge {
    /// Whether the bound `far_gap` shows every point of the edge at the end points `a`, `b`
    /// farther than `gap` from the obstacle (of pose `pose`).
    #[inline]
    fn beyond(&self, a: &Vector3<f64>, b: &Vector3<f64>, pose: u64, gap: f64) -> bool {
        let room = self.far_gap - gap;
        self.pose == pose
            && room > 0.0
            && (a - self.a).norm_squared().max((b - self.b).norm_squared()) < room * room
    }
}

impl Default for CachedEdge {
    fn default() -> Self {
        CachedEdge {
            a: Vector3::zeros(),
            b: Vector3::zeros(),
            d_mid: f64::INFINITY,
            far_gap: f64::NEG_INFINITY,
            pose: u64::MAX,
        }
    }
}

/// A node of the cable inside an obstacle deeper than the allowed penetration.
#[derive(Clone, Debug, PartialEq)]
pub struct Penetration {
    pub node: usize,
    /// Index and name of the obstacle.
    pub obstacle: usize,
    pub name: String,
    /// How far the cable surface is inside, m (> 0).
    pub depth: f64,
}

/// Invalid contact settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactError(pub String);

impl fmt::Display for ContactError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for ContactError {}

impl Contact {
    /// The term for a cable; `n_bodies` sizes the per-body totals.
    pub fn new(
        rod: &Rod,
        obstacles: Vec<Obstacle>,
        opts: ContactOptions,
        n_bodies: usize,
    ) -> Result<Contact, ContactError> {
        let bad = |what: &str, v: f64, allowed: &str| {
            Err(ContactError(format!("contact {what} = {v}: {allowed}")))
        };
        if !(opts.radius.is_finite() && opts.radius > 0.0) {
            return bad("radius", opts.radius, "must be a positive length in m");
        }
        if !(opts.distance.is_finite() && opts.distance > 0.0) {
            return bad("distance", opts.distance, "must be a positive length in m");
        }
        if !(opts.stiffness.is_finite() && opts.stiffness >= 0.0) {
            return bad(
                "stiffness",
                opts.stiffness,
                "must be ≥ 0 N/m² (0: automatic)",
            );
        }
        if !(opts.stick_distance.is_finite() && opts.stick_distance > 0.0) {
            return bad("stick_distance", opts.stick_distance, "must be > 0 m");
        }
        if !(opts.stick_velocity.is_finite() && opts.stick_velocity > 0.0) {
            return bad("stick_velocity", opts.stick_velocity, "must be > 0 m/s");
        }
        if !(opts.damping.is_finite() && opts.damping >= 0.0) {
            return bad(
                "damping",
                opts.damping,
                "must be ≥ 0 s (0: an elastic contact)",
            );
        }
        if opts.max_samples < 1 {
            return Err(ContactError("contact max_samples = 0: must be ≥ 1".into()));
        }
        for o in &obstacles {
            if !(o.friction.is_finite() && o.friction >= 0.0) {
                return Err(ContactError(format!(
                    "geometry '{}': friction = {}: must be a number ≥ 0",
                    o.name, o.friction
                )));
            }
            if o.body >= n_bodies {
                return Err(ContactError(format!(
                    "geometry '{}': body index {} out of range (0..{n_bodies})",
                    o.name, o.body
                )));
            }
        }
        let kappa = if opts.stiffness > 0.0 {
            opts.stiffness
        } else {
            // The weight per length (standard gravity) at a gap of about d̂/2.
            rod.spec.section.mass_per_length * 9.81 / opts.distance
        };
        let ds = rod.ds_edge.iter().cloned().fold(0.0, f64::max);
        // Sample spacing: the chord between samples dips into a surface of radius R by at
        // most spacing²/(8R); keep that below half the 1 %-of-r tolerance.
        let samples = obstacles
            .iter()
            .map(|o| {
                let radius = o.shape.min_radius();
                if radius.is_infinite() {
                    1
                } else {
                    let spacing = (8.0 * radius * 0.005 * opts.radius).sqrt();
                    ((ds / spacing).ceil() as usize).clamp(1, opts.max_samples)
                }
            })
            .collect();
        let n = rod.arc.len();
        let n_obstacles = obstacles.len();
        let opts_samples = opts.max_samples.max(1);
        let poses: Vec<_> = obstacles.iter().map(|o| (o.position, o.rotation)).collect();
        let sample_slots = n_obstacles * n.saturating_sub(1) * (opts_samples + 1);
        Ok(Contact {
            reference_pose_n: poses.clone(),
            reference_pose: poses,
            reference_gap: vec![f64::NAN; sample_slots],
            transport: vec![(Matrix3::identity(), Vector3::zeros()); n_obstacles],
            obstacles,
            kappa,
            obstacle_kappa: vec![kappa; n_obstacles],
            obstacle_gap: vec![f64::INFINITY; n_obstacles],
            lowest_gap: vec![f64::INFINITY; n_obstacles],
            eps: opts.stick_distance,
            damping_floor: damping_floor(opts.distance),
            opts,
            reference: vec![Vector3::zeros(); n],
            step: None,
            samples,
            normal_force: vec![Vector3::zeros(); n],
            friction_force: vec![Vector3::zeros(); n],
            node_state: vec![NO_CONTACT; n],
            body_force: vec![Vector3::zeros(); n_bodies],
            active: 0,
            deep: vec![false; n_obstacles * n.saturating_sub(1)],
            line: Vec::new(),
            cache_edges: vec![CachedEdge::default(); n_obstacles * n.saturating_sub(1)],
            cache_samples: vec![(0.0, Vector3::zeros()); sample_slots],
        })
    }

    /// Starts a step from the positions `x`: the friction reference; `h` the time step of a
    /// dynamic step (None: static or quasistatic).
    pub fn begin_step(&mut self, x: &[Vector3<f64>], h: Option<f64>) {
        self.reference.copy_from_slice(x);
        self.step = h;
        // The obstacles' motion since their poses at the reference (set before this step):
        // friction and damping act on the motion relative to the geometry.
        self.reference_pose_n.clone_from(&self.reference_pose);
        self.reference_gap.fill(f64::NAN);
        for (k, o) in self.obstacles.iter().enumerate() {
            let (p0, r0) = self.reference_pose[k];
            let r = o.rotation * r0.transpose();
            self.transport[k] = (r, o.position - r * p0);
            self.reference_pose[k] = (o.position, o.rotation);
        }
        self.eps = match h {
            Some(h) => self.opts.stick_velocity * h,
            None => self.opts.stick_distance,
        };
    }

    /// Smallest gap (cable surface to geometry) over the sample points of the last full
    /// assembly, m (∞: none within reach).
    pub fn min_gap(&self) -> f64 {
        self.obstacle_gap
            .iter()
            .fold(f64::INFINITY, |m, &g| m.min(g))
    }

    /// The smallest gap as a result reports it: capped at the barrier's reach d̂ (gaps beyond
    /// it are not all computed: the broad phase skips far edges), so never ∞.
    pub fn reported_gap(&self) -> f64 {
        self.min_gap().min(self.opts.distance)
    }

    /// Starts the record of the smallest gaps of a static solve (`stiffen_after_failure`).
    pub fn begin_solve(&mut self) {
        self.lowest_gap.fill(f64::INFINITY);
    }

    /// Whether the stiffness is automatic (`ContactOptions::stiffness` = 0) and so adapts to
    /// the contact load.
    pub fn adapts(&self) -> bool {
        self.opts.stiffness == 0.0
    }

    /// Load-scaled barrier (automatic stiffness only). The automatic κ carries the cable's
    /// weight at about d̂/2; a load far above it (a wrap under tension, a clip pressing the
    /// cable onto a part, a chord's point contact on a convex part) presses the gap to
    /// nanometres, where the barrier is stiff and its Taylor continuation below d̂/1000 caps the
    /// force a sample can give. After a converged static solve, every obstacle whose most
    /// loaded sample (the smallest gap of the last full assembly) lies below d̂/10 gets the κ
    /// that carries that sample's line load κ|b'(g)| at d̂/2: κ ← κ b'(g_min)/b'(d̂/2). The
    /// contact forces of an equilibrium do not depend on κ (only its gaps do), so the solve
    /// is repeated from there. Returns whether any stiffness changed.
    pub fn adapt_stiffness(&mut self) -> bool {
        if !self.adapts() {
            return false;
        }
        let dhat = self.opts.distance;
        let target = barrier(0.5 * dhat, dhat).1;
        let mut changed = false;
        for (kappa, &g) in self.obstacle_kappa.iter_mut().zip(&self.obstacle_gap) {
            if g < 0.1 * dhat {
                *kappa *= barrier(g, dhat).1 / target;
                changed = true;
            }
        }
        changed
    }

    /// After a failed static solve (automatic stiffness only): ×30 the stiffness of every
    /// obstacle that a sample came closer to than the barrier's continuation gap d̂/1000
    /// since `begin_solve` — a load beyond what that sample's barrier can give (the Newton
    /// iteration creeps towards zero gap under the 90 % rule). Returns whether any changed.
    pub fn stiffen_after_failure(&mut self) -> bool {
        if !self.adapts() {
            return false;
        }
        let gs = continuation_gap(self.opts.distance);
        let mut changed = false;
        for (kappa, &g) in self.obstacle_kappa.iter_mut().zip(&self.lowest_gap) {
            if g < gs {
                *kappa *= 30.0;
                changed = true;
            }
        }
        changed
    }

    /// Undoes `begin_step`'s record of the obstacle poses (a step rolled back and redone).
    pub fn rollback_step(&mut self) {
        self.reference_pose.clone_from(&self.reference_pose_n);
    }

    /// Whether an obstacle moved since the last call (and clears the flags).
    pub fn take_moved(&mut self) -> bool {
        let mut any = false;
        for o in &mut self.obstacles {
            any |= o.moved;
            o.moved = false;
        }
        any
    }

    /// Moves the obstacles of body `b` to the body pose (their frames relative to the body are
    /// given by `local`, one per obstacle).
    /// Shrinks every obstacle by `by` (m, ≥ 0: every signed distance grows by it; 0 restores
    /// the geometry): the push-out continuation of a cable started inside the geometry
    /// deeper than the barrier reaches (`Statics::solve`).
    pub fn set_shrink(&mut self, by: f64) {
        for o in &mut self.obstacles {
            o.shrink = by;
        }
        for c in &mut self.cache_edges {
            // the cached distances and bounds are of the former surface
            c.d_mid = f64::INFINITY;
            c.far_gap = f64::NEG_INFINITY;
        }
    }

    pub fn set_obstacle_poses(&mut self, poses: &[Pose]) {
        for (o, p) in self.obstacles.iter_mut().zip(poses) {
            o.set_pose(p);
        }
    }

    /// The largest fraction α ∈ (0, 1] of a motion `dx(n)` of the nodes from the positions `x`
    /// that keeps every sample's gap above a tenth of its current value, by the gap's
    /// linearisation along the normal (exact for planes), and carries no frictional sample
    /// across its stick zone (`stick_cut`); for the edges `edges`.
    pub fn step_bound(
        &self,
        x: &[Vector3<f64>],
        dx: impl Fn(usize) -> Vector3<f64>,
        edges: impl Iterator<Item = usize> + Clone,
    ) -> f64 {
        let mut alpha = 1.0f64;
        for k in 0..self.obstacles.len() {
            for e in edges.clone() {
                let (da, db) = (dx(e), dx(e + 1));
                let motion = da.norm().max(db.norm());
                let slip = self.slip_ends(x, k, e);
                self.edge_samples(x, k, e, motion, |t, g, normal| {
                    let d = da + t * (db - da);
                    let approach = -normal.dot(&d);
                    if g > 0.0 && approach * alpha > 0.9 * g {
                        alpha = 0.9 * g / approach;
                    }
                    if let Some((ua, ub)) = slip.filter(|_| g < self.opts.distance) {
                        alpha = self.stick_cut(ua + t * (ub - ua), d, normal, alpha);
                    }
                });
            }
        }
        alpha
    }

    /// Friction against obstacle k (μ > 0): the slips since the step's start, relative to the
    /// geometry, of edge e's two nodes (a sample's is interpolated between them).
    #[inline]
    fn slip_ends(
        &self,
        x: &[Vector3<f64>],
        k: usize,
        e: usize,
    ) -> Option<(Vector3<f64>, Vector3<f64>)> {
        if self.obstacles[k].friction <= 0.0 {
            return None;
        }
        let (rot, shift) = self.transport[k];
        Some((
            x[e] - (rot * self.reference[e] + shift),
            x[e + 1] - (rot * self.reference[e + 1] + shift),
        ))
    }

    /// `alpha` lowered so that a sample with slip `u` and displacement `d` (normal `normal`) is
    /// not carried across its stick zone by its tangential parts (`friction::stick_cut`, as
    /// the sliding clips' guides). Measured: a harness whose trunk lies in a frictional guide
    /// and on a box with friction, with a branch stiffer than 6 GPa, stopped at step 5–6 at
    /// 1 ms ("Newton did not converge"); with this bound it runs. In `step_bound` (harnesses,
    /// and single cables without the line search) only: in the line search it cost the contact
    /// benchmark 8 % more iterations and 35 % more time (the cut corrections get fresh
    /// matrices), and no single-cable case was found that needs it.
    #[inline]
    fn stick_cut(
        &self,
        u: Vector3<f64>,
        d: Vector3<f64>,
        normal: &Vector3<f64>,
        alpha: f64,
    ) -> f64 {
        let ut = u - normal.dot(&u) * normal;
        let dt = d - normal.dot(&d) * normal;
        stick_cut(
            ut.norm_squared(),
            ut.dot(&dt),
            dt.norm_squared(),
            self.eps,
            alpha,
        )
    }

    /// Calls `f(t, gap, normal)` for the samples of edge e against obstacle k at the positions
    /// `x`, unless the edge's capsule is farther than `margin` from the obstacle: from the last
    /// assembly's queries if it was at these positions and this pose, else by new queries.
    fn edge_samples(
        &self,
        x: &[Vector3<f64>],
        k: usize,
        e: usize,
        margin: f64,
        mut f: impl FnMut(f64, f64, &Vector3<f64>),
    ) {
        let o = &self.obstacles[k];
        let r = self.opts.radius;
        let kk = self.samples[k];
        let (a, b) = (x[e], x[e + 1]);
        let half = 0.5 * (b - a).norm();
        let slot = k * (x.len() - 1) + e;
        let c = &self.cache_edges[slot];
        if c.beyond(&a, &b, o.pose_version, margin) {
            return; // every point of the edge farther than the margin (from the assembly)
        }
        let same = c.a == a && c.b == b && c.pose == o.pose_version;
        if same && c.d_mid.is_finite() {
            if c.d_mid - half - r > margin {
                return;
            }
            let stride = self.opts.max_samples.max(1) + 1;
            for (i, (d, n)) in self.cache_samples[slot * stride..][..=kk]
                .iter()
                .enumerate()
            {
                f(i as f64 / kk as f64, d - r, n);
            }
            return;
        }
        let mid = 0.5 * (a + b);
        if o.distance_within(&mid, half + r + margin) - half - r > margin {
            return;
        }
        for i in 0..=kk {
            let t = i as f64 / kk as f64;
            let q = o.query(&(a + t * (b - a)));
            f(t, q.distance - r, &q.normal);
        }
    }

    /// The step α ∈ (0, 1] along a Newton correction `dx(n)` of the nodes from `x` (edges
    /// `edges`, lengths `ds`): a line search on a model of the barrier-augmented merit,
    ///
    ///   ψ(α) = −α (R + C₀) + ½ α² max(R − S, 0) + Σ κ w [b(g − α a) − b(g)],
    ///
    /// the rest of the system quadratic (its slope −R − C₀ and curvature R − S from the Newton
    /// decrement R = −Δxᵀ r, in the position unit: `decrement`), the barrier exact along the
    /// linearised gap g − α a of each sample (a its approach along the normal; C₀ = Σ κ w b'(g)(−a)
    /// and S = Σ κ w b''(g) a² the barrier's own slope and curvature). The full step is taken
    /// when it decreases ψ sufficiently (Armijo, 1e-4) and keeps every gap above a tenth of its
    /// value (the feasible bound, `step_bound`'s); otherwise the minimiser of ψ within that
    /// bound. With R ≤ 0 (a reused matrix giving no descent): the feasible bound alone.
    /// With `stick_cut`, the feasible bound also keeps frictional samples from being carried
    /// across their stick zone (`stick_cut`, as `step_bound`): for an iteration that cycles.
    pub fn line_search(
        &mut self,
        x: &[Vector3<f64>],
        dx: impl Fn(usize) -> Vector3<f64>,
        edges: impl Iterator<Item = usize> + Clone,
        ds: &[f64],
        decrement: f64,
        stick_cut: bool,
    ) -> f64 {
        let mut feasible = 1.0f64;
        let dhat = self.opts.distance;
        self.line.clear();
        let mut line = std::mem::take(&mut self.line);
        for k in 0..self.obstacles.len() {
            let kk = self.samples[k];
            for e in edges.clone() {
                let (da, db) = (dx(e), dx(e + 1));
                let motion = da.norm().max(db.norm());
                let w_end = 0.5 * ds[e] / kk as f64;
                let slip = if stick_cut {
                    self.slip_ends(x, k, e)
                } else {
                    None
                };
                self.edge_samples(x, k, e, motion + dhat, |t, g, normal| {
                    let d = da + t * (db - da);
                    let approach = -normal.dot(&d);
                    if g > 0.0 && approach * feasible > 0.9 * g {
                        feasible = 0.9 * g / approach;
                    }
                    if let Some((ua, ub)) = slip.filter(|_| g < dhat) {
                        feasible = self.stick_cut(ua + t * (ub - ua), d, normal, feasible);
                    }
                    if g - approach.max(0.0) < dhat {
                        let w = if t == 0.0 || t == 1.0 {
                            w_end
                        } else {
                            2.0 * w_end
                        };
                        line.push((self.obstacle_kappa[k] * w, g, approach));
                    }
                });
            }
        }
        self.line = line;
        if decrement <= 0.0 || self.line.is_empty() {
            return feasible;
        }
        let (mut c0, mut s) = (0.0, 0.0);
        for &(kw, g, a) in &self.line {
            let (_, b1, b2) = barrier(g, dhat);
            c0 -= kw * b1 * a;
            s += kw * b2 * a * a;
        }
        let slope = -decrement - c0;
        let curv = (decrement - s).max(0.0);
        let dmerit = |al: f64| {
            let mut v = slope + al * curv;
            for &(kw, g, a) in &self.line {
                v -= kw * barrier(g - al * a, dhat).1 * a;
            }
            v
        };
        // ψ is convex (b is): the minimiser within the feasible bound, by bisection on ψ'.
        if dmerit(feasible) <= 0.0 {
            return feasible;
        }
        if feasible == 1.0 && dmerit(0.95) <= 0.0 {
            return 1.0; // Newton's own step (near convergence ψ' vanishes near 1)
        }
        let (mut lo, mut hi) = (0.0, feasible);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if dmerit(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
            if hi - lo < 1e-3 * feasible {
                break;
            }
        }
        lo.max(1e-3 * feasible)
    }

    /// Whether a trial state is acceptable after one with the smallest gap `before`: its
    /// smallest gap (from the last full assembly) stays above a tenth of min(before, d̂), or
    /// does not shrink if the cable already penetrated.
    pub fn gap_acceptable(&self, before: f64) -> bool {
        if before > 0.0 {
            self.min_gap() >= 0.1 * before.min(self.opts.distance)
        } else {
            self.min_gap() >= before
        }
    }

    /// Whether any edge comes within d̂ + `margin` of an obstacle (broad phase only).
    pub fn near(&self, x: &[Vector3<f64>], margin: f64) -> bool {
        let reach = self.opts.radius + self.opts.distance + margin;
        self.obstacles.iter().any(|o| {
            x.windows(2).any(|w| {
                let half = 0.5 * (w[1] - w[0]).norm();
                o.distance_within(&(0.5 * (w[0] + w[1])), half + reach) - half < reach
            })
        })
    }

    /// While a start inside the geometry is resolved: the edges at a node of `x` inside an
    /// obstacle (its centreline, exact signed distance) take the broad phase by exact distances
    /// (slower on meshes, where the bounded query prunes the hierarchy); `None` clears.
    pub fn mark_deep_edges(&mut self, x: Option<&[Vector3<f64>]>) {
        self.deep.fill(false);
        let Some(x) = x else { return };
        let ne = x.len().saturating_sub(1);
        for (k, o) in self.obstacles.iter().enumerate() {
            for (n, p) in x.iter().enumerate() {
                if o.distance(p) < 0.0 {
                    if n > 0 {
                        self.deep[k * ne + n - 1] = true;
                    }
                    if n < ne {
                        self.deep[k * ne + n] = true;
                    }
                }
            }
        }
    }

    /// Where the cable surface (the capsules of its edges) lies deepest inside an obstacle, if
    /// deeper than the documented tolerance (1 % of r): exact signed distances, the node
    /// nearest the deepest point of the edge. Edges the bounded broad phase finds clear are
    /// skipped unless marked deep (`mark_deep_edges`).
    pub fn deepest_penetration(&self, st: &State) -> Option<Penetration> {
        let r = self.opts.radius;
        let mut worst: Option<Penetration> = None;
        for (k, o) in self.obstacles.iter().enumerate() {
            for e in 0..st.x.len().saturating_sub(1) {
                let (a, b) = (st.x[e], st.x[e + 1]);
                let mid = 0.5 * (a + b);
                let half = 0.5 * (b - a).norm();
                let deep = self.deep[k * (st.x.len() - 1) + e];
                if o.distance_within(&mid, half + r) - half >= r
                    && (!deep || o.distance(&mid) - half >= r)
                {
                    continue;
                }
                let q = o.segment_query(&a, &b);
                let depth = r - q.distance;
                if depth > 0.01 * r && worst.as_ref().is_none_or(|w| depth > w.depth) {
                    worst = Some(Penetration {
                        node: if q.t < 0.5 { e } else { e + 1 },
                        obstacle: k,
                        name: o.name.clone(),
                        depth,
                    });
                }
            }
        }
        worst
    }

    /// Moves every free node whose surface gap is below `margin` out along the obstacle's
    /// normal to the gap `margin`, and turns the edge frames with their chords (the minimal
    /// rotation) from their directions at `since` (default: the positions at the call; a
    /// harness gives the positions before its junctions moved the held ends): a feasible start
    /// for the barrier (the push-out continuation).
    pub fn move_out(&self, rod: &Rod, st: &mut State, margin: f64, since: Option<&[Vector3<f64>]>) {
        let before = since.map_or_else(|| st.x.clone(), <[Vector3<f64>]>::to_vec);
        for (n, x) in st.x.iter_mut().enumerate() {
            if rod.node_kind[n] == NodeKind::Free {
                self.move_point_out(x, margin);
            }
        }
        for (e, p) in st.p.iter_mut().enumerate() {
            let (a, b) = (before[e + 1] - before[e], st.x[e + 1] - st.x[e]);
            if a != b && a.norm() > 0.0 && b.norm() > 0.0 {
                *p = crate::rotation::min_rotation(&a.normalize(), &b.normalize()) * *p;
            }
        }
    }

    /// Moves a point of the cable's axis whose surface gap is below `margin` out along each
    /// obstacle's normal to the gap `margin` (`move_out`; a harness junction).
    pub fn move_point_out(&self, x: &mut Vector3<f64>, margin: f64) {
        for o in &self.obstacles {
            let q = o.query(x);
            let gap = q.distance - self.opts.radius;
            if gap < margin {
                *x += (margin - gap) * q.normal;
            }
        }
    }

    /// Whether a free node of the state lies inside an obstacle (negative gap).
    pub fn penetrates(&self, rod: &Rod, st: &State) -> bool {
        self.obstacles.iter().any(|o| {
            st.x.iter().enumerate().any(|(n, x)| {
                rod.node_kind[n] == NodeKind::Free && o.query(x).distance - self.opts.radius < 0.0
            })
        })
    }

    /// The smallest signed gap between the cable surface (capsules of the edges) and the
    /// geometry, with where it is: (gap, edge, obstacle).
    pub fn surface_gap(&self, st: &State) -> (f64, usize, usize) {
        let mut best = (f64::INFINITY, 0, 0);
        for (k, o) in self.obstacles.iter().enumerate() {
            for e in 0..st.x.len().saturating_sub(1) {
                let g = o.segment_query(&st.x[e], &st.x[e + 1]).distance - self.opts.radius;
                if g < best.0 {
                    best = (g, e, k);
                }
            }
        }
        best
    }

    /// Energy, gradient and Jacobian of edge e (nodes a = x_e, b = x_{e+1}) against obstacle k;
    /// adds into the workspace (Jacobian rows of free nodes only) and, with `outputs`, the
    /// force outputs.
    #[allow(clippy::too_many_arguments)]
    fn add_edge(
        &mut self,
        rod: &Rod,
        st: &State,
        ws: &mut Workspace,
        e: usize,
        k: usize,
        want_jac: bool,
        outputs: bool,
    ) {
        let o = &self.obstacles[k];
        let (a, b) = (st.x[e], st.x[e + 1]);
        let ds = rod.ds_edge[e];
        let reach = self.opts.radius + self.opts.distance;
        // Broad phase: every point of the edge is within |b − a|/2 of its midpoint.
        let mid = 0.5 * (a + b);
        let half = 0.5 * (b - a).norm();
        let far = o.bounding_radius;
        let slot = k * rod.n_edges() + e;
        // An edge known to be beyond the barrier's reach by more than it moved since (every
        // point of it moved at most as far as one of its ends): still beyond, no query.
        if !self.deep[slot]
            && self.cache_edges[slot].beyond(&a, &b, o.pose_version, self.opts.distance)
        {
            return;
        }
        // Beyond the barrier's reach: kept with a lower bound of the edge's gap (every point of
        // the edge is within |b − a|/2 of its midpoint).
        let mut far_edge = |far_gap: f64| {
            self.cache_edges[slot] = CachedEdge {
                a,
                b,
                d_mid: f64::INFINITY,
                far_gap,
                pose: o.pose_version,
            };
        };
        if far.is_finite() {
            let beyond = (mid - o.position).norm() - half - far; // (no root for unbounded shapes)
            if beyond > reach {
                far_edge(beyond - self.opts.radius);
                return;
            }
        }
        // The bound reaches a cable radius beyond the barrier: a mesh then gives a far edge's
        // exact distance up to there, a bound that lasts while the edge moves less.
        let bound = half + reach + self.opts.radius;
        let mut d_mid = o.distance_within(&mid, bound);
        if self.deep[slot] && d_mid >= bound {
            d_mid = o.distance(&mid); // deeper inside than the bound, or far
        }
        if d_mid - half >= reach {
            // d_mid exact, or ∞ beyond the bound (a mesh)
            let d = if d_mid.is_finite() { d_mid } else { bound };
            far_edge(d - half - self.opts.radius);
            return;
        }
        // Exact here (within the bound): kept with the samples' queries below.
        self.cache_edges[slot] = CachedEdge {
            a,
            b,
            d_mid,
            far_gap: f64::NEG_INFINITY,
            pose: o.pose_version,
        };
        let stride = self.opts.max_samples.max(1) + 1;
        let kk = self.samples[k];
        let (rot, shift) = self.transport[k];
        let (ra, rb) = (
            rot * self.reference[e] + shift,
            rot * self.reference[e + 1] + shift,
        );
        let damping_rate = self.step.map_or(0.0, |h| self.opts.damping / h);
        for i in 0..=kk {
            let t = i as f64 / kk as f64;
            let w = if i == 0 || i == kk { 0.5 } else { 1.0 } * ds / kk as f64;
            let x = a + t * (b - a);
            let q = o.query(&x);
            self.cache_samples[slot * stride + i] = (q.distance, q.normal);
            if outputs {
                let g = q.distance - self.opts.radius;
                self.obstacle_gap[k] = self.obstacle_gap[k].min(g);
                self.lowest_gap[k] = self.lowest_gap[k].min(g);
            }
            let xr = ra + t * (rb - ra);
            let mut gap_ref = 0.0;
            if damping_rate > 0.0 && q.distance - self.opts.radius < self.opts.distance {
                let cached = &mut self.reference_gap[slot * stride + i];
                if cached.is_nan() {
                    *cached = o.query(&xr).distance - self.opts.radius;
                }
                gap_ref = *cached;
            }
            let Some(s) = sample_terms(
                &q,
                &x,
                &xr,
                w,
                self.opts.radius,
                self.opts.distance,
                self.obstacle_kappa[k],
                o.friction,
                self.eps,
                damping_rate,
                gap_ref,
                self.damping_floor,
                want_jac,
            ) else {
                continue;
            };
            self.active += 1;
            ws.contact_energy += s.energy;
            if let Some(h) = self.step {
                ws.dissipation += s.friction_work / h;
            }
            let grad = s.normal_grad + s.friction_grad;
            let ta = 1.0 - t;
            ws.node_grad[e] += ta * grad;
            ws.node_grad[e + 1] += t * grad;
            if want_jac {
                if ta > 0.0 {
                    ws.add_node_block(rod, e, e, &(ta * ta * s.jac));
                }
                if t > 0.0 {
                    ws.add_node_block(rod, e + 1, e + 1, &(t * t * s.jac));
                }
                if t > 0.0 && t < 1.0 {
                    let m = ta * t * s.jac;
                    ws.add_node_block(rod, e, e + 1, &m);
                    ws.add_node_block(rod, e + 1, e, &m);
                }
            }
            if outputs {
                self.body_force[o.body] -= grad;
                for (n, c) in [(e, ta), (e + 1, t)] {
                    if c == 0.0 {
                        continue;
                    }
                    self.normal_force[n] -= c * s.normal_grad;
                    self.friction_force[n] -= c * s.friction_grad;
                }
                // Node states from the samples nearer to each node (a chord over a convex part
                // touches between its nodes).
                for (n, near) in [(e, 2 * i <= kk), (e + 1, 2 * i >= kk)] {
                    if near && s.normal_grad != Vector3::zeros() {
                        let state = if o.friction > 0.0 && s.slip_ratio >= 1.0 {
                            SLIP
                        } else {
                            STICK
                        };
                        self.node_state[n] = self.node_state[n].max(state);
                    }
                }
            }
        }
    }
}

impl Term for Contact {
    fn add_residual_jacobian(
        &mut self,
        rod: &Rod,
        st: &State,
        ev: &Eval,
        ws: &mut Workspace,
    ) -> Result<(), KinkAt> {
        let outputs = matches!(ev.part, Part::All);
        self.active = 0;
        if outputs {
            self.normal_force.iter_mut().for_each(|v| v.fill(0.0));
            self.friction_force.iter_mut().for_each(|v| v.fill(0.0));
            self.body_force.iter_mut().for_each(|v| v.fill(0.0));
            self.node_state.fill(NO_CONTACT);
            self.obstacle_gap.fill(f64::INFINITY);
        }
        for k in 0..self.obstacles.len() {
            match ev.part {
                Part::All => {
                    for e in 0..rod.n_edges() {
                        self.add_edge(rod, st, ws, e, k, ev.want_jac, outputs);
                    }
                }
                Part::Segment(seg) => {
                    for &e in &seg.edges {
                        self.add_edge(rod, st, ws, e, k, ev.want_jac, outputs);
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fd_check::check_derivatives;
    use crate::rotation::frame_quaternion;

    fn shapes() -> Vec<(&'static str, Box<dyn Shape>)> {
        vec![
            ("plane", Box::new(Plane)),
            ("sphere", Box::new(Sphere { radius: 0.05 })),
            (
                "cylinder",
                Box::new(Cylinder {
                    radius: 0.04,
                    length: 0.1,
                }),
            ),
            (
                "box",
                Box::new(Cuboid {
                    half: Vector3::new(0.03, 0.04, 0.05),
                }),
            ),
            (
                "box mesh",
                Box::new(crate::contact_mesh::box_mesh(Vector3::new(
                    0.03, 0.04, 0.05,
                ))),
            ),
        ]
    }

    fn tilted() -> Pose {
        Pose {
            position: Vector3::new(0.01, -0.02, 0.03),
            orientation: frame_quaternion(
                &Vector3::new(0.3, 0.2, 1.0).normalize(),
                &Vector3::new(1.0, 0.0, -0.3).normalize(),
            )
            .unwrap(),
        }
    }

    /// Points just outside the surface (gap within the barrier) of each region of a shape.
    fn probes(o: &Obstacle, gap: f64) -> Vec<Vector3<f64>> {
        let mut out = Vec::new();
        let dirs = [
            Vector3::new(0.1, 0.2, 1.0),
            Vector3::new(1.0, 0.1, 0.05),
            Vector3::new(1.0, 1.0, 0.1),
            Vector3::new(1.0, 0.9, 1.1),
            Vector3::new(-0.4, 1.0, 0.2),
            Vector3::new(0.7, 0.0, 1.2),
        ];
        for d in dirs {
            // March from far out along d (in the obstacle frame) to the gap.
            let dir = o.rotation * d.normalize();
            let mut s = 1.0;
            for _ in 0..200 {
                let p = o.position + s * dir;
                let g = o.query(&p).distance;
                s -= g - gap;
                if (g - gap).abs() < 1e-14 {
                    break;
                }
            }
            out.push(o.position + s * dir);
        }
        out
    }

    #[test]
    fn signed_distance_normal_and_hessian_match_finite_differences() {
        for (name, shape) in shapes() {
            let o = Obstacle::new(name, 0, shape, 0.0, &tilted());
            for p in probes(&o, 0.003) {
                let q = o.query(&p);
                let h = 1e-6;
                for k in 0..3 {
                    let mut dp = Vector3::zeros();
                    dp[k] = h;
                    let (qp, qm) = (o.query(&(p + dp)), o.query(&(p - dp)));
                    let fd = (qp.distance - qm.distance) / (2.0 * h);
                    assert!((fd - q.normal[k]).abs() < 1e-7, "{name} normal {k} at {p}");
                    let fdn = (qp.normal - qm.normal) / (2.0 * h);
                    let an = q.hessian.column(k);
                    assert!(
                        (fdn - an).amax() < 1e-5 * (1.0 + an.amax()),
                        "{name} hessian col {k} at {p}: fd {fdn} analytic {an}"
                    );
                }
                assert!((q.normal.norm() - 1.0).abs() < 1e-12);
                assert!(
                    (o.distance(&p) - q.distance).abs() < 1e-15,
                    "{name} distance"
                );
            }
        }
    }

    #[test]
    fn segment_query_finds_interior_closest_points() {
        let o = Obstacle::new(
            "s",
            0,
            Box::new(Sphere { radius: 0.1 }),
            0.0,
            &Pose {
                position: Vector3::zeros(),
                orientation: crate::rotation::Quat::identity(),
            },
        );
        let q = o.segment_query(&Vector3::new(-1.0, 0.0, 0.2), &Vector3::new(1.0, 0.0, 0.2));
        assert!((q.distance - 0.1).abs() < 1e-9 && (q.t - 0.5).abs() < 1e-6);
        assert!((q.normal - Vector3::z()).norm() < 1e-6);
        // Endpoint closest.
        let q = o.segment_query(&Vector3::new(0.0, 0.0, 0.3), &Vector3::new(0.0, 0.0, 0.5));
        assert!(q.t == 0.0 && (q.distance - 0.2).abs() < 1e-12);
    }

    #[test]
    fn barrier_is_c2_and_vanishes_at_the_activation_distance() {
        let d = 1e-4;
        let (b, b1, b2) = barrier(d * (1.0 - 1e-9), d);
        assert!(b.abs() < 1e-25 && b1.abs() < 1e-12 && b2.abs() < 1e-6);
        for g in [0.5 * d, 2e-3 * d, -0.2 * d] {
            let h = 1e-5 * g.abs();
            let (bp, b1p, _) = barrier(g + h, d);
            let (bm, b1m, _) = barrier(g - h, d);
            let (_, b1, b2) = barrier(g, d);
            assert!(((bp - bm) / (2.0 * h) - b1).abs() < 1e-6 * b1.abs());
            assert!(((b1p - b1m) / (2.0 * h) - b2).abs() < 1e-5 * b2.abs());
        }
    }

    /// The energy of an edge against each shape, as a function of its two end points: gradient
    /// and Hessian against finite differences (frictionless), and the friction force's
    /// Jacobian against finite differences of the force.
    #[test]
    fn edge_energy_and_friction_derivatives_match_finite_differences() {
        let radius = 0.004;
        let dhat = 0.01;
        for (name, shape) in shapes() {
            let o = Obstacle::new(name, 0, shape, 0.4, &tilted());
            // Gaps in the barrier, in the damping's fade (> ¾ d̂) and below its saturation.
            let gaps = [0.3, 0.85, 0.5 * DAMPING_SATURATION];
            for p in gaps.iter().flat_map(|f| probes(&o, radius + f * dhat)) {
                let q0 = o.query(&p);
                let t = Matrix3::identity() - q0.normal * q0.normal.transpose();
                let along = (t * Vector3::new(0.3, -0.5, 0.8)).normalize() * 0.004;
                let (a0, b0) = (p - along, p + 1.1 * along);
                for slip in [1e-4, 2e-3] {
                    let (ra, rb) = (a0 + Vector3::new(0.5, 1.0, -0.5) * slip, b0);
                    let eval = |z: &[f64; 6], mu: f64, damping: f64, jac: bool| {
                        // Coordinates in units of 1 mm (the FD steps of check_derivatives).
                        let a = a0 + 1e-3 * Vector3::new(z[0], z[1], z[2]);
                        let b = b0 + 1e-3 * Vector3::new(z[3], z[4], z[5]);
                        let mut e = 0.0;
                        let mut g = [0.0; 6];
                        let mut m = [[0.0; 6]; 6];
                        for i in 0..=4 {
                            let tt = i as f64 / 4.0;
                            let x = a + tt * (b - a);
                            let xr = ra + tt * (rb - ra);
                            let q = o.query(&x);
                            let w = 0.002;
                            let gr = o.query(&xr).distance - radius;
                            if let Some(s) = sample_terms(
                                &q,
                                &x,
                                &xr,
                                w,
                                radius,
                                dhat,
                                50.0,
                                mu,
                                1e-3,
                                damping,
                                gr,
                                damping_floor(dhat),
                                jac,
                            ) {
                                e += s.energy;
                                let gr = s.normal_grad + s.friction_grad;
                                let c = [1.0 - tt, tt];
                                for r in 0..2 {
                                    for k in 0..3 {
                                        g[3 * r + k] += c[r] * gr[k];
                                        for cc in 0..2 {
                                            for l in 0..3 {
                                                m[3 * r + k][3 * cc + l] +=
                                                    c[r] * c[cc] * s.jac[(k, l)];
                                            }
                                        }
                                    }
                                }
                            }
                        }
                        (e, g, m)
                    };
                    let (_, g, m) = eval(&[0.0; 6], 0.0, 0.0, true);
                    assert!(g.iter().any(|v| *v != 0.0), "{name}: no contact");
                    check_derivatives::<6>(
                        |z| eval(z, 0.0, 0.0, false).0,
                        |i| 1e-3 * g[i],
                        |i, j| 1e-6 * m[i][j],
                    );
                    // Friction and normal damping (τ_c/h = 5, the reference moved by `slip`
                    // across the normal too): the Jacobian of the force.
                    let damping = 5.0;
                    let (_, _, m) = eval(&[0.0; 6], 0.4, damping, true);
                    let scale = m.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
                    let h = 1e-5; // 10 nm
                    for j in 0..6 {
                        let mut zp = [0.0; 6];
                        let mut zm = [0.0; 6];
                        zp[j] = h;
                        zm[j] = -h;
                        let (gp, gm) = (
                            eval(&zp, 0.4, damping, false).1,
                            eval(&zm, 0.4, damping, false).1,
                        );
                        for i in 0..6 {
                            let fd = (gp[i] - gm[i]) / (2.0 * h * 1e-3);
                            assert!(
                                (fd - m[i][j]).abs() < 1e-5 * scale,
                                "{name} friction and damping jac {i},{j}: fd {fd} analytic {}",
                                m[i][j]
                            );
                        }
                    }
                }
            }
        }
    }
}

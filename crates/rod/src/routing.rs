//! The initial configuration: a smooth curve through the clips with the clip tangents and the
//! prescribed cable length between clips (cubic Hermite, tangent scale solved for the length);
//! free ends follow the natural curvature from the last clip. Frames are parallel-transported
//! and the twist mismatch at the next clip is spread linearly over the span.
use crate::model::{Pose, Rod, SpecError};
use crate::rotation::{exp_half, min_rotation, rotation_matrix, Quat};
use crate::state::{twist, State};
use nalgebra::Vector3;

const SAMPLES: usize = 400;

/// Routes the cable through its clips at the given poses (reference poses if `None`).
pub fn route(rod: &Rod, poses: Option<&[Pose]>) -> Result<State, SpecError> {
    let spec = &rod.spec;
    let poses: Vec<Pose> = match poses {
        Some(p) => p.to_vec(),
        None => spec.clips.iter().map(|c| c.pose).collect(),
    };
    let n_nodes = rod.arc.len();
    let mut x = vec![Vector3::zeros(); n_nodes];
    let mut p = vec![Quat::identity(); rod.n_edges()];
    let mut done = vec![false; n_nodes];
    let mut order: Vec<usize> = (0..spec.clips.len()).collect();
    order.sort_by(|&a, &b| spec.clips[a].s.partial_cmp(&spec.clips[b].s).unwrap());

    if order.is_empty() {
        // No clip: the natural shape from the origin along global x (useful for inspection only).
        let start = Pose {
            position: Vector3::zeros(),
            orientation: Quat::identity(),
        };
        natural_shape(rod, &start, 0, n_nodes - 1, &mut x, &mut p);
        return Ok(State {
            x,
            p,
            ghost: vec![],
            clip_pose: vec![],
        });
    }
    // Inside clips.
    for &c in &order {
        for &n in &rod.clip_nodes[c] {
            x[n] = rod.clip_node_position(c, n, &poses[c]);
            done[n] = true;
        }
        for &e in &rod.clip_edges[c] {
            p[e] = poses[c].orientation;
        }
    }
    // Spans between consecutive clips.
    for w in order.windows(2) {
        let (ca, cb) = (w[0], w[1]);
        let na = *rod.clip_nodes[ca].last().unwrap();
        let nb = rod.clip_nodes[cb][0];
        let (ra, rb) = (
            rotation_matrix(&poses[ca].orientation),
            rotation_matrix(&poses[cb].orientation),
        );
        let (a, b) = (x[na], x[nb]);
        let (ta, tb) = (ra * Vector3::z(), rb * Vector3::z());
        let span = rod.arc[nb] - rod.arc[na];
        let chord = (b - a).norm();
        if chord > span * (1.0 + 1e-9) {
            return Err(SpecError(format!(
                "the cable is too short between clip '{}' (s = {} m) and clip '{}' (s = {} m): \
                 the clips are {:.6} m apart but the cable between them is {:.6} m long",
                spec.clips[ca].name,
                spec.clips[ca].s,
                spec.clips[cb].name,
                spec.clips[cb].s,
                chord,
                span
            )));
        }
        let lambda = solve_tangent_scale(&a, &b, &ta, &tb, span);
        let pts: Vec<Vector3<f64>> = (0..=SAMPLES)
            .map(|i| {
                hermite(
                    &a,
                    &b,
                    &(lambda * ta),
                    &(lambda * tb),
                    i as f64 / SAMPLES as f64,
                )
            })
            .collect();
        let mut cum = vec![0.0; pts.len()];
        for i in 1..pts.len() {
            cum[i] = cum[i - 1] + (pts[i] - pts[i - 1]).norm();
        }
        let total = cum[SAMPLES];
        for n in na + 1..nb {
            let target = (rod.arc[n] - rod.arc[na]) / span * total;
            let i = cum.partition_point(|&c| c < target).clamp(1, SAMPLES);
            let t = (target - cum[i - 1]) / (cum[i] - cum[i - 1]).max(1e-300);
            x[n] = pts[i - 1] + (pts[i] - pts[i - 1]) * t;
            done[n] = true;
        }
        // Frames: parallel transport from clip a, then spread the twist mismatch at clip b.
        let mut frame = poses[ca].orientation;
        for e in na..nb {
            let t_new = (x[e + 1] - x[e]).try_normalize(1e-300).unwrap_or(ta);
            let t_old = rotation_matrix(&frame) * Vector3::z();
            frame = min_rotation(&t_old, &t_new) * frame;
            frame /= frame.norm();
            p[e] = frame;
        }
        let t_end = rotation_matrix(&frame) * Vector3::z();
        let arrive = min_rotation(&t_end, &tb) * frame;
        let mismatch = twist_angle(&arrive, &poses[cb].orientation);
        #[allow(clippy::needless_range_loop)]
        for e in na..nb {
            let mid = 0.5 * (rod.arc[e] + rod.arc[e + 1]) - rod.arc[na];
            p[e] = twist(&p[e], mismatch * mid / span);
        }
    }
    // Free ends.
    let first = order[0];
    let n0 = rod.clip_nodes[first][0];
    if n0 > 0 {
        let pose = Pose {
            position: x[n0],
            orientation: poses[first].orientation,
        };
        natural_shape_backward(rod, &pose, n0, &mut x, &mut p);
    }
    let last = *order.last().unwrap();
    let n1 = *rod.clip_nodes[last].last().unwrap();
    if n1 < n_nodes - 1 {
        let pose = Pose {
            position: x[n1],
            orientation: poses[last].orientation,
        };
        natural_shape(rod, &pose, n1, n_nodes - 1, &mut x, &mut p);
    }
    let ghost = rod
        .ghosts
        .iter()
        .map(|g| poses[g.clip].orientation)
        .collect();
    Ok(State {
        x,
        p,
        ghost,
        clip_pose: poses,
    })
}

/// Signed angle about the common d3 axis that takes frame `a` to frame `b`.
fn twist_angle(a: &Quat, b: &Quat) -> f64 {
    let q = a.conjugate() * b;
    2.0 * q.k.atan2(q.w)
}

fn hermite(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    ta: &Vector3<f64>,
    tb: &Vector3<f64>,
    t: f64,
) -> Vector3<f64> {
    let (t2, t3) = (t * t, t * t * t);
    a * (2.0 * t3 - 3.0 * t2 + 1.0)
        + ta * (t3 - 2.0 * t2 + t)
        + b * (-2.0 * t3 + 3.0 * t2)
        + tb * (t3 - t2)
}

fn curve_length(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    ta: &Vector3<f64>,
    tb: &Vector3<f64>,
    lambda: f64,
) -> f64 {
    let (ta, tb) = (ta * lambda, tb * lambda);
    let mut len = 0.0;
    let mut prev = *a;
    for i in 1..=SAMPLES {
        let p = hermite(a, b, &ta, &tb, i as f64 / SAMPLES as f64);
        len += (p - prev).norm();
        prev = p;
    }
    len
}

/// The tangent scale λ at which the Hermite curve has length `span` (bisection; λ = 0 gives the
/// chord, the shortest curve).
fn solve_tangent_scale(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    ta: &Vector3<f64>,
    tb: &Vector3<f64>,
    span: f64,
) -> f64 {
    let mut hi = span.max(1e-12);
    let mut k = 0;
    while curve_length(a, b, ta, tb, hi) < span && k < 60 {
        hi *= 2.0;
        k += 1;
    }
    let mut lo = 0.0;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if curve_length(a, b, ta, tb, mid) < span {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Integrates the natural shape forward from node `from` (pose at that node) to node `to`.
fn natural_shape(
    rod: &Rod,
    start: &Pose,
    from: usize,
    to: usize,
    x: &mut [Vector3<f64>],
    p: &mut [Quat],
) {
    let k0 = rod.spec.natural_curvature;
    let mut frame = start.orientation;
    x[from] = start.position;
    for e in from..to {
        let ds = rod.ds_edge[e];
        let half = if e == from {
            0.5 * rod.ds_edge[e]
        } else {
            rod.ds_node[e]
        };
        frame *= exp_half(&(k0 * half));
        p[e] = frame;
        x[e + 1] = x[e] + rotation_matrix(&frame) * Vector3::z() * ds;
    }
}

/// Integrates the natural shape backward from node `from` to node 0.
fn natural_shape_backward(
    rod: &Rod,
    start: &Pose,
    from: usize,
    x: &mut [Vector3<f64>],
    p: &mut [Quat],
) {
    let k0 = rod.spec.natural_curvature;
    let mut frame = start.orientation;
    for e in (0..from).rev() {
        let half = if e + 1 == from {
            0.5 * rod.ds_edge[e]
        } else {
            rod.ds_node[e + 1]
        };
        frame *= exp_half(&(-k0 * half));
        p[e] = frame;
        x[e] = x[e + 1] - rotation_matrix(&frame) * Vector3::z() * rod.ds_edge[e];
    }
}

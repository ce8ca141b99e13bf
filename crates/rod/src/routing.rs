//! The initial configuration: a smooth curve through the clips with the clip tangents and the
//! prescribed cable length between clips (cubic Hermite plus a sag bulge, solved for the length);
//! free ends follow the natural curvature from the last clip. Frames are parallel-transported
//! and the twist mismatch at the next clip is spread linearly over the span.
use crate::model::{Pose, Rod, SpecError};
use crate::rotation::{any_normal, exp_half, min_rotation, rotation_matrix, Quat};
use crate::simd::{f64x4, splat};
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
        if chord > span {
            // Pre-tensioned: the clips are farther apart than the cable between them is long;
            // the span starts straight and uniformly stretched (see `span_stretches`).
            for n in na + 1..nb {
                x[n] = a + (b - a) * ((rod.arc[n] - rod.arc[na]) / span);
                done[n] = true;
            }
        } else {
            let sag = sag_direction(&a, &b, &ta, &tb, &spec.gravity);
            let curve = SpanCurve::fit(a, b, ta, tb, sag, span);
            let pts: Vec<Vector3<f64>> = (0..=SAMPLES)
                .map(|i| curve.at(i as f64 / SAMPLES as f64))
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

/// One span between consecutive clips: the distance of the held ends (chord) against the cable
/// length between them.
#[derive(Clone, Debug, PartialEq)]
pub struct SpanStretch {
    pub clips: (usize, usize),
    pub chord: f64,
    pub length: f64,
}

impl SpanStretch {
    /// The axial strain of the span if it were straight: chord/length − 1 (> 0: pre-tensioned).
    pub fn strain(&self) -> f64 {
        self.chord / self.length - 1.0
    }
}

/// The spans between consecutive clips (by arc length) at the given clip poses.
pub fn span_stretches(rod: &Rod, poses: &[Pose]) -> Vec<SpanStretch> {
    let mut order: Vec<usize> = (0..rod.spec.clips.len()).collect();
    order.sort_by(|&a, &b| rod.spec.clips[a].s.total_cmp(&rod.spec.clips[b].s));
    order
        .windows(2)
        .map(|w| {
            let (ca, cb) = (w[0], w[1]);
            let na = *rod.clip_nodes[ca].last().unwrap();
            let nb = rod.clip_nodes[cb][0];
            let a = rod.clip_node_position(ca, na, &poses[ca]);
            let b = rod.clip_node_position(cb, nb, &poses[cb]);
            SpanStretch {
                clips: (ca, cb),
                chord: (b - a).norm(),
                length: rod.arc[nb] - rod.arc[na],
            }
        })
        .collect()
}

/// Signed angle about the common d3 axis that takes frame `a` to frame `b`.
fn twist_angle(a: &Quat, b: &Quat) -> f64 {
    let q = a.conjugate() * b;
    2.0 * q.k.atan2(q.w)
}

/// The curve of one span: a cubic Hermite with tangent scale λ ≤ chord (larger λ makes loops),
/// plus a sag bulge β·n·16t²(1−t)² (zero offset and slope at both ends) for the slack a
/// Hermite curve without loops cannot take up.
struct SpanCurve {
    a: Vector3<f64>,
    b: Vector3<f64>,
    ta: Vector3<f64>,
    tb: Vector3<f64>,
    sag: Vector3<f64>,
}

impl SpanCurve {
    fn at(&self, t: f64) -> Vector3<f64> {
        let (t2, t3) = (t * t, t * t * t);
        let bump = 16.0 * t2 * (1.0 - t) * (1.0 - t);
        self.a * (2.0 * t3 - 3.0 * t2 + 1.0)
            + self.ta * (t3 - 2.0 * t2 + t)
            + self.b * (-2.0 * t3 + 3.0 * t2)
            + self.tb * (t3 - t2)
            + self.sag * bump
    }

    /// The length of the polyline through the samples at t = i/SAMPLES (from `a`): the
    /// points and the lengths of its pieces four at a time in f64x4 lanes, each lane with the
    /// operations of `at` and `norm` in their order, then summed in order — the value of the
    /// one-point loop (`length_by_points`) to the last bit, ~3× faster (the span fit takes
    /// ~120 lengths).
    fn length(&self) -> f64 {
        const PADDED: usize = SAMPLES + 4;
        let (mut px, mut py, mut pz) = ([0.0; PADDED], [0.0; PADDED], [0.0; PADDED]);
        (px[0], py[0], pz[0]) = (self.a.x, self.a.y, self.a.z);
        let s = splat;
        let n = s(SAMPLES as f64);
        let mut i = 1;
        while i <= SAMPLES {
            let t = f64x4::new([i as f64, (i + 1) as f64, (i + 2) as f64, (i + 3) as f64]) / n;
            let (t2, t3) = (t * t, t * t * t);
            let bump = s(16.0) * t2 * (s(1.0) - t) * (s(1.0) - t);
            let h00 = s(2.0) * t3 - s(3.0) * t2 + s(1.0);
            let h10 = t3 - s(2.0) * t2 + t;
            let h01 = -s(2.0) * t3 + s(3.0) * t2;
            let h11 = t3 - t2;
            let c = |k: usize| {
                s(self.a[k]) * h00
                    + s(self.ta[k]) * h10
                    + s(self.b[k]) * h01
                    + s(self.tb[k]) * h11
                    + s(self.sag[k]) * bump
            };
            px[i..i + 4].copy_from_slice(&c(0).to_array());
            py[i..i + 4].copy_from_slice(&c(1).to_array());
            pz[i..i + 4].copy_from_slice(&c(2).to_array());
            i += 4;
        }
        let mut pieces = [0.0; PADDED];
        let mut i = 1;
        while i <= SAMPLES {
            let d = |p: &[f64; PADDED]| {
                f64x4::new(p[i..i + 4].try_into().expect("4"))
                    - f64x4::new(p[i - 1..i + 3].try_into().expect("4"))
            };
            let (dx, dy, dz) = (d(&px), d(&py), d(&pz));
            pieces[i..i + 4].copy_from_slice(&(dx * dx + dy * dy + dz * dz).sqrt().to_array());
            i += 4;
        }
        pieces[1..=SAMPLES].iter().fold(0.0, |len, p| len + p)
    }

    /// `length` one point at a time (the reference of its test).
    #[cfg(test)]
    fn length_by_points(&self) -> f64 {
        let mut len = 0.0;
        let mut prev = self.a;
        for i in 1..=SAMPLES {
            let p = self.at(i as f64 / SAMPLES as f64);
            len += (p - prev).norm();
            prev = p;
        }
        len
    }

    fn fit(
        a: Vector3<f64>,
        b: Vector3<f64>,
        ta: Vector3<f64>,
        tb: Vector3<f64>,
        n: Vector3<f64>,
        span: f64,
    ) -> Self {
        let chord = (b - a).norm();
        let make = |lambda: f64, beta: f64| SpanCurve {
            a,
            b,
            ta: ta * lambda,
            tb: tb * lambda,
            sag: n * beta,
        };
        let lmax = chord.max(1e-3 * span);
        if make(lmax, 0.0).length() >= span {
            let (mut lo, mut hi) = (0.0, lmax);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if make(mid, 0.0).length() < span {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            return make(0.5 * (lo + hi), 0.0);
        }
        let mut hi = span;
        while make(lmax, hi).length() < span {
            hi *= 2.0;
        }
        let mut lo = 0.0;
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if make(lmax, mid).length() < span {
                lo = mid
            } else {
                hi = mid
            }
        }
        make(lmax, 0.5 * (lo + hi))
    }
}

/// The direction a slack span sags: along gravity, orthogonal to the chord; without gravity
/// (or gravity along the chord) along the mean end tangent's orthogonal part, else any normal.
fn sag_direction(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    ta: &Vector3<f64>,
    tb: &Vector3<f64>,
    gravity: &Vector3<f64>,
) -> Vector3<f64> {
    let c = (b - a).try_normalize(1e-300).unwrap_or(*ta);
    for cand in [*gravity, ta + tb, ta - tb] {
        let v = cand - c * cand.dot(&c);
        if v.norm() > 1e-6 * cand.norm().max(1e-300) && v.norm() > 0.0 {
            return v.normalize();
        }
    }
    any_normal(&c)
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

/// The normal (d1) that clip `to` gets when the frame of clip `from` is parallel-transported
/// along the routed reference centreline to it (no twist about the curve on the way): the
/// default normal of a junction's end (docs/harness.md). Orthogonal to `to`'s tangent.
pub fn transported_normal(rod: &Rod, from: usize, to: usize) -> Result<Vector3<f64>, SpecError> {
    let st = route(rod, None)?;
    let node = |c: usize| {
        let s = rod.spec.clips[c].s;
        (0..rod.arc.len())
            .min_by(|&a, &b| (rod.arc[a] - s).abs().total_cmp(&(rod.arc[b] - s).abs()))
            .unwrap_or(0)
    };
    let (a, b) = (node(from), node(to));
    let q_from = rotation_matrix(&rod.spec.clips[from].pose.orientation);
    let (mut d1, mut t) = (q_from * Vector3::x(), q_from * Vector3::z());
    let carry = |t_next: Vector3<f64>, d1: &mut Vector3<f64>, t: &mut Vector3<f64>| {
        *d1 = rotation_matrix(&min_rotation(t, &t_next)) * *d1;
        *t = t_next;
    };
    let edges: Vec<usize> = if a <= b {
        (a..b).collect()
    } else {
        (b..a).rev().collect()
    };
    for e in edges {
        if let Some(te) = (st.x[e + 1] - st.x[e]).try_normalize(1e-300) {
            carry(te, &mut d1, &mut t);
        }
    }
    let t_to = rotation_matrix(&rod.spec.clips[to].pose.orientation) * Vector3::z();
    carry(t_to, &mut d1, &mut t);
    (d1 - t_to * d1.dot(&t_to))
        .try_normalize(1e-12)
        .ok_or_else(|| SpecError(format!("clip {to}: no normal transported from clip {from}")))
}

#[cfg(test)]
mod transport_tests {
    use super::*;
    use crate::model::{CableSpec, ClipKind, ClipSpec};
    use crate::rotation::frame_quaternion;

    fn clip(s: f64, p: [f64; 3], t: [f64; 3], n: [f64; 3]) -> ClipSpec {
        ClipSpec {
            name: format!("c{s}"),
            s,
            length: 0.0,
            kind: ClipKind::Fixed,
            pose: Pose {
                position: Vector3::from(p),
                orientation: frame_quaternion(&Vector3::from(t), &Vector3::from(n)).unwrap(),
            },
        }
    }

    fn rod(clips: Vec<ClipSpec>, length: f64) -> Rod {
        Rod::new(CableSpec {
            length,
            segments: 64,
            section: crate::harness::tests::section(),
            natural_curvature: Vector3::zeros(),
            clips,
            loads: vec![],
            gravity: Vector3::zeros(),
        })
        .unwrap()
    }

    #[test]
    fn transport_along_a_plane_bend_keeps_the_binormal_and_along_a_straight_line_the_normal() {
        // A quarter circle in the x–y plane (tangent x at the start, y at the end, radius 0.3):
        // a normal along z (the binormal) stays z; a normal in the plane turns with the
        // tangent (x-tangent with normal y ends as the y-tangent with normal −x).
        let l = 0.3 * std::f64::consts::FRAC_PI_2;
        for (n0, n1) in [
            ([0.0, 0.0, 1.0], Vector3::z()),
            ([0.0, 1.0, 0.0], -Vector3::x()),
        ] {
            let r = rod(
                vec![
                    clip(0.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], n0),
                    // The end's own normal (any): the transport ignores it.
                    clip(l, [0.3, 0.3, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
                ],
                l,
            );
            let d1 = transported_normal(&r, 0, 1).unwrap();
            assert!((d1 - n1).norm() < 1e-9, "{d1:?} for {n0:?}");
            // And back.
            let back = transported_normal(&r, 1, 0).unwrap();
            assert!(back.z.abs() > 1.0 - 1e-9, "{back:?}");
        }
        // Straight: the normal stays.
        let r = rod(
            vec![
                clip(0.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.6, 0.8]),
                clip(0.5, [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ],
            0.5,
        );
        let d1 = transported_normal(&r, 0, 1).unwrap();
        assert!((d1 - Vector3::new(0.0, 0.6, 0.8)).norm() < 1e-12, "{d1:?}");
    }

    #[test]
    fn transport_out_of_the_plane_is_orthogonal_and_reversible() {
        // Out of the plane: the end's normal from the route must be orthogonal to the end
        // tangent and the routed frame twist-free: the transported normal differs from the
        // endpoint clip rule in general, and transporting back returns the start normal.
        let r = rod(
            vec![
                clip(0.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
                clip(0.6, [0.3, 0.25, 0.2], [0.0, 0.6, 0.8], [1.0, 0.0, 0.0]),
            ],
            0.6,
        );
        let d1 = transported_normal(&r, 0, 1).unwrap();
        let t1 = Vector3::new(0.0, 0.6, 0.8);
        assert!(d1.dot(&t1).abs() < 1e-12 && (d1.norm() - 1.0).abs() < 1e-12);
        // Put that normal on the end clip and transport back: z again.
        let mut spec = r.spec.clone();
        spec.clips[1].pose.orientation = frame_quaternion(&t1, &d1).unwrap();
        let r2 = Rod::new(spec).unwrap();
        let back = transported_normal(&r2, 1, 0).unwrap();
        assert!((back - Vector3::z()).norm() < 1e-9, "{back:?}");
    }
}

#[cfg(test)]
mod length_tests {
    use super::*;

    /// The span curve's length in lanes is the one-point loop's to the last bit, for curves
    /// with and without sag, short and long, and through the fit's brackets.
    #[test]
    fn length_in_lanes_is_the_pointwise_length_bit_for_bit() {
        let mut rng = crate::modal::Rng(17);
        let mut rnd = || rng.next();
        for k in 0..50 {
            let scale = [1e-3, 0.3, 2.0, 40.0][k % 4];
            let mut v = || Vector3::new(rnd(), rnd(), rnd()) * scale;
            let curve = SpanCurve {
                a: v(),
                b: v(),
                ta: v(),
                tb: v(),
                sag: if k % 3 == 0 { Vector3::zeros() } else { v() },
            };
            let (fast, slow) = (curve.length(), curve.length_by_points());
            assert_eq!(
                fast.to_bits(),
                slow.to_bits(),
                "curve {k}: {fast} vs {slow}"
            );
        }
    }
}

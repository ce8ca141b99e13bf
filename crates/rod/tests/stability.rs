//! Stability of equilibria: the inertia of the tangent stiffness, the escape from unstable
//! equilibria to stable ones, snap-through in quasistatic sequences. References: the Euler
//! load and the post-buckled elastica of a clamped–free column (exact, elliptic integrals).
mod common;
use common::*;
use nalgebra::Vector3;
use rod::routing::route;
use rod::{CableSpec, ClipKind, NewtonOptions, PointLoad, Rod, Section, State, Statics};
use std::f64::consts::PI;

/// Nearly inextensible and shear-rigid section with bending stiffnesses ei1, ei2.
fn stiff(ei1: f64, ei2: f64) -> Section {
    Section {
        shear_stiffness: Vector3::new(1e8, 1e8, 1e8),
        bend_stiffness: Vector3::new(ei1, ei2, 1.0),
        mass_per_length: 0.1,
        rotary_inertia: Vector3::new(1e-9, 1e-9, 2e-9),
    }
}

/// A clamped–free column along +x (d1 = +z, d2 = −y) under the dead tip load
/// (−p, −imperfection, 0): the imperfection bends it about d1.
fn column(n: usize, sec: Section, p: f64, imperfection: f64) -> CableSpec {
    let mut spec = cantilever(1.0, n, sec);
    spec.loads.push(PointLoad {
        s: 1.0,
        force: Vector3::new(-p, -imperfection, 0.0),
        moment: Vector3::zeros(),
    });
    spec
}

/// Complete elliptic integrals K(m), E(m) (parameter m = k²) by the arithmetic–geometric mean.
fn ellip_ke(m: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    let mut sum = 0.5 * m;
    let mut pow = 0.5;
    loop {
        let c = 0.5 * (a - b);
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
        pow *= 2.0;
        sum += pow * c * c;
        if c.abs() < 1e-16 {
            break;
        }
    }
    let k = PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// The post-buckled clamped–free elastica under tip load p (EI, L = 1): K(k) = √(p/EI), tip
/// angle 2 asin k, tip at x = 2E/K − 1 along the load line, 2k/K across it.
fn elastica(p: f64, ei: f64) -> (f64, f64, f64) {
    let target = (p / ei).sqrt();
    let (mut lo, mut hi) = (0.0, 1.0 - 1e-15);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ellip_ke(mid).0 < target {
            lo = mid
        } else {
            hi = mid
        }
    }
    let m = 0.5 * (lo + hi);
    let (kk, ee) = ellip_ke(m);
    let k = m.sqrt();
    (2.0 * k.asin(), 2.0 * ee / kk - 1.0, 2.0 * k / kk)
}

fn euler_load(ei: f64) -> f64 {
    PI * PI * ei / 4.0
}

/// Plain Newton from the straight routed shape (no stability check): the near-straight state.
fn plain_newton(spec: CableSpec) -> (Rod, State, Statics) {
    let rod = Rod::new(spec).unwrap();
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    solver.newton(&rod, &mut st, 1.0, false).unwrap();
    (rod, st, solver)
}

#[test]
fn the_straight_column_is_stable_below_and_unstable_above_its_euler_loads() {
    let ei = 1.0;
    let pe = euler_load(ei);
    // Round section: two equal Euler loads, so 0 or 2 negative eigenvalues; the second mode
    // (9 P_E) adds two more.
    for (factor, expected) in [(0.9, 0), (1.1, 2), (3.0, 2), (10.0, 4)] {
        let (rod, st, mut solver) = plain_newton(column(40, stiff(ei, ei), factor * pe, 0.0));
        assert!(st.x.last().unwrap().z.abs() < 1e-12, "stays straight");
        let inertia = solver.inertia(&rod, &st, true).unwrap();
        assert_eq!(inertia.negative, expected, "P = {factor} P_E");
    }
    // Flat section EI₁ = 1 < EI₂ = 4: between the two Euler loads only the weak plane buckles.
    for (factor, expected) in [(0.9, 0), (2.0, 1), (4.5, 2)] {
        let (rod, st, mut solver) = plain_newton(column(40, stiff(ei, 4.0 * ei), factor * pe, 0.0));
        let inertia = solver.inertia(&rod, &st, true).unwrap();
        assert_eq!(inertia.negative, expected, "flat, P = {factor} P_E");
    }
}

#[test]
fn above_its_euler_load_the_imperfect_column_is_solved_to_the_buckled_elastica() {
    let ei = 1.0;
    let p = 2.0 * euler_load(ei);
    // Flat section (EI₂ = 4 EI₁): the buckled state is isolated (a round one could turn its
    // plane about the load line freely: a neutral mode).
    let spec = column(80, stiff(ei, 4.0 * ei), p, 1e-6 * p);
    // Plain Newton finds the near-straight unstable state (its tip even moves against the
    // imperfection) …
    let (rod, st, mut solver) = plain_newton(spec.clone());
    assert!(st.x.last().unwrap().y.abs() < 1e-4);
    assert_eq!(solver.inertia(&rod, &st, true).unwrap().negative, 1);
    // … the static solve leaves it for the stable buckled state.
    let mut st = route(&rod, None).unwrap();
    let stats = solver.solve(&rod, &mut st).unwrap();
    assert_eq!(stats.unstable, Some(0));
    assert!(stats.escapes >= 1);
    assert_eq!(solver.inertia(&rod, &st, true).unwrap().negative, 0);
    let (alpha, x_tip, y_tip) = elastica(p, ei);
    let tip = st.x.last().unwrap();
    let lateral = (tip.y * tip.y + tip.z * tip.z).sqrt();
    assert!((tip.x - x_tip).abs() < 2e-3, "x {} vs {x_tip}", tip.x);
    assert!((lateral - y_tip).abs() < 2e-3, "δ {lateral} vs {y_tip}");
    let t = rod::rotation::rotation_matrix(st.p.last().unwrap()) * Vector3::z();
    let angle = (-t.x).acos(); // from the load line (−x is where the column points … at 180°)
    let tip_angle = PI - angle;
    assert!((tip_angle - alpha).abs() < 5e-3, "α {tip_angle} vs {alpha}");
}

/// Tip position error of the buckled column (weak EI = 1, strong EI `ei2`) against the
/// elastica, N segments.
fn elastica_error(n: usize, p: f64, ei2: f64, imperfection: f64) -> f64 {
    let ei = 1.0;
    let rod = Rod::new(column(n, stiff(ei, ei2), p, imperfection * p)).unwrap();
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    let stats = solver.solve(&rod, &mut st).unwrap();
    assert_eq!(stats.unstable, Some(0));
    let (_, x_tip, y_tip) = elastica(p, ei);
    let tip = st.x.last().unwrap();
    let lateral = (tip.y * tip.y + tip.z * tip.z).sqrt();
    ((tip.x - x_tip).powi(2) + (lateral - y_tip).powi(2)).sqrt()
}

#[test]
fn the_buckled_column_converges_to_the_elastica_at_second_order() {
    let p = 1.5 * euler_load(1.0);
    let errs: Vec<f64> = [10, 20, 40, 80]
        .iter()
        .map(|&n| elastica_error(n, p, 4.0, 1e-9))
        .collect();
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.2).contains(&order), "order {order}: {errs:?}");
    }
    assert!(errs[3] < 1e-3, "{errs:?}");
}

/// The round column (EI₁ = EI₂ = 1, EA = GA = 1e8) at tip load p with a lateral imperfection
/// (fraction of p, along −y), N segments, solved from the straight routed shape: the tip
/// position error against the elastica, the tip angle error, and the buckling plane's angle
/// from the imperfection's (−y) plane.
fn round_column(n: usize, p: f64, imperfection: f64) -> (f64, f64, f64) {
    let rod = Rod::new(column(n, stiff(1.0, 1.0), p, imperfection * p)).unwrap();
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    let stats = solver.solve(&rod, &mut st).unwrap();
    assert_eq!(
        stats.unstable,
        Some(0),
        "N = {n}, imperfection {imperfection}"
    );
    assert_eq!(solver.inertia(&rod, &st, true).unwrap().negative, 0);
    let (alpha, x_tip, y_tip) = elastica(p, 1.0);
    let tip = st.x.last().unwrap();
    let lateral = (tip.y * tip.y + tip.z * tip.z).sqrt();
    let t = rod::rotation::rotation_matrix(st.p.last().unwrap()) * Vector3::z();
    let tip_angle = PI - (-t.x).acos();
    (
        ((tip.x - x_tip).powi(2) + (lateral - y_tip).powi(2)).sqrt(),
        (tip_angle - alpha).abs(),
        tip.z.atan2(-tip.y),
    )
}

#[test]
fn a_round_column_escapes_to_the_buckled_elastica_at_second_order() {
    // EI₁ = EI₂ and EA/EI = 1e8: two nearly equal negative eigenvalues at the straight state
    // (one per plane, split only by the imperfection), and the buckled state turns its plane
    // about the load line at a cost the tangent cannot resolve next to the stiff axis (a
    // neutral equilibrium without imperfection). Before the escape along the mode with the
    // projection onto the stiff axis and the line search along the neutral mode (docs/
    // solver.md), 9 of these 16 cases reached the stable state (the perfect column 4/4).
    let p = 1.5 * euler_load(1.0);
    for imperfection in [0.0, 1e-9, 1e-6, 1e-4] {
        let runs: Vec<(f64, f64, f64)> = [10, 20, 40, 80]
            .iter()
            .map(|&n| round_column(n, p, imperfection))
            .collect();
        for w in runs.windows(2) {
            for (a, b, what) in [(w[0].0, w[1].0, "tip"), (w[0].1, w[1].1, "angle")] {
                let order = (a / b).log2();
                assert!(
                    (1.8..2.2).contains(&order),
                    "imperfection {imperfection}, {what}: order {order}: {runs:?}"
                );
            }
        }
        assert!(runs[3].0 < 1e-3 && runs[3].1 < 1e-3, "{runs:?}");
        if imperfection >= 1e-6 {
            // The imperfection picks the plane (to the resolution of the energy's round-off:
            // ½ F δ ψ² against 1e-10 of the energy).
            for r in &runs {
                assert!(r.2.abs() < 0.05, "plane {} rad: {runs:?}", r.2);
            }
        }
    }
}

/// A straight cable of length 1 along x between fixed point clips at x = 0 and x = `d`.
fn between_clips(d: f64, sec: Section, kinds: [ClipKind; 2]) -> CableSpec {
    CableSpec {
        length: 1.0,
        segments: 20,
        section: sec,
        natural_curvature: Vector3::zeros(),
        clips: vec![
            clip(
                "a",
                0.0,
                0.0,
                kinds[0],
                pose([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            ),
            clip(
                "b",
                1.0,
                0.0,
                kinds[1],
                pose([d, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            ),
        ],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    }
}

#[test]
fn clips_farther_apart_than_the_cable_is_long_pre_tension_it() {
    let sec = circle(0.004, 1e8, 0.45, 1200.0);
    let ea = sec.shear_stiffness.z;
    let d = 1.02;
    let mut spec = between_clips(d, sec, [ClipKind::Fixed, ClipKind::Fixed]);
    spec.gravity = Vector3::zeros(); // the straight state is then exact
    let rod = Rod::new(spec).unwrap();
    let stretch =
        rod::routing::span_stretches(&rod, &[rod.spec.clips[0].pose, rod.spec.clips[1].pose]);
    assert_eq!(stretch.len(), 1);
    assert!((stretch[0].strain() - 0.02).abs() < 1e-12);
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    let stats = solver.solve(&rod, &mut st).unwrap();
    assert_eq!(stats.unstable, Some(0));
    solver.ws.assemble_static(&rod, &st, 1.0, false).unwrap();
    for f in &solver.ws.edge_force {
        assert!((f.z - ea * (d - 1.0)).abs() < 1e-9 * ea * (d - 1.0), "{f}");
        assert!(f.x.abs() + f.y.abs() < 1e-9 * ea * (d - 1.0));
    }
}

#[test]
fn a_tiny_bending_stiffness_is_ill_conditioned_not_singular() {
    // EI, GJ 1e-9 N m² against GA, EA ~ 1e3 N: the pivots span 1e15 but none is zero.
    let sec = Section {
        shear_stiffness: Vector3::new(1e3, 1e3, 3e3),
        bend_stiffness: Vector3::new(1e-9, 1e-9, 1e-9),
        mass_per_length: 0.1,
        rotary_inertia: Vector3::new(1e-12, 1e-12, 2e-12),
    };
    // Taut (1 ‰ pre-strain) under gravity: a string with a little sag.
    let rod = Rod::new(between_clips(
        1.001,
        sec,
        [ClipKind::Fixed, ClipKind::Fixed],
    ))
    .unwrap();
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    let stats = solver.solve(&rod, &mut st).unwrap();
    assert!(stats.iterations > 0);
    // Sag of a shallow elastic string: w = ρ g L² / (8 T), T = EA (ε₀ + 8w²/(3L²)) (the
    // parabola's extra length), solved by bisection.
    let sag = -st.x[10].z;
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..100 {
        let w = 0.5 * (lo + hi);
        if 8.0 * w * 3e3 * (1e-3 + 8.0 * w * w / 3.0) < 0.1 * 9.81 {
            lo = w
        } else {
            hi = w
        }
    }
    let expected = 0.5 * (lo + hi);
    assert!(
        (sag - expected).abs() < 0.02 * expected,
        "{sag} vs {expected}"
    );
    // The factorisation judges each pivot against its own column: scales 1e6 and 1e-9 in
    // one block factor; a pivot cancelled to round-off by the elimination is singular.
    use rod::block_tridiag::{Block, BlockTridiag};
    let mut j = BlockTridiag::new(2);
    let d = Block::from_diagonal(&nalgebra::Vector6::new(1e6, 1e6, 1e6, 1e-9, 1e-9, 1e-9));
    j.diag = vec![2.0 * d, 2.0 * d];
    j.upper[0] = -d;
    j.lower[1] = -d;
    assert!(j.factor().is_ok());
    j.diag[1] = 0.5 * d; // D₁ − L₁ D₀⁻¹ U₀ = 0
    assert_eq!(j.factor(), Err(rod::block_tridiag::Singular { block: 1 }));
}

#[test]
fn free_rigid_body_motions_are_named() {
    let sec = circle(0.004, 1e8, 0.45, 1200.0);
    // Two swivel clips on a straight span: the whole cable can spin about its axis.
    for (kinds, axis) in [
        ([ClipKind::Swivel, ClipKind::Swivel], true),
        ([ClipKind::Ball, ClipKind::Ball], true),
        ([ClipKind::Ball, ClipKind::Swivel], true),
        ([ClipKind::Fixed, ClipKind::Ball], false),
    ] {
        let rod = Rod::new(between_clips(0.9, sec.clone(), kinds)).unwrap();
        let mut st = route(&rod, None).unwrap();
        let result = Statics::new(&rod, NewtonOptions::default()).solve(&rod, &mut st);
        match result {
            Err(e @ rod::SolveError::RigidBody { .. }) => {
                assert!(axis, "{kinds:?}: {e}");
                let msg = e.to_string();
                assert!(
                    msg.contains("clips 'a', 'b' leave a rigid-body motion")
                        && msg.contains("a rotation about the axis (")
                        && msg.contains("1.000, "),
                    "{msg}"
                );
            }
            other => assert!(!axis && other.is_ok(), "{kinds:?}: {other:?}"),
        }
    }
    // One ball clip: every rotation about it is free.
    let mut spec = between_clips(0.9, sec, [ClipKind::Ball, ClipKind::Ball]);
    spec.clips.pop();
    let rod = Rod::new(spec).unwrap();
    let mut st = route(&rod, None).unwrap();
    let e = Statics::new(&rod, NewtonOptions::default())
        .solve(&rod, &mut st)
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("rigid-body motion of the cable free (a rotation"),
        "{e}"
    );
}

/// Incomplete elliptic integral of the first kind F(φ | m) by composite Simpson (smooth for
/// m < 1).
fn ellip_f(phi: f64, m: f64) -> f64 {
    let n = 2000;
    let h = phi / n as f64;
    let f = |t: f64| 1.0 / (1.0 - m * t.sin().powi(2)).sqrt();
    let mut sum = f(0.0) + f(phi);
    for i in 1..n {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i as f64 * h);
    }
    sum * h / 3.0
}

/// The clamp angle β (against the lean) at which the buckled clamped–free elastica under the
/// dead load p (EI = 1, L = 1) loses its branch: the shape turns from β through 0 to the tip
/// angle θ_L = 2 asin k, so √p = K(k) + F(asin(sin(β/2)/k) | k²); the branch exists while the
/// minimum over k of the right side is ≤ √p, and folds where it equals it.
fn fold_clamp_angle(p: f64) -> f64 {
    let lam = p.sqrt();
    let g_min = |beta: f64| {
        let s = (0.5 * beta).sin();
        let g = |k: f64| ellip_ke(k * k).0 + ellip_f((s / k).min(1.0).asin(), k * k);
        let (mut a, mut b) = (s * (1.0 + 1e-12), 1.0 - 1e-9);
        let r = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..100 {
            let (c, d) = (b - r * (b - a), a + r * (b - a));
            if g(c) < g(d) {
                b = d
            } else {
                a = c
            }
        }
        g(0.5 * (a + b))
    };
    let (mut lo, mut hi) = (1e-3, 1.5);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if g_min(mid) < lam {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// Turns the clamp of the buckled column against its lean in steps of `d_beta` until it snaps
/// to the other side; returns the clamp angle of the snap and the snap.
fn snap_angle(n: usize, d_beta: f64) -> (f64, rod::Snap) {
    let ei = 1.0;
    let p = 2.0 * euler_load(ei);
    let rod = Rod::new(column(n, stiff(ei, 4.0 * ei), p, 1e-6 * p)).unwrap();
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    solver.solve(&rod, &mut st).unwrap();
    assert!(st.x.last().unwrap().y < -0.5, "leans to −y");
    for k in 1..200 {
        let beta = k as f64 * d_beta;
        // The clamp turns about +z: its tangent towards +y, against the lean.
        let pose = pose([0.0; 3], [beta.cos(), beta.sin(), 0.0], [0.0, 0.0, 1.0]);
        let stats = solver
            .sequence_step(&rod, &mut st, &[pose])
            .unwrap_or_else(|e| panic!("step {k}, β = {beta}: {e}"));
        assert_eq!(stats.unstable, Some(0), "step {k}");
        if let Some(snap) = stats.snap {
            assert!(st.x.last().unwrap().y > 0.5, "leans to +y after the snap");
            return (beta - (1.0 - snap.fraction) * d_beta, snap);
        }
    }
    panic!("no snap-through");
}

#[test]
fn the_buckled_column_snaps_through_where_its_elastica_branch_folds() {
    let beta_c = fold_clamp_angle(2.0 * euler_load(1.0));
    assert!((beta_c - 0.54498).abs() < 1e-4, "{beta_c}"); // scipy: 0.5449801
    let d_beta = 0.01;
    let (beta, snap) = snap_angle(40, d_beta);
    // The jump is the tip's, across to the other side (≈ twice the lean of ~0.8 m).
    assert_eq!(snap.node, 40);
    assert!(snap.jump > 1.0, "{snap:?}");
    let err40 = (beta - beta_c).abs();
    let (beta80, _) = snap_angle(80, d_beta);
    let err80 = (beta80 - beta_c).abs();
    eprintln!("snap at {beta} (N = 40), {beta80} (N = 80), fold {beta_c}");
    assert!(err80 < 0.01 * beta_c, "{beta80} vs {beta_c}");
    assert!(err80 < err40, "{err40} → {err80}");
}

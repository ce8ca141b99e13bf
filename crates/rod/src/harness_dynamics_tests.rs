//! Harness dynamics against the single continuous cable (same mesh), energy conservation of
//! an undamped harness against a single cable, and the iteration matrix against finite
//! differences.
use super::*;
use crate::harness::JunctionSpec;
use crate::model::Rod;
use crate::routing::route;
use crate::state::State;

/// A straight cable from a to b with fixed clips at both ends.
fn straight(a: [f64; 3], b: [f64; 3], n: usize) -> Rod {
    crate::harness::tests::straight_with(
        a,
        b,
        n,
        crate::harness::tests::section(),
        vec![],
        Vector3::new(0.0, 0.0, -9.81),
    )
}

fn junction(mass: f64, inertia: f64, ends: Vec<(usize, usize)>) -> JunctionSpec {
    JunctionSpec {
        name: "j".into(),
        mass,
        rotary_inertia: Vector3::repeat(inertia),
        ends,
    }
}

fn initial(h: &Harness) -> HarnessState {
    let mut st = HarnessState {
        cables: h.cables.iter().map(|r| route(r, None).unwrap()).collect(),
        junctions: h.reference.clone(),
    };
    st.sync_ends(h);
    st
}

/// The clips of a state at rest, the first clip of cable 0 moved by `lift` along z with the
/// given velocity and acceleration.
fn motions(st: &[State], lift: [f64; 3]) -> Vec<Vec<ClipMotion>> {
    st.iter()
        .enumerate()
        .map(|(c, s)| {
            s.clip_pose
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let mut m = ClipMotion {
                        pose: *p,
                        velocity: Vector3::zeros(),
                        angular_velocity: Vector3::zeros(),
                        acceleration: Vector3::zeros(),
                        angular_acceleration: Vector3::zeros(),
                    };
                    if c == 0 && k == 0 {
                        m.pose.position.z = lift[0];
                        m.velocity.z = lift[1];
                        m.acceleration.z = lift[2];
                    }
                    m
                })
                .collect()
        })
        .collect()
}

/// The lift of the moved clip at time t: 2 mm at 15 Hz, starting smoothly.
fn lift(t: f64) -> [f64; 3] {
    let w = 2.0 * std::f64::consts::PI * 15.0;
    let a = 2e-3;
    // a (1 − cos ωt): position, velocity, acceleration.
    [
        a * (1.0 - (w * t).cos()),
        a * w * (w * t).sin(),
        a * w * w * (w * t).cos(),
    ]
}

fn tight() -> DynamicOptions {
    DynamicOptions {
        rho_inf: 1.0,
        tolerance: 1e-8,
        ..Default::default()
    }
}

/// Largest node distance between the collinear pair (n + n segments, junction without mass
/// or rotary inertia) and the continuous cable (2n segments) over 0.1 s of the shaken clip,
/// and the largest displacement.
fn pair_difference(n: usize, dt: f64) -> (f64, f64) {
    let h = Harness::new(
        vec!["a".into(), "b".into()],
        vec![
            straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], n),
            straight([0.5, 0.0, 0.0], [1.0, 0.0, 0.0], n),
        ],
        vec![junction(0.0, 0.0, vec![(0, 1), (1, 0)])],
    )
    .unwrap();
    let rod = straight([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 2 * n);
    let mut hs = initial(&h);
    let mut ss = route(&rod, None).unwrap();
    let mut hd = HarnessDynamics::new(&h, &hs, &motions(&hs.cables, lift(0.0)), tight());
    hd.start(&h, &mut hs).unwrap();
    let m0 = motions(std::slice::from_ref(&ss), lift(0.0));
    let mut sd = Dynamics::new(&rod, &ss, &m0[0], tight());
    sd.start(&rod, &ss).unwrap();
    let (mut worst, mut moved) = (0.0f64, 0.0f64);
    let x0 = ss.x.clone();
    for k in 1..=(0.1 / dt).round() as usize {
        let t = k as f64 * dt;
        let (mh, ms) = (
            motions(&hs.cables, lift(t)),
            motions(std::slice::from_ref(&ss), lift(t)),
        );
        hd.step(&h, &mut hs, dt, &mh).unwrap();
        sd.step(&rod, &mut ss, dt, &ms[0]).unwrap();
        for (i, (x, x_start)) in ss.x.iter().zip(&x0).enumerate() {
            let xh = if i <= n {
                hs.cables[0].x[i]
            } else {
                hs.cables[1].x[i - n]
            };
            worst = worst.max((xh - x).norm());
            moved = moved.max((x - x_start).norm());
        }
    }
    (worst, moved)
}

#[test]
fn collinear_pair_follows_the_single_cable_in_dynamics() {
    // Same nodes, edges, lumped masses, rotary inertias and shear elements: the only
    // difference is the bending cell at the junction, two half cells through the junction's
    // rotation instead of one. The curvature (2/δs) tan(φ/2) is not additive over half cells
    // (their energy differs from the cell's by a relative O(φ²), φ ~ κΔs: O(Δs³) in all), so
    // the responses differ by O(Δs³), independent of the time step and of the Newton
    // tolerance (which stops both at 1e-8 of the local error estimate).
    let mut diffs = Vec::new();
    for n in [8, 16, 32] {
        let (worst, moved) = pair_difference(n, 1e-3);
        // The cable sags under gravity and follows the shaken clip (centimetres).
        assert!(moved > 5e-3, "{moved}");
        diffs.push(worst / moved);
    }
    let (fine_dt, moved) = pair_difference(16, 5e-4);
    let fine_dt = fine_dt / moved;
    eprintln!(
        "collinear: relative differences {diffs:?} (n = 8, 16, 32); n = 16 at dt/2: {fine_dt:e}"
    );
    for w in diffs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((2.5..3.3).contains(&order), "differences {diffs:?}");
    }
    // Not a time-discretisation effect (that would shrink 4× at half the step): of the same
    // size at half the step (it follows the trajectory, which changes with the step).
    assert!(
        (0.5..2.0).contains(&(fine_dt / diffs[1])),
        "{fine_dt:e} {diffs:?}"
    );
    // Far below the time-discretisation error at this step (~1e-3 of the motion).
    assert!(diffs[1] < 1e-5, "{diffs:?}");
}

/// A Y: the trunk along −x from a clamp to the junction at the origin, two branches at ±30°
/// to clamps (n segments each), gravity.
fn y_harness(n: usize, mass: f64, inertia: f64) -> Harness {
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    Harness::new(
        vec!["trunk".into(), "a".into(), "b".into()],
        vec![
            straight([-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], n),
            straight([0.0, 0.0, 0.0], [0.4 * c, 0.4 * s, 0.0], n),
            straight([0.0, 0.0, 0.0], [0.4 * c, -0.4 * s, 0.0], n),
        ],
        vec![junction(mass, inertia, vec![(0, 1), (1, 0), (2, 0)])],
    )
    .unwrap()
}

/// The largest |E(t) − E(0)| over `duration` of free motion from the straight routed shape
/// under gravity (clips at rest, undamped, ρ∞ = 1), relative to the largest kinetic energy.
fn harness_drift(n: usize, dt: f64, duration: f64) -> f64 {
    let h = y_harness(n, 0.01, 1e-6);
    let mut st = initial(&h);
    let m = motions(&st.cables, [0.0; 3]);
    let mut hd = HarnessDynamics::new(
        &h,
        &st,
        &m,
        DynamicOptions {
            rho_inf: 1.0,
            ..Default::default()
        },
    );
    hd.start(&h, &mut st).unwrap();
    let total = |e: &Energies| e.kinetic + e.elastic + e.load_potential;
    let e0 = total(&hd.energies);
    let (mut drift, mut kin) = (0.0f64, 0.0f64);
    for _ in 0..(duration / dt).round() as usize {
        hd.step(&h, &mut st, dt, &m).unwrap();
        drift = drift.max((total(&hd.energies) - e0).abs());
        kin = kin.max(hd.energies.kinetic);
    }
    drift / kin
}

/// The same for a single clamped cable of the Y's segment length (the trunk alone).
fn single_drift(n: usize, dt: f64, duration: f64) -> f64 {
    let rod = straight([-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], n);
    let mut st = route(&rod, None).unwrap();
    let m = motions(std::slice::from_ref(&st), [0.0; 3]);
    let mut dy = Dynamics::new(
        &rod,
        &st,
        &m[0],
        DynamicOptions {
            rho_inf: 1.0,
            ..Default::default()
        },
    );
    dy.start(&rod, &st).unwrap();
    let total = |e: &Energies| e.kinetic + e.elastic + e.load_potential;
    let e0 = total(&dy.energies);
    let (mut drift, mut kin) = (0.0f64, 0.0f64);
    for _ in 0..(duration / dt).round() as usize {
        dy.step(&rod, &mut st, dt, &m[0]).unwrap();
        drift = drift.max((total(&dy.energies) - e0).abs());
        kin = kin.max(dy.energies.kinetic);
    }
    drift / kin
}

#[test]
fn undamped_harness_conserves_energy_as_a_single_cable() {
    // Generalized-α with ρ∞ = 1 conserves the energy of a linear system exactly; on the
    // geometrically exact rod the drift is a second-order time-discretisation error (plus the
    // Newton tolerance, a fixed fraction of the local error estimate): it shrinks 4× when
    // the step halves, for the harness as for a single cable of the same discretisation.
    let (n, t) = (16, 0.2);
    let h1 = harness_drift(n, 1e-3, t);
    let h2 = harness_drift(n, 5e-4, t);
    let s1 = single_drift(n, 1e-3, t);
    let s2 = single_drift(n, 5e-4, t);
    eprintln!("energy drift / max kinetic: harness {h1:e} {h2:e}, single cable {s1:e} {s2:e}");
    let (oh, os) = ((h1 / h2).log2(), (s1 / s2).log2());
    assert!(
        (1.7..2.5).contains(&oh),
        "harness order {oh}: {h1:e} {h2:e}"
    );
    assert!((1.7..2.5).contains(&os), "single order {os}: {s1:e} {s2:e}");
    // Of the size of the single cable's (same segment length and step).
    assert!(h1 < 3.0 * s1, "harness {h1:e}, single {s1:e}");
}

/// Along the Newton correction δ of the tree-eliminated system (S δ = −r) of a Y with a
/// junction mass and rotary inertia, shaken at the trunk's clamp for 12 steps, the central
/// difference of the residual: (largest deviation from −r, |r|) for forces and moments.
fn newton_direction(tau: f64) -> [f64; 4] {
    let h = y_harness(10, 0.02, 1e-6);
    let mut st = initial(&h);
    let opts = DynamicOptions {
        tolerance: 1e-9,
        tau_shear: Vector3::new(2e-3, 2e-3, 1e-3) * tau,
        tau_bend: Vector3::new(3e-3, 3e-3, 2e-3) * tau,
        ..Default::default()
    };
    let dt = 1e-3;
    let mut hd = HarnessDynamics::new(&h, &st, &motions(&st.cables, lift(0.0)), opts);
    hd.start(&h, &mut st).unwrap();
    for k in 1..=12 {
        let m = motions(&st.cables, lift(k as f64 * dt));
        hd.step(&h, &mut st, dt, &m).unwrap();
    }
    // Move away from the converged iterate (a residual to check against). The correction δ
    // is small: ε = 1e-4 keeps the difference above the round-off of the section forces
    // (EA ε_mach against a residual of ~1 N; 1e-6 and 1e-7 measure that round-off), the
    // truncation O(ε²|δ|²) far below.
    // The step starts from constant velocity (as after a restart): from the learnt predictor
    // (session 17: a recursion of order 6) the residual of the damped case is so small that
    // ε = 1e-4 of the correction measures the round-off (1.1e-5 of |r|).
    let m = motions(&st.cables, lift(13.0 * dt));
    for dy in &mut hd.cables {
        dy.restarted = true;
    }
    hd.begin_step(&h, &mut st, dt, &m);
    hd.newton_direction_fd(&h, &mut st, dt, 1e-4).unwrap()
}

#[test]
fn harness_iteration_matrix_matches_finite_differences() {
    let [fdev, fscale, mdev, mscale] = newton_direction(0.0);
    eprintln!("undamped: forces {fdev:e} of {fscale:e}, moments {mdev:e} of {mscale:e}");
    assert!(fscale > 0.0 && mscale > 0.0);
    assert!(fdev < 1e-6 * fscale, "forces {fdev:e} of {fscale:e}");
    assert!(mdev < 1e-6 * mscale, "moments {mdev:e} of {mscale:e}");
}

#[test]
fn damped_harness_iteration_matrix_matches_finite_differences() {
    // With Kelvin–Voigt damping (the single cable's FD test's retardation times).
    let [fdev, fscale, mdev, mscale] = newton_direction(1.0);
    eprintln!("damped: forces {fdev:e} of {fscale:e}, moments {mdev:e} of {mscale:e}");
    assert!(fscale > 0.0 && mscale > 0.0);
    assert!(fdev < 1e-6 * fscale, "forces {fdev:e} of {fscale:e}");
    assert!(mdev < 1e-6 * mscale, "moments {mdev:e} of {mscale:e}");
}

/// The outputs pass of the saved steps gives the full assembly's harness outputs to the last
/// bit: each branch's load on the junction, the section loads and the energies, with a clip
/// moving and the junction carrying a mass and rotary inertia (`Workspace::outputs_only`).
#[test]
fn harness_outputs_pass_equals_the_full_assembly() {
    let h = y_harness(8, 0.02, 1e-6);
    let mut st = initial(&h);
    let mut hd = HarnessDynamics::new(&h, &st, &motions(&st.cables, lift(0.0)), tight());
    hd.start(&h, &mut st).unwrap();
    let outputs = |hd: &HarnessDynamics, st: &HarnessState| -> Vec<f64> {
        let mut v: Vec<f64> = hd
            .branch_loads(&h, st)
            .iter()
            .flat_map(|(f, m)| f.iter().chain(m.iter()).copied().collect::<Vec<_>>())
            .collect();
        for dy in &hd.cables {
            let ws = &dy.ws;
            for a in [&ws.edge_force, &ws.node_moment, &ws.edge_force_viscous] {
                v.extend(a.iter().flat_map(|x| x.iter().copied()));
            }
        }
        let e = &hd.energies;
        v.extend([e.kinetic, e.elastic, e.load_potential, e.dissipated]);
        v
    };
    for k in 1..=20 {
        let t = k as f64 * 1e-3;
        let m = motions(&st.cables, lift(t));
        hd.step(&h, &mut st, 1e-3, &m).unwrap();
        hd.update_outputs(&h, &st).unwrap();
        let pass = outputs(&hd, &st);
        hd.cables.iter_mut().for_each(|dy| dy.outputs_pass = false);
        hd.update_outputs(&h, &st).unwrap();
        hd.cables.iter_mut().for_each(|dy| dy.outputs_pass = true);
        assert_eq!(pass, outputs(&hd, &st), "step {k}");
    }
}

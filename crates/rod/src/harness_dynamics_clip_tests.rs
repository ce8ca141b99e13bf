//! Harness dynamics with sliding clips on a branch and with a junction held by a clip:
//! against quasistatic runs of a slow motion, against independent clamped cables, energy of
//! an undamped frictionless case, the iteration matrix against finite differences.
use super::*;
use crate::harness::tests::{section, straight_with};
use crate::harness::JunctionSpec;
use crate::model::{ClipKind, ClipSpec, Rod};
use crate::routing::route;
use crate::state::State;

fn straight(a: [f64; 3], b: [f64; 3], n: usize, g: f64) -> Rod {
    straight_with(a, b, n, section(), vec![], Vector3::new(0.0, 0.0, -g))
}

const DEG30: (f64, f64) = (0.866_025_403_784_438_6, 0.5);

/// A Y (trunk along −x to the junction at the origin, branches at ±30°, n segments each) whose
/// branch 1 runs through a sliding guide (8 cm) at its middle with friction `mu`.
fn y_with_guide(n: usize, g: f64, mu: f64, mass: f64, inertia: f64) -> Harness {
    let (c, s) = DEG30;
    let trunk = straight([-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], n, g);
    let a = straight([0.0, 0.0, 0.0], [0.4 * c, 0.4 * s, 0.0], n, g);
    let b = straight([0.0, 0.0, 0.0], [0.4 * c, -0.4 * s, 0.0], n, g);
    let mut spec = a.spec.clone();
    let q = spec.clips[0].pose.orientation;
    spec.clips.push(ClipSpec {
        name: "guide".into(),
        s: 0.2,
        length: 0.08,
        kind: ClipKind::Sliding { friction: mu },
        pose: Pose {
            position: Vector3::new(0.2 * c, 0.2 * s, 0.0),
            orientation: q,
        },
    });
    Harness::new(
        vec!["trunk".into(), "a".into(), "b".into()],
        vec![trunk, Rod::new(spec).unwrap(), b],
        vec![JunctionSpec {
            name: "y".into(),
            mass,
            rotary_inertia: Vector3::repeat(inertia),
            ends: vec![(0, 1), (1, 0), (2, 0)],
        }],
    )
    .unwrap()
}

fn initial(h: &Harness) -> HarnessState {
    let mut st = HarnessState {
        cables: h.cables.iter().map(|r| route(r, None).unwrap()).collect(),
        junctions: h.reference.clone(),
    };
    st.sync_ends(h);
    st
}

fn at_rest(p: &Pose) -> ClipMotion {
    ClipMotion {
        pose: *p,
        velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
        acceleration: Vector3::zeros(),
        angular_acceleration: Vector3::zeros(),
    }
}

/// A smooth ramp over `T`: (1 − cos πt/T)/2 and its two derivatives (held after T).
fn ramp(t: f64, big_t: f64) -> [f64; 3] {
    if t >= big_t {
        return [1.0, 0.0, 0.0];
    }
    let w = std::f64::consts::PI / big_t;
    [
        0.5 * (1.0 - (w * t).cos()),
        0.5 * w * (w * t).sin(),
        0.5 * w * w * (w * t).cos(),
    ]
}

/// The clips of the guided Y at time t: branch 2's far clamp pulled 2 mm outwards and the
/// guide moved 3 cm along its line and 2 cm sideways (+z) over the ramp.
fn guide_motion(st: &HarnessState, t: f64, big_t: f64) -> Vec<Vec<ClipMotion>> {
    let (c, s) = DEG30;
    let r = ramp(t, big_t);
    let mut m: Vec<Vec<ClipMotion>> = st
        .cables
        .iter()
        .map(|x| x.clip_pose.iter().map(at_rest).collect())
        .collect();
    let moved = |m: &mut ClipMotion, d: Vector3<f64>| {
        m.pose.position += r[0] * d;
        m.velocity = r[1] * d;
        m.acceleration = r[2] * d;
    };
    moved(&mut m[2][1], 0.002 * Vector3::new(c, -s, 0.0));
    moved(&mut m[1][2], Vector3::new(0.03 * c, 0.03 * s, 0.02));
    m
}

/// Largest difference of the guide's slid length between a dynamic run of the slow motion
/// (ramp over `big_t`, 1 ms) and the quasistatic run through the same clip poses, and the
/// largest slid length.
fn slid_against_quasistatic(big_t: f64, tau: f64, mu: f64) -> (f64, f64, f64) {
    let h = y_with_guide(20, 0.0, mu, 0.0, 0.0);
    let mut rest = initial(&h);
    let mut qs = HarnessStatics::new(&h, NewtonOptions::default());
    qs.solve_static(&h, &mut rest).unwrap();
    let poses0: Vec<Vec<Pose>> = rest.cables.iter().map(|x| x.clip_pose.clone()).collect();
    let base = HarnessState {
        cables: rest.cables.clone(),
        junctions: rest.junctions.clone(),
    };
    let with_poses = |t: f64| {
        let mut b = base.clone();
        for (c, p) in poses0.iter().enumerate() {
            b.cables[c].clip_pose.clone_from(p);
        }
        guide_motion(&b, t, big_t)
    };
    let mut st = rest.clone();
    let opts = DynamicOptions {
        tolerance: 1e-6,
        tau_shear: Vector3::repeat(tau),
        tau_bend: Vector3::repeat(tau),
        ..Default::default()
    };
    let mut hd = HarnessDynamics::new(&h, &st, &with_poses(0.0), opts);
    hd.start(&h, &mut st).unwrap();
    let sigma0 = hd.cables[1].sliding.as_ref().unwrap().sigma[0];
    let mut q = rest.clone();
    let dt = 1e-3;
    let (mut worst, mut slid, mut last) = (0.0f64, 0.0f64, 0.0f64);
    for k in 1..=((big_t + 0.1) / dt).round() as usize {
        let t = k as f64 * dt;
        let m = with_poses(t);
        hd.advance(&h, &mut st, dt, &with_poses(t - dt), &m, 4)
            .unwrap();
        if k % 10 == 0 {
            let target: Vec<Vec<Pose>> = m
                .iter()
                .map(|c| c.iter().map(|x| x.pose).collect())
                .collect();
            qs.step_to(&h, &mut q, &target).unwrap();
            let d = hd.cables[1].sliding.as_ref().unwrap().sigma[0] - sigma0;
            let s = qs.sliding[1].as_ref().unwrap().sigma[0] - sigma0;
            worst = worst.max((d - s).abs());
            last = (d - s).abs();
            slid = slid.max(s.abs());
        }
    }
    (worst, slid, last)
}

#[test]
fn guide_slides_in_a_slow_dynamic_run_as_in_the_quasistatic_run() {
    // The guide moves 3 cm along its line and 2 cm across it over 0.25 s, then stays (0.1 s);
    // with Kelvin–Voigt damping the dynamic run settles on the quasistatic equilibrium. (The
    // difference during the motion does not shrink with a slower motion: each node entering
    // the guide is pulled onto its line within a small fraction of the taper, by the stiff
    // hold, which excites the branch at every entry.)
    let (worst, slid, last) = slid_against_quasistatic(0.25, 2e-3, 0.0);
    eprintln!("slid {slid:e} m; dynamic − quasistatic: largest {worst:e}, at the end {last:e}");
    assert!(slid > 0.02, "slid {slid}");
    assert!(worst < 1e-3 * slid, "{worst:e} of {slid:e}");
    assert!(last < 1e-6 * slid, "{last:e} of {slid:e}");
}

#[test]
fn frictionless_guide_passes_the_tension_in_a_dynamic_run() {
    // Weightless, the guide at rest after the ramp: the axial force before and after the
    // guide differs by the axial inertia of the cable between the two edges only: the mass
    // between times the axial acceleration, far below the tension.
    let n = 20;
    let h = y_with_guide(n, 0.0, 0.0, 0.0, 0.0);
    let mut st = initial(&h);
    HarnessStatics::new(&h, NewtonOptions::default())
        .solve_static(&h, &mut st)
        .unwrap();
    let base = st.clone();
    let opts = DynamicOptions {
        tolerance: 1e-6,
        tau_shear: Vector3::repeat(2e-3),
        tau_bend: Vector3::repeat(2e-3),
        ..Default::default()
    };
    let mut hd = HarnessDynamics::new(&h, &st, &guide_motion(&base, 0.0, 0.2), opts);
    hd.start(&h, &mut st).unwrap();
    let dt = 1e-3;
    for k in 1..=300 {
        let t = k as f64 * dt;
        let (a, b) = (
            guide_motion(&base, t - dt, 0.2),
            guide_motion(&base, t, 0.2),
        );
        hd.advance(&h, &mut st, dt, &a, &b, 4).unwrap();
    }
    hd.update_outputs(&h, &st).unwrap();
    let ws = &hd.cables[1].ws;
    let tg = rotation_matrix(&st.cables[1].clip_pose[2].orientation) * Vector3::z();
    let force = |e: usize| rotation_matrix(&st.cables[1].p[e]) * ws.edge_force[e];
    let (before, after) = (force(n / 4), force(3 * n / 4));
    let tension = tg.dot(&before);
    // Mass between the two edges times the largest node acceleration there.
    let rod = &h.cables[1];
    let (mut mass, mut acc) = (0.0, 0.0f64);
    for b in n / 4 + 1..=3 * n / 4 {
        mass += rod.node_mass[b];
        acc = acc.max(top(&hd.cables[1].vdot[b]).norm());
    }
    eprintln!(
        "tension {tension} N before, {} after; m a = {:e}",
        tg.dot(&after),
        mass * acc
    );
    assert!(tension > 1.0, "tension {tension}");
    assert!(
        (tg.dot(&after) - tension).abs() <= 1.01 * mass * acc + 1e-9 * tension,
        "{tension} before, {} after, m a = {:e}",
        tg.dot(&after),
        mass * acc
    );
    let slid = hd.cables[1].sliding.as_ref().unwrap().sigma[0] - 0.2;
    assert!(slid.abs() > 0.02, "slid {slid}");
}

/// Largest |E − E₀| relative to the largest kinetic energy: the guided Y with gravity,
/// undamped (ρ∞ = 1), frictionless, released from its straight routing.
fn guided_drift(dt: f64) -> f64 {
    guided_balance(0.0, dt).0
}

#[test]
fn undamped_frictionless_guide_does_not_gain_energy() {
    // The guide's hold is the gradient of ½ k w |Q d|² but for the window's taper term (a
    // force along the line of ½ k w′|Q d|², O(F² Δs/EA)): its energy error is far below the
    // time discretisation's, which is second order.
    let (d1, d2) = (guided_drift(1e-3), guided_drift(5e-4));
    let order = (d1 / d2).log2();
    eprintln!("energy drift / max kinetic: {d1:e} (1 ms), {d2:e} (0.5 ms), order {order}");
    assert!((1.7..2.5).contains(&order), "order {order}: {d1:e} {d2:e}");
    assert!(d1 < 1e-2, "{d1:e}");
}

/// ε of the finite differences of the guided Y (its moment residuals are small: 1e-4 keeps
/// the round-off of the section forces, ~4e-9 N m, at a few 1e-5 of them).
const EPS: f64 = 1e-2;

/// FD check of the iteration matrix of the guided Y (friction `mu`) after 12 steps of the
/// guide's motion (ramp over 0.2 s).
fn guided_newton_direction(mu: f64, tau: f64) -> [f64; 4] {
    let h = y_with_guide(12, 9.81, mu, 0.02, 1e-6);
    let mut st = initial(&h);
    HarnessStatics::new(&h, NewtonOptions::default())
        .solve_static(&h, &mut st)
        .unwrap();
    let base = st.clone();
    let opts = DynamicOptions {
        tolerance: 1e-9,
        tau_shear: Vector3::new(2e-3, 2e-3, 1e-3) * tau,
        tau_bend: Vector3::new(3e-3, 3e-3, 2e-3) * tau,
        ..Default::default()
    };
    let dt = 1e-3;
    let mut hd = HarnessDynamics::new(&h, &st, &guide_motion(&base, 0.0, 0.2), opts);
    hd.start(&h, &mut st).unwrap();
    for k in 1..=12 {
        let m = guide_motion(&base, k as f64 * dt, 0.2);
        hd.step(&h, &mut st, dt, &m).unwrap();
    }
    let m = guide_motion(&base, 13.0 * dt, 0.2);
    hd.begin_step(&h, &mut st, dt, &m);
    hd.newton_direction_fd(&h, &mut st, dt, EPS).unwrap()
}

#[test]
fn iteration_matrix_with_a_sliding_guide_matches_finite_differences() {
    // The guide's term acts on node positions (forces): exact to 1e-6 with and without
    // friction and damping. The moment rows carry, with damping, the harness's documented
    // inexactness (a held ghost's rate c_damp δθ without its J_r⁻¹(hΔq) factor, relative
    // O(h|Δq|)), here ~1e-5 of moment residuals that are 1e-6 of the forces: checked without
    // damping only.
    for (mu, tau) in [(0.0, 0.0), (0.0, 1.0), (0.3, 1.0), (0.3, 0.0)] {
        let [fdev, fscale, mdev, mscale] = guided_newton_direction(mu, tau);
        eprintln!(
            "μ = {mu}, τ × {tau}: forces {fdev:e} of {fscale:e}, moments {mdev:e} of {mscale:e}"
        );
        assert!(fscale > 0.0 && mscale > 0.0);
        assert!(
            fdev < 1e-6 * fscale,
            "μ = {mu}: forces {fdev:e} of {fscale:e}"
        );
        if tau == 0.0 {
            assert!(
                mdev < 1e-6 * mscale,
                "μ = {mu}: moments {mdev:e} of {mscale:e}"
            );
        }
    }
}

#[test]
fn a_branch_that_runs_out_of_its_guide_in_a_dynamic_run_is_named() {
    let h = y_with_guide(12, 0.0, 0.0, 0.0, 0.0);
    let mut st = initial(&h);
    HarnessStatics::new(&h, NewtonOptions::default())
        .solve_static(&h, &mut st)
        .unwrap();
    let (c, s) = DEG30;
    let base = st.clone();
    // The guide moves along its line beyond the branch's far end within 0.1 s.
    let motion = |t: f64| {
        let mut m: Vec<Vec<ClipMotion>> = base
            .cables
            .iter()
            .map(|x| x.clip_pose.iter().map(at_rest).collect())
            .collect();
        let r = ramp(t, 0.1);
        let d = 0.25 * Vector3::new(c, s, 0.0);
        m[1][2].pose.position += r[0] * d;
        m[1][2].velocity = r[1] * d;
        m[1][2].acceleration = r[2] * d;
        m
    };
    let mut hd = HarnessDynamics::new(&h, &st, &motion(0.0), DynamicOptions::default());
    hd.start(&h, &mut st).unwrap();
    let dt = 1e-3;
    let mut failed = None;
    for k in 1..=100 {
        let t = k as f64 * dt;
        if let Err(e) = hd.advance(&h, &mut st, dt, &motion(t - dt), &motion(t), 2) {
            failed = Some((k, e));
            break;
        }
    }
    let (k, e) = failed.expect("the guide left the branch without an error");
    // The guide (8 cm) reaches beyond the far end (0.4 m) once it moved by 0.16 m.
    let moved = 0.25 * ramp(k as f64 * dt, 0.1)[0];
    assert!(
        moved > 0.155 && moved < 0.175,
        "failed at step {k}, moved {moved}"
    );
    assert!(
        e.0.contains("cable 'a'") && e.0.contains("ran out of sliding clip 'guide'"),
        "{e}"
    );
}

/// A Y of weighty branches whose junction (mass, rotary inertia) a clip holds; the clip moves
/// and turns (10 Hz): the clip motions of every cable (the first end's entry gives the
/// junction's clip).
fn held_y() -> Harness {
    let (c, s) = DEG30;
    let mut h = Harness::new(
        vec!["trunk".into(), "a".into(), "b".into()],
        vec![
            straight([-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], 12, 9.81),
            straight([0.0, 0.0, 0.0], [0.4 * c, 0.4 * s, 0.0], 12, 9.81),
            straight([0.0, 0.0, 0.0], [0.4 * c, -0.4 * s, 0.0], 12, 9.81),
        ],
        vec![JunctionSpec {
            name: "y".into(),
            mass: 0.05,
            rotary_inertia: Vector3::new(1e-5, 2e-5, 3e-5),
            ends: vec![(0, 1), (1, 0), (2, 0)],
        }],
    )
    .unwrap();
    h.hold_junction(0).unwrap();
    h
}

/// The held junction's motion at t: translation a(1 − cos ωt) along (0, 0.6, 0.8) and a turn
/// b(1 − cos ωt) about a fixed skew axis; (pose, velocity, ω, acceleration, ω̇), global.
fn junction_motion(t: f64) -> ClipMotion {
    let w = 2.0 * std::f64::consts::PI * 10.0;
    let (c, s) = ((w * t).cos(), (w * t).sin());
    let dir = Vector3::new(0.0, 0.6, 0.8);
    let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
    let (a, b) = (3e-3, 0.05);
    ClipMotion {
        pose: Pose {
            position: a * (1.0 - c) * dir,
            orientation: nalgebra::UnitQuaternion::from_scaled_axis(b * (1.0 - c) * axis)
                .into_inner(),
        },
        velocity: a * w * s * dir,
        angular_velocity: b * w * s * axis,
        acceleration: a * w * w * c * dir,
        angular_acceleration: b * w * w * c * axis,
    }
}

/// Every cable's clips at rest but the junction's (given on its first end, cable 0's clip 1)
/// moving with the junction.
fn held_motions(h: &Harness, st: &HarnessState, t: f64) -> Vec<Vec<ClipMotion>> {
    let mut m: Vec<Vec<ClipMotion>> = st
        .cables
        .iter()
        .map(|x| x.clip_pose.iter().map(at_rest).collect())
        .collect();
    let j = junction_motion(t);
    let e = &h.ends[h.junction_ends[0][0]];
    m[e.cable][e.topo.clip] = ClipMotion {
        pose: h.end_pose(0, &j.pose),
        ..j
    };
    m
}

#[test]
fn held_junction_follows_its_clip_as_clamped_cable_ends() {
    // A held junction clamps its ends: the harness is then three cables, each clamped at the
    // junction's moving pose. Against the three single cables with clamps moving the same way,
    // and the clip's reaction against their end reactions plus the junction's own inertia and
    // weight.
    let h = held_y();
    let mut st = initial(&h);
    let mut hs = HarnessStatics::new(&h, NewtonOptions::default());
    let poses0: Vec<Vec<Pose>> = held_motions(&h, &st, 0.0)
        .iter()
        .map(|c| c.iter().map(|x| x.pose).collect())
        .collect();
    st.set_clip_poses(&h, &poses0);
    hs.solve_static(&h, &mut st).unwrap();
    let base = st.clone();
    let opts = DynamicOptions {
        tolerance: 1e-9,
        ..Default::default()
    };
    let motion = |t: f64| -> Vec<Vec<ClipMotion>> {
        let mut m = held_motions(&h, &base, t);
        // Each joined end's clip follows the junction (for the single cables).
        let j = junction_motion(t);
        let qj = rotation_matrix(&j.pose.orientation);
        let _ = qj;
        for (k, e) in h.ends.iter().enumerate() {
            m[e.cable][e.topo.clip] = ClipMotion {
                pose: h.end_pose(k, &j.pose),
                ..j
            };
        }
        m
    };
    let mut hd = HarnessDynamics::new(&h, &st, &motion(0.0), opts.clone());
    hd.start(&h, &mut st).unwrap();
    let mut singles: Vec<(Dynamics, State)> = h
        .cables
        .iter()
        .enumerate()
        .map(|(c, rod)| {
            let s = st.cables[c].clone();
            let mut d = Dynamics::new(rod, &s, &motion(0.0)[c], opts.clone());
            d.start(rod, &s).unwrap();
            (d, s)
        })
        .collect();
    let dt = 1e-3;
    let (mut worst, mut moved, mut worst_f, mut peak_f) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut worst_m, mut peak_m) = (0.0f64, 0.0f64);
    for k in 1..=100 {
        let t = k as f64 * dt;
        let m = motion(t);
        hd.step(&h, &mut st, dt, &m).unwrap();
        hd.update_outputs(&h, &st).unwrap();
        let j = junction_motion(t);
        assert!((st.junctions[0].position - j.pose.position).norm() < 1e-15);
        let (mut f, mut mom) = (Vector3::zeros(), Vector3::zeros());
        for (c, rod) in h.cables.iter().enumerate() {
            let (d, s) = &mut singles[c];
            d.step(rod, s, dt, &m[c]).unwrap();
            for (a, b) in s.x.iter().zip(&st.cables[c].x) {
                worst = worst.max((a - b).norm());
                moved = moved.max(
                    (a - base.cables[c].x[0])
                        .norm()
                        .min((b - a).norm().max(0.0)),
                );
            }
            for (x, x0) in s.x.iter().zip(&base.cables[c].x) {
                moved = moved.max((x - x0).norm());
            }
            let clip = h.ends[h.cable_ends[c][0]].topo.clip;
            let (fc, mc) = d.ws.clip_reaction(rod, s, clip);
            f += fc;
            mom += mc;
        }
        // The junction: mass 0.05 kg, body-frame inertia; the clip holds it and its ends.
        let js = &h.junctions[0];
        let q = rotation_matrix(&j.pose.orientation);
        let (wb, wdb) = (
            q.transpose() * j.angular_velocity,
            q.transpose() * j.angular_acceleration,
        );
        let jw = js.rotary_inertia;
        f += js.mass * (j.acceleration - h.gravity);
        mom += q * (jw.component_mul(&wdb) + wb.cross(&jw.component_mul(&wb)));
        let (rf, rm) = hd.junction_reactions(&h, &st)[0];
        worst_f = worst_f.max((rf - f).norm());
        peak_f = peak_f.max(f.norm());
        worst_m = worst_m.max((rm - mom).norm());
        peak_m = peak_m.max(mom.norm());
    }
    eprintln!(
        "held junction vs clamped cables: nodes {worst:e} of motion {moved:e} m; reaction \
         force {worst_f:e} of {peak_f:e} N, moment {worst_m:e} of {peak_m:e} N m"
    );
    assert!(moved > 1e-3, "moved {moved}");
    assert!(worst < 1e-9 * moved.max(1.0), "nodes {worst:e}");
    assert!(worst_f < 1e-8 * peak_f, "force {worst_f:e} of {peak_f:e}");
    assert!(worst_m < 1e-8 * peak_m, "moment {worst_m:e} of {peak_m:e}");
}

#[test]
fn held_junction_iteration_matrix_matches_finite_differences() {
    // The held junction takes no increment; the other unknowns' iteration matrix is exact.
    let h = held_y();
    let mut st = initial(&h);
    let mut hs = HarnessStatics::new(&h, NewtonOptions::default());
    let poses0: Vec<Vec<Pose>> = held_motions(&h, &st, 0.0)
        .iter()
        .map(|c| c.iter().map(|x| x.pose).collect())
        .collect();
    st.set_clip_poses(&h, &poses0);
    hs.solve_static(&h, &mut st).unwrap();
    let base = st.clone();
    let opts = DynamicOptions {
        tolerance: 1e-9,
        ..Default::default()
    };
    let dt = 1e-3;
    let mut hd = HarnessDynamics::new(&h, &st, &held_motions(&h, &base, 0.0), opts);
    hd.start(&h, &mut st).unwrap();
    for k in 1..=12 {
        hd.step(&h, &mut st, dt, &held_motions(&h, &base, k as f64 * dt))
            .unwrap();
    }
    hd.begin_step(&h, &mut st, dt, &held_motions(&h, &base, 13.0 * dt));
    let [fdev, fscale, mdev, mscale] = hd.newton_direction_fd(&h, &mut st, dt, 1e-4).unwrap();
    eprintln!("held: forces {fdev:e} of {fscale:e}, moments {mdev:e} of {mscale:e}");
    assert!(fscale > 0.0 && mscale > 0.0);
    assert!(fdev < 1e-6 * fscale, "forces {fdev:e} of {fscale:e}");
    assert!(mdev < 1e-6 * mscale, "moments {mdev:e} of {mscale:e}");
}

/// The guided Y with gravity, friction `mu` in its guide, undamped (ρ∞ = 1) and released
/// from its straight routing for 0.2 s at steps `dt`: the largest |E − E₀| with E the kinetic,
/// elastic and gravity energy plus the dissipated energy, relative to the largest kinetic
/// energy; that kinetic energy; the energy dissipated.
fn guided_balance(mu: f64, dt: f64) -> (f64, f64, f64) {
    let h = y_with_guide(20, 9.81, mu, 0.01, 1e-6);
    let mut st = initial(&h);
    let m: Vec<Vec<ClipMotion>> = st
        .cables
        .iter()
        .map(|x| x.clip_pose.iter().map(at_rest).collect())
        .collect();
    let opts = DynamicOptions {
        rho_inf: 1.0,
        ..Default::default()
    };
    let mut hd = HarnessDynamics::new(&h, &st, &m, opts);
    hd.start(&h, &mut st).unwrap();
    let total = |e: &Energies| e.kinetic + e.elastic + e.load_potential + e.dissipated;
    let e0 = total(&hd.energies);
    let (mut drift, mut kin) = (0.0f64, 0.0f64);
    for _ in 0..(0.2 / dt).round() as usize {
        hd.advance(&h, &mut st, dt, &m, &m, 4).unwrap();
        drift = drift.max((total(&hd.energies) - e0).abs());
        kin = kin.max(hd.energies.kinetic);
    }
    (drift / kin, kin, hd.energies.dissipated)
}

#[test]
fn a_frictional_guide_dissipates_what_the_energy_balance_misses() {
    // Without damping the only loss is the guide's friction: its power (friction force times
    // the velocity relative to the guide) integrated into the dissipated energy closes the
    // balance as well as the frictionless run closes its own (the time error), and the
    // friction only takes energy out. With the friction on the current normal force the
    // energy grew (peak 1.8× the frictionless one, the balance off by 1.6× it).
    let (free, free_kin, none) = guided_balance(0.0, 1e-3);
    assert_eq!(none, 0.0);
    for mu in [0.3, 1.0] {
        let (drift, kin, dissipated) = guided_balance(mu, 1e-3);
        eprintln!("μ = {mu}: balance {drift:e} of the peak kinetic energy {kin:e} (frictionless {free:e} of {free_kin:e}), dissipated {dissipated:e}");
        assert!(dissipated > 0.05 * kin, "dissipated {dissipated:e}");
        assert!(kin < free_kin, "{kin:e} ≥ {free_kin:e}");
        assert!(
            drift < 4.0 * free,
            "{drift:e} against {free:e} without friction"
        );
    }
}

//! Sliding clips: a heavy, axially soft cable hanging from a clamp through a frictionless guide
//! (tension continuous through the guide, the material slides to the analytical stretch), pulled
//! through it quasistatically and dynamically, and run off its end.
mod common;
use common::*;
use nalgebra::Vector3;
use rod::routing::route;
use rod::{
    CableSpec, ClipKind, ClipMotion, DynamicOptions, Dynamics, NewtonOptions, Pose, Rod, Section,
    SolveError, State, Statics,
};

const W: f64 = 0.1 * 9.81; // weight per length, N/m
const EA: f64 = 50.0;
const L: f64 = 1.0;
const H: f64 = 0.5; // clamp height above the guide

fn section() -> Section {
    Section {
        shear_stiffness: Vector3::new(50.0, 50.0, EA),
        bend_stiffness: Vector3::new(1e-3, 1e-3, 1e-3),
        mass_per_length: 0.1,
        rotary_inertia: Vector3::new(1e-9, 1e-9, 2e-9),
    }
}

/// A clamp at (0, 0, H) pointing down, a 0.1 m guide at the origin pointing down.
fn hanging(segments: usize) -> CableSpec {
    let down = [0.0, 0.0, -1.0];
    let normal = [1.0, 0.0, 0.0];
    CableSpec {
        length: L,
        segments,
        section: section(),
        natural_curvature: Vector3::zeros(),
        clips: vec![
            clip(
                "top",
                0.0,
                0.0,
                ClipKind::Fixed,
                pose([0.0, 0.0, H], down, normal),
            ),
            clip(
                "guide",
                H,
                0.1,
                ClipKind::Sliding { friction: 0.0 },
                pose([0.0; 3], down, normal),
            ),
        ],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    }
}

/// Material coordinate at the guide when the clamp is `h` above it: the stretched length of
/// [0, σ] is h, with strain T/EA and T(s) = w (L − s): σ + (w/EA)(Lσ − σ²/2) = h.
fn sigma_exact(h: f64) -> f64 {
    let c = W / EA;
    // (c/2) σ² − (1 + cL) σ + h = 0, the root below L.
    let (a, b) = (0.5 * c, -(1.0 + c * L));
    (-b - (b * b - 4.0 * a * h).sqrt()) / (2.0 * a)
}

fn solve(rod: &Rod) -> (State, Statics) {
    let mut st = route(rod, None).unwrap();
    let mut s = Statics::new(rod, NewtonOptions::default());
    s.solve(rod, &mut st).unwrap();
    s.assemble(rod, &st, 1.0, false).unwrap();
    (st, s)
}

#[test]
fn frictionless_guide_passes_the_tension_and_lets_the_cable_slide() {
    let rod = Rod::new(hanging(50)).unwrap();
    let (st, s) = solve(&rod);
    let sliding = s.sliding.as_ref().unwrap();
    let sigma = sliding.sigma[0];
    let exact = sigma_exact(H);
    // Stretch: exact at the nodes (lumped weights, uniform strain per edge); the crossing is
    // interpolated linearly in an edge: error ≤ (w/EA) Δs²/8 = 1e-6 m.
    assert!(
        (sigma - exact).abs() < 1e-6,
        "σ = {sigma} vs {exact} (slid {:.3e} m)",
        sigma - H
    );
    assert!(
        (exact - H).abs() > 5e-3,
        "the test must slide: {}",
        exact - H
    );
    // The tension is w (L − s) at every edge midpoint: continuous through the guide.
    for e in 0..rod.n_edges() {
        let mid = rod.arc[e] + 0.5 * rod.ds_edge[e];
        let t = s.ws.edge_force[e].z;
        assert!((t - W * (L - mid)).abs() < 1e-6 * W * L, "edge {e}: {t}");
    }
    // The guide takes nothing (no lateral load), the clamp the whole weight.
    let (f, m) = s.ws.clip_reaction(&rod, &st, 1);
    assert!(f.norm() < 1e-9 && m.norm() < 1e-9, "{f:?} {m:?}");
    let (f0, _) = s.ws.clip_reaction(&rod, &st, 0);
    assert!((f0.z - W * L).abs() < 1e-9 * W * L, "{f0:?}");
}

#[test]
fn guide_holds_the_line_and_its_reaction_balances_a_side_load() {
    // A horizontal pull at the free end bends the cable below the guide: the guide holds the
    // axis on its line (nodes inside within F_n Δs/(100 EA)) and takes the side load with a
    // moment; the whole cable is in equilibrium.
    let mut spec = hanging(50);
    spec.loads.push(rod::PointLoad {
        s: L,
        force: Vector3::new(0.2, 0.0, 0.0),
        moment: Vector3::zeros(),
    });
    let rod = Rod::new(spec).unwrap();
    let (st, s) = solve(&rod);
    let sigma = s.sliding.as_ref().unwrap().sigma[0];
    for n in 0..st.x.len() {
        if (rod.arc[n] - sigma).abs() < 0.05 - 1e-9 && st.x[n].z.abs() < 0.05 {
            let off = (st.x[n].x.powi(2) + st.x[n].y.powi(2)).sqrt();
            // The node forces are the side load plus the guide's moment couple: below 1 N.
            assert!(
                off < 1.0 * rod.mean_ds() / (100.0 * EA),
                "node {n}: {off:e}"
            );
        }
    }
    let (f1, m1) = s.ws.clip_reaction(&rod, &st, 1);
    let (f0, m0) = s.ws.clip_reaction(&rod, &st, 0);
    assert!(f1.x < -0.1 && f1.z.abs() < 1e-6, "{f1:?}");
    let mut force = f0 + f1 + Vector3::new(0.2, 0.0, 0.0);
    let top = Vector3::new(0.0, 0.0, H);
    let mut moment = m0 + m1 + (Vector3::zeros() - top).cross(&f1);
    moment += (st.x.last().unwrap() - top).cross(&Vector3::new(0.2, 0.0, 0.0));
    for n in 0..st.x.len() {
        let g = rod.node_mass[n] * rod.spec.gravity;
        force += g;
        moment += (st.x[n] - top).cross(&g);
    }
    assert!(force.norm() < 1e-8, "ΣF = {force:?}");
    assert!(moment.norm() < 1e-8, "ΣM = {moment:?}");
}

fn moved_top(rod: &Rod, lift: f64) -> Vec<Pose> {
    let mut poses: Vec<Pose> = rod.spec.clips.iter().map(|c| c.pose).collect();
    poses[0].position.z += lift;
    poses
}

#[test]
fn pulled_through_quasistatically_the_slid_length_follows_the_clamp_and_then_runs_off() {
    let rod = Rod::new(hanging(50)).unwrap();
    let (mut st, mut s) = solve(&rod);
    let sigma0 = s.sliding.as_ref().unwrap().sigma[0];
    let mut lift = 0.0;
    for _ in 0..8 {
        lift += 0.05;
        s.sequence_step(&rod, &mut st, &moved_top(&rod, lift))
            .unwrap();
        let sigma = s.sliding.as_ref().unwrap().sigma[0];
        let exact = sigma_exact(H + lift);
        assert!(
            (sigma - exact).abs() < 1e-6,
            "lift {lift}: σ {sigma} vs {exact}"
        );
    }
    assert!(s.sliding.as_ref().unwrap().sigma[0] - sigma0 > 0.35);
    // The guide (half-length 0.05) leaves the cable's lower end when σ > L − 0.05.
    let mut err = None;
    for _ in 0..10 {
        lift += 0.05;
        if let Err(e) = s.sequence_step(&rod, &mut st, &moved_top(&rod, lift)) {
            err = Some(e);
            break;
        }
    }
    match err {
        Some(SolveError::SlidOff { clip }) => assert_eq!(clip, "guide"),
        other => panic!("expected the cable to run out of the guide, got {other:?}"),
    }
    assert!(sigma_exact(H + lift) > L - 0.05 - 0.05 * 1.1);
}

#[test]
fn pulled_through_dynamically_at_constant_speed_the_slid_length_follows() {
    // The clamp moves up at 0.2 m/s after a smooth start; slowly compared with the axial wave
    // (√(EA/ρA) = 22 m/s), so the cable follows quasistatically up to the axial vibration the
    // start excites (amplitude ~ v/ω = 0.2 / (π/2 · 22 / 1) ≈ 6 mm, damped by Kelvin–Voigt).
    let rod = Rod::new(hanging(40)).unwrap();
    let (mut st, mut s) = solve(&rod);
    let sigma0 = s.sliding.as_ref().unwrap().sigma[0];
    let speed = 0.2;
    let ramp = 0.2;
    let lift = |t: f64| {
        if t < ramp {
            speed * t * t / (2.0 * ramp)
        } else {
            speed * (t - 0.5 * ramp)
        }
    };
    let vel = |t: f64| speed * (t / ramp).min(1.0);
    let acc = |t: f64| if t < ramp { speed / ramp } else { 0.0 };
    let motion = |t: f64| -> Vec<ClipMotion> {
        moved_top(&rod, lift(t))
            .into_iter()
            .enumerate()
            .map(|(c, pose)| ClipMotion {
                pose,
                velocity: Vector3::new(0.0, 0.0, if c == 0 { vel(t) } else { 0.0 }),
                angular_velocity: Vector3::zeros(),
                acceleration: Vector3::new(0.0, 0.0, if c == 0 { acc(t) } else { 0.0 }),
                angular_acceleration: Vector3::zeros(),
            })
            .collect()
    };
    let opts = DynamicOptions {
        tau_shear: Vector3::new(0.01, 0.01, 0.01),
        tau_bend: Vector3::new(0.01, 0.01, 0.01),
        ..Default::default()
    };
    let mut dy = Dynamics::new(&rod, &st, &motion(0.0), opts);
    dy.sliding = s.sliding.take();
    dy.start(&rod, &st).unwrap();
    let h = 1e-3;
    let steps = 1500;
    for k in 1..=steps {
        dy.step(&rod, &mut st, h, &motion(k as f64 * h)).unwrap();
    }
    let t = steps as f64 * h;
    let sigma = dy.sliding.as_ref().unwrap().sigma[0];
    let exact = sigma_exact(H + lift(t));
    assert!(sigma - sigma0 > 0.25, "slid {}", sigma - sigma0);
    assert!(
        (sigma - exact).abs() < 5e-3,
        "σ {sigma} vs quasistatic {exact}"
    );
}

#[test]
fn jacobian_with_a_sliding_clip_matches_finite_differences() {
    // A bent cable through an oblique guide, nodes moved off the line (and into the guide's
    // tapered ends): the assembled Jacobian against central differences of the residual;
    // frictionless, and with friction sticking (slip < ε) and slipping (slip ≫ ε).
    jacobian_check(0.0, 0.0);
    jacobian_check(0.4, 0.3);
    jacobian_check(0.4, 20.0);
}

/// FD check with friction μ and each node's slip since the reference `slip` stick widths.
#[allow(clippy::needless_range_loop)] // rows of three block vectors
fn jacobian_check(mu: f64, slip: f64) {
    let mut spec = hanging(30);
    spec.clips[1].kind = ClipKind::Sliding { friction: mu };
    spec.clips[1].pose = pose([0.02, 0.01, 0.0], [0.2, 0.1, -1.0], [1.0, 0.0, 0.2]);
    spec.loads.push(rod::PointLoad {
        s: L,
        force: Vector3::new(0.1, -0.05, 0.0),
        moment: Vector3::zeros(),
    });
    let rod = Rod::new(spec).unwrap();
    let mut st = route(&rod, None).unwrap();
    for (i, x) in st.x.iter_mut().enumerate().skip(1) {
        *x += Vector3::new(
            (i as f64).sin(),
            (1.3 * i as f64).cos(),
            (0.4 * i as f64).sin(),
        ) * 2e-3;
    }
    let mut s = Statics::new(&rod, NewtonOptions::default());
    let sl = s.sliding.as_mut().unwrap();
    let mut reference = st.clone();
    let t = rod::rotation::rotation_matrix(&st.clip_pose[1].orientation) * Vector3::z();
    for (i, x) in reference.x.iter_mut().enumerate() {
        *x -= t * slip * sl.stick_distance * (1.0 + 0.1 * (i as f64).sin());
    }
    sl.begin_step(&rod, &reference, None);
    s.assemble(&rod, &st, 1.0, true).unwrap();
    if mu > 0.0 {
        let sl = s.sliding.as_ref().unwrap();
        assert!(sl.friction_force[0].abs() > 1e-3 * mu * sl.normal_force[0]);
    }
    let jac = s.ws.jac.clone();
    let nb = rod.arc.len();
    let h = 1e-7;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for b in 0..nb {
        for k in 0..6 {
            if !rod.mask[b][k] {
                continue;
            }
            let mut r = [vec![], vec![]];
            for (i, step) in [h, -h].into_iter().enumerate() {
                let mut d = vec![nalgebra::Vector6::zeros(); nb];
                d[b][k] = step;
                let mut s2 = st.clone();
                s2.apply_increment(&rod, &d, 1.0);
                s.assemble(&rod, &s2, 1.0, false).unwrap();
                r[i] = s.ws.rhs.clone();
            }
            for row in b.saturating_sub(1)..(b + 2).min(nb) {
                let fd = (r[0][row] - r[1][row]) / (2.0 * h);
                let an = if row == b {
                    jac.diag[b].column(k).into_owned()
                } else if row + 1 == b {
                    jac.upper[row].column(k).into_owned()
                } else {
                    jac.lower[row].column(k).into_owned()
                };
                for i in (0..6).filter(|&i| rod.mask[row][i]) {
                    worst = worst.max((fd[i] - an[i]).abs());
                    scale = scale.max(an[i].abs());
                }
            }
        }
    }
    // The guide's term is in it: its hold stiffness dominates the scale.
    assert!(scale > 0.5 * 100.0 * EA / rod.mean_ds(), "scale {scale:e}");
    assert!(
        worst < 1e-6 * scale,
        "Jacobian vs FD: {worst:e} (scale {scale:e})"
    );
}

#[test]
fn modal_stiffness_includes_the_guide() {
    // The modal tangent is the static Jacobian (symmetric part), guide term included.
    let mut spec = hanging(30);
    spec.loads.push(rod::PointLoad {
        s: L,
        force: Vector3::new(0.2, 0.0, 0.0),
        moment: Vector3::zeros(),
    });
    let rod = Rod::new(spec).unwrap();
    let (st, mut s) = solve(&rod);
    s.assemble(&rod, &st, 1.0, true).unwrap();
    let k = rod::modal::tangent_stiffness(&rod, &st).unwrap();
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for b in 0..rod.arc.len() {
        let sym = 0.5 * (s.ws.jac.diag[b] + s.ws.jac.diag[b].transpose());
        worst = worst.max((k.diag[b] - sym).amax());
        scale = scale.max(sym.amax());
    }
    assert!(
        scale > 100.0 * EA / rod.mean_ds(),
        "no guide in the scale {scale:e}"
    );
    assert!(worst < 1e-9 * scale, "{worst:e} of {scale:e}");
}

#[test]
fn pulling_through_a_guide_with_friction_costs_mu_times_the_normal_force() {
    // A side pull at the lower end presses the cable against the guide; lifting the clamp
    // drags it up through the guide. Fully slipping (each step's slip ≫ the stick width), the
    // guide's friction on the cable is μ Σ N along the line (down, against the motion), and the
    // clamp pulls the weight plus that: the friction law's Coulomb force.
    let mu = 0.3;
    let side = Vector3::new(0.3, 0.0, 0.0);
    let mut spec = hanging(50);
    spec.clips[1].kind = ClipKind::Sliding { friction: mu };
    spec.loads.push(rod::PointLoad {
        s: L,
        force: side,
        moment: Vector3::zeros(),
    });
    let rod = Rod::new(spec).unwrap();
    let (mut st, mut s) = solve(&rod);
    for k in 1..=4 {
        let stats = s
            .sequence_step(&rod, &mut st, &moved_top(&rod, 0.02 * k as f64))
            .unwrap();
        assert!(stats.iterations < 15, "{stats:?}");
        s.assemble(&rod, &st, 1.0, false).unwrap();
        let sl = s.sliding.as_ref().unwrap();
        let normal = sl.normal_force[0];
        assert!(normal > 0.1, "the guide must be pressed: N = {normal}");
        // Along the line t = −z: the friction on the cable points down (+t), μ N.
        let (f1, _) = s.ws.clip_reaction(&rod, &st, 1);
        assert!(
            (-f1.z - mu * normal).abs() < 1e-6 * mu * normal,
            "friction {} vs μN = {}",
            -f1.z,
            mu * normal
        );
        assert!((sl.friction_force[0] + f1.z).abs() < 1e-9);
        // The clamp carries the weight and the friction: ΣF_z = 0 to the solver tolerance.
        let (f0, _) = s.ws.clip_reaction(&rod, &st, 0);
        let weight: f64 = rod.node_mass.iter().sum::<f64>() * 9.81;
        assert!(
            (f0.z - weight - mu * normal).abs() < 1e-8,
            "pull {} vs weight {weight} + μN {}",
            f0.z,
            mu * normal
        );
    }
}

#[test]
fn dynamic_pull_through_a_guide_with_friction_runs() {
    // The dynamic pull with friction and a side load: it runs (regularised stick within the
    // step) and the guide's friction stays within its Coulomb bound μ Σ N (N at the start of
    // the step, on which dynamic friction acts; the current one differs by its change in a
    // step).
    let mut spec = hanging(40);
    spec.clips[1].kind = ClipKind::Sliding { friction: 0.3 };
    spec.loads.push(rod::PointLoad {
        s: L,
        force: Vector3::new(0.3, 0.0, 0.0),
        moment: Vector3::zeros(),
    });
    let rod = Rod::new(spec).unwrap();
    let (mut st, _) = solve(&rod);
    let speed = 0.1;
    let motion = |t: f64| -> Vec<ClipMotion> {
        let ramp = (t / 0.2).min(1.0);
        moved_top(
            &rod,
            speed * t * ramp * 0.5 + speed * (t - 0.2).max(0.0) * 0.5,
        )
        .into_iter()
        .enumerate()
        .map(|(c, pose)| ClipMotion {
            pose,
            velocity: Vector3::new(0.0, 0.0, if c == 0 { speed * ramp } else { 0.0 }),
            angular_velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        })
        .collect()
    };
    let opts = DynamicOptions {
        tau_shear: Vector3::new(0.01, 0.01, 0.01),
        tau_bend: Vector3::new(0.01, 0.01, 0.01),
        ..Default::default()
    };
    let mut dy = Dynamics::new(&rod, &st, &motion(0.0), opts);
    dy.start(&rod, &st).unwrap();
    let h = 1e-3;
    let mut prev = motion(0.0);
    for k in 1..=500 {
        let next = motion(k as f64 * h);
        dy.advance(&rod, &mut st, h, &prev, &next, 6).unwrap();
        prev = next;
    }
    dy.update_outputs(&rod, &st).unwrap();
    let sl = dy.sliding.as_ref().unwrap();
    assert!(sl.normal_force[0] > 0.1);
    assert!((sl.friction_normal[0] / sl.normal_force[0] - 1.0).abs() < 1e-2);
    assert!(
        sl.friction_force[0].abs() <= 0.3 * sl.friction_normal[0] * (1.0 + 1e-9),
        "{sl:?}"
    );
    assert!(
        sl.friction_force[0].abs() > 0.1 * 0.3 * sl.normal_force[0],
        "{sl:?}"
    );
}

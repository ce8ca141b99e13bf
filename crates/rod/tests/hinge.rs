//! Hinged clips: a beam on a hinge against the pinned–supported (overhanging) beam solution with
//! second-order convergence, a zero hinge moment about the axis with the constraint moment across
//! it in the reaction, and a pendulum hanging from a hinge against the rigid pendulum.
mod common;
use common::*;
use nalgebra::Vector3;
use rod::rotation::rotation_matrix;
use rod::routing::route;
use rod::{
    CableSpec, ClipKind, ClipMotion, DynamicOptions, Dynamics, NewtonOptions, PointLoad, Rod,
    Section, State, Statics,
};

fn solve(spec: CableSpec) -> (Rod, State, Statics) {
    let rod = Rod::new(spec).unwrap();
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    solver.solve(&rod, &mut st).unwrap();
    solver.ws.assemble_static(&rod, &st, 1.0, false).unwrap();
    (rod, st, solver)
}

/// Stiff in shear (Euler–Bernoulli limit: the shear part of the deflections below is 2e-7
/// relative), EI = GJ = 1. EA is moderate: both supports hold positions, so the span's
/// deflection stretches it by ~∫w′²/2; the membrane tension EA ε ~ 1e-5 N stiffens the span
/// by T a²/EI ~ 1e-6 relative (with EA = 1e9 it would be 30 %).
fn beam_section() -> Section {
    Section {
        shear_stiffness: Vector3::new(1e9, 1e9, 1e4),
        bend_stiffness: Vector3::new(1.0, 1.0, 1.0),
        mass_per_length: 0.1,
        rotary_inertia: Vector3::new(1e-9, 1e-9, 2e-9),
    }
}

/// A beam along +x (d1 = +z): a hinge about d2 (the y axis) at x = 0, a ball support at x = a,
/// the overhang to x = l loaded by a tip force −F z.
fn overhang(segments: usize, a: f64, l: f64, f: f64) -> CableSpec {
    let mut spec = cantilever(l, segments, beam_section());
    spec.clips = vec![
        clip(
            "hinge",
            0.0,
            0.0,
            ClipKind::Hinge {
                axis: Vector3::new(0.0, 1.0, 0.0),
            },
            pose([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "support",
            a,
            0.0,
            ClipKind::Ball,
            pose([a, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ),
    ];
    spec.loads.push(PointLoad {
        s: l,
        force: Vector3::new(0.0, 0.0, -f),
        moment: Vector3::zeros(),
    });
    spec
}

#[test]
fn hinged_overhanging_beam_matches_the_pinned_solution_with_order_two() {
    // Pinned at 0 (the hinge), supported at a, tip load F at l = a + b: small deflection
    // (F b² l / 3EI = 5e-5 l), so geometric non-linearity is ~1e-9 relative.
    // Tip deflection F b² l / (3EI); hinge rotation F a b / (6EI) (the span bulges upwards).
    let (a, l, f) = (0.6, 1.0, 1e-3);
    let b = l - a;
    let tip_exact = f * b * b * l / 3.0;
    let angle_exact = f * a * b / 6.0;
    let mut tip_err = vec![];
    let mut angle_err = vec![];
    for n in [10, 20, 40, 80] {
        let (rod, st, s) = solve(overhang(n, a, l, f));
        let tip = -st.x.last().unwrap().z;
        let g = rod.clip_ghost[0].unwrap();
        let d3 = rotation_matrix(&st.ghost[g]) * Vector3::z();
        let angle = d3.z.atan2(d3.x);

        tip_err.push((tip - tip_exact).abs() / tip_exact);
        angle_err.push((angle - angle_exact).abs() / angle_exact);
        // The hinge transmits no moment about its axis (to round-off of the Newton solve), and
        // a pinned end none at all in the plane problem.
        let (_, m) = s.ws.clip_reaction(&rod, &st, 0);
        let axis = rotation_matrix(&st.clip_pose[0].orientation) * Vector3::y();
        assert!(m.dot(&axis).abs() < 1e-12 * f * l, "hinge moment {m:?}");
    }
    let fmt = |v: &[f64]| v.iter().map(|e| format!("{e:.2e}")).collect::<Vec<_>>();
    eprintln!(
        "hinged overhang, N = 10..80: tip errors {:?}, angle errors {:?}",
        fmt(&tip_err),
        fmt(&angle_err)
    );
    for errs in [&tip_err, &angle_err] {
        let orders: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        assert!(
            orders.iter().all(|&p| (p - 2.0).abs() < 0.1),
            "errors {errs:?}, orders {orders:?}"
        );
    }
    assert!(
        tip_err[3] < 1e-3 && angle_err[3] < 1e-3,
        "{tip_err:?} {angle_err:?}"
    );
}

#[test]
fn hinge_reaction_carries_the_constraint_moment_and_none_about_the_axis() {
    // A 3-D case: an oblique hinge axis, loads in all directions, a ball further on. The clip
    // reactions and the loads are in equilibrium (force and moment), the hinge moment about its
    // axis is zero and the moment across it is not.
    let l = 1.0;
    let mut spec = cantilever(l, 40, circle(0.005, 5e7, 0.45, 1500.0));
    spec.gravity = Vector3::new(0.0, 0.0, -9.81);
    let axis = Vector3::new(0.3, 1.0, 0.4);
    spec.clips = vec![
        clip(
            "hinge",
            0.0,
            0.0,
            ClipKind::Hinge { axis },
            pose([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "ball",
            0.7,
            0.0,
            ClipKind::Ball,
            pose([0.65, 0.1, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ),
    ];
    spec.loads.push(PointLoad {
        s: l,
        force: Vector3::new(0.05, 0.1, -0.2),
        moment: Vector3::new(0.01, 0.0, 0.02),
    });
    let (rod, st, s) = solve(spec);
    let (f0, m0) = s.ws.clip_reaction(&rod, &st, 0);
    let (f1, m1) = s.ws.clip_reaction(&rod, &st, 1);
    let o = st.clip_pose[0].position;
    let mut force = f0 + f1;
    let mut moment = m0 + m1 + (st.clip_pose[1].position - o).cross(&f1);
    for n in 0..st.x.len() {
        let w = rod.node_mass[n] * rod.spec.gravity + rod.node_force[n];
        force += w;
        moment += (st.x[n] - o).cross(&w);
    }
    moment += rod.spec.loads[0].moment;
    // clip_reaction is what the clip does on the cable: with the loads it sums to zero.
    let scale = 0.25 * l + rod.spec.section.mass_per_length * 9.81 * l * l;
    assert!(force.norm() < 1e-9 * scale, "ΣF = {force:?}");
    assert!(moment.norm() < 1e-9 * scale, "ΣM = {moment:?}");
    let a = rotation_matrix(&st.clip_pose[0].orientation) * axis.normalize();
    assert!(
        m0.dot(&a).abs() < 1e-12 * scale,
        "about the axis: {}",
        m0.dot(&a)
    );
    assert!(
        (m0 - a * m0.dot(&a)).norm() > 1e-4 * scale,
        "no constraint moment across the axis: {m0:?}"
    );
}

/// Times of upward zero crossings (linear interpolation).
fn crossings(x: &[f64], h: f64) -> Vec<f64> {
    (1..x.len())
        .filter(|&i| x[i - 1] < 0.0 && x[i] >= 0.0)
        .map(|i| h * ((i - 1) as f64 + -x[i - 1] / (x[i] - x[i - 1])))
        .collect()
}

#[test]
fn pendulum_on_a_hinge_swings_at_the_rigid_pendulum_frequency_and_keeps_its_energy() {
    // A stiff steel rod (ρgL³/EI = 0.01; first bending frequency / pendulum frequency ≈ 120)
    // hanging from a hinge about y, released from rest at θ₀ = 0.02 rad. Reference: the rigid
    // pendulum of the discrete masses, ω² = g Σ m z / (Σ m z² + L ρI) about the hinge.
    // Error budget (relative frequency): bending flexibility ~(ω/ω_b)² = 7e-5, amplitude
    // θ₀²/16 = 2.5e-5, trapezoidal rule (ωh)²/12 = 8e-5 at h = T/200.
    let (l, n, theta0) = (0.3, 30, 0.02f64);
    let sec = circle(0.002, 2e11, 0.3, 7850.0);
    let down = [theta0.sin(), 0.0, -theta0.cos()];
    let normal = [theta0.cos(), 0.0, theta0.sin()];
    let spec = CableSpec {
        length: l,
        segments: n,
        section: sec.clone(),
        natural_curvature: Vector3::zeros(),
        clips: vec![clip(
            "hinge",
            0.0,
            0.0,
            ClipKind::Hinge {
                axis: Vector3::new(0.0, 1.0, 0.0),
            },
            pose([0.0; 3], down, normal),
        )],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    let mut st = route(&rod, None).unwrap();
    let g = 9.81;
    let first: f64 = (0..rod.arc.len())
        .map(|k| rod.node_mass[k] * rod.arc[k])
        .sum();
    let second: f64 = (0..rod.arc.len())
        .map(|k| rod.node_mass[k] * rod.arc[k] * rod.arc[k])
        .sum();
    let omega = (g * first / (second + l * sec.rotary_inertia.x)).sqrt();
    let period = 2.0 * std::f64::consts::PI / omega;
    let h = period / 200.0;
    let clips: Vec<ClipMotion> = rod
        .spec
        .clips
        .iter()
        .map(|c| ClipMotion {
            pose: c.pose,
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        })
        .collect();
    let opts = DynamicOptions {
        rho_inf: 1.0,
        tolerance: 1e-9,
        ..Default::default()
    };
    let mut dy = Dynamics::new(&rod, &st, &clips, opts);
    dy.start(&rod, &st).unwrap();
    let energy = |d: &Dynamics| d.energies.kinetic + d.energies.elastic + d.energies.load_potential;
    let e0 = energy(&dy);
    let mut tip = vec![st.x.last().unwrap().x];
    let mut drift = 0.0f64;
    let mut kinetic = 0.0f64;
    let axis = Vector3::y();
    let mut hinge_moment = 0.0f64;
    for _ in 0..(10.0 * period / h) as usize {
        dy.step(&rod, &mut st, h, &clips).unwrap();
        tip.push(st.x.last().unwrap().x);
        drift = drift.max((energy(&dy) + dy.energies.dissipated - e0).abs());
        kinetic = kinetic.max(dy.energies.kinetic);
        let (_, m) = dy.ws.clip_reaction(&rod, &st, 0);
        hinge_moment = hinge_moment.max(m.dot(&axis).abs());
    }
    let z = crossings(&tip, h);
    let measured = 2.0 * std::f64::consts::PI * (z.len() - 1) as f64 / (z[z.len() - 1] - z[0]);
    eprintln!(
        "pendulum: ω {measured:.6} vs {omega:.6} rad/s ({:.2e}), energy drift {:.2e} of the \
         swing, hinge moment {hinge_moment:.1e} N m",
        measured / omega - 1.0,
        drift / kinetic
    );
    assert!(
        (measured / omega - 1.0).abs() < 3e-4,
        "ω = {measured} vs rigid pendulum {omega} rad/s"
    );
    // Energy: the swing's energy (max kinetic ≈ m g L/2 · θ₀²/2) is kept to 1e-3.
    assert!(
        drift < 1e-3 * kinetic,
        "energy drift {drift:e} of {kinetic:e}"
    );
    let weight = sec.mass_per_length * l * g;
    assert!(hinge_moment < 1e-9 * weight * l, "{hinge_moment:e}");
}

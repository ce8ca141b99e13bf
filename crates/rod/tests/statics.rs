//! Static solutions against analytical references. Tolerances follow from the discretisation:
//! the scheme is second order in the edge length (midpoint rule in x, tan(φ/2) in K).
mod common;
use common::*;
use nalgebra::{Rotation3, Vector3};
use rod::rotation::from_matrix;
use rod::routing::route;
use rod::{CableSpec, NewtonOptions, PointLoad, Pose, Rod, Section, State, Statics};

fn solve(spec: CableSpec) -> (Rod, State, Statics) {
    let rod = Rod::new(spec).unwrap();
    let mut st = route(&rod, None).unwrap();
    let mut solver = Statics::new(&rod, NewtonOptions::default());
    solver.solve(&rod, &mut st).unwrap();
    solver.ws.assemble_static(&rod, &st, 1.0, false).unwrap();
    assert!(
        st.max_unit_error() < 1e-12,
        "|p| = 1 violated: {}",
        st.max_unit_error()
    );
    (rod, st, solver)
}

/// A section with prescribed effective stiffnesses (inextensible / shear-rigid limits).
fn effective(ea: f64, ga: f64, ei: f64, gj: f64, mass: f64) -> Section {
    Section {
        shear_stiffness: Vector3::new(ga, ga, ea),
        bend_stiffness: Vector3::new(ei, ei, gj),
        mass_per_length: mass,
        rotary_inertia: Vector3::new(1e-9, 1e-9, 2e-9),
    }
}

#[test]
fn cantilever_under_own_weight_small_deflection() {
    // Steel-like wire: deflection/L ≈ 1e-4, so geometric non-linearity is ~1e-8 relative.
    let (r, e, nu, rho, l) = (0.004, 2.0e11, 0.3, 7850.0, 1.0);
    let sec = circle(r, e, nu, rho);
    let mut spec = cantilever(l, 50, sec.clone());
    spec.gravity = Vector3::new(0.0, 0.0, -9.81);
    let (_, st, _) = solve(spec);
    let q = sec.mass_per_length * 9.81;
    let exact =
        q * l.powi(4) / (8.0 * sec.bend_stiffness.x) + q * l * l / (2.0 * sec.shear_stiffness.x);
    let tip = -st.x.last().unwrap().z;
    let rel = (tip - exact).abs() / exact;
    assert!(rel < 5e-3, "tip {tip:e} vs {exact:e}: {rel:e}");
}

#[test]
fn shear_flexible_cantilever_tip_force() {
    // Short, thick beam: shear deflection is ~10 % of the total.
    let (r, e, nu, l, f) = (0.01, 1.0e7, 0.4, 0.06, -0.01);
    let sec = circle(r, e, nu, 1000.0);
    let mut spec = cantilever(l, 40, sec.clone());
    spec.loads.push(PointLoad {
        s: l,
        force: Vector3::new(0.0, 0.0, f),
        moment: Vector3::zeros(),
    });
    let (_, st, _) = solve(spec);
    let exact = f * l / sec.shear_stiffness.x + f * l.powi(3) / (3.0 * sec.bend_stiffness.x);
    let shear_part = f * l / sec.shear_stiffness.x / exact;
    assert!(
        shear_part > 0.05,
        "set-up must exercise shear: {shear_part}"
    );
    let tip = st.x.last().unwrap().z;
    let rel = (tip - exact).abs() / exact.abs();
    assert!(rel < 2e-3, "tip {tip:e} vs {exact:e}: {rel:e}");
}

#[test]
fn axial_pull_elongation() {
    let sec = circle(0.003, 1.0e9, 0.35, 1000.0);
    let (l, f) = (0.8, 50.0);
    let mut spec = cantilever(l, 7, sec.clone());
    spec.loads.push(PointLoad {
        s: l,
        force: Vector3::new(f, 0.0, 0.0),
        moment: Vector3::zeros(),
    });
    let (rod, st, solver) = solve(spec);
    let elong = st.x.last().unwrap().x - l;
    let exact = f * l / sec.shear_stiffness.z;
    assert!(
        (elong - exact).abs() < 1e-9 * exact,
        "elongation {elong:e} vs {exact:e}"
    );
    for e in 0..rod.n_edges() {
        assert!((solver.ws.edge_force[e].z - f).abs() < 1e-8 * f);
    }
    // The clamp holds the pull: reaction −F.
    let (rf, _) = solver.ws.clip_reaction(&rod, &st, 0);
    assert!((rf + Vector3::new(f, 0.0, 0.0)).norm() < 1e-8 * f);
}

fn roll_up_error(n: usize) -> f64 {
    let (l, ei) = (1.0, 0.02);
    let sec = effective(1e5, 1e5, ei, 0.015, 0.1);
    let mut spec = cantilever(l, n, sec);
    let m = 2.0 * std::f64::consts::PI * ei / l;
    // d1 = +z and the cable along +x: a moment about −y bends it up into the x–z plane.
    spec.loads.push(PointLoad {
        s: l,
        force: Vector3::zeros(),
        moment: Vector3::new(0.0, -m, 0.0),
    });
    let (_, st, _) = solve(spec);
    st.x.last().unwrap().norm()
}

#[test]
fn roll_up_returns_to_the_clamp_at_second_order() {
    let errs: Vec<f64> = [20, 40, 80, 160]
        .iter()
        .map(|&n| roll_up_error(n))
        .collect();
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(
            (order - 2.0).abs() < 0.1,
            "order {order} from errors {errs:?}"
        );
    }
    assert!(errs[3] < 1e-3, "{errs:?}");
}

#[test]
fn large_deflection_bisshopp_drucker() {
    // α = PL²/EI = 1, dead tip force ⟂ axis, inextensible & shear-rigid limit.
    let (l, ei) = (1.0, 1.0);
    let sec = effective(1e8, 1e8, ei, 1.0, 0.1);
    let mut spec = cantilever(l, 100, sec);
    spec.loads.push(PointLoad {
        s: l,
        force: Vector3::new(0.0, 0.0, -1.0),
        moment: Vector3::zeros(),
    });
    let (_, st, _) = solve(spec);
    let tip = st.x.last().unwrap();
    let (w, u) = (-tip.z / l, tip.x / l - 1.0);
    assert!((w - 0.30172).abs() < 0.002 * 0.30172, "w/L = {w}");
    assert!((u + 0.05643).abs() < 0.002 * 0.05643, "u/L = {u}");
}

#[test]
fn objectivity_under_rigid_motion() {
    let sec = circle(0.005, 5e7, 0.45, 1500.0);
    let base = |rot: &Rotation3<f64>, shift: Vector3<f64>| {
        let mut spec = cantilever(1.2, 40, sec.clone());
        spec.gravity = rot * Vector3::new(0.0, 0.0, -9.81);
        spec.natural_curvature = Vector3::new(0.3, 0.0, 0.1);
        let poses = [
            pose([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            pose([0.5, 0.3, 0.1], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            pose([0.2, 0.6, 0.0], [-1.0, 0.2, 0.0], [0.0, 0.0, 1.0]),
        ];
        let kinds = [
            rod::ClipKind::Fixed,
            rod::ClipKind::Swivel,
            rod::ClipKind::Fixed,
        ];
        spec.clips = poses
            .iter()
            .zip([0.0, 0.7, 1.2])
            .zip(kinds)
            .enumerate()
            .map(|(i, ((p, s), k))| {
                let q = from_matrix(rot.matrix());
                let moved = Pose {
                    position: rot * p.position + shift,
                    orientation: q * p.orientation,
                };
                clip(&format!("c{i}"), s, 0.0, k, moved)
            })
            .collect();
        spec.loads.push(PointLoad {
            s: 0.35,
            force: rot * Vector3::new(0.0, 0.1, -0.2),
            moment: Vector3::zeros(),
        });
        solve(spec)
    };
    let (rod, st0, s0) = base(&Rotation3::identity(), Vector3::zeros());
    let rot = Rotation3::from_euler_angles(0.4, -1.1, 2.0);
    let shift = Vector3::new(1.0, -2.0, 0.5);
    let (_, st1, s1) = base(&rot, shift);
    for n in 0..st0.x.len() {
        assert!(
            (rot * st0.x[n] + shift - st1.x[n]).norm() < 1e-9,
            "node {n}"
        );
    }
    let fscale = s0
        .ws
        .edge_force
        .iter()
        .map(|f| f.amax())
        .fold(0.0, f64::max);
    let mscale = s0
        .ws
        .node_moment
        .iter()
        .map(|m| m.amax())
        .fold(0.0, f64::max);
    for e in 0..rod.n_edges() {
        assert!((s0.ws.edge_force[e] - s1.ws.edge_force[e]).amax() < 1e-7 * fscale);
    }
    for n in 0..st0.x.len() {
        assert!((s0.ws.node_moment[n] - s1.ws.node_moment[n]).amax() < 1e-7 * mscale);
    }
}

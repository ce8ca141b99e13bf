//! Cost of the pieces of one Newton iteration at N segments (run with
//! `cargo run --release -p cablelife-rod --example bench_assembly -- 100`); with the rates of a
//! dynamic step also the residual alone and with the section outputs (the outputs pass),
//! the shear and bending terms' four-lane kernels (docs/dynamics.md, session 20).
use nalgebra::{Matrix3, Quaternion, Vector3, Vector6};
use rod::assembly::{Part, Rates, Workspace};
use rod::rotation::exp_half;
use rod::routing::route;
use rod::{CableSpec, ClipKind, ClipSpec, Pose, Rod, Section};
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100);
    let section = Section {
        shear_stiffness: Vector3::new(1e4, 1e4, 3e4),
        bend_stiffness: Vector3::new(0.02, 0.02, 0.015),
        mass_per_length: 0.1,
        rotary_inertia: Vector3::new(1e-7, 1e-7, 2e-7),
    };
    let pose = Pose {
        position: Vector3::zeros(),
        orientation: Quaternion::identity(),
    };
    let spec = CableSpec {
        length: 1.0,
        segments: n,
        section,
        natural_curvature: Vector3::new(0.5, 0.0, 0.0),
        clips: vec![ClipSpec {
            name: "a".into(),
            s: 0.0,
            length: 0.0,
            kind: ClipKind::Fixed,
            pose,
        }],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    let st = route(&rod, None).unwrap();
    let mut ws = Workspace::new(&rod);
    let reps = 2000;
    let time = |label: &str, f: &mut dyn FnMut()| {
        let t0 = Instant::now();
        for _ in 0..reps {
            f();
        }
        println!(
            "{label:>28}: {:8.2} µs",
            t0.elapsed().as_secs_f64() / reps as f64 * 1e6
        );
    };
    time("assembly, residual only", &mut || {
        ws.assemble_static(&rod, &st, 1.0, false).unwrap()
    });
    time("assembly with Jacobian", &mut || {
        ws.assemble_static(&rod, &st, 1.0, true).unwrap()
    });
    // A dynamic step's elastic residual: a bent state with velocities and viscous damping.
    let mut bent = st.clone();
    for (k, p) in bent.p.iter_mut().enumerate() {
        *p *= exp_half(&Vector3::new(0.01 * (k as f64).sin(), 0.02, 0.0));
    }
    let rates = Rates {
        v: (0..n + 1)
            .map(|k| Vector6::from_fn(|i, _| ((k * 6 + i) as f64).sin()))
            .collect(),
        ghost_omega: vec![Vector3::zeros(); rod.ghosts.len()],
        shear_damping: Vector3::new(3.0, 4.0, 5.0),
        bend_damping: Vector3::new(2e-3, 3e-3, 1e-3),
        damping_factor: 0.0,
        tangent: Vec::<Matrix3<f64>>::new(),
    };
    for (label, outputs) in [
        ("elastic residual, rates", false),
        ("the same with outputs", true),
    ] {
        ws.section_outputs = outputs;
        time(label, &mut || {
            ws.clear(false);
            ws.add_elastic_part(&rod, &bent, Some(&rates), false, Part::All)
                .unwrap()
        });
    }
    ws.section_outputs = true;
    let mut jac = ws.jac.clone();
    time("block LU factorisation", &mut || jac.factor().unwrap());
    let mut rhs = vec![Vector6::repeat(1.0); n + 1];
    time("forward/back substitution", &mut || {
        jac.solve_factored(&mut rhs)
    });
    // The stability check after a converged solve: the inertia of the symmetric tangent.
    let mut check = ws.jac.clone();
    let inertia = check.inertia(0..n + 1);
    time("stability check (LDLᵀ inertia)", &mut || {
        check.inertia(0..n + 1);
    });
    time("LDLᵀ with the pivot inverses (for a solve)", &mut || {
        check.ldlt(0..n + 1);
    });
    println!(
        "  (negative pivots at the routed shape: {})",
        inertia.negative
    );
}

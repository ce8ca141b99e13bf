//! The residual assembly of the elastic terms with rates (a dynamic Newton iteration with a
//! reused matrix, and with the section outputs: the outputs pass) of a 400-segment cable: the
//! best of 5 × 20000, µs (docs/dynamics.md, session 20). Run with
//! `cargo run --release -p cablelife-rod --example bench_elastic`.
use nalgebra::{Matrix3, Quaternion, Vector3, Vector6};
use rod::assembly::{Part, Rates, Workspace};
use rod::rotation::exp_half;
use rod::routing::route;
use rod::{CableSpec, ClipKind, ClipSpec, Pose, Rod, Section};
use std::time::Instant;

fn main() {
    let n = 400;
    let spec = CableSpec {
        length: 1.0,
        segments: n,
        section: Section {
            shear_stiffness: Vector3::new(1e4, 1e4, 3e4),
            bend_stiffness: Vector3::new(0.02, 0.02, 0.015),
            mass_per_length: 0.1,
            rotary_inertia: Vector3::new(1e-7, 1e-7, 2e-7),
        },
        natural_curvature: Vector3::new(0.5, 0.0, 0.0),
        clips: vec![ClipSpec {
            name: "a".into(),
            s: 0.0,
            length: 0.0,
            kind: ClipKind::Fixed,
            pose: Pose {
                position: Vector3::zeros(),
                orientation: Quaternion::identity(),
            },
        }],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    let mut st = route(&rod, None).unwrap();
    for (k, p) in st.p.iter_mut().enumerate() {
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
    let mut ws = Workspace::new(&rod);
    for outputs in [false, true] {
        ws.section_outputs = outputs;
        let reps = 20000;
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let t0 = Instant::now();
            for _ in 0..reps {
                ws.clear(false);
                ws.add_elastic_part(&rod, &st, Some(&rates), false, Part::All)
                    .unwrap();
            }
            best = best.min(t0.elapsed().as_secs_f64() / reps as f64 * 1e6);
        }
        println!("outputs {outputs}: {best:.2} µs per residual assembly of {n} segments");
    }
}

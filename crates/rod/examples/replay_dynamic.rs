//! Replays a dumped dynamic run (cable, clip kinematics, damping) without Python and prints the
//! time of the static equilibrium, the cost per step (median and minimum over REPS runs; wall
//! time and this thread's CPU time), Newton iterations and factorisations per step, and the
//! largest section loads. Outputs are assembled every 5th step, as the benchmark saves them.
//! `cargo run --release -p cablelife-rod --example replay_dynamic -- FILE [REPS] [OUT]`
//! (FILE from `python3 benchmarks/bench_dynamic.py --dump N DURATION FILE`; OUT: the largest
//! bending moments and forces per node/edge and the moments of every saved step, f64 LE).
//! Environment: TOL (Newton tolerance: fraction of the local time-error estimate), RATE (refactor rate), MAXIT; FDCHECK=k
//! compares the iteration matrix with finite differences after step k (EPS: the step);
//! PIECES=1 times residual, matrix, factorisation and substitution at step 300.
use nalgebra::{Quaternion, Vector3};
use rod::routing::route;
use rod::{
    CableSpec, ClipKind, ClipMotion, ClipSpec, DynamicOptions, Dynamics, NewtonOptions, Pose, Rod,
    Section, Statics,
};
use std::io::Write;
use std::time::Instant;

/// CPU time of this thread, s (Linux: /proc/thread-self/schedstat; 0 elsewhere).
fn cpu_time() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| {
            s.split_whitespace()
                .next()
                .and_then(|v| v.parse::<f64>().ok())
        })
        .map(|ns| ns * 1e-9)
        .unwrap_or(0.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(&args[1]).expect("scene file");
    let reps: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(3);
    let mut lines = text.lines();
    let nums = |line: &str| -> Vec<f64> {
        line.split_whitespace()
            .map(|t| t.parse::<f64>().unwrap())
            .collect()
    };
    let head = nums(lines.next().unwrap());
    let sec = nums(lines.next().unwrap());
    let kg = nums(lines.next().unwrap());
    let n_clips: usize = lines.next().unwrap().trim().parse().unwrap();
    let mut clips = Vec::new();
    for i in 0..n_clips {
        let l = lines.next().unwrap();
        let t: Vec<&str> = l.split_whitespace().collect();
        let v: Vec<f64> = t[3..].iter().map(|x| x.parse().unwrap()).collect();
        clips.push(ClipSpec {
            name: format!("c{i}"),
            s: t[0].parse().unwrap(),
            length: t[1].parse().unwrap(),
            kind: match t[2] {
                "fixed" => ClipKind::Fixed,
                "swivel" => ClipKind::Swivel,
                _ => ClipKind::Ball,
            },
            pose: Pose {
                position: Vector3::new(v[0], v[1], v[2]),
                orientation: Quaternion::new(v[3], v[4], v[5], v[6]),
            },
        });
    }
    let d = nums(lines.next().unwrap());
    let t_count: usize = lines.next().unwrap().trim().parse().unwrap();
    let mut motions: Vec<Vec<ClipMotion>> = Vec::with_capacity(t_count);
    for _ in 0..t_count {
        let mut row = Vec::new();
        for _ in 0..n_clips {
            let v = nums(lines.next().unwrap());
            let v3 = |i: usize| Vector3::new(v[i], v[i + 1], v[i + 2]);
            row.push(ClipMotion {
                pose: Pose {
                    position: v3(0),
                    orientation: Quaternion::new(v[3], v[4], v[5], v[6]),
                },
                velocity: v3(7),
                angular_velocity: v3(10),
                acceleration: v3(13),
                angular_acceleration: v3(16),
            });
        }
        motions.push(row);
    }
    let spec = CableSpec {
        length: head[0],
        segments: head[1] as usize,
        section: Section {
            shear_stiffness: Vector3::new(sec[0], sec[1], sec[2]),
            bend_stiffness: Vector3::new(sec[3], sec[4], sec[5]),
            mass_per_length: sec[6],
            rotary_inertia: Vector3::new(sec[7], sec[8], sec[9]),
        },
        natural_curvature: Vector3::new(kg[0], kg[1], kg[2]),
        clips,
        loads: vec![],
        gravity: Vector3::new(kg[3], kg[4], kg[5]),
    };
    let rod = Rod::new(spec).unwrap();
    let env = |k: &str, default: f64| -> f64 {
        std::env::var(k)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let defaults = DynamicOptions::default();
    let opts = DynamicOptions {
        rho_inf: d[6],
        tau_shear: Vector3::new(d[0], d[1], d[2]),
        tau_bend: Vector3::new(d[3], d[4], d[5]),
        tolerance: env("TOL", defaults.tolerance),
        refactor_rate: env("RATE", defaults.refactor_rate),
        max_iterations: env("MAXIT", 25.0) as usize,
        outputs_every_step: false,
        ..defaults
    };
    let h = d[7];
    let mut st0 = route(
        &rod,
        Some(&motions[0].iter().map(|m| m.pose).collect::<Vec<_>>()),
    )
    .unwrap();
    let t_static = Instant::now();
    let sst = Statics::new(&rod, NewtonOptions::default())
        .solve(&rod, &mut st0)
        .unwrap();
    println!(
        "static equilibrium: {:.2} ms ({} iterations, {} substeps)",
        t_static.elapsed().as_secs_f64() * 1e3,
        sst.iterations,
        sst.substeps
    );
    let mut times = Vec::new();
    let mut cpu = Vec::new();
    let (mut iters, mut facts) = (0usize, 0usize);
    let mut max_moment = vec![0.0f64; rod.arc.len()];
    let mut max_force = vec![0.0f64; rod.n_edges()];
    let mut history: Vec<f64> = Vec::new();
    for rep in 0..reps {
        let mut st = st0.clone();
        // BRANCH=k: the first k steps with the default options (a common start, with the same
        // sub-steps in the start-up transient), the rest with the options from the environment.
        let branch = env("BRANCH", 0.0) as usize;
        let split = env("SPLIT", 1.0) as usize;
        let mut dy = Dynamics::new(
            &rod,
            &st,
            &motions[0],
            if branch > 0 {
                DynamicOptions {
                    outputs_every_step: false,
                    ..DynamicOptions {
                        tolerance: defaults.tolerance,
                        refactor_rate: defaults.refactor_rate,
                        max_iterations: defaults.max_iterations,
                        ..opts.clone()
                    }
                }
            } else {
                opts.clone()
            },
        );
        dy.start(&rod, &st).unwrap();
        let t0 = Instant::now();
        let c0 = cpu_time();
        let (mut it, mut fa) = (0, 0);
        for k in 1..t_count {
            if branch > 0 && k == branch + 1 {
                dy.opts = opts.clone();
            }
            let s = if split > 1 {
                // SPLIT sub-steps per signal step on the quintic Hermite interpolant of the
                // clip kinematics (the time-discretisation error on the same input).
                let mut sum = rod::StepStats::default();
                let mut from = motions[k - 1].clone();
                for j in 1..=split {
                    let to = interpolate(&motions[k - 1], &motions[k], h, j as f64 / split as f64);
                    let s = dy
                        .advance(&rod, &mut st, h / split as f64, &from, &to, 6)
                        .unwrap_or_else(|e| panic!("step {k}: {e}"));
                    sum = sum.then(s);
                    from = to;
                }
                sum
            } else {
                dy.advance(&rod, &mut st, h, &motions[k - 1], &motions[k], 6)
                    .unwrap_or_else(|e| panic!("step {k}: {e}"))
            };
            it += s.iterations;
            if rep == 0 && k == 20 {
                println!(
                    "first 20 steps (start-up transient): {:.2} ms",
                    t0.elapsed().as_secs_f64() * 1e3
                );
            }
            if rep == 0 && s.substeps > 1 {
                println!(
                    "step {k}: {} substeps, {} iterations, {} factorisations",
                    s.substeps, s.iterations, s.factorizations
                );
            }
            fa += s.factorizations;
            if rep == 0
                && std::env::var("FDCHECK")
                    .ok()
                    .and_then(|v| v.parse::<usize>().ok())
                    == Some(k)
            {
                let eps: f64 = std::env::var("EPS")
                    .ok()
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(1e-7);
                let (a, f) = dy.iteration_matrix_fd(&rod, &mut st, h, eps).unwrap();
                report(&a, &f);
            }
            // Outputs on the saved steps (every 5th, as the benchmark saves them).
            if k % 5 == 0 {
                dy.update_outputs(&rod, &st).unwrap();
                if rep == 0 {
                    for (m, v) in max_moment.iter_mut().zip(&dy.ws.node_moment) {
                        *m = m.max(v.xy().norm());
                    }
                    for (m, v) in max_force.iter_mut().zip(&dy.ws.edge_force) {
                        *m = m.max(v.norm());
                    }
                    history.extend(dy.ws.node_moment.iter().flat_map(|v| [v.x, v.y, v.z]));
                }
            }
        }
        times.push(t0.elapsed().as_secs_f64());
        cpu.push(cpu_time() - c0);
        iters = it;
        facts = fa;
    }
    times.sort_by(|a, b| a.partial_cmp(b).unwrap());
    cpu.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let steps = (t_count - 1) as f64;
    let med = times[times.len() / 2];
    println!(
        "N={} steps={} wall median {:.1} µs/step (min {:.1}), cpu min {:.1} → {:.1}× real \
         time; it/step {:.3}, factorizations/step {:.3}; max |M_b| {:.6e} N m, max |F| {:.6e} N",
        rod.n_edges(),
        t_count - 1,
        med / steps * 1e6,
        times[0] / steps * 1e6,
        cpu[0] / steps * 1e6,
        steps * h / med,
        iters as f64 / steps,
        facts as f64 / steps,
        max_moment.iter().cloned().fold(0.0, f64::max),
        max_force.iter().cloned().fold(0.0, f64::max),
    );
    if std::env::var("PIECES").is_ok() {
        // Cost of the pieces of an iteration at the end state of a run.
        let mut st = st0.clone();
        let mut dy = Dynamics::new(&rod, &st, &motions[0], opts.clone());
        dy.start(&rod, &st).unwrap();
        for k in 1..t_count.min(301) {
            dy.advance(&rod, &mut st, h, &motions[k - 1], &motions[k], 6)
                .unwrap();
        }
        if let Ok(what) = std::env::var("LOOP") {
            for _ in 0..200000 {
                match what.as_str() {
                    "r" => dy.assemble_iterate(&rod, &st, h, false).unwrap(),
                    _ => dy.assemble_iterate(&rod, &st, h, true).unwrap(),
                }
            }
            return;
        }
        let reps = 5000;
        let time = |label: &str, f: &mut dyn FnMut()| {
            let mut best = f64::INFINITY;
            for _ in 0..50 {
                let t0 = Instant::now();
                for _ in 0..reps / 50 {
                    f();
                }
                best = best.min(t0.elapsed().as_secs_f64() / (reps / 50) as f64);
            }
            println!("{label:>30}: {:8.2} µs (best of 50)", best * 1e6);
        };
        time("dynamic residual", &mut || {
            dy.assemble_iterate(&rod, &st, h, false).unwrap()
        });
        time("dynamic residual + matrix", &mut || {
            dy.assemble_iterate(&rod, &st, h, true).unwrap()
        });
        let mut ws = dy.ws.clone();
        time("block LU factorisation", &mut || ws.factor(&rod).unwrap());
        let mut delta = vec![nalgebra::Vector6::zeros(); rod.arc.len()];
        time("correction (substitution)", &mut || {
            ws.newton_correction(&mut delta);
        });
    }
    if let Some(out) = args.get(3) {
        let mut f = std::fs::File::create(out).unwrap();
        for v in max_moment.iter().chain(&max_force).chain(&history) {
            f.write_all(&v.to_le_bytes()).unwrap();
        }
    }
}

/// Largest differences between the assembled and the finite-difference iteration matrix, by
/// kind of block entry (x/θ rows and columns; diagonal, off-diagonal blocks).
fn report(a: &rod::block_tridiag::BlockTridiag, f: &rod::block_tridiag::BlockTridiag) {
    let n = a.n_blocks();
    let names = ["xx", "xt", "tx", "tt"];
    for (label, pick) in [("diag", 0), ("lower", 1), ("upper", 2)] {
        let mut err = [0.0f64; 4];
        let mut mag = [0.0f64; 4];
        let mut at = [(0usize, 0usize, 0usize); 4];
        for b in 0..n {
            let (ma, mf) = match pick {
                0 => (&a.diag[b], &f.diag[b]),
                1 => (&a.lower[b], &f.lower[b]),
                _ => (&a.upper[b], &f.upper[b]),
            };
            for i in 0..6 {
                for j in 0..6 {
                    let t = 2 * (i / 3) + j / 3;
                    let e = (ma[(i, j)] - mf[(i, j)]).abs();
                    mag[t] = mag[t].max(mf[(i, j)].abs());
                    if e > err[t] {
                        err[t] = e;
                        at[t] = (b, i, j);
                    }
                }
            }
        }
        for t in 0..4 {
            println!(
                "{label:>5} {}: max |fd| {:.3e}, max |an − fd| {:.3e} ({:.2e} rel) at {:?}",
                names[t],
                mag[t],
                err[t],
                err[t] / mag[t].max(1e-300),
                at[t]
            );
        }
    }
}

/// The clip kinematics at t_0 + λh on the quintic Hermite interpolant of position, velocity and
/// acceleration between two samples (angular motion: slerp and linear; consistent derivatives
/// for the translation).
fn interpolate(a: &[ClipMotion], b: &[ClipMotion], h: f64, l: f64) -> Vec<ClipMotion> {
    a.iter()
        .zip(b)
        .map(|(a, b)| {
            let (p0, v0, a0) = (a.pose.position, a.velocity * h, a.acceleration * h * h);
            let (p1, v1, a1) = (b.pose.position, b.velocity * h, b.acceleration * h * h);
            // Quintic Hermite basis in λ and its first two derivatives.
            let (t, t2, t3, t4, t5) = (l, l * l, l.powi(3), l.powi(4), l.powi(5));
            let h0 = [
                1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5,
                -30.0 * t2 + 60.0 * t3 - 30.0 * t4,
                -60.0 * t + 180.0 * t2 - 120.0 * t3,
            ];
            let h1 = [
                t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5,
                1.0 - 18.0 * t2 + 32.0 * t3 - 15.0 * t4,
                -36.0 * t + 96.0 * t2 - 60.0 * t3,
            ];
            let h2 = [
                0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5,
                t - 4.5 * t2 + 6.0 * t3 - 2.5 * t4,
                1.0 - 9.0 * t + 18.0 * t2 - 10.0 * t3,
            ];
            let h5 = [
                10.0 * t3 - 15.0 * t4 + 6.0 * t5,
                30.0 * t2 - 60.0 * t3 + 30.0 * t4,
                60.0 * t - 180.0 * t2 + 120.0 * t3,
            ];
            let h4 = [
                -4.0 * t3 + 7.0 * t4 - 3.0 * t5,
                -12.0 * t2 + 28.0 * t3 - 15.0 * t4,
                -24.0 * t + 84.0 * t2 - 60.0 * t3,
            ];
            let h3 = [
                0.5 * t3 - t4 + 0.5 * t5,
                1.5 * t2 - 4.0 * t3 + 2.5 * t4,
                3.0 * t - 12.0 * t2 + 10.0 * t3,
            ];
            let at = |d: usize| {
                p0 * h0[d] + v0 * h1[d] + a0 * h2[d] + a1 * h3[d] + v1 * h4[d] + p1 * h5[d]
            };
            ClipMotion {
                pose: Pose {
                    position: at(0),
                    orientation: rod::rotation::slerp(&a.pose.orientation, &b.pose.orientation, l),
                },
                velocity: at(1) / h,
                acceleration: at(2) / (h * h),
                angular_velocity: a.angular_velocity * (1.0 - l) + b.angular_velocity * l,
                angular_acceleration: a.angular_acceleration * (1.0 - l)
                    + b.angular_acceleration * l,
            }
        })
        .collect()
}

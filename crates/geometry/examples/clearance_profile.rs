//! The clearance benchmark's case without Python, for profiling (perf, callgrind):
//! `cargo run -p cablelife-geometry --release --example clearance_profile -- [quads] [steps] [dt in µs]`.
//! The figures to report come from `benchmarks/bench_clearance.py`.
use std::f64::consts::PI;
use std::time::Instant;

use geometry::{clearance, height_field, Part, RigidMap, Shape, TriMesh, V3};

fn height(x: f64, y: f64) -> f64 {
    0.01 * (2.0 * PI * x / 0.15).sin() * (2.0 * PI * y / 0.1).cos()
        + 0.005 * (2.0 * PI * (x + y) / 0.3).sin()
}

/// CPU time of all threads of this process (s), from /proc/self/stat (Linux).
fn cpu_time() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = s.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    // fields 14, 15 (utime, stime) in clock ticks; rest starts at field 3
    (f.get(11).unwrap_or(&0.0) + f.get(12).unwrap_or(&0.0)) / 100.0
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let n = args.first().copied().unwrap_or(707);
    let steps = args.get(1).copied().unwrap_or(5001);
    // time between saved steps in µs (1000: the benchmark's 1 ms)
    let dt = args.get(2).copied().unwrap_or(1000) as f64 * 1e-6;
    let (v, f) = height_field(n, height);
    let (t0, c0) = (Instant::now(), cpu_time());
    let mesh = TriMesh::new(&v, &f).unwrap();
    let build = t0.elapsed().as_secs_f64();
    let build_cpu = cpu_time() - c0;
    let edges = 100;
    let mut pos = Vec::with_capacity(steps * (edges + 1));
    for s in 0..steps {
        let t = s as f64 * dt;
        for k in 0..=edges {
            let u = k as f64 / edges as f64;
            let x = 0.1 + 0.8 * u + 0.002 * (2.0 * PI * 10.0 * t + 3.0 * u).sin();
            let y = 0.2
                + 0.6 * u
                + 0.05 * (PI * u).sin()
                + 0.002 * (2.0 * PI * 23.0 * t + 5.0 * u).sin();
            let z = height(x, y)
                + 0.025
                + 0.015 * (2.0 * PI * u).sin()
                + 0.002 * (2.0 * PI * 60.0 * t).sin();
            pos.push(V3::new(x, y, z));
        }
    }
    let parts = vec![Part {
        shape: Shape::Mesh(mesh),
        body: 0,
    }];
    let maps = vec![RigidMap::identity(); steps];
    let (t0, c0) = (Instant::now(), cpu_time());
    let c = clearance(&parts, &pos, edges + 1, 0.006, &maps, Default::default()).unwrap();
    let run = t0.elapsed().as_secs_f64();
    let cpu = cpu_time() - c0;
    let sum: f64 = c.value.iter().sum();
    println!(
        "{} triangles, build {build:.3} s (CPU {build_cpu:.2} s), clearance wall {run:.3} s, CPU {cpu:.2} s \
         ({:.2} µs CPU per node), sum {sum:.12e}",
        f.len(),
        cpu / c.value.len() as f64 * 1e6
    );
}

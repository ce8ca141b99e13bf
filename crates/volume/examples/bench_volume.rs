//! Motion-volume kernel benchmark: a synthetic dynamic result through the signed-distance kernel.
//!
//! A 1.25 m cable of 100 edges along a gentle 3D curve, 5001 saved steps of 1 ms, every node
//! moving by a smooth motion of about 2 mm (a sum of sines at 10–60 Hz), radius 6 mm: 500 k
//! capsules that overlap almost completely step to step. Band 3 voxels, grid = bounding box +
//! 2 voxels (as `cablelife.volume.field.grid_for`). Prints the median wall time and a checksum
//! of the field, and checks it against brute-force point distances on a subsample. (The
//! pre-speed-up kernel, to compare with, is in git history before the merge of
//! `volume-speed`: it gave the same field bit for bit, 20–30× slower on this case.)
//! Wall times are medians, CPU times means over all threads; both include the hierarchy.
//!
//!     cargo run --release -p cablelife-volume --example bench_volume -- [--runs 3]
//!         [--voxel 4,2] [--stride 1,5] [--steps 5001]
//!
//! Small cases: `--steps 10` (1000 capsules) or `--steps 100 --voxel 4,2,1`. `--load FILE`
//! reads the capsules from raw little-endian f64 rows (start xyz, end xyz, radius) instead,
//! e.g. those of benchmarks/bench_volume.py's cable (`--stride` then takes every n-th row).

use std::time::Instant;
use volume::{signed_distance, Capsules, Grid, Vec3};

const LENGTH: f64 = 1.25;
const EDGES: usize = 100;
const RADIUS: f64 = 0.006;
const DT: f64 = 1e-3;

/// Node positions (steps, EDGES + 1): a gentle 3D curve plus a smooth motion of ~2 mm.
fn motion(steps: usize) -> Vec<Vec<Vec3>> {
    // Sines: (frequency Hz, amplitude m, spatial wave number, phase) per axis.
    let waves: [[(f64, f64, f64, f64); 3]; 3] = [
        [
            (11.0, 1.0e-3, 1.0, 0.3),
            (27.0, 0.6e-3, 2.0, 1.1),
            (53.0, 0.3e-3, 3.0, 2.0),
        ],
        [
            (13.0, 1.1e-3, 1.0, 0.7),
            (31.0, 0.5e-3, 2.5, 0.2),
            (47.0, 0.3e-3, 4.0, 1.7),
        ],
        [
            (10.0, 0.9e-3, 1.5, 2.2),
            (23.0, 0.7e-3, 2.0, 0.9),
            (59.0, 0.3e-3, 3.5, 0.4),
        ],
    ];
    (0..steps)
        .map(|n| {
            let t = n as f64 * DT;
            (0..=EDGES)
                .map(|e| {
                    let u = e as f64 / EDGES as f64;
                    // Base curve: about 1.25 m long (x over ~1.2 m, gentle y and z bows).
                    let base = [
                        1.2 * u,
                        0.12 * (std::f64::consts::PI * u).sin(),
                        0.08 * (2.0 * std::f64::consts::PI * u).sin() - 0.05 * u,
                    ];
                    let mut p = base;
                    for (axis, w) in waves.iter().enumerate() {
                        for &(f, a, kappa, phase) in w {
                            p[axis] += a
                                * (2.0 * std::f64::consts::PI * f * t + phase).sin()
                                * (std::f64::consts::PI * kappa * u + phase).sin();
                        }
                    }
                    p
                })
                .collect()
        })
        .collect()
}

struct Case {
    starts: Vec<Vec3>,
    ends: Vec<Vec3>,
    radius: Vec<f64>,
}

fn capsules_of(nodes: &[Vec<Vec3>], stride: usize) -> Case {
    let mut c = Case {
        starts: Vec::new(),
        ends: Vec::new(),
        radius: Vec::new(),
    };
    for step in nodes.iter().step_by(stride) {
        for e in 0..EDGES {
            c.starts.push(step[e]);
            c.ends.push(step[e + 1]);
            c.radius.push(RADIUS);
        }
    }
    c
}

/// Capsules from a raw file of little-endian f64 rows (start xyz, end xyz, radius); every
/// `stride`-th row.
fn loaded(path: &str, stride: usize) -> Case {
    let bytes = std::fs::read(path).unwrap();
    let v: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let mut c = Case {
        starts: Vec::new(),
        ends: Vec::new(),
        radius: Vec::new(),
    };
    for row in v.chunks_exact(7).step_by(stride) {
        c.starts.push([row[0], row[1], row[2]]);
        c.ends.push([row[3], row[4], row[5]]);
        c.radius.push(row[6]);
    }
    c
}

/// As `grid_for(bounds, voxel, pad=2)` in python/cablelife/volume/field.py.
fn grid_for(c: &Case, voxel: f64) -> Grid {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for i in 0..c.starts.len() {
        for k in 0..3 {
            lo[k] = lo[k].min(c.starts[i][k].min(c.ends[i][k]) - c.radius[i]);
            hi[k] = hi[k].max(c.starts[i][k].max(c.ends[i][k]) + c.radius[i]);
        }
    }
    let pad = 2.0;
    Grid {
        origin: [0, 1, 2].map(|k| lo[k] - pad * voxel),
        spacing: voxel,
        shape: [0, 1, 2].map(|k| ((hi[k] - lo[k]) / voxel).ceil() as usize + 5),
    }
}

/// CPU time of this process (all threads), s, from /proc (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let f: Vec<&str> = s.rsplit(')').next().unwrap().split_whitespace().collect();
    (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / 100.0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median wall time and mean CPU time (all threads) of some runs, s.
#[derive(Clone, Copy)]
struct Time {
    wall: f64,
    cpu: f64,
}

impl Time {
    fn plus(self, o: Time) -> Time {
        Time {
            wall: self.wall + o.wall,
            cpu: self.cpu + o.cpu,
        }
    }

    fn show(&self) -> String {
        format!("{:.3} s (cpu {:.3} s)", self.wall, self.cpu)
    }
}

fn timed<T>(runs: usize, mut f: impl FnMut() -> T) -> (Time, T) {
    let mut times = Vec::new();
    let mut last = None;
    let cpu0 = cpu_seconds();
    for _ in 0..runs {
        let t0 = Instant::now();
        last = Some(f());
        times.push(t0.elapsed().as_secs_f64());
    }
    let cpu = (cpu_seconds() - cpu0) / runs as f64;
    let wall = median(times);
    (Time { wall, cpu }, last.unwrap())
}

/// Exact distance from `p` to the union of the capsules, by brute force (no hierarchy).
fn brute_distance(c: &Case, p: Vec3) -> f64 {
    let mut best = f64::INFINITY;
    for i in 0..c.starts.len() {
        let (a, b) = (c.starts[i], c.ends[i]);
        let ab = [0, 1, 2].map(|k| b[k] - a[k]);
        let ap = [0, 1, 2].map(|k| p[k] - a[k]);
        let l2: f64 = ab.iter().map(|x| x * x).sum();
        let t = if l2 > 0.0 {
            ((0..3).map(|k| ap[k] * ab[k]).sum::<f64>() / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d2: f64 = (0..3).map(|k| (ap[k] - t * ab[k]).powi(2)).sum();
        best = best.min(d2.sqrt() - c.radius[i]);
    }
    best
}

fn checksum(field: &[f32]) -> f64 {
    field
        .iter()
        .enumerate()
        .map(|(i, &v)| v as f64 * (1.0 + (i % 7) as f64))
        .sum()
}

fn list<T: std::str::FromStr>(s: &str) -> Vec<T> {
    s.split(',').map(|x| x.parse().ok().unwrap()).collect()
}

fn main() {
    let mut runs = 3;
    let mut voxels: Vec<f64> = vec![4.0, 2.0];
    let mut strides: Vec<usize> = vec![1, 5];
    let mut steps = 5001;
    let mut load: Option<String> = None;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--runs" => runs = args[i + 1].parse().unwrap(),
            "--voxel" => voxels = list(&args[i + 1]),
            "--stride" => strides = list(&args[i + 1]),
            "--steps" => steps = args[i + 1].parse().unwrap(),
            "--load" => load = Some(args[i + 1].clone()),
            a => panic!("unknown argument {a}"),
        }
        i += 2;
    }
    match &load {
        Some(path) => println!("capsules of {path}"),
        None => println!(
            "cable {LENGTH} m, {EDGES} edges, r = {} mm, {steps} steps of 1 ms",
            RADIUS * 1e3
        ),
    }
    println!(
        "{} threads, median wall time of {runs} runs",
        rayon::current_num_threads()
    );
    let nodes = motion(if load.is_some() { 0 } else { steps });
    for &stride in &strides {
        let c = match &load {
            Some(path) => loaded(path, stride),
            None => capsules_of(&nodes, stride),
        };
        let (build_new, caps) = timed(runs, || {
            Capsules::new(&c.starts, &c.ends, &c.radius).unwrap()
        });
        println!(
            "every {stride} step(s): {} capsules; hierarchy {} (included below)",
            c.starts.len(),
            build_new.show()
        );
        for &voxel_mm in &voxels {
            let voxel = voxel_mm * 1e-3;
            let grid = grid_for(&c, voxel);
            let band = 3.0 * voxel;
            let (t_new, new) = timed(runs, || signed_distance(&caps, &grid, band).unwrap());
            let t_new = t_new.plus(build_new);
            print!(
                "  voxel {voxel_mm} mm, {:?} = {:.2} M voxels: ",
                grid.shape,
                new.len() as f64 / 1e6
            );
            print!("{}, checksum {:.6}", t_new.show(), checksum(&new));
            // Brute-force check on a subsample of the voxels within the band.
            let [_, ny, nz] = grid.shape;
            let mut worst: f32 = 0.0;
            let mut checked = 0;
            for (idx, &v) in new.iter().enumerate().step_by(97) {
                if v.abs() >= band as f32 || checked >= 300 {
                    continue;
                }
                let index = [idx / (ny * nz), idx / nz % ny, idx % nz];
                let p = [0, 1, 2].map(|a| grid.origin[a] + voxel * index[a] as f64);
                let exact = brute_distance(&c, p).clamp(-band, band) as f32;
                worst = worst.max((v - exact).abs());
                checked += 1;
            }
            println!("; vs exact point distances at {checked} voxels: max |Δ| {worst:.1e}");
        }
    }
}

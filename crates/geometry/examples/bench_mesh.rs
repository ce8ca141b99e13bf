//! Hierarchy build and query cost on a bumpy height field (n × n quads):
//! `cargo run -p cablelife-geometry --release --example bench_mesh -- 707`
use geometry::{height_field, Surface, TriMesh, V3};
use std::time::Instant;

fn height(x: f64, y: f64) -> f64 {
    use std::f64::consts::PI;
    0.01 * (2.0 * PI * x / 0.15).sin() * (2.0 * PI * y / 0.1).cos()
        + 0.005 * (2.0 * PI * (x + y) / 0.3).sin()
}

fn main() {
    let n: usize = std::env::args().nth(1).map_or(707, |a| a.parse().unwrap());
    let (v, f) = height_field(n, height);
    let t0 = Instant::now();
    let m = TriMesh::new(&v, &f).unwrap();
    println!(
        "{} triangles: build {:.3} s",
        m.n_triangles(),
        t0.elapsed().as_secs_f64()
    );
    let q: Vec<V3> = (0..20000)
        .map(|k| {
            let u = k as f64 / 20000.0;
            let (x, y) = (0.1 + 0.8 * u, 0.2 + 0.6 * u);
            V3::new(x, y, height(x, y) + 0.025)
        })
        .collect();
    let t0 = Instant::now();
    let mut s = 0.0;
    for p in &q {
        s += m
            .project_point(p, f64::INFINITY, usize::MAX)
            .unwrap()
            .distance;
    }
    let tp = t0.elapsed().as_secs_f64() / q.len() as f64;
    let t0 = Instant::now();
    for w in q.windows(2) {
        s += m
            .closest_to_segment(&w[0], &w[1], f64::INFINITY, usize::MAX)
            .unwrap()
            .distance;
    }
    let ts = t0.elapsed().as_secs_f64() / q.len() as f64;
    println!(
        "point {:.2} µs, segment {:.2} µs ({s:.3})",
        tp * 1e6,
        ts * 1e6
    );
    // clearance-like: 50 steps of 101 nodes moving slightly
    let steps = 50;
    let mut pos = vec![];
    for t in 0..steps {
        for i in 0..101 {
            let u = i as f64 / 100.0;
            let (x, y) = (
                0.1 + 0.8 * u + 0.002 * (t as f64 * 0.06).sin(),
                0.2 + 0.6 * u,
            );
            pos.push(V3::new(
                x,
                y,
                height(x, y) + 0.025 + 0.015 * (2.0 * std::f64::consts::PI * u).sin(),
            ));
        }
    }
    let parts = vec![geometry::Part {
        shape: geometry::Shape::Mesh(m),
        body: 0,
    }];
    let maps = vec![geometry::RigidMap::identity(); steps];
    let t0 = Instant::now();
    geometry::clearance(&parts, &pos, 101, 0.006, &maps, Default::default()).unwrap();
    let n = pos.len() as f64;
    println!(
        "clearance {:.2} µs/node",
        t0.elapsed().as_secs_f64() / n * 1e6
    );
}

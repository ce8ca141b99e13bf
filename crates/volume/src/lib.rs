//! Motion volumes of cables: the signed distance to a union of capsules (one per cable edge and
//! saved step) on a voxel grid, computed in parallel, and exact point distances for comparing
//! two volumes. Meshing (marching cubes) and files are done by the Python package.

pub mod capsules;
pub mod grid;

pub use capsules::{Aabb, Capsules, InputError, Vec3};
pub use grid::{signed_distance, Grid, MAX_VOXELS};

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (no dependency).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn vec(&mut self, scale: f64) -> Vec3 {
            [
                self.next() * scale,
                self.next() * scale,
                self.next() * scale,
            ]
        }
    }

    fn brute(starts: &[Vec3], ends: &[Vec3], radius: &[f64], p: Vec3) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..starts.len() {
            let (a, b) = (starts[i], ends[i]);
            let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
            let l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
            let t = if l2 > 0.0 {
                ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = [0, 1, 2].map(|k| ap[k] - t * ab[k]);
            best = best.min((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - radius[i]);
        }
        best
    }

    fn random_capsules(n: usize, seed: u64) -> (Vec<Vec3>, Vec<Vec3>, Vec<f64>) {
        let mut g = Lcg(seed);
        let starts: Vec<Vec3> = (0..n).map(|_| g.vec(1.0)).collect();
        let ends: Vec<Vec3> = starts
            .iter()
            .map(|s| {
                let d = g.vec(0.2);
                [s[0] + d[0] - 0.1, s[1] + d[1] - 0.1, s[2] + d[2] - 0.1]
            })
            .collect();
        let radius: Vec<f64> = (0..n).map(|_| 0.01 + 0.05 * g.next()).collect();
        (starts, ends, radius)
    }

    #[test]
    fn point_distance_equals_brute_force() {
        let (s, e, r) = random_capsules(300, 1);
        let caps = Capsules::new(&s, &e, &r).unwrap();
        let mut g = Lcg(7);
        for _ in 0..2000 {
            let p = g.vec(1.6);
            let p = [p[0] - 0.3, p[1] - 0.3, p[2] - 0.3];
            let exact = brute(&s, &e, &r, p);
            assert!((caps.distance(p) - exact).abs() < 1e-12);
        }
    }

    #[test]
    fn grid_equals_clamped_brute_force() {
        let (s, e, r) = random_capsules(120, 3);
        let caps = Capsules::new(&s, &e, &r).unwrap();
        let grid = Grid {
            origin: [-0.1, -0.1, -0.1],
            spacing: 0.031,
            shape: [41, 37, 23],
        };
        let band = 0.07;
        let field = signed_distance(&caps, &grid, band).unwrap();
        let [nx, ny, nz] = grid.shape;
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let p = [
                        -0.1 + 0.031 * i as f64,
                        -0.1 + 0.031 * j as f64,
                        -0.1 + 0.031 * k as f64,
                    ];
                    let want = brute(&s, &e, &r, p).clamp(-band, band) as f32;
                    let got = field[(i * ny + j) * nz + k];
                    assert!(
                        (got - want).abs() < 1e-6,
                        "voxel {i},{j},{k}: {got} vs {want}"
                    );
                }
            }
        }
    }

    /// The capsules of a cable's edges over many saved steps: a few edges along a sloped
    /// polyline, each moved by a few mm per step pattern, so consecutive capsules nearly
    /// coincide; some axes reversed, some degenerate, radii 5–6 mm.
    fn swept_edges(edges: usize, steps: usize, seed: u64) -> (Vec<Vec3>, Vec<Vec3>, Vec<f64>) {
        let mut g = Lcg(seed);
        let node = |e: usize, t: f64| -> Vec3 {
            let u = e as f64 * 0.0125;
            let w = [
                (70.0 * t + 3.0 * u).sin(),
                (110.0 * t + 0.5 + 5.0 * u).sin(),
                (160.0 * t + 1.0 + 7.0 * u).sin(),
            ];
            [
                u + 0.001 * w[0],
                0.3 * u + 0.002 * w[1],
                -0.4 * u + 0.002 * w[2],
            ]
        };
        let (mut s, mut e, mut r) = (vec![], vec![], vec![]);
        for step in 0..steps {
            let t = step as f64 * 1e-3;
            for k in 0..edges {
                let (a, b) = (node(k, t), node(k + 1, t));
                let (a, b) = if g.next() < 0.3 { (b, a) } else { (a, b) };
                let b = if g.next() < 0.02 { a } else { b };
                s.push(a);
                e.push(b);
                r.push(0.005 + 0.001 * g.next());
            }
        }
        (s, e, r)
    }

    #[test]
    fn many_nearly_coincident_capsules_equal_brute_force() {
        // 2000 capsules, hundreds over every brick: the per-voxel hierarchy queries.
        let (s, e, r) = swept_edges(4, 500, 11);
        let caps = Capsules::new(&s, &e, &r).unwrap();
        let h = 0.002;
        let grid = Grid {
            origin: [-0.012, -0.012, -0.032],
            spacing: h,
            shape: [38, 24, 24],
        };
        let band = 3.0 * h;
        let field = signed_distance(&caps, &grid, band).unwrap();
        let [nx, ny, nz] = grid.shape;
        let mut inside_band = 0;
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let p = [i, j, k].map(|x| x as f64);
                    let p = [0, 1, 2].map(|a| grid.origin[a] + h * p[a]);
                    let exact = brute(&s, &e, &r, p);
                    let want = exact.clamp(-band, band) as f32;
                    let got = field[(i * ny + j) * nz + k];
                    assert_eq!(got, want, "voxel {i},{j},{k}");
                    inside_band += (exact.abs() < band) as usize;
                }
            }
        }
        assert!(inside_band > 3000, "{inside_band}");
        let mut g = Lcg(5);
        for _ in 0..3000 {
            let p = g.vec(0.07);
            let p = [p[0] - 0.01, p[1] - 0.015, p[2] - 0.045];
            assert!((caps.distance(p) - brute(&s, &e, &r, p)).abs() < 1e-12);
        }
    }

    #[test]
    fn degenerate_capsule_is_a_ball_and_empty_set_is_far() {
        let caps = Capsules::new(&[[0.0; 3]], &[[0.0; 3]], &[0.5]).unwrap();
        assert!((caps.distance([2.0, 0.0, 0.0]) - 1.5).abs() < 1e-15);
        let none = Capsules::new(&[], &[], &[]).unwrap();
        assert!(none.distance([0.0; 3]).is_infinite());
    }

    #[test]
    fn bad_input_names_the_argument() {
        let err = Capsules::new(&[[0.0; 3]], &[[0.0; 3]], &[-1.0]).unwrap_err();
        assert!(err.0.contains("radius[0] = -1"), "{}", err.0);
        let caps = Capsules::new(&[[0.0; 3]], &[[0.0; 3]], &[1.0]).unwrap();
        let grid = Grid {
            origin: [0.0; 3],
            spacing: 0.0,
            shape: [1, 1, 1],
        };
        assert!(signed_distance(&caps, &grid, 1.0)
            .unwrap_err()
            .0
            .contains("spacing"));
    }
}

//! Harness tests against the single continuous cable, symmetry and equilibrium of a Y, and
//! the coupled Jacobian and tree solve against finite differences and the assembled system.
use super::*;
use crate::model::{CableSpec, ClipSpec, PointLoad, Section};
use crate::rotation::frame_quaternion;
use crate::routing::route;
use crate::statics::NewtonOptions;

pub(crate) fn section() -> Section {
    Section {
        shear_stiffness: Vector3::new(2e4, 2e4, 5e4),
        bend_stiffness: Vector3::new(0.02, 0.02, 0.015),
        mass_per_length: 0.1,
        rotary_inertia: Vector3::new(1e-6, 1e-6, 2e-6),
    }
}

pub(crate) fn frame(t: &Vector3<f64>) -> Quat {
    let n = if t.z.abs() < 0.9 {
        Vector3::z()
    } else {
        Vector3::x()
    };
    frame_quaternion(t, &n).unwrap()
}

/// A straight cable from a to b with fixed point clips at both ends (named "a" and "b"),
/// shared by the harness statics, dynamics and modal tests.
pub(crate) fn straight_with(
    a: [f64; 3],
    b: [f64; 3],
    n: usize,
    section: Section,
    loads: Vec<PointLoad>,
    gravity: Vector3<f64>,
) -> Rod {
    let (a, b) = (Vector3::from(a), Vector3::from(b));
    let l = (b - a).norm();
    let q = frame(&((b - a) / l));
    let clip = |name: &str, s: f64, p: Vector3<f64>| ClipSpec {
        name: name.into(),
        s,
        length: 0.0,
        kind: ClipKind::Fixed,
        pose: Pose {
            position: p,
            orientation: q,
        },
    };
    Rod::new(CableSpec {
        length: l,
        segments: n,
        section,
        natural_curvature: Vector3::zeros(),
        clips: vec![clip("a", 0.0, a), clip("b", l, b)],
        loads,
        gravity,
    })
    .unwrap()
}

/// A straight cable from a to b with fixed point clips at both ends (named "a" and "b").
fn straight(a: [f64; 3], b: [f64; 3], n: usize, loads: Vec<PointLoad>, g: f64) -> Rod {
    straight_with(a, b, n, section(), loads, Vector3::new(0.0, 0.0, -g))
}

fn junction(name: &str, mass: f64, ends: Vec<(usize, usize)>) -> JunctionSpec {
    JunctionSpec {
        name: name.into(),
        mass,
        rotary_inertia: Vector3::new(1e-5, 1e-5, 1e-5),
        ends,
    }
}

fn initial(h: &Harness) -> HarnessState {
    let mut st = HarnessState {
        cables: h.cables.iter().map(|r| route(r, None).unwrap()).collect(),
        junctions: h.reference.clone(),
    };
    st.sync_ends(h);
    st
}

fn names(n: usize) -> Vec<String> {
    (0..n).map(|i| format!("c{i}")).collect()
}

/// Two collinear cables, clamped at the far ends and joined at x = 0.5, under gravity and a
/// lateral point load on the second: the junction's position.
fn joined_pair(n: usize) -> (Vector3<f64>, usize) {
    let lateral = vec![PointLoad {
        s: 0.25,
        force: Vector3::new(0.0, 0.3, 0.0),
        moment: Vector3::zeros(),
    }];
    let a = straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], n, vec![], 9.81);
    let b = straight([0.5, 0.0, 0.0], [1.0, 0.0, 0.0], n, lateral, 9.81);
    let h = Harness::new(
        names(2),
        vec![a, b],
        vec![junction("j", 0.0, vec![(0, 1), (1, 0)])],
    )
    .unwrap();
    let mut st = initial(&h);
    let mut solver = HarnessStatics::new(&h, NewtonOptions::default());
    let stats = solver.solve_static(&h, &mut st).unwrap();
    (st.junctions[0].position, stats.iterations)
}

/// The single continuous cable of the same problem: its point at s = 0.5.
fn single(n: usize) -> Vector3<f64> {
    let lateral = vec![PointLoad {
        s: 0.75,
        force: Vector3::new(0.0, 0.3, 0.0),
        moment: Vector3::zeros(),
    }];
    let rod = straight([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], n, lateral, 9.81);
    let mut st = route(&rod, None).unwrap();
    let mut s = crate::Statics::new(&rod, NewtonOptions::default());
    s.solve(&rod, &mut st).unwrap();
    let k = rod
        .arc
        .iter()
        .position(|a| (a - 0.5).abs() < 1e-12)
        .unwrap();
    st.x[k]
}

#[test]
fn collinear_pair_converges_with_second_order_to_the_single_cable() {
    let reference = single(1024);
    let mut errors = Vec::new();
    for n in [32, 64, 128] {
        let (xj, _) = joined_pair(n);
        errors.push((xj - reference).norm());
    }
    eprintln!("junction errors {errors:?}");
    // Sag and lateral deflection held by the membrane tension (geometrically nonlinear).
    assert!(reference.z < -0.005 && reference.y > 0.001, "{reference:?}");
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.3).contains(&order), "errors {errors:?}");
    }
}

/// A Y: the trunk along −x from a clamp to the junction at the origin, two branches at ±30°
/// to clamps, gravity, a junction mass.
fn y_harness(n: usize, mass: f64) -> Harness {
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let trunk = straight([-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], n, vec![], 9.81);
    let a = straight([0.0, 0.0, 0.0], [0.4 * c, 0.4 * s, 0.0], n, vec![], 9.81);
    let b = straight([0.0, 0.0, 0.0], [0.4 * c, -0.4 * s, 0.0], n, vec![], 9.81);
    Harness::new(
        names(3),
        vec![trunk, a, b],
        vec![junction("y", mass, vec![(0, 1), (1, 0), (2, 0)])],
    )
    .unwrap()
}

#[test]
fn symmetric_y_has_mirrored_branch_loads_and_a_junction_in_equilibrium() {
    let h = y_harness(20, 0.05);
    let mut st = initial(&h);
    let mut solver = HarnessStatics::new(&h, NewtonOptions::default());
    solver.solve_static(&h, &mut st).unwrap();
    // Two more Newton iterations take the residual to round-off.
    solver.opts.residual_tolerance = 0.0;
    solver.opts.step_tolerance = 1e-15;
    solver.opts.max_iterations = 2;
    let _ = solver.newton(&h, &mut st, 1.0, false);
    solver.assemble(&h, &st, 1.0, false).unwrap();
    let loads = solver.branch_loads(&h, &st);
    let (fa, ma) = loads[1];
    let (fb, mb) = loads[2];
    let scale = fa.norm().max(loads[0].0.norm());
    assert!(scale > 0.1, "{loads:?}");
    let mirror = |v: Vector3<f64>| Vector3::new(v.x, -v.y, v.z);
    assert!((fb - mirror(fa)).norm() < 1e-9 * scale, "{fa:?} {fb:?}");
    // Moments are pseudo-vectors: mirrored and negated.
    let mscale = ma.norm().max(1e-3);
    assert!((mb + mirror(ma)).norm() < 1e-9 * mscale, "{ma:?} {mb:?}");
    // The junction's own equilibrium: branch loads plus its weight.
    let x = st.junctions[0].position;
    let weight = Vector3::new(0.0, 0.0, -9.81 * 0.05);
    let sum_f: Vector3<f64> = loads.iter().map(|l| l.0).sum::<Vector3<f64>>() + weight;
    let sum_m: Vector3<f64> = loads.iter().map(|l| l.1).sum();
    // Round-off of the section forces: ε·EA per element (the strain is a difference of
    // numbers of order 1), moments the same times a segment length (0.025 m).
    let floor = 100.0 * f64::EPSILON * section().shear_stiffness.z;
    assert!(
        sum_f.norm() < floor,
        "ΣF = {sum_f:?} (round-off floor {floor:e})"
    );
    assert!(sum_m.norm() < floor * 0.025, "ΣM = {sum_m:?}");
    assert!(x.y.abs() < 1e-12 && x.z < -1e-3, "{x:?}");
}

/// Two junctions joined by a cable (a link of the tree) with two more branches each.
fn two_junctions(n: usize) -> Harness {
    let c0 = straight([-0.4, 0.0, 0.0], [0.0, 0.0, 0.0], n, vec![], 9.81);
    let mid = straight([0.0, 0.0, 0.0], [0.3, 0.05, 0.0], n, vec![], 9.81);
    let c2 = straight([0.0, 0.0, 0.0], [0.1, -0.3, 0.1], n, vec![], 9.81);
    let c3 = straight([0.3, 0.05, 0.0], [0.6, 0.2, 0.0], n, vec![], 9.81);
    let c4 = straight([0.6, -0.3, 0.1], [0.3, 0.05, 0.0], n, vec![], 9.81);
    Harness::new(
        names(5),
        vec![c0, mid, c2, c3, c4],
        vec![
            junction("j1", 0.02, vec![(0, 1), (1, 0), (2, 0)]),
            junction("j2", 0.0, vec![(1, 1), (3, 0), (4, 1)]),
        ],
    )
    .unwrap()
}

/// A deterministic pseudo-random number in [−1, 1].
pub(crate) fn rnd(k: &mut u64) -> f64 {
    *k = k
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*k >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A perturbed state of `h` and a random direction over every unknown.
type Blocks = Vec<Vec<Vector6<f64>>>;

fn perturbed(h: &Harness) -> (HarnessState, Blocks, Vec<Vector6<f64>>) {
    let mut k = 7u64;
    let mut st = initial(h);
    fn rand_dir(rod: &Rod, k: &mut u64) -> Vec<Vector6<f64>> {
        rod.mask
            .iter()
            .map(|m| Vector6::from_fn(|i, _| if m[i] { rnd(k) } else { 0.0 }))
            .collect()
    }
    let d: Vec<Vec<Vector6<f64>>> = h.cables.iter().map(|r| rand_dir(r, &mut k)).collect();
    let dj: Vec<Vector6<f64>> = h
        .junctions
        .iter()
        .map(|_| Vector6::from_fn(|_, _| rnd(&mut k)))
        .collect();
    st.apply_increment(h, &d, &dj, 0.02);
    let v: Vec<Vec<Vector6<f64>>> = h.cables.iter().map(|r| rand_dir(r, &mut k)).collect();
    let vj = h
        .junctions
        .iter()
        .map(|_| Vector6::from_fn(|_, _| rnd(&mut k)))
        .collect();
    (st, v, vj)
}

fn residual(
    s: &mut HarnessStatics,
    h: &Harness,
    st: &HarnessState,
) -> (Vec<Vec<Vector6<f64>>>, Vec<Vector6<f64>>) {
    s.assemble(h, st, 1.0, false).unwrap();
    (
        s.ws.iter().map(|w| w.rhs.clone()).collect(),
        s.junction_residual.clone(),
    )
}

#[test]
fn coupled_jacobian_matches_finite_differences() {
    let h = two_junctions(6);
    let (st, v, vj) = perturbed(&h);
    let mut s = HarnessStatics::new(&h, NewtonOptions::default());
    s.assemble(&h, &st, 1.0, true).unwrap();
    let (jv, jvj) = s.jacobian_times(&h, &v, &vj);
    let eps = 1e-6;
    let mut plus = st.clone();
    plus.apply_increment(&h, &v, &vj, eps);
    let mut minus = st.clone();
    minus.apply_increment(&h, &v, &vj, -eps);
    let (rp, rpj) = residual(&mut s, &h, &plus);
    let (rm, rmj) = residual(&mut s, &h, &minus);
    let scale = jv
        .iter()
        .flatten()
        .chain(&jvj)
        .map(|x| x.amax())
        .fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for c in 0..h.cables.len() {
        for b in 0..jv[c].len() {
            let fd = (rp[c][b] - rm[c][b]) / (2.0 * eps);
            worst = worst.max((fd - jv[c][b]).amax());
        }
    }
    for j in 0..h.junctions.len() {
        let fd = (rpj[j] - rmj[j]) / (2.0 * eps);
        worst = worst.max((fd - jvj[j]).amax());
    }
    assert!(worst < 1e-6 * scale, "worst {worst:e} scale {scale:e}");
    // Position and rotation rows separately (rotation rows are small against EA terms).
    for half in 0..2 {
        let rows = |v: &Vector6<f64>| v.fixed_rows::<3>(3 * half).amax();
        let scale = jv
            .iter()
            .flatten()
            .chain(&jvj)
            .map(rows)
            .fold(0.0, f64::max);
        let mut worst = 0.0f64;
        for c in 0..h.cables.len() {
            for b in 0..jv[c].len() {
                let fd = (rp[c][b] - rm[c][b]) / (2.0 * eps);
                worst = worst.max(rows(&(fd - jv[c][b])));
            }
        }
        for j in 0..h.junctions.len() {
            let fd = (rpj[j] - rmj[j]) / (2.0 * eps);
            let e = rows(&(fd - jvj[j]));
            eprintln!("junction {j} half {half}: err {e:e} of {:e}", rows(&jvj[j]));
            worst = worst.max(e);
        }
        assert!(
            worst < 1e-6 * scale,
            "half {half}: worst {worst:e} scale {scale:e}"
        );
    }
    // The junction rows alone are checked too (they are a small part of the vector).
    let jscale = jvj.iter().map(|x| x.amax()).fold(0.0, f64::max);
    for j in 0..h.junctions.len() {
        let fd = (rpj[j] - rmj[j]) / (2.0 * eps);
        assert!(
            (fd - jvj[j]).amax() < 1e-6 * jscale,
            "junction {j}: {fd:?} {:?}",
            jvj[j]
        );
    }
}

/// The tree elimination solves J Δ = −r, both ways: with a branch whose only junction end is
/// eliminated last (its Schur complement from the last two blocks, ends at a cable's start and
/// at its end) and with the A⁻¹ B columns of every end; the two agree to round-off.
#[test]
fn tree_elimination_solves_the_coupled_system() {
    // As built, and with a fixed clip in the middle of the link between the junctions: its two
    // segments are then branches too (one joined at its start, one at its end).
    tree_elimination_both_ways(&two_junctions(7), (4, 2));
    let mut h = two_junctions(7);
    let mut spec = h.cables[1].spec.clone();
    let (a, b) = (&spec.clips[0].pose, &spec.clips[1].pose);
    let middle = ClipSpec {
        name: "m".into(),
        s: 0.5 * spec.length,
        length: 0.0,
        kind: ClipKind::Fixed,
        pose: Pose {
            position: 0.5 * (a.position + b.position),
            orientation: a.orientation,
        },
    };
    spec.clips.push(middle); // after the ends: the junctions name the ends by index
    h.cables[1] = Rod::new(spec).unwrap();
    let h = Harness::new(names(5), h.cables.clone(), h.junctions.clone()).unwrap();
    tree_elimination_both_ways(&h, (6, 3));
}

/// The tree solve with and without the tail path for branches; `tails`: (ends on it, of
/// them at a cable's start).
fn tree_elimination_both_ways(h: &Harness, tails: (usize, usize)) {
    let h = h.clone();
    let (st, _, _) = perturbed(&h);
    let mut corrections = Vec::new();
    for tail in [true, false] {
        let mut s = HarnessStatics::new(&h, NewtonOptions::default());
        s.tail_path = tail;
        s.assemble(&h, &st, 1.0, true).unwrap();
        let (r, rj) = (
            s.ws.iter().map(|w| w.rhs.clone()).collect::<Vec<_>>(),
            s.junction_residual.clone(),
        );
        // J is read before factoring (the factorisation keeps the blocks it reads).
        let jac: Vec<_> = s.ws.iter().map(|w| w.jac.clone()).collect();
        s.factor(&h).unwrap();
        // Tail path: the four branches with one junction end (two at their start, two at
        // their end); the link between the junctions keeps its columns.
        let on_tail: Vec<bool> = (0..h.ends.len()).map(|k| s.on_tail(&h, k)).collect();
        let starts = (0..h.ends.len()).filter(|&k| on_tail[k] && h.ends[k].topo.at_start);
        assert_eq!(
            (on_tail.iter().filter(|&&t| t).count(), starts.count()),
            if tail { tails } else { (0, 0) }
        );
        s.newton_correction(&h);
        let (d, dj) = s.correction();
        let (d, dj) = (d.to_vec(), dj.to_vec());
        for (w, j) in s.ws.iter_mut().zip(jac) {
            w.jac = j;
        }
        let (jd, jdj) = s.jacobian_times(&h, &d, &dj);
        let scale = r
            .iter()
            .flatten()
            .chain(&rj)
            .map(|x| x.amax())
            .fold(0.0, f64::max);
        for c in 0..h.cables.len() {
            for b in 0..r[c].len() {
                assert!(
                    (jd[c][b] + r[c][b]).amax() < 1e-9 * scale,
                    "tail {tail}: cable {c} block {b}"
                );
            }
        }
        for j in 0..h.junctions.len() {
            assert!(
                (jdj[j] + rj[j]).amax() < 1e-9 * scale,
                "tail {tail}: junction {j}"
            );
        }
        corrections.push((d, dj));
    }
    let ((d1, j1), (d0, j0)) = (&corrections[0], &corrections[1]);
    let size = |v: &Vector6<f64>| v.amax();
    let scale = d0.iter().flatten().chain(j0).map(size).fold(0.0, f64::max);
    for (a, b) in d1
        .iter()
        .flatten()
        .zip(d0.iter().flatten())
        .chain(j1.iter().zip(j0))
    {
        assert!((a - b).amax() < 1e-12 * scale, "{a:?} vs {b:?}");
    }
}

#[test]
fn two_junction_harness_solves_statics_and_a_quasistatic_step() {
    let h = two_junctions(20);
    let mut st = initial(&h);
    let mut s = HarnessStatics::new(&h, NewtonOptions::default());
    let stats = s.solve_static(&h, &mut st).unwrap();
    assert_eq!(stats.substeps, 0);
    assert!(stats.iterations <= 12, "{stats:?}");
    // A quasistatic step: the far clamp of cable 3 moves by 2 cm.
    let mut target: Vec<Vec<Pose>> = st.cables.iter().map(|c| c.clip_pose.clone()).collect();
    target[3][1].position += Vector3::new(0.0, 0.02, 0.0);
    let before = st.junctions[1].position;
    s.step_to(&h, &mut st, &target).unwrap();
    assert!((st.junctions[1].position - before).norm() > 1e-4);
    assert!((st.cables[3].x.last().unwrap() - target[3][1].position).norm() < 1e-14);
}

#[test]
fn loops_and_bad_ends_are_named() {
    let a = straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], 4, vec![], 9.81);
    let b = straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], 4, vec![], 9.81);
    let e = Harness::new(
        vec!["a".into(), "b".into()],
        vec![a.clone(), b.clone()],
        vec![
            junction("j1", 0.0, vec![(0, 0), (1, 0)]),
            junction("j2", 0.0, vec![(0, 1), (1, 1)]),
        ],
    )
    .unwrap_err();
    assert!(
        e.0.contains("loop") && e.0.contains("not supported yet"),
        "{e}"
    );
    let e = Harness::new(
        vec!["a".into(), "b".into()],
        vec![a.clone(), b.clone()],
        vec![
            junction("j1", 0.0, vec![(0, 0), (1, 0)]),
            junction("j2", 0.0, vec![(0, 0)]),
        ],
    )
    .unwrap_err();
    assert!(
        e.0.contains("cable 'a'") && e.0.contains("joined twice"),
        "{e}"
    );
    let e = Harness::new(
        vec!["a".into(), "b".into()],
        vec![a, b],
        vec![junction("j1", 0.0, vec![(0, 1), (1, 0)])],
    )
    .unwrap_err();
    assert!(e.0.contains("not at the junction"), "{e}");
}

/// The internal force of edge e, global.
fn edge_force_global(ws: &crate::assembly::Workspace, st: &State, e: usize) -> Vector3<f64> {
    rotation_matrix(&st.p[e]) * ws.edge_force[e]
}

/// A weightless Y whose branch c1 runs through a frictionless sliding guide at its middle.
fn y_with_guide(n: usize) -> Harness {
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let trunk = straight([-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], n, vec![], 0.0);
    let mut a = straight([0.0, 0.0, 0.0], [0.4 * c, 0.4 * s, 0.0], n, vec![], 0.0);
    let b = straight([0.0, 0.0, 0.0], [0.4 * c, -0.4 * s, 0.0], n, vec![], 0.0);
    let mut spec = a.spec.clone();
    let q = spec.clips[0].pose.orientation;
    spec.clips.push(ClipSpec {
        name: "guide".into(),
        s: 0.2,
        length: 0.05,
        kind: ClipKind::Sliding { friction: 0.0 },
        pose: Pose {
            position: Vector3::new(0.2 * c, 0.2 * s, 0.0),
            orientation: q,
        },
    });
    a = Rod::new(spec).unwrap();
    Harness::new(
        names(3),
        vec![trunk, a, b],
        vec![junction("y", 0.0, vec![(0, 1), (1, 0), (2, 0)])],
    )
    .unwrap()
}

#[test]
fn frictionless_guide_on_a_branch_passes_the_tension_and_lets_it_slide() {
    let n = 40;
    let h = y_with_guide(n);
    let mut st = initial(&h);
    let mut solver = HarnessStatics::new(&h, NewtonOptions::default());
    solver.solve_static(&h, &mut st).unwrap();
    // Pull branch c2's far clamp outwards and push the guide 2 cm sideways: the branch bends
    // through the guide and slides.
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let mut target: Vec<Vec<Pose>> = st.cables.iter().map(|x| x.clip_pose.clone()).collect();
    target[2][1].position += 0.02 * Vector3::new(c, -s, 0.0);
    target[1][2].position += Vector3::new(0.0, 0.0, 0.02);
    solver.step_to(&h, &mut st, &target).unwrap();
    solver.opts.residual_tolerance = 0.0;
    solver.opts.step_tolerance = 1e-15;
    solver.opts.max_iterations = 2;
    let _ = solver.newton(&h, &mut st, 1.0, false);
    solver.assemble(&h, &st, 1.0, false).unwrap();
    let sl = solver.sliding[1].as_ref().unwrap();
    let slid = sl.sigma[0] - 0.2;
    assert!(slid.abs() > 1e-4, "slid {slid}");
    let ws = &solver.ws[1];
    let t = rotation_matrix(&st.cables[1].clip_pose[2].orientation) * Vector3::z();
    // Edges well outside the guide's window (0.17 … 0.23 m of 0.4 m): before and after.
    let (before, after) = (
        edge_force_global(ws, &st.cables[1], n / 4),
        edge_force_global(ws, &st.cables[1], 3 * n / 4),
    );
    let tension = t.dot(&before);
    assert!(tension > 1.0, "tension {tension} N");
    assert!(
        (t.dot(&after) - tension).abs() < 1e-9 * tension,
        "axial force {tension} before, {} after the guide",
        t.dot(&after)
    );
    // The guide's reaction is the jump of the internal force, across the line only.
    let (f, _) = sl.reaction[0];
    assert!(f.norm() > 0.01 * tension, "{f:?}");
    assert!((f - (before - after)).norm() < 1e-9 * tension, "{f:?}");
    assert!(t.dot(&f).abs() < 1e-9 * tension, "{f:?}");
}

#[test]
fn junction_held_by_a_clip_follows_it_and_the_reactions_balance() {
    let mut h = y_harness(20, 0.05);
    h.hold_junction(0).unwrap();
    let mut st = initial(&h);
    let mut solver = HarnessStatics::new(&h, NewtonOptions::default());
    let mut target: Vec<Vec<Pose>> = st.cables.iter().map(|x| x.clip_pose.clone()).collect();
    // The junction's clip (given as the pose of its first end's clip, cable 0's end b):
    // moved and turned about a skew axis.
    let turn =
        nalgebra::UnitQuaternion::from_scaled_axis(Vector3::new(0.05, -0.1, 0.15)).into_inner();
    let same = |a: &Quat, b: &Quat| (rotation_matrix(a) - rotation_matrix(b)).norm();
    let pose = Pose {
        position: Vector3::new(0.01, 0.02, -0.03),
        orientation: turn * st.cables[0].clip_pose[1].orientation,
    };
    target[0][1] = pose;
    st.set_clip_poses(&h, &target);
    solver.solve_static(&h, &mut st).unwrap();
    solver.opts.residual_tolerance = 0.0;
    solver.opts.step_tolerance = 1e-15;
    solver.opts.max_iterations = 2;
    let _ = solver.newton(&h, &mut st, 1.0, false);
    solver.assemble(&h, &st, 1.0, false).unwrap();
    let j = st.junctions[0];
    assert!((j.position - pose.position).norm() < 1e-15);
    assert!(same(&(j.orientation * h.ends[0].relative), &pose.orientation) < 1e-12);
    assert!(same(&j.orientation, &turn) < 1e-12);
    // Whole harness: the junction clip's reaction, the far clamps' reactions and the weights.
    let (rf, rm) = solver.junction_reactions(&h, &st)[0];
    let mut sum_f = rf + Vector3::new(0.0, 0.0, -9.81 * 0.05);
    let mut sum_m = rm + j.position.cross(&sum_f);
    for (c, rod) in h.cables.iter().enumerate() {
        let far = if c == 0 { 0 } else { 1 };
        let cs = &st.cables[c];
        let (f, m) = solver.ws[c].clip_reaction(rod, cs, far);
        sum_f += f;
        sum_m += m + cs.clip_pose[far].position.cross(&f);
        for (k, x) in cs.x.iter().enumerate() {
            let w = rod.ds_node[k] * rod.spec.section.mass_per_length * rod.spec.gravity;
            sum_f += w;
            sum_m += x.cross(&w);
        }
    }
    let scale = rf.norm();
    assert!(scale > 0.1, "{rf:?}");
    assert!(sum_f.norm() < 1e-9 * scale, "ΣF = {sum_f:?}");
    assert!(sum_m.norm() < 1e-9 * scale, "ΣM = {sum_m:?}");
    // The junction's own balance: its reaction against the branch loads and its weight.
    let loads = solver.branch_loads(&h, &st);
    let f_j: Vector3<f64> =
        loads.iter().map(|l| l.0).sum::<Vector3<f64>>() + rf + Vector3::new(0.0, 0.0, -9.81 * 0.05);
    let m_j: Vector3<f64> = loads.iter().map(|l| l.1).sum::<Vector3<f64>>() + rm;
    assert!(f_j.norm() < 1e-9 * scale, "{f_j:?}");
    assert!(m_j.norm() < 1e-9 * scale, "{m_j:?}");
}

#[test]
fn a_branch_that_runs_out_of_its_guide_is_named() {
    let h = y_with_guide(20);
    let mut st = initial(&h);
    let mut solver = HarnessStatics::new(&h, NewtonOptions::default());
    solver.solve_static(&h, &mut st).unwrap();
    // The guide moves along its line beyond the branch's far end.
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let mut target: Vec<Vec<Pose>> = st.cables.iter().map(|x| x.clip_pose.clone()).collect();
    target[1][2].position += 0.25 * Vector3::new(c, s, 0.0);
    let e = solver.step_to(&h, &mut st, &target).unwrap_err();
    assert!(
        e.0.contains("cable 'c1'") && e.0.contains("ran out of sliding clip 'guide'"),
        "{e}"
    );
}

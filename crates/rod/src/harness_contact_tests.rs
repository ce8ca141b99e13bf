//! Harness contact against the single continuous cable: two collinear cables joined by a
//! junction that lies on the table are the single cable's discrete model (contact included),
//! so they must reach its equilibrium; and the harness Jacobian with contact at a joined end
//! against finite differences.
use super::*;
use crate::contact::{Contact, ContactOptions, Obstacle, Plane};
use crate::harness::tests::{rnd, section, straight_with};
use crate::harness::JunctionSpec;
use crate::model::{Pose, Rod};
use crate::rotation::Quat;
use crate::routing::route;
use crate::statics::{NewtonOptions, Statics};
use nalgebra::Vector6;

pub(crate) const R: f64 = 0.005;

pub(crate) fn table(rod: &Rod) -> Contact {
    let origin = Pose {
        position: Vector3::zeros(),
        orientation: Quat::identity(),
    };
    let plane = Obstacle::new("table", 0, Box::new(Plane), 0.0, &origin);
    Contact::new(rod, vec![plane], ContactOptions::for_radius(R), 1).unwrap()
}

fn cable(a: f64, b: f64, z: f64, n: usize) -> Rod {
    let g = Vector3::new(0.0, 0.0, -9.81);
    straight_with([a, 0.0, z], [b, 0.0, z], n, section(), vec![], g)
}

/// The pair (junction at x = `split`) and the single cable, both clamped at x = 0 and 1 at
/// height z₀ just above the table, sagging onto it under gravity.
fn pair_and_single(split: f64, n: usize) -> (Harness, HarnessState, Rod, crate::State) {
    let z0 = 1.005 * R;
    let a = cable(0.0, split, z0, n);
    let b = cable(split, 1.0, z0, n);
    let j = JunctionSpec {
        name: "j".into(),
        mass: 0.0,
        rotary_inertia: Vector3::zeros(),
        ends: vec![(0, 1), (1, 0)],
    };
    let h = Harness::new(vec!["a".into(), "b".into()], vec![a, b], vec![j]).unwrap();
    let mut st = HarnessState {
        cables: h.cables.iter().map(|r| route(r, None).unwrap()).collect(),
        junctions: h.reference.clone(),
    };
    st.sync_ends(&h);
    let single = cable(0.0, 1.0, z0, 2 * n);
    let st1 = route(&single, None).unwrap();
    (h, st, single, st1)
}

#[test]
fn joined_pair_on_a_table_equals_the_single_cable() {
    let n = 20;
    let (h, mut st, single, mut st1) = pair_and_single(0.5, n);
    let mut s1 = Statics::new(&single, NewtonOptions::default());
    s1.contact = Some(table(&single));
    s1.solve(&single, &mut st1).unwrap();
    let mut hs = HarnessStatics::new(&h, NewtonOptions::default());
    for (slot, rod) in hs.contact.iter_mut().zip(&h.cables) {
        *slot = Some(table(rod));
    }
    let stats = hs.solve_static(&h, &mut st).unwrap();
    // The junction (the single cable's node n) lies on the table.
    let xj = st.junctions[0].position;
    assert!((xj.z - R).abs() < 0.01 * R, "junction at z = {}", xj.z);
    let mut worst = 0.0f64;
    for k in 0..=n {
        worst = worst.max((st.cables[0].x[k] - st1.x[k]).norm());
        worst = worst.max((st.cables[1].x[k] - st1.x[n + k]).norm());
    }
    assert!(
        worst < 1e-9,
        "positions differ by {worst} m ({} iterations)",
        stats.iterations
    );
    // Contact forces: each cable's node forces are the single cable's, the junction node's
    // split between the two ends.
    hs.assemble(&h, &st, 1.0, false).unwrap();
    s1.assemble(&single, &st1, 1.0, false).unwrap();
    let f1 = &s1.contact.as_ref().unwrap().normal_force;
    let fa = &hs.contact[0].as_ref().unwrap().normal_force;
    let fb = &hs.contact[1].as_ref().unwrap().normal_force;
    let scale = f1.iter().map(|f| f.norm()).fold(0.0, f64::max);
    for k in 0..n {
        assert!((fa[k] - f1[k]).norm() < 1e-8 * scale, "node {k}");
        assert!(
            (fb[k + 1] - f1[n + k + 1]).norm() < 1e-8 * scale,
            "node {}",
            n + k + 1
        );
    }
    assert!((fa[n] + fb[0] - f1[n]).norm() < 1e-8 * scale);
    assert!(
        f1[n].z > 0.1 * scale,
        "the junction's node carries weight: {}",
        f1[n].z
    );
}

/// The harness Jacobian at the pair's equilibrium on the table (the junction's node inside the
/// barrier's reach, friction on) against central differences of the residual along a random
/// direction of every unknown: the contact entries at the joined ends' node reach the
/// junction rows and the couplings to the cables.
#[test]
fn jacobian_with_contact_at_a_joined_end_matches_finite_differences() {
    let n = 8;
    let (h, mut st, _, _) = pair_and_single(0.5, n);
    let mut hs = HarnessStatics::new(&h, NewtonOptions::default());
    for (slot, rod) in hs.contact.iter_mut().zip(&h.cables) {
        let mut c = table(rod);
        c.obstacles[0].friction = 0.4;
        *slot = Some(c);
    }
    hs.solve_static(&h, &mut st).unwrap();
    let mut k = 11u64;
    // The friction reference moved by a random increment, so that every node's slip is a
    // generic point of the smoothed Coulomb law (at the equilibrium the junction node's slip
    // sits on the law's C¹ joint, where central differences lose their second order).
    let random = |k: &mut u64| -> (Vec<Vec<Vector6<f64>>>, Vec<Vector6<f64>>) {
        let v = h
            .cables
            .iter()
            .map(|r| {
                r.mask
                    .iter()
                    .map(|m| Vector6::from_fn(|i, _| if m[i] { rnd(k) } else { 0.0 }))
                    .collect()
            })
            .collect();
        (v, vec![Vector6::from_fn(|_, _| rnd(k))])
    };
    let (d, dj) = random(&mut k);
    let mut reference = st.clone();
    reference.apply_increment(&h, &d, &dj, 3e-4);
    hs.begin_contact_step(&reference);
    let (v, vj) = random(&mut k);
    hs.assemble(&h, &st, 1.0, true).unwrap();
    let (jv, jvj) = hs.jacobian_times(&h, &v, &vj);
    // A step far below the barrier's length scale (the gap at the junction, ~1e-5 m); the
    // differences then agree to ~1e-9 (measured: 1.2e-9 at 1e-8, round-off grows below).
    let eps = 1e-8;
    let mut res = |sign: f64| {
        let mut s = st.clone();
        s.apply_increment(&h, &v, &vj, sign * eps);
        hs.assemble(&h, &s, 1.0, false).unwrap();
        let r: Vec<Vec<Vector6<f64>>> = hs.ws.iter().map(|w| w.rhs.clone()).collect();
        (r, hs.junction_residual.clone())
    };
    let (rp, rpj) = res(1.0);
    let (rm, rmj) = res(-1.0);
    let fdj = (rpj[0] - rmj[0]) / (2.0 * eps);
    assert!(
        (fdj - jvj[0]).amax() < 1e-7 * jvj[0].amax(),
        "junction: {fdj:?} vs {:?}",
        jvj[0]
    );
    let scale = jv.iter().flatten().map(|x| x.amax()).fold(0.0, f64::max);
    for c in 0..2 {
        for b in 0..jv[c].len() {
            let fd = (rp[c][b] - rm[c][b]) / (2.0 * eps);
            assert!((fd - jv[c][b]).amax() < 1e-7 * scale, "cable {c} block {b}");
        }
    }
}

/// A route through a pipe (a cylinder across the middle of the pair, axis horizontal, its top
/// 2 cm above the straight route: the pair without contact sags 2.4 cm into it, beyond the
/// barrier's reach): the harness static solve pushes every cable and the junction out over the
/// pipe (the single cable's push-out continuation over the tree; it fails without), the same
/// equilibrium as the single continuous cable's push-out (frictionless: one equilibrium).
#[test]
fn a_pair_routed_through_a_pipe_is_pushed_out_as_the_single_cable() {
    use crate::contact::Cylinder;
    let n = 20;
    let (h, mut st, single, mut st1) = pair_and_single(0.5, n);
    let radius = 0.05;
    let pipe = |rod: &Rod| {
        let pose = Pose {
            position: Vector3::new(0.5, 0.0, 0.01 - radius),
            orientation: crate::harness::tests::frame(&Vector3::y()),
        };
        let shape = Cylinder {
            radius,
            length: f64::INFINITY,
        };
        let o = Obstacle::new("pipe", 0, Box::new(shape), 0.0, &pose);
        Contact::new(rod, vec![o], ContactOptions::for_radius(R), 1).unwrap()
    };
    assert!(pipe(&single).penetrates(&single, &st1));
    let mut s1 = Statics::new(&single, NewtonOptions::default());
    s1.contact = Some(pipe(&single));
    s1.solve(&single, &mut st1).unwrap();
    let mut hs = HarnessStatics::new(&h, NewtonOptions::default());
    for (slot, rod) in hs.contact.iter_mut().zip(&h.cables) {
        *slot = Some(pipe(rod));
    }
    hs.solve_static(&h, &mut st).unwrap();
    let mut worst = 0.0f64;
    for k in 0..=n {
        worst = worst.max((st.cables[0].x[k] - st1.x[k]).norm());
        worst = worst.max((st.cables[1].x[k] - st1.x[n + k]).norm());
    }
    assert!(worst < 1e-7, "harness vs single cable: {worst} m");
    for (c, contact) in hs.contact.iter().enumerate() {
        let gap = contact.as_ref().unwrap().surface_gap(&st.cables[c]).0;
        assert!(gap > -0.01 * R, "cable {c}: gap {gap}");
    }
    // Over the pipe, not under it: the junction (the middle) lies on its top.
    let zj = st.junctions[0].position.z;
    assert!((zj - (0.01 + R)).abs() < 0.01 * R, "junction at z = {zj}");
}

//! Harness modal tests: the L-frame against its transcendental frequency equation (second
//! order in the mesh), two collinear cables against the single cable, and the tree inertia
//! against the eigenvalues of the dense assembled stiffness.
use super::*;
use crate::harness::JunctionSpec;
use crate::model::{Rod, Section};
use crate::routing::route;
use nalgebra::{DMatrix, Vector3};

const EI: f64 = 0.02;
const RHO_A: f64 = 0.1;

/// Stiff in shear and extension (GA L²/EI ~ 1e7) and with a tiny rotary inertia, so that the
/// discrete model converges to the Euler–Bernoulli frame.
fn section() -> Section {
    Section {
        shear_stiffness: Vector3::new(2e6, 2e6, 5e6),
        bend_stiffness: Vector3::new(EI, EI, 0.015),
        mass_per_length: RHO_A,
        rotary_inertia: Vector3::new(1e-12, 1e-12, 2e-12),
    }
}

/// A straight cable from a to b with fixed clips at both ends.
fn straight(a: [f64; 3], b: [f64; 3], n: usize) -> Rod {
    crate::harness::tests::straight_with(a, b, n, section(), vec![], Vector3::zeros())
}

fn harness(cables: Vec<Rod>, ends: Vec<(usize, usize)>) -> Harness {
    harness_with_inertia(cables, ends, 0.0)
}

/// One junction without mass, with an isotropic rotary inertia `j` (kg m²).
fn harness_with_inertia(cables: Vec<Rod>, ends: Vec<(usize, usize)>, j: f64) -> Harness {
    let names = (0..cables.len()).map(|i| format!("c{i}")).collect();
    let j = JunctionSpec {
        name: "j".into(),
        mass: 0.0,
        rotary_inertia: Vector3::new(j, j, j),
        ends,
    };
    Harness::new(names, cables, vec![j]).unwrap()
}

fn initial(h: &Harness) -> HarnessState {
    let mut st = HarnessState {
        cables: h.cables.iter().map(|r| route(r, None).unwrap()).collect(),
        junctions: h.reference.clone(),
    };
    st.sync_ends(h);
    st
}

/// Dynamic end stiffness (per EI) of a beam clamped at its far end, turned by a unit angle
/// at this end held against translation: β (cosh βL sin βL − sinh βL cos βL) / (1 − cosh βL
/// cos βL), returned as (numerator, denominator); → 4/L as β → 0.
fn end_stiffness(beta: f64, l: f64) -> (f64, f64) {
    let x = beta * l;
    (
        beta * (x.cosh() * x.sin() - x.sinh() * x.cos()),
        1.0 - x.cosh() * x.cos(),
    )
}

/// The first root β of the L-frame's in-plane frequency equation: two beams clamped at their
/// far ends, joined rigidly at a joint that does not translate (both beams axially rigid and
/// at right angles) with rotary inertia `j`, so the two end moments balance its inertia:
/// EI (S₁(β) + S₂(β)) = j ω², ω² = β⁴ EI/ρA, cleared of denominators:
/// N₁ D₂ + N₂ D₁ − (j β⁴/ρA) D₁ D₂ = 0. Bracketed by a scan, then bisection.
fn l_frame_beta(l1: f64, l2: f64, j: f64) -> f64 {
    let g = |b: f64| {
        let (n1, d1) = end_stiffness(b, l1);
        let (n2, d2) = end_stiffness(b, l2);
        n1 * d2 + n2 * d1 - j * b.powi(4) / RHO_A * d1 * d2
    };
    let mut a = 0.5;
    let step = 1e-3;
    while g(a) * g(a + step) > 0.0 {
        a += step;
    }
    let (mut lo, mut hi) = (a, a + step);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(lo) * g(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The lowest in-plane (x–y) mode's ω of the L-frame with `n` segments per beam.
fn l_frame_omega(n: usize, l1: f64, l2: f64, j: f64) -> f64 {
    let a = straight([-l1, 0.0, 0.0], [0.0, 0.0, 0.0], n);
    let b = straight([0.0, 0.0, 0.0], [0.0, l2, 0.0], n);
    let h = harness_with_inertia(vec![a, b], vec![(0, 1), (1, 0)], j);
    let st = initial(&h);
    let modes = harness_lowest_modes(&h, &st, 6).unwrap();
    let in_plane = |m: &HarnessMode| {
        let (mut z, mut all) = (0.0, 0.0);
        for v in m.cables.iter().flatten() {
            z += v[2] * v[2];
            all += v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        }
        z < 1e-12 * all
    };
    let first = modes
        .iter()
        .find(|m| in_plane(m))
        .expect("an in-plane mode");
    // The junction turns about z in the in-plane mode (it is not a clamped–pinned one).
    let jz = first.junctions[0];
    assert!(jz[5].abs() > 1e3 * jz[3].abs().max(jz[4].abs()), "{jz:?}");
    first.omega
}

#[test]
fn l_frame_matches_the_frequency_equation_with_second_order_convergence() {
    let (l1, l2) = (0.5, 0.3);
    let mut exacts = Vec::new();
    // Without and with a rotary inertia of the joint (it lowers ω by 5 %, 20× the error at 32
    // segments: the junction's inertia is in the pencil).
    for j in [0.0, 1e-4] {
        let beta = l_frame_beta(l1, l2, j);
        let exact = beta * beta * (EI / RHO_A).sqrt();
        exacts.push(exact);
        let omegas: Vec<f64> = [8, 16, 32]
            .iter()
            .map(|&n| l_frame_omega(n, l1, l2, j))
            .collect();
        let errors: Vec<f64> = omegas.iter().map(|w| (w - exact).abs() / exact).collect();
        // Richardson extrapolation of the two finest meshes removes the h² term.
        let richardson = ((4.0 * omegas[2] - omegas[1]) / 3.0 - exact).abs() / exact;
        eprintln!(
            "L-frame j = {j}: ω exact {exact}, relative errors {errors:?}, extrapolated \
             {richardson:e}"
        );
        for w in errors.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!((1.8..2.3).contains(&order), "j = {j}: errors {errors:?}");
        }
        assert!(
            richardson < 0.02 * errors[2],
            "j = {j}: {richardson} vs {errors:?}"
        );
    }
    // Without inertia: between the clamped–pinned roots of the two beams (3.9266 / L); the
    // joint's inertia lowers it.
    let (w0, wj) = (exacts[0], exacts[1]);
    let bound = |l: f64| (3.9266 / l).powi(2) * (EI / RHO_A).sqrt();
    assert!(bound(l1) < w0 && w0 < bound(l2), "ω = {w0}");
    assert!(wj < 0.97 * w0, "{wj} vs {w0}");
}

#[test]
fn collinear_pair_has_the_frequencies_of_the_single_cable() {
    let n = 20;
    let single = straight([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 2 * n);
    let st = route(&single, None).unwrap();
    let reference = crate::modal::lowest_modes(&single, &st, 8).unwrap();
    let a = straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], n);
    let b = straight([0.5, 0.0, 0.0], [1.0, 0.0, 0.0], n);
    let h = harness(vec![a, b], vec![(0, 1), (1, 0)]);
    let modes = harness_lowest_modes(&h, &initial(&h), 8).unwrap();
    for (m, r) in modes.iter().zip(&reference) {
        // The same discrete model: a massless junction rotation between two bending half
        // cells condenses to the single cable's full cell, and the junction carries the two
        // end nodes' masses. Agreement to the modal solver's convergence tolerance. (The
        // kinds are not compared: the two bending planes are degenerate, any mix is a mode.)
        assert!(
            (m.omega - r.omega).abs() < 1e-6 * r.omega,
            "harness {} single {}",
            m.omega,
            r.omega
        );
    }
    // The mass normalisation covers cables and junction: φᵀMφ = 1.
    let mut sys = ModalSystem::new(&h);
    sys.load(&h, &initial(&h)).unwrap();
    let p = HarnessPencil { h: &h, s: &mut sys };
    let flat: Vec<Vector6<f64>> = modes[0]
        .cables
        .iter()
        .flatten()
        .chain(&modes[0].junctions)
        .copied()
        .collect();
    assert!((p.mdot(&flat, &flat) - 1.0).abs() < 1e-12);
}

/// The collinear pair uniformly strained by `strain` (negative: compressed), an equilibrium.
fn strained_pair(n: usize, strain: f64) -> (Harness, HarnessState) {
    let a = straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], n);
    let b = straight([0.5, 0.0, 0.0], [1.0, 0.0, 0.0], n);
    let h = harness(vec![a, b], vec![(0, 1), (1, 0)]);
    let mut st = initial(&h);
    let f = 1.0 + strain;
    for c in &mut st.cables {
        c.x.iter_mut().for_each(|x| *x *= f);
        c.clip_pose.iter_mut().for_each(|p| p.position *= f);
    }
    st.junctions[0].position *= f;
    st.sync_ends(&h);
    (h, st)
}

/// Negative eigenvalues of the dense assembled symmetric stiffness over the active unknowns.
fn dense_negative_count(h: &Harness, st: &HarnessState) -> usize {
    dense_negative_count_with(h, st, &mut vec![None; h.cables.len()])
}

/// `dense_negative_count` with each cable's contact term in the stiffness.
fn dense_negative_count_with(
    h: &Harness,
    st: &HarnessState,
    contact: &mut Vec<Option<crate::contact::Contact>>,
) -> usize {
    let mut p = ModalSystem::new(h);
    p.load_with_contact(h, st, contact).unwrap();
    let mut slots = Vec::new(); // (cable or None for the junction, block, slot)
    for (c, rod) in h.cables.iter().enumerate() {
        for (b, m) in rod.mask.iter().enumerate() {
            for k in (0..6).filter(|&k| m[k]) {
                slots.push((Some(c), b, k));
            }
        }
    }
    for j in 0..h.junctions.len() {
        for k in 0..6 {
            slots.push((None, j, k));
        }
    }
    let n = slots.len();
    let mut dense = DMatrix::zeros(n, n);
    for (col, &(c, b, k)) in slots.iter().enumerate() {
        let mut v: Vec<Vec<Vector6<f64>>> = h
            .cables
            .iter()
            .map(|r| vec![Vector6::zeros(); r.arc.len()])
            .collect();
        let mut vj = vec![Vector6::zeros(); h.junctions.len()];
        match c {
            Some(c) => v[c][b][k] = 1.0,
            None => vj[b][k] = 1.0,
        }
        let (y, yj) = p.k.jacobian_times(h, &v, &vj);
        for (row, &(c, b, k)) in slots.iter().enumerate() {
            dense[(row, col)] = match c {
                Some(c) => y[c][b][k],
                None => yj[b][k],
            };
        }
    }
    let asym = (&dense - dense.transpose()).amax();
    assert!(asym < 1e-9 * dense.amax(), "not symmetric: {asym}");
    let eig = dense.symmetric_eigen().eigenvalues;
    let top = eig.amax();
    assert!(eig.iter().all(|l| l.abs() > 1e-12 * top), "singular: {eig}");
    eig.iter().filter(|&&l| l < 0.0).count()
}

#[test]
fn tree_inertia_counts_the_negative_eigenvalues_of_the_dense_stiffness() {
    // Euler load of the clamped 1 m pair 4π²EI/L² = 0.79 N; EA ε = 5 N at ε = −1e-6·5.
    for (strain, unstable) in [(0.0, false), (1e-5, false), (-1e-6, true)] {
        let (h, st) = strained_pair(6, strain);
        let dense = dense_negative_count(&h, &st);
        let tree = harness_negative_count(&h, &st).unwrap();
        assert_eq!(tree, dense, "strain {strain}");
        assert_eq!(tree > 0, unstable, "strain {strain}: {tree} negative");
    }
    // Beyond the first buckling loads of both planes: at least two negative directions.
    let (h, st) = strained_pair(6, -1e-6);
    assert!(harness_negative_count(&h, &st).unwrap() >= 2);
    // The modal analysis refuses the unstable equilibrium with a clear error.
    let e = harness_lowest_modes(&h, &st, 3).unwrap_err();
    assert!(e.0.contains("unstable"), "{e}");
}

/// The compressed pair (beyond its first buckling loads) lying on a table, every node inside the
/// barrier's reach: the tree inertia with the (frictionless) contact stiffness in K equals the
/// dense count, and contact removes the buckling modes that push into the table (those in the
/// table's plane stay).
#[test]
fn tree_inertia_with_contact_counts_the_dense_stiffness_with_contact() {
    use crate::contact::{Contact, ContactOptions, Obstacle, Plane};
    use crate::model::Pose;
    use crate::rotation::Quat;
    let r = 0.005;
    let (h, st) = strained_pair(6, -1e-6);
    let opts = ContactOptions::for_radius(r);
    let below = Pose {
        position: Vector3::new(0.0, 0.0, -r - 0.1 * opts.distance),
        orientation: Quat::identity(),
    };
    let mut contact: Vec<Option<Contact>> = h
        .cables
        .iter()
        .map(|rod| {
            let table = Obstacle::new("table", 0, Box::new(Plane), 0.0, &below);
            Some(Contact::new(rod, vec![table], opts.clone(), 1).unwrap())
        })
        .collect();
    let free = harness_negative_count(&h, &st).unwrap();
    let dense = dense_negative_count_with(&h, &st, &mut contact);
    let tree = ModalSystem::new(&h)
        .negative_count_with_contact(&h, &st, &mut contact)
        .unwrap();
    eprintln!("negative eigenvalues: {free} without contact, {tree} with");
    assert_eq!(tree, dense);
    assert!(
        tree >= 1 && tree < free,
        "with contact {tree}, without {free}"
    );
    // The solver's contact terms are handed back.
    assert!(contact.iter().all(Option::is_some));
}

/// The first root β of a clamped–clamped beam of length 2a with a point mass `mass` at its
/// middle (the junction), symmetric mode: each half is clamped at its far end and guided at
/// the middle (slope zero), the two halves' shear forces carry the mass: 2 EI β³ N/D = m ω²,
/// N = cosh x sin x + sinh x cos x, D = 1 − cosh x cos x, x = βa, ω² = β⁴ EI/ρA; cleared:
/// 2N − (m β/ρA) D = 0.
fn point_mass_beta(a: f64, mass: f64) -> f64 {
    let g = |b: f64| {
        let x = b * a;
        let n = x.cosh() * x.sin() + x.sinh() * x.cos();
        let d = 1.0 - x.cosh() * x.cos();
        2.0 * n - mass * b / RHO_A * d
    };
    let mut lo = 0.5;
    while g(lo) * g(lo + 1e-3) > 0.0 {
        lo += 1e-3;
    }
    let mut hi = lo + 1e-3;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(lo) * g(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn junction_mass_on_a_clamped_pair_matches_the_point_mass_beam() {
    // Without the mass: the clamped–clamped beam, β L = 4.7300.
    assert!((point_mass_beta(0.5, 0.0) - 4.730_040_7).abs() < 1e-6);
    let mass = 0.05; // half the beam's mass
    let beta = point_mass_beta(0.5, mass);
    let exact = beta * beta * (EI / RHO_A).sqrt();
    let clamped = 4.730_040_7f64.powi(2) * (EI / RHO_A).sqrt();
    assert!(exact < 0.8 * clamped, "{exact} vs {clamped}");
    let omegas: Vec<f64> = [8, 16, 32]
        .iter()
        .map(|&n| {
            let a = straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], n);
            let b = straight([0.5, 0.0, 0.0], [1.0, 0.0, 0.0], n);
            let names = vec!["a".to_string(), "b".to_string()];
            let j = JunctionSpec {
                name: "j".into(),
                mass,
                rotary_inertia: Vector3::zeros(),
                ends: vec![(0, 1), (1, 0)],
            };
            let h = Harness::new(names, vec![a, b], vec![j]).unwrap();
            harness_lowest_modes(&h, &initial(&h), 2).unwrap()[0].omega
        })
        .collect();
    let errors: Vec<f64> = omegas.iter().map(|w| (w - exact).abs() / exact).collect();
    let richardson = ((4.0 * omegas[2] - omegas[1]) / 3.0 - exact).abs() / exact;
    eprintln!("point mass: ω exact {exact}, errors {errors:?}, extrapolated {richardson:e}");
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.3).contains(&order), "errors {errors:?}");
    }
    assert!(richardson < 0.05 * errors[2], "{richardson} vs {errors:?}");
}

/// One retardation time τ on every stiffness of an unstressed harness makes the damping
/// matrix τK (the junction coupling is the cables' own end cells), so every mode is damped by
/// exactly ζ = τω/2 — in an L-frame whose junction turns and translates in the modes and
/// carries rotary inertia (mass only in M). Without the junction's motion in the held ends'
/// velocities the cells next to it would dissipate as if clamped (checked below).
#[test]
fn harness_damping_ratio_is_tau_omega_over_two_with_one_retardation_time() {
    // The bound is the mode shapes' accuracy: the subspace iteration stops at a relative
    // change of the Ritz values of 1e-11 per iteration, and its error is that change over
    // (1 − convergence ratio) — up to ~1e2 times it for the in-plane modes (measured ≤ 1.6e-9;
    // out-of-plane ≤ 2e-12). A moderately stiff section (GA L²/EI ≈ 1e5) keeps the
    // cancellation of the assembled shear and axial forces below that.
    let sec = Section {
        shear_stiffness: Vector3::new(1e4, 1e4, 2e4),
        bend_stiffness: Vector3::new(EI, EI, 0.015),
        mass_per_length: RHO_A,
        rotary_inertia: Vector3::new(1e-6, 1e-6, 2e-6),
    };
    let cable = |a, b, n| {
        crate::harness::tests::straight_with(a, b, n, sec.clone(), vec![], Vector3::zeros())
    };
    let a = cable([-0.5, 0.0, 0.0], [0.0, 0.0, 0.0], 16);
    let b = cable([0.0, 0.0, 0.0], [0.0, 0.3, 0.0], 12);
    let h = harness_with_inertia(vec![a, b], vec![(0, 1), (1, 0)], 1e-4);
    let st = initial(&h);
    let modes = harness_lowest_modes(&h, &st, 8).unwrap();
    let tau = vec![Vector3::repeat(3e-3); 2];
    let mut moving_junction = 0;
    for m in &modes {
        let zeta = harness_damping_ratio(&h, &st, m, &tau, &tau).unwrap();
        let exact = 0.5 * 3e-3 * m.omega;
        assert!(
            (zeta - exact).abs() < 1e-8 * exact,
            "ω {}: ζ {zeta} vs τω/2 {exact}",
            m.omega
        );
        // The same mode with the junction held still in the damping: not τω/2.
        let mut still = m.clone();
        if m.junctions[0].norm() > 1e-3 * m.cables.iter().flatten().map(|v| v.norm()).sum::<f64>() {
            moving_junction += 1;
            still.junctions[0] = Vector6::zeros();
            let wrong = harness_damping_ratio(&h, &st, &still, &tau, &tau).unwrap();
            assert!((wrong - exact).abs() > 1e-3 * exact, "{wrong} vs {exact}");
        }
    }
    assert!(
        moving_junction >= 4,
        "{moving_junction} modes move the junction"
    );
    // A wrong number of retardation times is an error naming the counts.
    let err = harness_damping_ratio(&h, &st, &modes[0], &tau[..1], &tau).unwrap_err();
    assert!(err.0.contains("2 cables"), "{}", err.0);
}

/// Two collinear cables joined by a massless junction are the single cable (same discrete
/// model): their modes have the single cable's damping ratios with retardation times that
/// differ per deformation (C not proportional to K: bending, torsion, extension and shear
/// each their own τ).
#[test]
fn collinear_pair_has_the_damping_ratios_of_the_single_cable() {
    use crate::modal::damping_ratio;
    let n = 20;
    let single = straight([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 2 * n);
    let st1 = route(&single, None).unwrap();
    let reference = crate::modal::lowest_modes(&single, &st1, 8).unwrap();
    let a = straight([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], n);
    let b = straight([0.5, 0.0, 0.0], [1.0, 0.0, 0.0], n);
    let h = harness(vec![a, b], vec![(0, 1), (1, 0)]);
    let st = initial(&h);
    let modes = harness_lowest_modes(&h, &st, 8).unwrap();
    let (shear, bend) = (
        Vector3::new(2e-3, 2e-3, 1e-4),
        Vector3::new(4e-3, 4e-3, 5e-4),
    );
    for (m, r) in modes.iter().zip(&reference) {
        let zeta = harness_damping_ratio(&h, &st, m, &[shear; 2], &[bend; 2]).unwrap();
        let exact = damping_ratio(&single, &st1, &r.shape, r.omega, shear, bend).unwrap();
        // Round section, equal τ in both bending planes: any mix of the degenerate pair has
        // the same ratio. Agreement to the modal solver's tolerance on ω (1e-6).
        assert!(
            (zeta - exact).abs() < 1e-6 * exact,
            "ω {}: harness ζ {zeta} single {exact}",
            m.omega
        );
    }
}

//! The impact remedy of the dynamic step guard (docs/contact.md, "The impact energy at the
//! guard's deepest sub-step"). A step near the geometry that gains energy is split, down to
//! 1/64 of the time step; a sub-step there that still gained energy beyond the clips' work
//! gives the gain back from the cable's motion near the contact: the inertial velocities of
//! the blocks within [`IMPACT_REACH`] of a node touching the geometry are scaled by one factor
//! s < 1 so that their kinetic energy drops by exactly the gain (T' = s² T: the lumped masses
//! and the edges' principal inertias make the kinetic energy of a set of slots a sum of
//! squares). Physically an impact that is a little less elastic than the integrator made it;
//! the energy taken is counted as dissipated. Where no node touches at the sub-step's end (a
//! rebound has left the barrier), the region is about the edge nearest the geometry. Where the
//! motion near the contact holds less than the gain, the region widens (twice the reach each
//! time) until its motion holds it, up to the whole cable; where even that holds less, nothing
//! is taken and the gain is reported as unresolved.
use crate::dynamics::Dynamics;
use crate::model::Rod;
use crate::state::State;

/// Blocks (nodes and their following edges) within this many blocks of a node touching the
/// geometry make up an impact's region: the node, the edges on either side and the next
/// neighbours, through which the impulse of one sub-step has spread.
pub const IMPACT_REACH: usize = 2;

/// The nodes about which an impact's region lies: those touching the geometry in the last
/// whole-cable assembly (`Contact::node_state`), or, where none does, the two of the edge
/// nearest the geometry (`Contact::surface_gap` at `st`); none without contact.
pub(crate) fn impact_nodes(dy: &Dynamics, st: &State) -> Vec<usize> {
    let Some(c) = &dy.contact else {
        return vec![];
    };
    let touching: Vec<usize> = (c.node_state.iter().enumerate())
        .filter(|(_, &state)| state != crate::contact::NO_CONTACT)
        .map(|(node, _)| node)
        .collect();
    if !touching.is_empty() || st.x.len() < 2 {
        return touching;
    }
    let (_, edge, _) = c.surface_gap(st);
    vec![edge, edge + 1]
}

/// Per block: within `reach` blocks of one of `nodes`.
pub(crate) fn impact_region(n: usize, nodes: &[usize], reach: usize) -> Vec<bool> {
    let mut region = vec![false; n];
    for &node in nodes {
        let lo = node.saturating_sub(reach);
        let hi = (node + reach + 1).min(n);
        region[lo..hi].iter_mut().for_each(|b| *b = true);
    }
    region
}

/// Kinetic energy of the inertial slots of the blocks in `region` (J).
pub(crate) fn region_kinetic(dy: &Dynamics, rod: &Rod, region: &[bool]) -> f64 {
    let mut t = 0.0;
    for (b, v) in dy.rates.v.iter().enumerate() {
        if !region[b] {
            continue;
        }
        let slots = &dy.inertial[b];
        for k in 0..3 {
            if slots[k] {
                t += 0.5 * rod.node_mass[b] * v[k] * v[k];
            }
            if slots[k + 3] {
                t += 0.5 * dy.edge_inertia[b][k] * v[k + 3] * v[k + 3];
            }
        }
    }
    t
}

/// Scales the inertial velocities of the blocks in `region` by `s`.
fn scale_region(dy: &mut Dynamics, region: &[bool], s: f64) {
    for (b, v) in dy.rates.v.iter_mut().enumerate() {
        if region[b] {
            for k in 0..6 {
                if dy.inertial[b][k] {
                    v[k] *= s;
                }
            }
        }
    }
}

/// Takes `excess` J out of the kinetic energy of the cables' inertial velocities (per cable
/// its integrator, rod and state): from the blocks within [`IMPACT_REACH`] of the
/// [`impact_nodes`] where their motion holds it, else within twice, four times … that reach,
/// and last from the whole cables' motion; one factor for all the velocities concerned, and
/// each cable's part added to its dissipated energy. Returns the energy taken: `excess`, or 0
/// when even the whole motion holds less (the gain stays unresolved). The caller updates the
/// outputs.
pub(crate) fn take_gain(
    cables: &mut [&mut Dynamics],
    rods: &[&Rod],
    states: &[&State],
    excess: f64,
) -> f64 {
    if excess.is_nan() || excess <= 0.0 {
        return 0.0;
    }
    let nodes: Vec<Vec<usize>> = (cables.iter().zip(states))
        .map(|(dy, st)| impact_nodes(dy, st))
        .collect();
    let longest = cables.iter().map(|dy| dy.rates.v.len()).max().unwrap_or(0);
    let mut candidates: Vec<Vec<Vec<bool>>> = Vec::new();
    let mut reach = IMPACT_REACH;
    while reach < longest {
        candidates.push(
            (cables.iter().zip(&nodes))
                .map(|(dy, nodes)| impact_region(dy.rates.v.len(), nodes, reach))
                .collect(),
        );
        reach *= 2;
    }
    candidates.push(
        cables
            .iter()
            .map(|dy| vec![true; dy.rates.v.len()])
            .collect(),
    );
    for regions in candidates {
        let parts: Vec<f64> = cables
            .iter()
            .zip(rods)
            .zip(&regions)
            .map(|((dy, rod), region)| region_kinetic(dy, rod, region))
            .collect();
        let motion: f64 = parts.iter().sum();
        if motion > excess {
            let keep = 1.0 - excess / motion;
            let s = keep.sqrt();
            for ((dy, region), part) in cables.iter_mut().zip(&regions).zip(&parts) {
                scale_region(dy, region, s);
                dy.energies.dissipated += part * (1.0 - keep);
            }
            return excess;
        }
    }
    0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::DynamicOptions;
    use crate::model::{CableSpec, Section};
    use crate::routing::route;
    use nalgebra::{Vector3, Vector6};

    /// A free cable of 11 nodes in motion, above a table at z = 0 (node 7 lowest, 0.1 m up).
    fn moving_cable() -> (Rod, Dynamics, State) {
        let spec = CableSpec {
            length: 1.0,
            segments: 10,
            section: Section {
                shear_stiffness: Vector3::new(300.0, 300.0, 1000.0),
                bend_stiffness: Vector3::new(0.01, 0.01, 0.008),
                mass_per_length: 0.07,
                rotary_inertia: Vector3::new(2e-7, 2e-7, 4e-7),
            },
            natural_curvature: Vector3::zeros(),
            clips: vec![],
            loads: vec![],
            gravity: Vector3::zeros(),
        };
        let rod = Rod::new(spec).unwrap();
        let mut st = route(&rod, None).unwrap();
        for (b, x) in st.x.iter_mut().enumerate() {
            x.z = 0.1 + 0.01 * (b as f64 - 7.0).abs();
        }
        let mut dy = Dynamics::new(&rod, &st, &[], DynamicOptions::default());
        for (b, v) in dy.rates.v.iter_mut().enumerate() {
            let x = b as f64;
            *v = Vector6::new(0.1 * x, -0.2, 0.3 + x, 1.0, -2.0 * x, 0.5);
        }
        (rod, dy, st)
    }

    fn on_table() -> (Rod, Dynamics, State) {
        let (rod, mut dy, st) = moving_cable();
        dy.contact = Some(crate::harness_contact::tests::table(&rod));
        (rod, dy, st)
    }

    /// The energy taken is the given excess, from the region's velocities alone, and the
    /// kinetic energy (computed independently, `Dynamics::kinetic_energy`) drops by it.
    #[test]
    fn the_gain_comes_out_of_the_region_and_is_counted_as_dissipated() {
        let (rod, mut dy, _) = moving_cable();
        let before = dy.kinetic_energy(&rod);
        let v0 = dy.rates.v.clone();
        let region: Vec<bool> = (0..v0.len()).map(|b| (3..6).contains(&b)).collect();
        let local = region_kinetic(&dy, &rod, &region);
        let excess = 0.3 * local;
        let keep = 1.0 - excess / local;
        scale_region(&mut dy, &region, keep.sqrt());
        let after = dy.kinetic_energy(&rod);
        assert!(
            ((before - after) - excess).abs() <= 1e-12 * before,
            "{before} − {after} ≠ {excess}"
        );
        for (b, (v, w)) in v0.iter().zip(&dy.rates.v).enumerate() {
            if !region[b] {
                assert_eq!(v, w, "block {b} outside the region changed");
            }
        }
        // take_gain without contact: no region, so the whole cable gives it.
        let (rod, mut dy, st) = moving_cable();
        let total = dy.kinetic_energy(&rod);
        let taken = take_gain(&mut [&mut dy], &[&rod], &[&st], 0.25 * total);
        assert_eq!(taken, 0.25 * total);
        let after = dy.kinetic_energy(&rod);
        assert!(((total - after) - taken).abs() <= 1e-12 * total);
        assert!((dy.energies.dissipated - taken).abs() <= 1e-12 * total);
        // More than the motion holds: nothing is taken.
        let (rod, mut dy, st) = moving_cable();
        let total = dy.kinetic_energy(&rod);
        assert_eq!(
            take_gain(&mut [&mut dy], &[&rod], &[&st], 1.01 * total),
            0.0
        );
        assert_eq!(dy.kinetic_energy(&rod), total);
        assert_eq!(dy.energies.dissipated, 0.0);
    }

    /// The region: about the touching nodes (node 5 here: blocks 3..=7), widened to twice the
    /// reach (1..=9) when that holds less than the gain; with no node touching, about the edge
    /// nearest the geometry (edge 6, whose node 7 is lowest: blocks 4..=9).
    #[test]
    fn the_region_is_about_the_contact_and_widens_as_needed() {
        let check = |(rod, mut dy, st): (Rod, Dynamics, State), touching: Option<usize>| {
            if let Some(node) = touching {
                dy.contact.as_mut().unwrap().node_state[node] = 1;
            }
            let nodes = impact_nodes(&dy, &st);
            let n = dy.rates.v.len();
            let (near, wider) = (
                impact_region(n, &nodes, IMPACT_REACH),
                impact_region(n, &nodes, 2 * IMPACT_REACH),
            );
            let (local, wide) = (
                region_kinetic(&dy, &rod, &near),
                region_kinetic(&dy, &rod, &wider),
            );
            let total = dy.kinetic_energy(&rod);
            for (region, excess) in [(&near, 0.5 * local), (&wider, 0.5 * (local + wide))] {
                let mut dy = dy.clone();
                let v0 = dy.rates.v.clone();
                assert_eq!(take_gain(&mut [&mut dy], &[&rod], &[&st], excess), excess);
                assert!(((total - dy.kinetic_energy(&rod)) - excess).abs() <= 1e-12 * total);
                for (b, (v, w)) in v0.iter().zip(&dy.rates.v).enumerate() {
                    assert_eq!(v == w, !region[b], "block {b}");
                }
            }
            (nodes, near)
        };
        let blocks = |r: std::ops::RangeInclusive<usize>| -> Vec<bool> {
            (0..11).map(|b| r.contains(&b)).collect()
        };
        let (nodes, near) = check(on_table(), Some(5));
        assert_eq!((nodes, near), (vec![5], blocks(3..=7)));
        let (nodes, near) = check(on_table(), None);
        assert_eq!((nodes, near), (vec![6, 7], blocks(4..=9)));
    }
}

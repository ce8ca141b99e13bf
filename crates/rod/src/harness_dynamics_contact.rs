//! Contact in dynamic harness runs (docs/harness.md, "Surroundings"): each cable's `Contact`
//! is a term of its dynamic assembly (`Dynamics::assemble`), its entries at joined end nodes
//! reach the junction blocks (`Workspace::end_jac`); this module holds the single cable's
//! safeguards taken over the whole tree: the predictor and every Newton correction close at
//! most 90 % of any gap (`Contact::step_bound`) of any cable, a joined end's node moving with
//! its junction; and the energy guard of `Dynamics::advance` on the whole harness: near the
//! geometry a step whose energy (kinetic, elastic, loads, barrier; cables and junctions) grows
//! by more than `energy_tolerance` of the energies at play, beyond the work of the clips, is
//! split; at the deepest split a gain is given back from the cables' motion near the contact
//! (`impact::take_gain`).
use super::{top, HarnessDynamics};
use crate::dynamics::{reaction_work, Dynamics, Energies, StepStats};
use crate::harness::{Harness, HarnessError, HarnessState};
use crate::impact::take_gain;
use crate::model::{Pose, Rod};
use crate::sliding::SlidingClips;
use crate::state::State;
use nalgebra::Vector3;

/// A clip's (or held junction's) reaction force and moment on the harness and its pose.
type Reaction = (Vector3<f64>, Vector3<f64>, Pose);

/// What the energy guard keeps from t_n.
pub(crate) struct EnergyStart {
    energies: Energies,
    /// Per cable, its own clips (not the joined ends: internal to the harness).
    clips: Vec<Vec<(usize, Reaction)>>,
    /// Per junction held by a clip.
    held: Vec<Option<Reaction>>,
    /// Per cable: dissipated energy and power at t_n (restored when a step is refused).
    dissipated: Vec<(f64, f64)>,
}

impl HarnessDynamics {
    /// Whether any cable has contact.
    pub fn has_contact(&self) -> bool {
        self.cables.iter().any(|d| d.contact.is_some())
    }

    /// Whether samples of some cable are inside the contact barrier (at the last assembly).
    pub(crate) fn contact_active(&self) -> bool {
        self.cables
            .iter()
            .any(|d| d.contact.as_ref().is_some_and(|c| c.active > 0))
    }

    /// The largest α ≤ 1 such that the Newton correction in the tree's `delta` and `dj`,
    /// scaled by α, dives through no cable's barrier and carries no node across a frictional
    /// guide's stick zone (`SlidingClips::step_bound`). A node moves by h k_dq c_mass δx (v̇ +=
    /// c_mass δx, x = x_n + h(dq0 + k_dq v̇)), a joined end's node with its junction alike.
    /// With it: whether a guide's bound cut the correction (a node stops inside its stick
    /// zone).
    pub(crate) fn correction_alpha(
        &self,
        h: &Harness,
        st: &HarnessState,
        dt: f64,
        c_mass: f64,
    ) -> (f64, bool) {
        let (mut alpha, mut stick) = (1.0f64, false);
        for (c, dy) in self.cables.iter().enumerate() {
            let guide = SlidingClips::frictional(&dy.sliding);
            if dy.contact.is_none() && guide.is_none() {
                continue;
            }
            let kx = dt * dy.k_dq * c_mass;
            let (delta, dj, inertial) = (&self.tree.delta[c], &self.tree.dj, &dy.inertial);
            let dx = |n: usize| {
                if inertial[n][0] {
                    return kx * top(&delta[n]);
                }
                for &k in &h.cable_ends[c] {
                    let e = &h.ends[k];
                    if e.topo.node == n && !h.held[e.junction] {
                        return kx * top(&dj[e.junction]);
                    }
                }
                Vector3::zeros()
            };
            if let Some(contact) = &dy.contact {
                let edges = 0..h.cables[c].n_edges();
                alpha = alpha.min(contact.step_bound(&st.cables[c].x, dx, edges));
            }
            if let Some(guide) = guide {
                let nodes = 0..h.cables[c].arc.len();
                let rod = &h.cables[c];
                let bound = guide.step_bound(rod, &st.cables[c], Some(&dy.rates), dx, nodes);
                stick |= bound < 1.0;
                alpha = alpha.min(bound);
            }
        }
        (alpha, stick)
    }

    /// Shortens the predictor (from t_n) of every cable and junction by one factor so that no
    /// cable dives through its barrier; returns the largest increment when it was shortened.
    pub(crate) fn limit_predictor(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        dt: f64,
    ) -> Option<f64> {
        let mut alpha = 1.0f64;
        for (c, dy) in self.cables.iter().enumerate() {
            let Some(contact) = &dy.contact else {
                continue;
            };
            let (x, x_n) = (&st.cables[c].x, dy.start_positions());
            let edges = 0..h.cables[c].n_edges();
            alpha = alpha.min(contact.step_bound(x_n, |n| x[n] - x_n[n], edges));
        }
        if alpha >= 1.0 {
            return None;
        }
        let k_dq = self.cables[0].k_dq;
        for j in 0..self.jv.len() {
            if h.held[j] {
                continue;
            }
            let dq = self.jdq0[j] + k_dq * self.jvdot[j];
            self.jvdot[j] = (alpha * dq - self.jdq0[j]) / k_dq;
        }
        let mut inc = self.junction_kinematics(st, dt, true);
        self.impose_held(st);
        for (c, rod) in h.cables.iter().enumerate() {
            let blocks = 0..rod.arc.len();
            inc = inc.max(self.cables[c].scale_predictor(&mut st.cables[c], dt, alpha, blocks));
        }
        self.sync_ends(h, st);
        Some(inc)
    }

    /// The energy guard's values at t_n, when some cable is near the geometry (within d̂ plus
    /// twice the step's travel at the harness's largest speed); None otherwise or without
    /// contact.
    pub(crate) fn energy_start(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        dt: f64,
    ) -> Result<Option<EnergyStart>, HarnessError> {
        // The harness's largest speed (as the single cable's over its nodes).
        let speed = self
            .cables
            .iter()
            .flat_map(|d| d.rates.v.iter())
            .chain(&self.jv)
            .map(|v| top(v).norm())
            .fold(0.0, f64::max);
        let travel = 2.0 * dt * speed;
        let near = self.cables.iter().enumerate().any(|(c, dy)| {
            dy.contact
                .as_ref()
                .is_some_and(|k| k.near(&st.cables[c].x, travel))
        });
        if !near {
            return Ok(None);
        }
        self.update_outputs(h, st)?;
        Ok(Some(EnergyStart {
            energies: self.energies,
            clips: self.own_clip_reactions(h, st),
            held: self.held_reactions(h, st),
            dissipated: self
                .cables
                .iter()
                .map(|d| (d.energies.dissipated, d.power_n))
                .collect(),
        }))
    }

    /// The energy the step just taken from `start` gained beyond the clips' work, relative to
    /// the energies at play, and that scale (J); a gain of 0 where moving geometry did work
    /// that is not counted.
    pub(crate) fn energy_gain(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        start: &EnergyStart,
    ) -> Result<(f64, f64), HarnessError> {
        if self.cables.iter().any(|d| d.obstacles_moved()) {
            return Ok((0.0, 0.0)); // moving geometry does work that is not counted
        }
        self.update_outputs(h, st)?;
        let work_of = |r0: &Reaction, r1: &Reaction| {
            reaction_work((&r0.0, &r0.1), (&r1.0, &r1.1), &r0.2, &r1.2)
        };
        let mut work = 0.0;
        for (c0, c1) in start.clips.iter().zip(self.own_clip_reactions(h, st)) {
            for ((_, r0), (_, r1)) in c0.iter().zip(&c1) {
                work += work_of(r0, r1);
            }
        }
        for (r0, r1) in start.held.iter().zip(self.held_reactions(h, st)) {
            if let (Some(r0), Some(r1)) = (r0, r1) {
                work += work_of(r0, &r1);
            }
        }
        Ok(start.energies.gain_to(&self.energies, work))
    }

    /// A sub-step at the deepest split that gained `gain` (relative to `scale`, J): the
    /// cables' motion near the contact gives it back (`impact::take_gain`) and the step reports
    /// it as impact dissipation, or, where the motion holds less, as unresolved.
    pub(crate) fn give_back(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        (gain, scale): (f64, f64),
        s: StepStats,
    ) -> Result<StepStats, HarnessError> {
        let rods: Vec<&Rod> = h.cables.iter().collect();
        let mut cables: Vec<&mut Dynamics> = self.cables.iter_mut().collect();
        let states: Vec<&State> = st.cables.iter().collect();
        let given_back = take_gain(&mut cables, &rods, &states, gain * scale) != 0.0;
        if given_back {
            self.update_outputs(h, st)?;
            for dy in &mut self.cables {
                dy.power_n = dy.ws.dissipation;
            }
        }
        Ok(s.with_impact(gain, given_back))
    }

    /// Puts back the dissipated energies of `start` (a step that will be redone).
    pub(crate) fn restore_dissipated(&mut self, start: &EnergyStart) {
        for (dy, &(d, p)) in self.cables.iter_mut().zip(&start.dissipated) {
            (dy.energies.dissipated, dy.power_n) = (d, p);
        }
    }

    /// Every cable's own clips (not the joined ends): reaction on the cable and pose.
    fn own_clip_reactions(&self, h: &Harness, st: &HarnessState) -> Vec<Vec<(usize, Reaction)>> {
        h.cables
            .iter()
            .enumerate()
            .map(|(c, rod)| {
                let ends: Vec<usize> = h.cable_ends[c]
                    .iter()
                    .map(|&k| h.ends[k].topo.clip)
                    .collect();
                (0..rod.spec.clips.len())
                    .filter(|k| !ends.contains(k))
                    .map(|k| {
                        let (f, m) = self.cables[c].ws.clip_reaction(rod, &st.cables[c], k);
                        (k, (f, m, st.cables[c].clip_pose[k]))
                    })
                    .collect()
            })
            .collect()
    }

    /// The reaction of the clip on each junction it holds, with the junction's pose.
    fn held_reactions(&self, h: &Harness, st: &HarnessState) -> Vec<Option<Reaction>> {
        self.junction_reactions(h, st)
            .into_iter()
            .enumerate()
            .map(|(j, (f, m))| h.held[j].then_some((f, m, st.junctions[j])))
            .collect()
    }
}

#[cfg(test)]
#[path = "harness_dynamics_contact_tests.rs"]
mod tests;

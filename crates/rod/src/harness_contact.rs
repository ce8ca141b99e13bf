//! Contact with the surroundings on harness cables (docs/harness.md, "Contact"): each cable's
//! `Contact` is one more term of its assembly (`HarnessStatics::assemble`); this module holds
//! what the harness Newton adds around it, with the rules of the single cable
//! (`Statics::newton`): the step bound "close at most 90 % of a gap" over every cable (a joined
//! end node moves with its junction), the trial's gap test, the lagged friction reference
//! (the last equilibrium) and the penetration check.
use crate::contact::Contact;
use crate::harness::{Harness, HarnessError, HarnessState};
use crate::harness_solver::HarnessStatics;
use crate::statics::{SolveError, SolveStats};
use nalgebra::Vector3;

/// `max_iterations` of the harness push-out's stage solves (plain Newton, and 6× that for
/// the pseudo-transient fallback, `HarnessStatics::stage`): bench_harness's tray, 0.67 s with
/// the full 100 (three failed stages of ≈ 200 ms each), 0.25 s with 10, the same equilibrium to
/// 1e-16 m; with 3 the pair pushed out of a pipe (harness_contact_tests) fails, with 5 it
/// passes. Session 10: a failed stage still took 60 ms (the pseudo-transient fallback's 20×
/// budget, then the load continuation): with 6× and no continuation 18 ms, the tray 0.28 →
/// 0.15 s, the same stages and equilibrium.
const PUSH_OUT_STAGE_ITERATIONS: usize = 10;

impl HarnessStatics {
    /// Whether any cable has contact.
    pub fn has_contact(&self) -> bool {
        self.contact.iter().any(Option::is_some)
    }

    /// Limits the step fraction `alpha` of the Newton correction (`delta`, `dj`) so that no
    /// cable dives through the contact barrier; stores each cable's smallest gap at `st` (from
    /// its assembly) for `contact_feasible`.
    pub(crate) fn contact_bound(&mut self, h: &Harness, st: &HarnessState, alpha: &mut f64) {
        let a = *alpha;
        let mut bound = 1.0f64;
        for (c, contact) in self.contact.iter().enumerate() {
            let Some(contact) = contact else {
                self.gap0[c] = f64::INFINITY;
                continue;
            };
            let rod = &h.cables[c];
            let delta = &self.delta[c];
            let dj = &self.dj;
            let dx = |n: usize| {
                if rod.mask[n][0] {
                    return a * delta[n].fixed_rows::<3>(0).into_owned();
                }
                // A joined end's node sits at its junction's point and moves with it.
                for &k in &h.cable_ends[c] {
                    let e = &h.ends[k];
                    if e.topo.node == n {
                        return a * dj[e.junction].fixed_rows::<3>(0).into_owned();
                    }
                }
                Vector3::zeros()
            };
            bound = bound.min(contact.step_bound(&st.cables[c].x, dx, 0..rod.n_edges()));
            self.gap0[c] = contact.min_gap();
        }
        *alpha *= bound;
    }

    /// Whether the trial just assembled keeps every cable's gap acceptable against the gaps
    /// stored by `contact_bound`.
    pub(crate) fn contact_feasible(&self) -> bool {
        self.contact
            .iter()
            .zip(&self.gap0)
            .all(|(c, &g)| c.as_ref().is_none_or(|c| c.gap_acceptable(g)))
    }

    /// Friction reference of every cable's contact: the positions of `st` (the last
    /// equilibrium of a sequence; the start of a static solve).
    pub(crate) fn begin_contact_step(&mut self, st: &HarnessState) {
        for (c, contact) in self.contact.iter_mut().enumerate() {
            if let Some(contact) = contact {
                contact.begin_step(&st.cables[c].x, None);
            }
        }
    }

    /// Applies `f` to every cable's contact (all of them); whether any returned true.
    pub(crate) fn any_contact(&mut self, f: &mut dyn FnMut(&mut Contact) -> bool) -> bool {
        let mut any = false;
        for c in self.contact.iter_mut().flatten() {
            any |= f(c);
        }
        any
    }

    /// Whether a free node of some cable lies inside an obstacle at `st`.
    pub(crate) fn contact_penetrates(&self, h: &Harness, st: &HarnessState) -> bool {
        self.contact.iter().enumerate().any(|(c, contact)| {
            contact
                .as_ref()
                .is_some_and(|k| k.penetrates(&h.cables[c], &st.cables[c]))
        })
    }

    /// Marks the edges at nodes inside an obstacle for exact distances (`Some(st)`) or clears
    /// the marks (`None`), on every cable.
    pub(crate) fn mark_deep_edges(&mut self, st: Option<&HarnessState>) {
        for (c, contact) in self.contact.iter_mut().enumerate() {
            if let Some(contact) = contact {
                contact.mark_deep_edges(st.map(|s| s.cables[c].x.as_slice()));
            }
        }
    }

    /// A cable left inside the geometry deeper than the tolerance (1 % of r) at `st`: the
    /// error naming the cable, the geometry, the node and the depth.
    pub(crate) fn penetration_error(
        &mut self,
        h: &Harness,
        st: &HarnessState,
    ) -> Option<HarnessError> {
        self.mark_deep_edges(Some(st));
        let mut found = None;
        for (c, contact) in self.contact.iter().enumerate() {
            let Some(p) = contact
                .as_ref()
                .and_then(|k| k.deepest_penetration(&st.cables[c]))
            else {
                continue;
            };
            let e = SolveError::Penetration {
                node: p.node,
                s: h.cables[c].arc[p.node],
                obstacle: p.name,
                depth: p.depth,
            };
            found = Some(HarnessError(format!("cable '{}': {e}", h.names[c])));
            break;
        }
        self.mark_deep_edges(None);
        found
    }

    /// The single cable's push-out continuation (`Statics::solve`) over every cable: the
    /// geometry shrunk until every cable is clear of it, grown back in halving stages, the
    /// free nodes it reaches moved out along its normal before each solve. Returns the Newton
    /// iterations spent.
    fn push_out(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        solve: &mut impl FnMut(
            &mut Self,
            &Harness,
            &mut HarnessState,
        ) -> Result<SolveStats, HarnessError>,
    ) -> usize {
        let mut depth = 0.0f64;
        let mut reach = 0.0f64;
        for (c, contact) in self.contact.iter().enumerate() {
            if let Some(k) = contact {
                if let Some(p) = k.deepest_penetration(&st.cables[c]) {
                    depth = depth.max(p.depth);
                }
                reach = reach.max(k.opts.distance);
            }
        }
        if depth == 0.0 {
            return 0;
        }
        let mut iterations = 0;
        let mut shrink = depth + 2.0 * reach;
        let mut last = st.clone();
        let (mut fraction, mut failures) = (0.5, 0);
        while shrink > 0.0 && failures < 8 {
            let next = if shrink <= 4.0 * reach {
                0.0
            } else {
                fraction * shrink
            };
            let before: Vec<Vec<_>> = st.cables.iter().map(|c| c.x.clone()).collect();
            for k in self.contact.iter_mut().flatten() {
                k.set_shrink(next);
            }
            // A junction (not held by a clip) moves out with its ends' cables, then the free
            // nodes; the edge frames turn from their directions before either moved.
            for e in &h.ends {
                if let (false, Some(k)) = (h.held[e.junction], &self.contact[e.cable]) {
                    k.move_point_out(&mut st.junctions[e.junction].position, 0.5 * reach);
                }
            }
            st.sync_ends(h);
            for (c, contact) in self.contact.iter().enumerate() {
                if let Some(k) = contact {
                    k.move_out(
                        &h.cables[c],
                        &mut st.cables[c],
                        0.5 * reach,
                        Some(&before[c]),
                    );
                }
            }
            // A stage solve that cannot converge fails fast (its fallbacks' budgets scale with
            // `max_iterations`): the loop then takes a smaller stage.
            let full = self.opts.max_iterations;
            self.opts.max_iterations = full.min(PUSH_OUT_STAGE_ITERATIONS);
            self.stage = true;
            let r = solve(self, h, st);
            self.stage = false;
            self.opts.max_iterations = full;
            if let Ok(s) = r {
                iterations += s.iterations;
                (shrink, fraction) = (next, 0.5);
                last.clone_from(st);
            } else {
                st.clone_from(&last);
                fraction = 0.5 + 0.5 * fraction;
                failures += 1;
                if next == 0.0 {
                    shrink = 8.0 * reach;
                }
            }
        }
        for k in self.contact.iter_mut().flatten() {
            k.set_shrink(0.0);
        }
        iterations
    }

    /// `solve_static` with contact: a start that runs through the geometry (a routed shape) is
    /// first solved without contact (as `Statics::solve`); the barrier then pushes it out. A
    /// cable left inside is an error naming it.
    pub(crate) fn solve_static_with_contact(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        mut solve: impl FnMut(
            &mut Self,
            &Harness,
            &mut HarnessState,
        ) -> Result<SolveStats, HarnessError>,
    ) -> Result<SolveStats, HarnessError> {
        let inside = self.contact_penetrates(h, st);
        let mut pre = 0;
        if inside {
            let contact = std::mem::take(&mut self.contact);
            self.contact = vec![None; contact.len()];
            let start = st.clone();
            match solve(self, h, st) {
                Ok(s) => pre += s.iterations,
                Err(_) => st.clone_from(&start),
            }
            self.contact = contact;
            self.mark_deep_edges(Some(st));
            // Straight to the push-out (unlike `Statics::solve`, which tries the direct solve
            // with contact first): on bench_harness's harness on a tray the direct attempt
            // fails after ~100 pseudo-transient iterations, 0.87 s against 0.67 s without it.
            pre += self.push_out(h, st, &mut solve);
        }
        let result = solve(self, h, st);
        self.mark_deep_edges(None);
        let mut stats = result?;
        stats.iterations += pre; // the solves without contact and of the push-out too
        if inside {
            if let Some(e) = self.penetration_error(h, st) {
                return Err(e);
            }
        }
        Ok(stats)
    }
}

#[cfg(test)]
#[path = "harness_contact_tests.rs"]
pub(crate) mod tests;

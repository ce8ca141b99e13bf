//! Escape from an unstable harness equilibrium (issue 16): as `Statics::ensure_stable` for one
//! cable. Newton finds equilibria whether stable or not (a trunk compressed beyond its Euler
//! load stays straight); the static solve checks the inertia of the tree LDLᵀ of the
//! symmetric tangent stiffness (`harness_modal`) and, with negative eigenvalues, moves the
//! harness along the mode of the most negative one (0.1 rad of rotation or 2 % of the shortest
//! cable, whichever comes first; both signs, the lower energy kept), relaxes it by the
//! pseudo-transient path (a damped motion, which settles in a stable equilibrium) finished by
//! Newton, and checks again: up to 4 attempts with doubled perturbations. If none ends stable
//! the unstable equilibrium is returned and its count reported (`SolveStats::unstable`).
//! Applied to the static solve and to every step of a sequence (a column compressed past its
//! Euler load during a quasistatic run buckles there).
//! Skipped where the loads are not conservative (dead moments, sliding clips' friction: the
//! symmetric part of the tangent is then no stability criterion), as for one cable.
use crate::harness::{Harness, HarnessError, HarnessState};
use crate::harness_modal::ModalSystem;
use crate::harness_solver::HarnessStatics;
use crate::statics::SolveStats;
use nalgebra::Vector3;

/// Attempts of the escape (each from the unstable state, the perturbation doubled).
const ATTEMPTS: u32 = 4;

impl HarnessStatics {
    /// The potential energy of the harness at the last assembly: the cables' elastic energy
    /// and load potentials, and the junctions' weight.
    fn potential_energy(&self, h: &Harness, st: &HarnessState) -> f64 {
        let cables: f64 = self
            .ws
            .iter()
            .map(|ws| ws.elastic_energy + ws.load_potential)
            .sum();
        let junctions: f64 = h
            .junctions
            .iter()
            .zip(&st.junctions)
            .map(|(j, pose)| -j.mass * h.gravity.dot(&pose.position))
            .sum();
        cables + junctions
    }

    /// Checks the equilibrium `st` for stability and leaves an unstable one for a stable one
    /// (see the module); `stats.unstable` is the negative count at the state returned (None:
    /// not checked, non-conservative loads).
    pub fn ensure_stable(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        stats: &mut SolveStats,
    ) -> Result<(), HarnessError> {
        let moments = h
            .cables
            .iter()
            .any(|r| r.edge_moment.iter().any(|m| *m != Vector3::zeros()));
        // Friction in contact is not conservative (as `Statics::ensure_stable`).
        let frictional = self
            .contact
            .iter()
            .flatten()
            .any(|c| c.active > 0 && c.obstacles.iter().any(|o| o.friction > 0.0));
        if moments || frictional || self.sliding.iter().any(Option::is_some) {
            stats.unstable = None;
            return Ok(());
        }
        // The pencil's buffers are kept between the steps of a sequence (no allocation).
        let mut modal = self
            .escape_modal
            .take()
            .unwrap_or_else(|| Box::new(ModalSystem::new(h)));
        let result = self.escape(h, st, stats, &mut modal);
        self.escape_modal = Some(modal);
        result
    }

    fn escape(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        stats: &mut SolveStats,
        modal: &mut ModalSystem,
    ) -> Result<(), HarnessError> {
        let count = modal.negative_count_with_contact(h, st, &mut self.contact)?;
        stats.unstable = Some(count);
        if count == 0 {
            return Ok(());
        }
        let before = st.clone();
        let shortest = h
            .cables
            .iter()
            .map(|r| r.spec.length)
            .fold(f64::INFINITY, f64::min);
        let Some((_, dc, dj)) = modal.unstable_mode(h, st, &mut self.contact)? else {
            return Ok(());
        };
        let (mut dx, mut dth) = (0.0f64, 0.0f64);
        for (c, rod) in h.cables.iter().enumerate() {
            for (b, v) in dc[c].iter().enumerate() {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        if k < 3 {
                            dx = dx.max(v[k].abs());
                        } else {
                            dth = dth.max(v[k].abs());
                        }
                    }
                }
            }
        }
        for v in &dj {
            dx = dx.max(v.fixed_rows::<3>(0).amax());
            dth = dth.max(v.fixed_rows::<3>(3).amax());
        }
        let unit = 1.0 / (dth / 0.1).max(dx / (0.02 * shortest)).max(1e-300);
        for attempt in 0..ATTEMPTS {
            let amp = unit * f64::from(1u32 << attempt);
            let mut best = (f64::INFINITY, 0.0);
            for sign in [1.0, -1.0] {
                st.clone_from(&before);
                st.apply_increment(h, &dc, &dj, sign * amp);
                if self.assemble(h, st, 1.0, false).is_ok() {
                    let e = self.potential_energy(h, st);
                    if e < best.0 {
                        best = (e, sign);
                    }
                }
            }
            if best.1 == 0.0 {
                break;
            }
            st.clone_from(&before);
            st.apply_increment(h, &dc, &dj, best.1 * amp);
            let max_it = 20 * self.opts.max_iterations;
            let relaxed = match self.pseudo_transient(h, st, 1.0, max_it) {
                Ok(s) => Ok(s),
                Err(_) => self.newton(h, st, 1.0, false),
            };
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!("harness escape {attempt}: amp {amp:.3e} -> {relaxed:?}");
            }
            if let Ok(s) = relaxed {
                stats.iterations += s.iterations;
                stats.residual = s.residual;
                let count = modal.negative_count_with_contact(h, st, &mut self.contact)?;
                if count == 0 {
                    stats.unstable = Some(0);
                    stats.escapes += 1;
                    return Ok(());
                }
            }
        }
        st.clone_from(&before);
        self.assemble(h, st, 1.0, true)?;
        stats.unstable = Some(count);
        Ok(())
    }
}

#[cfg(test)]
#[path = "harness_escape_tests.rs"]
mod tests;

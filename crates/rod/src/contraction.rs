//! The contraction of a step's Newton iteration with a reused matrix, and the stopping rule
//! built on it (Hairer & Wanner, Solving ODE II, IV.8).
//!
//! With the matrix S of an earlier iterate, the corrections of a step shrink by a factor θ per
//! iteration, so the iterate after a correction Δ is still about η|Δ| from the solution,
//! η = θ/(1 − θ). The iteration may stop when that estimate is below the tolerance — often
//! after the first correction, when the predictor was close and S still fits. θ is measured
//! within a step from two successive corrections with the same matrix; a step's first
//! correction has none, so the rule carries the largest η of the last `MEMORY` measurements
//! over, for at most `MAX_AGE` steps: then a step iterates once more to measure it again (so a
//! matrix that fits less and less is noticed and refactored, as when it is measured every
//! step). Without a measurement, the plain rule: the correction itself below the tolerance.
//!
//! Measured on the engine-PSD harness of `benchmarks/bench_harness.py` (docs/dynamics.md,
//! "Stopping rule"): a step's first correction is ~11× the tolerance (median), θ ≈ 0.02–0.2.

/// Measurements of η kept (their largest is used; none before this many).
const MEMORY: usize = 3;
/// Steps an estimate is carried over before a step measures it again.
const MAX_AGE: usize = 8;

/// The contraction estimate of one Newton iteration (a cable segment, or a whole harness).
#[derive(Clone, Copy, Debug)]
pub struct Contraction {
    /// The last measurements of η (newest first; ∞: none).
    recent: [f64; MEMORY],
    /// Steps begun since the last measurement.
    age: usize,
}

impl Default for Contraction {
    fn default() -> Self {
        Self::new()
    }
}

impl Contraction {
    pub fn new() -> Self {
        Contraction {
            recent: [f64::INFINITY; MEMORY],
            age: 0,
        }
    }

    /// A new step begins.
    pub fn begin_step(&mut self) {
        self.age += 1;
    }

    /// Two successive corrections of this step with the same matrix: records their η
    /// (∞ when the second is no smaller).
    pub fn measure(&mut self, norm: f64, last_norm: f64) {
        let theta = norm / last_norm;
        let eta = if theta < 1.0 {
            theta / (1.0 - theta)
        } else {
            f64::INFINITY
        };
        self.recent.copy_within(0..MEMORY - 1, 1);
        self.recent[0] = eta;
        self.age = 0;
    }

    /// The estimate for this step's iterations: the largest recent η, ∞ once too old.
    fn eta(&self) -> f64 {
        if self.age > MAX_AGE {
            f64::INFINITY
        } else {
            self.recent.iter().cloned().fold(0.0, f64::max)
        }
    }

    /// Whether the iteration stops after a correction of size `norm`: the correction below
    /// the tolerance, or, where the tolerance is the error rule's, its estimated remaining
    /// error η|Δ|.
    pub fn converged(&self, norm: f64, tolerance: Tolerance) -> bool {
        norm < tolerance.value || (tolerance.of_error && self.eta() * norm < tolerance.value)
    }
}

/// A step's Newton tolerance (`DynamicOptions::step_tolerance`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub value: f64,
    /// Whether `value` is the error rule's (a fraction of the estimated time-discretisation
    /// error), not a cap or floor on the correction.
    pub of_error: bool,
}

impl Tolerance {
    /// At most `v` (a bound on the correction itself where it binds).
    pub fn at_most(self, v: f64) -> Tolerance {
        if v < self.value {
            Tolerance {
                value: v,
                of_error: false,
            }
        } else {
            self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Contraction {
        fn converged_at(&self, norm: f64, value: f64) -> bool {
            self.converged(
                norm,
                Tolerance {
                    value,
                    of_error: true,
                },
            )
        }
    }

    #[test]
    fn a_cap_or_floor_bounds_the_correction_itself() {
        let mut c = Contraction::new();
        for _ in 0..MEMORY {
            c.measure(0.1, 1.0);
        }
        let error = Tolerance {
            value: 1.0,
            of_error: true,
        };
        assert!(c.converged(5.0, error));
        assert!(!c.converged(5.0, error.at_most(0.5)));
        assert!(c.converged(0.4, error.at_most(0.5)));
        assert_eq!(error.at_most(2.0), error);
    }

    #[test]
    fn without_a_measurement_the_correction_itself_must_be_below_the_tolerance() {
        let c = Contraction::new();
        assert!(c.converged_at(0.9, 1.0));
        assert!(!c.converged_at(1.1, 1.0));
    }

    #[test]
    fn a_measured_contraction_accepts_a_correction_whose_remaining_error_is_small() {
        let mut c = Contraction::new();
        c.measure(0.1, 1.0); // θ = 0.1: η = 1/9
        c.measure(0.1, 1.0);
        assert!(!c.converged_at(8.9, 1.0)); // fewer than MEMORY measurements: the plain rule
        c.measure(0.1, 1.0);
        c.begin_step();
        assert!(c.converged_at(8.9, 1.0));
        assert!(!c.converged_at(9.1, 1.0));
        // not contracting: only the plain rule
        c.measure(1.0, 1.0);
        assert!(!c.converged_at(1.1, 1.0));
    }

    #[test]
    fn the_largest_recent_measurement_rules_and_old_ones_expire() {
        let mut c = Contraction::new();
        c.measure(0.5, 1.0); // η = 1
        c.measure(0.1, 1.0);
        c.measure(0.1, 1.0);
        assert!(!c.converged_at(2.0, 1.0)); // η = 1 still among the last three
        c.measure(0.1, 1.0);
        assert!(c.converged_at(2.0, 1.0)); // dropped out
        for _ in 0..MAX_AGE {
            c.begin_step();
        }
        assert!(c.converged_at(2.0, 1.0));
        c.begin_step(); // too old: measured again
        assert!(!c.converged_at(2.0, 1.0));
        assert!(c.converged_at(0.5, 1.0));
    }
}

//! Wöhler (S–N) curve in stress RANGES and the Palmgren–Miner sum.
//!
//! N(ΔS) = α · ΔS^(−k) cycles to failure for a constant-amplitude stress RANGE ΔS (not an
//! amplitude: with amplitudes S_a = ΔS/2 the same curve reads N = α 2^(−k) S_a^(−k)).
//! Optional knee at ΔS_D (N_D = α ΔS_D^(−k)): below it either Haibach's fictitious slope
//! 2k − 1, N = N_D (ΔS/ΔS_D)^(−(2k−1)), or a cut-off (no damage below ΔS_D).
//! Miner: D = Σ n_i / N(ΔS_i).

use crate::rainflow::Cycle;
use crate::FatigueError;

/// Behaviour below the knee of the curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KneeKind {
    /// Continue with slope 2k − 1 (Haibach).
    Haibach,
    /// No damage below the knee (endurance limit).
    CutOff,
}

impl KneeKind {
    /// Parse `"haibach"` or `"cutoff"`.
    pub fn parse(name: &str) -> Result<Self, FatigueError> {
        match name {
            "haibach" => Ok(KneeKind::Haibach),
            "cutoff" | "cut-off" => Ok(KneeKind::CutOff),
            _ => Err(FatigueError::param(
                "knee_kind",
                format!("{name:?}"),
                "must be \"haibach\" or \"cutoff\"",
            )),
        }
    }
}

/// A Wöhler curve N = α ΔS^(−k) in ranges, optionally with a knee.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wohler {
    k: f64,
    alpha: f64,
    knee_range: f64,
    knee_kind: KneeKind,
    has_knee: bool,
    // derived
    inv_alpha: f64,
    k_int: Option<i32>,
    knee_cycles: f64,
    k_below: f64,
    k_below_int: Option<i32>,
}

fn as_int(k: f64) -> Option<i32> {
    (k.fract() == 0.0 && k.abs() <= 64.0).then_some(k as i32)
}

#[inline(always)]
fn pow(x: f64, k: f64, k_int: Option<i32>) -> f64 {
    match k_int {
        Some(n) => x.powi(n),
        None => x.powf(k),
    }
}

impl Wohler {
    /// Single-slope curve; `k` > 0 and `alpha` > 0 (unit: stress^k · cycles).
    pub fn new(k: f64, alpha: f64) -> Result<Self, FatigueError> {
        if !(k > 0.0 && k.is_finite()) {
            return Err(FatigueError::param(
                "k",
                k,
                "the Wöhler slope must be a finite number > 0",
            ));
        }
        if !(alpha > 0.0 && alpha.is_finite()) {
            return Err(FatigueError::param(
                "alpha",
                alpha,
                "the Wöhler constant must be a finite number > 0",
            ));
        }
        Ok(Wohler {
            k,
            alpha,
            knee_range: 0.0,
            knee_kind: KneeKind::Haibach,
            has_knee: false,
            inv_alpha: 1.0 / alpha,
            k_int: as_int(k),
            knee_cycles: f64::INFINITY,
            k_below: 2.0 * k - 1.0,
            k_below_int: as_int(2.0 * k - 1.0),
        })
    }

    /// The same curve with a knee at range `knee_range` (> 0).
    pub fn with_knee(mut self, knee_range: f64, kind: KneeKind) -> Result<Self, FatigueError> {
        if !(knee_range > 0.0 && knee_range.is_finite()) {
            return Err(FatigueError::param(
                "knee_range",
                knee_range,
                "the knee stress range must be a finite number > 0",
            ));
        }
        self.has_knee = true;
        self.knee_range = knee_range;
        self.knee_kind = kind;
        self.knee_cycles = self.alpha * knee_range.powf(-self.k);
        Ok(self)
    }

    /// Curve through the knee point (ΔS_D, N_D) with slope `k`.
    pub fn from_knee(
        k: f64,
        knee_range: f64,
        knee_cycles: f64,
        kind: KneeKind,
    ) -> Result<Self, FatigueError> {
        if !(knee_cycles > 0.0 && knee_cycles.is_finite()) {
            return Err(FatigueError::param(
                "knee_cycles",
                knee_cycles,
                "the cycle count at the knee must be a finite number > 0",
            ));
        }
        if !(knee_range > 0.0 && knee_range.is_finite()) {
            return Err(FatigueError::param(
                "knee_range",
                knee_range,
                "the knee stress range must be a finite number > 0",
            ));
        }
        Wohler::new(k, 1.0)?;
        let alpha = knee_cycles * knee_range.powf(k);
        Wohler::new(k, alpha)?.with_knee(knee_range, kind)
    }

    pub fn k(&self) -> f64 {
        self.k
    }

    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// (ΔS_D, N_D, kind) if the curve has a knee.
    pub fn knee(&self) -> Option<(f64, f64, KneeKind)> {
        self.has_knee
            .then_some((self.knee_range, self.knee_cycles, self.knee_kind))
    }

    /// Damage of one full cycle of range `range`: 1 / N(ΔS) (0 for a zero range).
    #[inline(always)]
    pub fn damage_per_cycle(&self, range: f64) -> f64 {
        if range <= 0.0 {
            return 0.0;
        }
        if !self.has_knee || range >= self.knee_range {
            return pow(range, self.k, self.k_int) * self.inv_alpha;
        }
        match self.knee_kind {
            KneeKind::CutOff => 0.0,
            KneeKind::Haibach => {
                pow(range / self.knee_range, self.k_below, self.k_below_int) / self.knee_cycles
            }
        }
    }

    /// Cycles to failure N(ΔS) (infinite for a zero range or below a cut-off).
    pub fn cycles_to_failure(&self, range: f64) -> f64 {
        1.0 / self.damage_per_cycle(range)
    }

    /// Palmgren–Miner sum Σ n_i / N(ΔS_i) of a cycle list.
    pub fn miner(&self, cycles: &[Cycle]) -> f64 {
        cycles
            .iter()
            .map(|c| c.count * self.damage_per_cycle(c.range))
            .sum()
    }

    /// Damage-equivalent stress range for `n_ref` cycles: the constant range that, applied
    /// `n_ref` times, gives `damage` on the single-slope line, ΔS_eq = (α D / n_ref)^(1/k).
    /// `damage` must come from a curve without knee (else the equivalence is not defined).
    pub fn equivalent_range(&self, damage: f64, n_ref: f64) -> Result<f64, FatigueError> {
        if self.has_knee {
            return Err(FatigueError::param(
                "knee_range",
                self.knee_range,
                "the damage-equivalent range is defined on the single-slope curve: \
                 use a curve without knee",
            ));
        }
        if !(n_ref > 0.0 && n_ref.is_finite()) {
            return Err(FatigueError::param(
                "n_ref",
                n_ref,
                "the reference cycle count must be a finite number > 0",
            ));
        }
        Ok((self.alpha * damage / n_ref).powf(1.0 / self.k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    #[test]
    fn single_slope() {
        let w = Wohler::new(5.0, 1e12).unwrap();
        assert!(close(w.cycles_to_failure(10.0), 1e7));
        assert!(close(w.damage_per_cycle(100.0), 1e-2));
        assert_eq!(w.damage_per_cycle(0.0), 0.0);
        let w = Wohler::new(4.5, 1e12).unwrap();
        assert!(close(w.cycles_to_failure(10.0), 1e12 / 10f64.powf(4.5)));
    }

    #[test]
    fn knee_haibach_and_cutoff() {
        let w = Wohler::from_knee(5.0, 50.0, 2e6, KneeKind::Haibach).unwrap();
        assert!(close(w.cycles_to_failure(50.0), 2e6));
        assert!(close(w.cycles_to_failure(100.0), 2e6 / 32.0));
        assert!(close(w.cycles_to_failure(25.0), 2e6 * 2f64.powi(9)));
        let c = Wohler::from_knee(5.0, 50.0, 2e6, KneeKind::CutOff).unwrap();
        assert_eq!(c.damage_per_cycle(49.0), 0.0);
        assert!(close(c.cycles_to_failure(50.0), 2e6));
    }

    #[test]
    fn equivalent_range_roundtrip() {
        let w = Wohler::new(5.0, 1e12).unwrap();
        let d = 1e3 * w.damage_per_cycle(20.0);
        assert!(close(w.equivalent_range(d, 1e3).unwrap(), 20.0));
        let wk = w.with_knee(10.0, KneeKind::CutOff).unwrap();
        assert!(wk.equivalent_range(d, 1e3).is_err());
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Wohler::new(0.0, 1.0).is_err());
        assert!(Wohler::new(-3.0, 1.0).is_err());
        assert!(Wohler::new(f64::NAN, 1.0).is_err());
        let e = Wohler::new(5.0, -1.0).unwrap_err();
        assert!(e.to_string().contains("alpha = -1"), "{e}");
        assert!(Wohler::new(5.0, 1.0)
            .unwrap()
            .with_knee(0.0, KneeKind::Haibach)
            .is_err());
        assert!(KneeKind::parse("elbow").is_err());
    }
}

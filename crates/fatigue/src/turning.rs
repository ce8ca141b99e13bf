//! Turning points (reversals) of a series, streaming, with an optional hysteresis gate.
//!
//! A turning point is a local extremum of the series. With a gate h > 0 a reversal is only
//! accepted once the series has retreated by more than h from the candidate extremum, so every
//! range between consecutive turning points exceeds h (small cycles are filtered out). With
//! h = 0 the result equals the reversals of ASTM E1049-85 / the PyPI `rainflow` package: the first
//! sample, every strict extremum (on a plateau: its last sample), and the last extremum.

use crate::FatigueError;

/// Streaming turning-point detector. Feed samples with [`TurningPoints::push`], then call
/// [`TurningPoints::finish`]. Holds no heap memory.
#[derive(Debug, Clone)]
pub struct TurningPoints {
    gate: f64,
    /// +1 rising, -1 falling, 0 not yet decided.
    dir: i8,
    started: bool,
    lo: (usize, f64),
    hi: (usize, f64),
    cand: (usize, f64),
}

impl TurningPoints {
    /// A detector with hysteresis gate `gate` (>= 0, same unit as the series).
    pub fn new(gate: f64) -> Result<Self, FatigueError> {
        if !(gate >= 0.0 && gate.is_finite()) {
            return Err(FatigueError::param(
                "hysteresis",
                gate,
                "must be a finite number >= 0",
            ));
        }
        Ok(Self::new_unchecked(gate))
    }

    pub(crate) fn new_unchecked(gate: f64) -> Self {
        TurningPoints {
            gate,
            dir: 0,
            started: false,
            lo: (0, 0.0),
            hi: (0, 0.0),
            cand: (0, 0.0),
        }
    }

    /// Forget all state (keeps the gate).
    #[inline]
    pub fn reset(&mut self) {
        *self = Self::new_unchecked(self.gate);
    }

    /// Feed sample `x` at index `i`; calls `out(index, value)` for each confirmed turning point.
    #[inline(always)]
    pub fn push(&mut self, i: usize, x: f64, mut out: impl FnMut(usize, f64)) {
        match self.dir {
            1 => {
                if x >= self.cand.1 {
                    self.cand = (i, x);
                } else if self.cand.1 - x > self.gate {
                    out(self.cand.0, self.cand.1);
                    self.dir = -1;
                    self.cand = (i, x);
                }
            }
            -1 => {
                if x <= self.cand.1 {
                    self.cand = (i, x);
                } else if x - self.cand.1 > self.gate {
                    out(self.cand.0, self.cand.1);
                    self.dir = 1;
                    self.cand = (i, x);
                }
            }
            _ => {
                if !self.started {
                    self.started = true;
                    self.lo = (i, x);
                    self.hi = (i, x);
                } else if x - self.lo.1 > self.gate {
                    // first move upwards: the lowest sample so far is the first turning point
                    out(self.lo.0, self.lo.1);
                    self.dir = 1;
                    self.cand = (i, x);
                } else if self.hi.1 - x > self.gate {
                    out(self.hi.0, self.hi.1);
                    self.dir = -1;
                    self.cand = (i, x);
                } else {
                    if x < self.lo.1 {
                        self.lo = (i, x);
                    }
                    if x > self.hi.1 {
                        self.hi = (i, x);
                    }
                }
            }
        }
    }

    /// End of the series: emits the last extremum. A series that never leaves the gate has a
    /// single turning point (its first sample) and hence no cycles.
    #[inline]
    pub fn finish(&mut self, mut out: impl FnMut(usize, f64)) {
        if self.dir != 0 {
            out(self.cand.0, self.cand.1);
        } else if self.started {
            out(self.lo.0, self.lo.1);
        }
        self.reset();
    }
}

/// Turning points of `series` as (indices, values). Errors on NaN/inf samples.
pub fn turning_points(
    series: &[f64],
    hysteresis: f64,
) -> Result<(Vec<usize>, Vec<f64>), FatigueError> {
    let mut tp = TurningPoints::new(hysteresis)?;
    let mut idx = Vec::new();
    let mut val = Vec::new();
    for (i, &x) in series.iter().enumerate() {
        if !x.is_finite() {
            return Err(FatigueError::NonFinite {
                series: 0,
                index: i,
                value: x,
            });
        }
        tp.push(i, x, |j, v| {
            idx.push(j);
            val.push(v);
        });
    }
    tp.finish(|j, v| {
        idx.push(j);
        val.push(v);
    });
    Ok((idx, val))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reversals_match_astm() {
        let s = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0];
        let (i, v) = turning_points(&s, 0.0).unwrap();
        assert_eq!(v, s.to_vec());
        assert_eq!(i, (0..9).collect::<Vec<_>>());
    }

    #[test]
    fn drops_intermediate_and_plateau_points() {
        let s = [0.0, 1.0, 2.0, 2.0, 1.0, 1.0, -1.0, 0.5];
        let (i, v) = turning_points(&s, 0.0).unwrap();
        assert_eq!(v, vec![0.0, 2.0, -1.0, 0.5]);
        assert_eq!(i, vec![0, 3, 6, 7]);
    }

    #[test]
    fn hysteresis_gate_removes_small_reversals() {
        let s = [0.0, 5.0, 4.5, 5.5, 0.2, 0.6, -1.0, 3.0];
        let (_, v) = turning_points(&s, 1.0).unwrap();
        assert_eq!(v, vec![0.0, 5.5, -1.0, 3.0]);
        // the gate also applies before the first reversal: the start is the extremum
        let s = [0.0, -0.5, 3.0, 0.0];
        let (i, v) = turning_points(&s, 1.0).unwrap();
        assert_eq!(v, vec![-0.5, 3.0, 0.0]);
        assert_eq!(i, vec![1, 2, 3]);
    }

    #[test]
    fn constant_and_short_series() {
        assert_eq!(turning_points(&[1.0, 1.0, 1.0], 0.0).unwrap().1, vec![1.0]);
        assert_eq!(turning_points(&[1.0], 0.0).unwrap().1, vec![1.0]);
        assert!(turning_points(&[], 0.0).unwrap().1.is_empty());
    }

    #[test]
    fn rejects_bad_input() {
        assert!(turning_points(&[0.0, f64::NAN], 0.0).is_err());
        assert!(TurningPoints::new(-1.0).is_err());
        assert!(TurningPoints::new(f64::NAN).is_err());
    }
}

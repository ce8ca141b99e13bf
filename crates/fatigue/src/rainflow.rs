//! Rainflow counting after ASTM E1049-85 §5.4.4 on turning points, with residue treatments.
//!
//! Implementation: ASTM's three-point rule on a stack. With X the newest range and Y the one
//! before it: if X < Y read the next point; if Y contains the starting point, count Y as a half
//! cycle and move the start past its first point; otherwise count Y as a full cycle and remove
//! its two points. Instead of deleting the start point, a start marker advances, so the whole
//! stack is the residue at the end: ASTM's start-rule half cycles (the points before the
//! marker) followed by the unclosed end of the history. Its consecutive pairs are exactly
//! ASTM's half cycles, in the same order, so [`Residue::Half`] reproduces ASTM E1049-85 and
//! the PyPI `rainflow` package cycle for cycle (ranges, means, counts, from/to indices); only
//! the order of emission differs (closed cycles as they close, residue half cycles last).
//!
//! Residue treatments ([`Residue`]):
//! - `Half` (ASTM default): each range of the residue counts 0.5 cycles.
//! - `Discard`: the residue is ignored (only closed hysteresis loops count; unconservative).
//! - `Full`: each range of the residue counts 1.0 cycle (conservative upper bound).
//! - `Repeated`: the history is taken as periodic (block loading). The ASTM residue is first
//!   reduced with the four-point rule (cycle B–C of A, B, C, D closes when |C−B| ≤ |B−A| and
//!   |C−B| ≤ |D−C|): ASTM's start-rule half cycles may still form closed loops (a constant
//!   amplitude history leaves all its ranges there), which count 1.0 each, once. The
//!   four-point residue R that remains closes no loop by itself; R followed by R is counted
//!   with the four-point rule and the loops it closes (those spanning the junction of two
//!   repetitions) count 1.0 each; its own residue (R again) is dropped. This equals counting
//!   the history rotated to start at its absolute extreme: a history of k periods of a
//!   constant-amplitude wave gives exactly k cycles, whatever its phase and round-off.
//!   It gives more damage than `Half` because large ranges pair up across the block
//!   boundary. From/to indices of these cycles refer to the residue samples in the original
//!   series (a cycle across the junction may have `to` < `from`).

use crate::turning::TurningPoints;
use crate::FatigueError;

/// What to do with the unclosed residue at the end of the counting.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Residue {
    /// Half cycles (ASTM E1049-85 default).
    #[default]
    Half,
    /// Ignore the residue.
    Discard,
    /// Full cycles.
    Full,
    /// Repeat the residue once (periodic history) and count the cycles it closes as full cycles.
    Repeated,
}

impl Residue {
    /// Parse `"half"`, `"discard"`, `"full"` or `"repeated"`.
    pub fn parse(name: &str) -> Result<Self, FatigueError> {
        match name {
            "half" => Ok(Residue::Half),
            "discard" => Ok(Residue::Discard),
            "full" => Ok(Residue::Full),
            "repeated" => Ok(Residue::Repeated),
            _ => Err(FatigueError::param(
                "residue",
                format!("{name:?}"),
                "must be one of \"half\", \"discard\", \"full\", \"repeated\"",
            )),
        }
    }
}

/// One counted (half) cycle: range (not amplitude), mean, count 0.5 or 1.0, and the sample
/// indices of its two turning points in time order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cycle {
    pub range: f64,
    pub mean: f64,
    pub count: f64,
    pub from: usize,
    pub to: usize,
}

#[inline(always)]
fn cycle(p: (usize, f64), q: (usize, f64), count: f64) -> Cycle {
    Cycle {
        range: (q.1 - p.1).abs(),
        mean: 0.5 * (p.1 + q.1),
        count,
        from: p.0,
        to: q.0,
    }
}

/// Push turning point `p` on a four-point stack and emit every cycle it closes.
#[inline(always)]
fn four_point_push(stack: &mut Vec<(usize, f64)>, p: (usize, f64), sink: &mut impl FnMut(Cycle)) {
    stack.push(p);
    loop {
        let n = stack.len();
        if n < 4 {
            return;
        }
        let a = stack[n - 4].1;
        let b = stack[n - 3];
        let c = stack[n - 2];
        let d = stack[n - 1].1;
        let inner = (c.1 - b.1).abs();
        if inner <= (b.1 - a).abs() && inner <= (d - c.1).abs() {
            sink(cycle(b, c, 1.0));
            stack[n - 3] = stack[n - 1];
            stack.truncate(n - 2);
        } else {
            return;
        }
    }
}

/// Streaming ASTM rainflow counter on turning points. Its stacks are reused between series,
/// so counting many series allocates only while a stack grows beyond its previous maximum.
#[derive(Debug, Clone, Default)]
pub struct Rainflow {
    stack: Vec<(usize, f64)>,
    /// ASTM's starting point: stack[..start] are the start-rule half cycles' points.
    start: usize,
    scratch: Vec<(usize, f64)>,
}

impl Rainflow {
    pub fn new() -> Self {
        Self::default()
    }

    /// Drop all state (keeps the capacity).
    pub fn clear(&mut self) {
        self.stack.clear();
        self.scratch.clear();
        self.start = 0;
    }

    /// Feed the next turning point (sample index, value); emits closed full cycles.
    #[inline(always)]
    pub fn push(&mut self, index: usize, value: f64, sink: &mut impl FnMut(Cycle)) {
        let stack = &mut self.stack;
        stack.push((index, value));
        loop {
            let n = stack.len();
            if n - self.start < 3 {
                return;
            }
            let p1 = stack[n - 3];
            let p2 = stack[n - 2];
            let x = (value - p2.1).abs();
            let y = (p2.1 - p1.1).abs();
            if x < y {
                return;
            }
            if n - self.start == 3 {
                // Y contains the starting point: a half cycle of the residue
                self.start += 1;
            } else {
                sink(cycle(p1, p2, 1.0));
                stack[n - 3] = stack[n - 1];
                stack.truncate(n - 2);
            }
        }
    }

    /// The current residue (all turning points not in a closed cycle, in time order).
    pub fn residue(&self) -> &[(usize, f64)] {
        &self.stack
    }

    /// End of the series: emit the residue cycles by `residue` and reset. `gate` is the
    /// hysteresis used for the turning points (reapplied at the junction of a repeated residue).
    pub fn finish(&mut self, residue: Residue, gate: f64, sink: &mut impl FnMut(Cycle)) {
        match residue {
            Residue::Discard => {}
            Residue::Half | Residue::Full => {
                let count = if residue == Residue::Half { 0.5 } else { 1.0 };
                for w in self.stack.windows(2) {
                    sink(cycle(w[0], w[1], count));
                }
            }
            Residue::Repeated => {
                // 1. The ASTM residue still holds closed loops (its start-rule half cycles
                //    are not a four-point residue): close them once, as full cycles.
                let scratch = &mut self.scratch;
                scratch.clear();
                for &p in self.stack.iter() {
                    four_point_push(scratch, p, sink);
                }
                // 2. The four-point residue R has no closed loop of its own; counting R R
                //    closes exactly the loops that span the junction of two repetitions
                //    (its own residue is R again and is dropped).
                std::mem::swap(&mut self.stack, scratch);
                scratch.clear();
                let mut tp = TurningPoints::new_unchecked(gate);
                for _ in 0..2 {
                    for &(i, x) in self.stack.iter() {
                        tp.push(i, x, |j, v| four_point_push(scratch, (j, v), sink));
                    }
                }
                tp.finish(|j, v| four_point_push(scratch, (j, v), sink));
                scratch.clear();
            }
        }
        self.stack.clear();
        self.start = 0;
    }
}

/// Options of the counting: residue treatment and hysteresis gate (>= 0, unit of the series).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct CountOptions {
    pub residue: Residue,
    pub hysteresis: f64,
}

impl CountOptions {
    pub fn new(residue: Residue, hysteresis: f64) -> Result<Self, FatigueError> {
        TurningPoints::new(hysteresis)?;
        Ok(CountOptions {
            residue,
            hysteresis,
        })
    }
}

/// Count the samples of one series (`series_id` only labels errors) with reusable state and
/// pass every cycle to `sink`. Errors on a non-finite sample.
#[inline]
pub fn for_each_cycle(
    samples: impl Iterator<Item = f64>,
    options: &CountOptions,
    series_id: usize,
    rainflow: &mut Rainflow,
    sink: &mut impl FnMut(Cycle),
) -> Result<(), FatigueError> {
    let mut tp = TurningPoints::new_unchecked(options.hysteresis);
    rainflow.clear();
    for (i, x) in samples.enumerate() {
        if !x.is_finite() {
            rainflow.clear();
            return Err(FatigueError::NonFinite {
                series: series_id,
                index: i,
                value: x,
            });
        }
        tp.push(i, x, |j, v| rainflow.push(j, v, sink));
    }
    tp.finish(|j, v| rainflow.push(j, v, sink));
    rainflow.finish(options.residue, options.hysteresis, sink);
    Ok(())
}

/// All cycles of `series`. Errors on an empty series or a non-finite sample.
pub fn count_cycles(series: &[f64], options: &CountOptions) -> Result<Vec<Cycle>, FatigueError> {
    if series.is_empty() {
        return Err(FatigueError::param(
            "series",
            "[] (empty)",
            "needs at least one sample",
        ));
    }
    let mut cycles = Vec::new();
    let mut rf = Rainflow::new();
    for_each_cycle(series.iter().copied(), options, 0, &mut rf, &mut |c| {
        cycles.push(c)
    })?;
    Ok(cycles)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASTM: [f64; 9] = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0];

    /// Histogram range -> total count, sorted by range.
    fn histogram(cycles: &[Cycle]) -> Vec<(f64, f64)> {
        let mut h: Vec<(f64, f64)> = Vec::new();
        let mut cs: Vec<_> = cycles.iter().map(|c| (c.range, c.count)).collect();
        cs.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
        for (r, n) in cs {
            match h.last_mut() {
                Some(last) if last.0 == r => last.1 += n,
                _ => h.push((r, n)),
            }
        }
        h
    }

    fn count(series: &[f64], residue: Residue) -> Vec<Cycle> {
        count_cycles(series, &CountOptions::new(residue, 0.0).unwrap()).unwrap()
    }

    #[test]
    fn astm_e1049_example() {
        let h = histogram(&count(&ASTM, Residue::Half));
        assert_eq!(
            h,
            vec![(3.0, 0.5), (4.0, 1.5), (6.0, 0.5), (8.0, 1.0), (9.0, 0.5)]
        );
    }

    #[test]
    fn astm_example_means_and_indices() {
        let c = count(&ASTM, Residue::Half);
        // the closed cycle -1 -> 3 (samples 4, 5), then the residue -2 1 -3 5 -4 4 -2
        assert_eq!(
            c[0],
            Cycle {
                range: 4.0,
                mean: 1.0,
                count: 1.0,
                from: 4,
                to: 5
            }
        );
        let froms: Vec<usize> = c[1..].iter().map(|c| c.from).collect();
        assert_eq!(froms, vec![0, 1, 2, 3, 6, 7]);
        assert!(c[1..].iter().all(|c| c.count == 0.5 && c.to > c.from));
    }

    #[test]
    fn residue_treatments() {
        assert_eq!(histogram(&count(&ASTM, Residue::Discard)), vec![(4.0, 1.0)]);
        assert_eq!(
            histogram(&count(&ASTM, Residue::Full)),
            vec![(3.0, 1.0), (4.0, 2.0), (6.0, 1.0), (8.0, 2.0), (9.0, 1.0)]
        );
        // periodic repetition of the ASTM history: 5 -1 3 -4 4 -2 1 -3 5 closes 4, 3, 7, 9
        assert_eq!(
            histogram(&count(&ASTM, Residue::Repeated)),
            vec![(3.0, 1.0), (4.0, 1.0), (7.0, 1.0), (9.0, 1.0)]
        );
    }

    #[test]
    fn repeated_residue_merges_the_junction() {
        // 0 2 -1 repeated: 0 -> 2 -> -1 -> (0) -> 2 -> -1: one cycle of range 3
        assert_eq!(
            histogram(&count(&[0.0, 2.0, -1.0], Residue::Repeated)),
            vec![(3.0, 1.0)]
        );
    }

    /// k periods of sin(2π t/P + φ) sampled at t = 0 … n−1.
    fn sine(period: usize, periods: usize, phase: f64, closed: bool) -> Vec<f64> {
        let n = period * periods + usize::from(closed);
        (0..n)
            .map(|t| (2.0 * std::f64::consts::PI * t as f64 / period as f64 + phase).sin())
            .collect()
    }

    #[test]
    fn repeated_residue_counts_periods_of_a_constant_amplitude_wave() {
        // the reported cases: 5 periods of 40 samples, and a square wave of 3 periods
        let c = count(&sine(40, 5, 0.0, true), Residue::Repeated);
        assert_eq!(c.iter().map(|c| c.count).sum::<f64>(), 5.0);
        let c = count(&[0., 1., -1., 1., -1., 1., -1., 0.], Residue::Repeated);
        assert_eq!(histogram(&c), vec![(2.0, 3.0)]);
        for period in [4, 5, 7, 10, 13, 40, 41, 100] {
            for periods in [1, 2, 3, 5, 8, 21] {
                for k in 0..12 {
                    let phase = k as f64 * 0.53 + 0.01 * period as f64;
                    for closed in [false, true] {
                        let s = sine(period, periods, phase, closed);
                        let peak = s.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                        let case = format!("P {period} × {periods}, φ {phase}, closed {closed}");
                        // gate 0: the full swings are exactly the periods; a closed series
                        // may also hold a round-off reversal where its ends meet (sample 0
                        // and sample n−1 differ in the last bit), counted as a cycle of its
                        // own ~1e-16 range
                        let c = count(&s, Residue::Repeated);
                        let swings: Vec<&Cycle> = c.iter().filter(|c| c.range > 1e-12).collect();
                        assert_eq!(swings.len(), periods, "{case}: {c:?}");
                        assert!(
                            swings
                                .iter()
                                .all(|c| c.count == 1.0 && c.range > 1.4 * peak),
                            "{case}: {c:?}"
                        );
                        // a gate above round-off: exactly the periods
                        let o = CountOptions::new(Residue::Repeated, 1e-9).unwrap();
                        let c = count_cycles(&s, &o).unwrap();
                        assert_eq!(c.iter().map(|c| c.count).sum::<f64>(), periods as f64);
                    }
                }
            }
        }
    }

    #[test]
    fn half_residue_of_a_sine_is_astm() {
        // 0 1 -1 1 -1 … 0 (5 periods): ASTM counts ranges 1 (twice) and 2 as half cycles only
        // where they are not closed; total range·count is the same whatever the round-off
        let c = count(&sine(40, 5, 0.0, true), Residue::Half);
        let total: f64 = c.iter().map(|c| c.count).sum();
        let ranges: f64 = c.iter().map(|c| c.count * c.range).sum();
        assert!((ranges - 10.0).abs() < 1e-9, "{c:?}");
        assert!(
            (total - 5.5).abs() < 1e-12 || (total - 6.0).abs() < 1e-12,
            "{c:?}"
        );
    }

    #[test]
    fn constant_amplitude_cycles() {
        let s: Vec<f64> = (0..41)
            .map(|i| if i % 2 == 0 { -1.0 } else { 1.0 })
            .collect();
        // 40 ranges of 2: 19 closed cycles and a residue of two half cycles
        let h = histogram(&count(&s, Residue::Half));
        assert_eq!(h.len(), 1);
        assert_eq!(h[0], (2.0, 20.0));
    }

    #[test]
    fn errors() {
        let o = CountOptions::default();
        assert!(count_cycles(&[], &o).is_err());
        let e = count_cycles(&[0.0, 1.0, f64::INFINITY], &o).unwrap_err();
        assert!(e.to_string().contains("index 2"), "{e}");
        assert!(Residue::parse("halves").is_err());
        assert!(CountOptions::new(Residue::Half, -0.1).is_err());
    }
}

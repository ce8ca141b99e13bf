//! The dynamic step's predictor of the accelerations, learnt from the run itself:
//! v̇_{n+1} ≈ v̇_n + μ v̇_n + λ (v̇_n − v̇_{n−1}).
//!
//! The Newton iteration of a step starts from predicted accelerations; its first correction
//! is the predictor's error, and the later ones shrink with it (the iteration matrix is
//! reused over many steps). The increments d_n = v̇_{n+1} − v̇_n are fitted, by least squares
//! over the accepted steps with exponential forgetting (`MEMORY` steps), as d_n ≈ μ v̇_n +
//! λ d_{n−1}: a linear recursion of order two, v̇_{n+1} = (1 + μ + λ) v̇_n − λ v̇_{n−1}. It
//! holds exactly for a sampled sinusoid, v̇_n = sin(ω n h): μ = 2 cos ωh − 2, λ = 1 — a
//! response dominated by one frequency is predicted almost exactly; a constant acceleration
//! gives μ = λ = 0 (constant acceleration, the predictor before), a ramp μ = 0, λ = 1 (linear
//! extrapolation), uncorrelated accelerations μ = −1, λ = 0 (their mean). The fit is taken
//! separately for the translational unknowns (m/s²), the bending rotations and the twist
//! (rad/s²; the twist's torsion dynamics are of their own: 1.73 → 1.70 iterations per step on
//! the harness benchmark, 1.47 → 1.40 on its single cable, against one fit for all rotations), with a ridge
//! of 1e-3 on the normal equations' diagonal (collinear data: alternation, constant motion)
//! and held to μ ∈ [−4, 0.5], λ ∈ [−1, 1.5], around the sinusoids' μ ∈ [−4, 0], λ = 1 (a fit
//! beyond is noise). Measured in docs/dynamics.md ("Predictor").
//!
//! The predictor changes only where Newton starts: the converged step is the same to the
//! tolerance, which bounds the iteration error by the time error.
use nalgebra::Vector6;

/// Steps of memory of the fit (forgetting factor 1 − 1/MEMORY per step).
const MEMORY: f64 = 20.0;
/// Steps observed before the fit is used (constant acceleration until then).
const WARM_UP: usize = 3;
/// Groups of unknowns fitted separately, and each slot's group.
const GROUPS: usize = 3;
const GROUP: [usize; 6] = [0, 0, 0, 1, 1, 2];
/// Ridge on the diagonal of the normal equations, relative.
const RIDGE: f64 = 1e-3;

/// The sums of the least-squares fit d_n ≈ μ v̇_n + λ d_{n−1} of one kind of unknown:
/// Σ v̇², Σ v̇ d_old, Σ d_old², Σ d v̇, Σ d d_old (exponentially weighted).
#[derive(Clone, Copy, Debug, Default)]
struct Fit([f64; 5]);

impl Fit {
    /// (μ, λ), or constant acceleration where the data do not determine them.
    fn solve(&self) -> (f64, f64) {
        let [vv, vd, dd, rv, rd] = self.0;
        let (a, c) = (vv * (1.0 + RIDGE), dd * (1.0 + RIDGE));
        let det = a * c - vd * vd;
        if det.is_nan() || det <= 0.0 || det.is_infinite() {
            return (0.0, 0.0);
        }
        let mu = (rv * c - vd * rd) / det;
        let lambda = (a * rd - vd * rv) / det;
        (mu.clamp(-4.0, 0.5), lambda.clamp(-1.0, 1.5))
    }
}

/// The extrapolation of one set of unknowns (a cable's blocks, a harness's junctions).
#[derive(Clone, Debug, Default)]
pub(crate) struct Extrapolation {
    /// v̇_{n−1} at the start of a step (from the second observed step on).
    prev: Vec<Vector6<f64>>,
    /// Translations, bending rotations, twist.
    fits: [Fit; GROUPS],
    /// Step size of the observed steps; steps observed since the last reset.
    h: f64,
    observed: usize,
    /// Size of the step begun last (None: none since a restart).
    last: Option<f64>,
}

impl Extrapolation {
    pub(crate) fn new(n: usize) -> Self {
        Extrapolation {
            prev: vec![Vector6::zeros(); n],
            ..Default::default()
        }
    }

    /// (μ, λ) for translations, bending rotations and twist (0 until enough steps are
    /// observed).
    pub(crate) fn coefficients(&self) -> [(f64, f64); GROUPS] {
        if self.observed < WARM_UP {
            return [(0.0, 0.0); GROUPS];
        }
        self.fits.map(|f| f.solve())
    }

    /// The start of a step of size `h`, in one pass: `vdot` holds v̇_n (the end of the step
    /// just accepted; `restarted`: the step begun last was given up or the integrator
    /// restarted, which forgets the past: the last accelerations may hold a shock) and
    /// `vdot_n` v̇_{n−1}. Adds the accepted step to the
    /// fit (d = v̇_n − v̇_{n−1} against v̇_{n−1} and d_old = v̇_{n−1} − v̇_{n−2}), sets `vdot_n`
    /// to v̇_n and, with `predict` and a step of the observed size, `vdot` to the prediction
    /// v̇_n + μ v̇_n + λ (v̇_n − v̇_{n−1}) (the fit of the steps before; the unknowns with
    /// `inertial[b][k]`, None: all). Otherwise `vdot` keeps v̇_n (constant acceleration).
    /// Steps of another size restart the count (the increments scale with the step).
    pub(crate) fn begin_step(
        &mut self,
        vdot: &mut [Vector6<f64>],
        vdot_n: &mut [Vector6<f64>],
        inertial: Option<&[[bool; 6]]>,
        restarted: bool,
        h: f64,
        predict: bool,
    ) {
        let h_last = if restarted { None } else { self.last };
        self.last = Some(h);
        match h_last {
            Some(h_last) if h_last == self.h => {}
            _ => {
                self.fits = Default::default();
                self.observed = 0;
                self.h = h_last.unwrap_or(0.0);
            }
        }
        let c = if predict && h == self.h {
            self.coefficients()
        } else {
            [(0.0, 0.0); GROUPS]
        };
        let mu: [f64; GROUPS] = c.map(|x| x.0);
        let lambda: [f64; GROUPS] = c.map(|x| x.1);
        let extrapolate = mu != [0.0; GROUPS] || lambda != [0.0; GROUPS];
        let observe = self.observed > 0;
        let mut sums = [[0.0; 5]; GROUPS];
        let all = [true; 6];
        for (b, ((v, l), p)) in vdot
            .iter_mut()
            .zip(vdot_n.iter_mut())
            .zip(&mut self.prev)
            .enumerate()
        {
            let m = inertial.map_or(&all, |m| &m[b]);
            let now = *v;
            let d = now - *l;
            if observe {
                let d_old = *l - *p;
                for k in 0..6 {
                    if m[k] {
                        let s = &mut sums[GROUP[k]];
                        s[0] += l[k] * l[k];
                        s[1] += l[k] * d_old[k];
                        s[2] += d_old[k] * d_old[k];
                        s[3] += d[k] * l[k];
                        s[4] += d[k] * d_old[k];
                    }
                }
            }
            if extrapolate {
                for k in 0..6 {
                    if m[k] {
                        v[k] = now[k] + mu[GROUP[k]] * now[k] + lambda[GROUP[k]] * d[k];
                    }
                }
            }
            *p = *l;
            *l = now;
        }
        if observe {
            let keep = 1.0 - 1.0 / MEMORY;
            for (fit, sum) in self.fits.iter_mut().zip(sums) {
                for (f, s) in fit.0.iter_mut().zip(sum) {
                    *f = keep * *f + s;
                }
            }
        }
        if h_last.is_some() {
            self.observed += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps of 1 ms through the values `signal(0..steps)` of one unknown (all six slots):
    /// the predictions made at the start of every step after the first.
    fn run(signal: impl Fn(usize) -> f64, steps: usize) -> (Extrapolation, Vec<f64>) {
        let mut e = Extrapolation::new(1);
        let mut vdot_n = vec![Vector6::repeat(signal(0))];
        let mut predicted = vec![];
        for t in 1..steps {
            let mut vdot = vec![Vector6::repeat(signal(t))];
            e.begin_step(&mut vdot, &mut vdot_n, None, false, 1e-3, true);
            assert_eq!(vdot_n[0], Vector6::repeat(signal(t)));
            predicted.push(vdot[0][0]);
        }
        (e, predicted)
    }

    /// RMS of the prediction errors from step `from` on, against constant acceleration's.
    fn error_ratio(signal: impl Fn(usize) -> f64, predicted: &[f64], from: usize) -> f64 {
        let (mut err, mut err0) = (0.0, 0.0);
        for t in from..predicted.len() {
            // predicted[t - 1] was made at step t for step t + 1
            err += (predicted[t - 1] - signal(t + 1)).powi(2);
            err0 += (signal(t) - signal(t + 1)).powi(2);
        }
        (err / err0).sqrt()
    }

    #[test]
    fn a_sinusoid_is_predicted_by_its_recursion() {
        // v̇ = sin(w n) fits d_n = μ v̇_n + λ d_{n−1} exactly with μ = 2 cos w − 2, λ = 1 (the
        // ridge of 1e-3 moves them by a few 1e-3)
        for steps_per_period in [8.0, 20.0, 60.0] {
            let w = 2.0 * std::f64::consts::PI / steps_per_period;
            let x = |t: usize| (w * t as f64).sin();
            let (e, predicted) = run(x, 600);
            let [(mu, la), bend, twist] = e.coefficients();
            for (m, l) in [bend, twist] {
                assert!((m - mu).abs() < 1e-12 && (l - la).abs() < 1e-12, "{m} {l}");
            }
            assert!((mu - (2.0 * w.cos() - 2.0)).abs() < 0.01, "{mu}");
            assert!((la - 1.0).abs() < 0.01, "{la}");
            // the prediction error against constant acceleration's (RMS ratio sin w for the
            // best linear extrapolation alone): below 2 %
            let ratio = error_ratio(x, &predicted, 100);
            assert!(ratio < 0.02, "{steps_per_period}: {ratio}");
        }
    }

    #[test]
    fn translations_bending_rotations_and_twist_have_their_own_recursions() {
        // each group a sinusoid of its own frequency: each fit finds its own μ = 2 cos w − 2
        let w = [0.3, 0.1, 0.7];
        let signal = |t: usize| Vector6::from_fn(|k, _| (w[GROUP[k]] * t as f64 + k as f64).sin());
        let mut e = Extrapolation::new(1);
        let mut vdot_n = vec![signal(0)];
        for t in 1..400 {
            let mut vdot = vec![signal(t)];
            e.begin_step(&mut vdot, &mut vdot_n, None, false, 1e-3, true);
        }
        for (g, (mu, la)) in e.coefficients().into_iter().enumerate() {
            assert!(
                (mu - (2.0 * w[g].cos() - 2.0)).abs() < 0.01,
                "group {g}: {mu}"
            );
            assert!((la - 1.0).abs() < 0.01, "group {g}: {la}");
        }
    }

    #[test]
    fn ramps_constants_and_alternation() {
        // a ramp: linear extrapolation (μ = 0, λ = 1), up to the ridge: over the 20 steps of
        // memory v̇ and its increments are nearly collinear there, and the ridge on Σ v̇²
        // (≈ 100 × Σ d²) pulls λ by a few per cent
        let (e, predicted) = run(|t| 0.5 * t as f64, 100);
        let [(mu, la), ..] = e.coefficients();
        assert!(mu.abs() < 1e-3 && (la - 1.0).abs() < 0.03, "{mu} {la}");
        assert!(error_ratio(|t| 0.5 * t as f64, &predicted, 50) < 0.03);
        // a constant: nothing to fit, constant acceleration (exact)
        let (e, predicted) = run(|_| 3.0, 50);
        assert_eq!(e.coefficients(), [(0.0, 0.0); GROUPS]);
        assert!(predicted.iter().all(|&p| p == 3.0));
        // alternation (the sampling limit): −v̇_n, to the ridge
        let alt = |t: usize| if t.is_multiple_of(2) { 1.0 } else { -1.0 };
        let (_, predicted) = run(alt, 100);
        assert!(error_ratio(alt, &predicted, 50) < 1e-2);
        // too few steps: constant acceleration
        let (e, _) = run(|t| (t * t) as f64, WARM_UP);
        assert_eq!(e.coefficients(), [(0.0, 0.0); GROUPS]);
    }

    #[test]
    fn restarts_other_step_sizes_and_masks() {
        let ramp = |t: usize| vec![Vector6::repeat(t as f64), Vector6::repeat(-(t as f64))];
        let mask = [[true, true, true, false, false, false], [false; 6]];
        let mut e = Extrapolation::new(2);
        let mut vdot_n = ramp(0);
        let mut step = |e: &mut Extrapolation, t: usize, restarted: bool, h: f64| {
            let mut vdot = ramp(t);
            e.begin_step(&mut vdot, &mut vdot_n, Some(&mask), restarted, h, true);
            vdot
        };
        for t in 1..50 {
            step(&mut e, t, false, 1e-3);
        }
        // a ramp: λ ≈ 1 for translations (up to the ridge, above); no rotational unknowns: 0
        let [(mu, la), bend, twist] = e.coefficients();
        assert!(mu.abs() < 1e-3 && (la - 1.0).abs() < 0.03);
        assert_eq!([bend, twist], [(0.0, 0.0); 2]);
        let vd = step(&mut e, 50, false, 1e-3);
        assert!((vd[0][0] - 51.0).abs() < 0.1, "{}", vd[0][0]);
        assert_eq!(vd[0].fixed_rows::<3>(3).sum(), 3.0 * 50.0);
        assert_eq!(vd[1], ramp(50)[1]);
        // a step of another size: constant acceleration, and the count starts again
        let vd = step(&mut e, 51, false, 5e-4);
        assert_eq!(vd, ramp(51));
        let vd = step(&mut e, 52, false, 5e-4);
        assert_eq!((vd, e.coefficients()), (ramp(52), [(0.0, 0.0); GROUPS]));
        // a restart forgets the past
        for t in 53..60 {
            step(&mut e, t, false, 5e-4);
        }
        assert_ne!(e.coefficients(), [(0.0, 0.0); GROUPS]);
        let vd = step(&mut e, 60, true, 5e-4);
        assert_eq!((vd, e.coefficients()), (ramp(60), [(0.0, 0.0); GROUPS]));
    }
}

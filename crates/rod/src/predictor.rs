//! The dynamic step's predictor of the accelerations, learnt from the run itself:
//! v̇_{n+1} ≈ v̇_n + c₀ v̇_n + c₁ d_{n−1} + … + c₅ d_{n−5}, d_k = v̇_{k+1} − v̇_k.
//!
//! The Newton iteration of a step starts from predicted accelerations; its first correction
//! is the predictor's error, and the later ones shrink with it (the iteration matrix is
//! reused over many steps). The increments d_n = v̇_{n+1} − v̇_n are fitted, by least squares
//! over the accepted steps with exponential forgetting (`MEMORY` steps), as d_n ≈ c₀ v̇_n +
//! c₁ d_{n−1} + … + c₅ d_{n−5}: a linear recursion of order `ORDER` = 6 on v̇. A recursion of
//! order 2k holds exactly for any sum of k sampled sinusoids (or damped ones) at the
//! frequencies it fitted, whatever their amplitudes and phases at each unknown: a response
//! dominated by up to three modes is predicted almost exactly. Constant acceleration
//! (c = 0: the predictor before session 16), linear extrapolation and the mean of
//! uncorrelated accelerations are special cases. The fit is taken separately for the
//! translational unknowns (m/s²), the bending rotations and the twist (rad/s²; the twist's
//! torsion dynamics are of their own), with a ridge of 1e-5 on the normal equations' diagonal
//! (collinear data: one sinusoid, alternation, constant motion), on every `STRIDE`-th block
//! in turn (the fit costs ORDER² per unknown, the prediction ORDER). The full order is used
//! only where it leaves less than a quarter (`HIGHER`) of the squared residual of order 2
//! (the leading two terms: session 16's recursion d_n ≈ μ v̇_n + λ d_{n−1}, exact for one
//! sinusoid), else order 2; a fit that explains the increments no better than none is not
//! used. Where a few modes dominate (the harness benchmark) order 6 takes the iterations per
//! step from 1.70 to 1.16–1.19; in a broadband response (bench_dynamic.py, 10–200 Hz) its
//! smaller first corrections left more of what a stale matrix handles badly (0.23 → 0.36
//! refactorizations per step, 7 % slower), which the choice avoids (docs/dynamics.md,
//! "Predictor").
//!
//! The predictor changes only where Newton starts: the converged step is the same to the
//! tolerance, which bounds the iteration error by the time error.
use nalgebra::{SMatrix, SVector, Vector6};

/// Regressors of the recursion: v̇_n and the increments d_{n−1} … d_{n−ORDER+1}.
const ORDER: usize = 6;
/// Steps of memory of the fit (forgetting factor 1 − 1/MEMORY per step).
const MEMORY: f64 = 20.0;
/// Fits observed before the recursion is used (constant acceleration until then).
const WARM_UP: usize = 3;
/// Ridge on the diagonal of the normal equations, relative.
const RIDGE: f64 = 1e-5;
/// The full order is used where its fit leaves less than this fraction of the squared
/// residual of order 2 (otherwise order 2; see `Fit::solve`).
const HIGHER: f64 = 0.25;
/// Groups of unknowns fitted separately (translations, bending rotations, twist) and each
/// slot's group.
const GROUPS: usize = 3;
const GROUP: [usize; 6] = [0, 0, 0, 1, 1, 2];
/// Blocks in the fit: every STRIDE-th (in turn), where there are at least 8·STRIDE.
const STRIDE: usize = 4;

type Coefficients = SVector<f64, ORDER>;
/// Entries of the upper triangle of an ORDER × ORDER matrix.
const TRI: usize = ORDER * (ORDER + 1) / 2;

/// The exponentially weighted normal equations of one group: Σ x xᵀ, Σ x y, Σ y².
#[derive(Clone, Copy, Debug)]
struct Fit {
    a: SMatrix<f64, ORDER, ORDER>,
    b: Coefficients,
    yy: f64,
}

impl Default for Fit {
    fn default() -> Self {
        Fit {
            a: SMatrix::zeros(),
            b: Coefficients::zeros(),
            yy: 0.0,
        }
    }
}

impl Fit {
    /// The coefficients, or none (constant acceleration) where they do not explain the data
    /// better than no increment at all.
    fn solve(&self) -> Coefficients {
        let mut a = self.a;
        for k in 0..ORDER {
            a[(k, k)] *= 1.0 + RIDGE;
        }
        // order 2 (the leading block: v̇_n, d_{n−1})
        let (a2, b2) = (
            a.fixed_view::<2, 2>(0, 0).into_owned(),
            self.b.fixed_rows::<2>(0),
        );
        let c2 = a2.cholesky().map(|ch| ch.solve(&b2.into_owned()));
        let sse2 = c2.map_or(self.yy, |c| self.yy - c.dot(&b2));
        let c = a.cholesky().map(|ch| ch.solve(&self.b));
        let sse = c.map_or(self.yy, |c| self.yy - c.dot(&self.b));
        let pick = match (c, c2) {
            (Some(c), _) if sse < HIGHER * sse2 && sse < self.yy => Some(c),
            (_, Some(c2)) if sse2 < self.yy => {
                let mut c = Coefficients::zeros();
                c.fixed_rows_mut::<2>(0).copy_from(&c2);
                Some(c)
            }
            _ => None,
        };
        match pick {
            Some(c) if c.iter().all(|x| x.is_finite()) => c,
            _ => Coefficients::zeros(),
        }
    }
}

/// The extrapolation of one set of unknowns (a cable's blocks, a harness's junctions).
#[derive(Clone, Debug, Default)]
pub(crate) struct Extrapolation {
    /// The increments d_{n−2} … d_{n−ORDER} per block (rows by age, `head` the newest).
    ring: Vec<Vector6<f64>>,
    head: usize,
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
            ring: vec![Vector6::zeros(); (ORDER - 1) * n],
            ..Default::default()
        }
    }

    /// The recursion's coefficients per group (0 until enough steps are observed).
    pub(crate) fn coefficients(&self) -> [Coefficients; GROUPS] {
        if self.observed < ORDER + WARM_UP {
            return [Coefficients::zeros(); GROUPS];
        }
        self.fits.map(|f| f.solve())
    }

    /// The start of a step of size `h`, in one pass: `vdot` holds v̇_n (the end of the step
    /// just accepted; `restarted`: the step begun last was given up or the integrator
    /// restarted, which forgets the past: the last accelerations may hold a shock) and
    /// `vdot_n` v̇_{n−1}. Adds the accepted step to the fit, sets `vdot_n` to v̇_n and, with
    /// `predict` and a step of the observed size, `vdot` to the prediction (the fit of the
    /// steps before; the unknowns with `inertial[b][k]`, None: all). Otherwise `vdot` keeps
    /// v̇_n (constant acceleration). Steps of another size restart the count (the increments
    /// scale with the step).
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
            [Coefficients::zeros(); GROUPS]
        };
        let extrapolate = c.iter().any(|c| c.iter().any(|&x| x != 0.0));
        // the fit needs v̇_{n−1} and d_{n−2} … d_{n−ORDER}: vdot_n and ORDER − 1 rows
        let observe = self.observed >= ORDER;
        let n = self.ring.len() / (ORDER - 1);
        let stride = if n >= 8 * STRIDE { STRIDE } else { 1 };
        let phase = self.observed % stride;
        let rows: [usize; ORDER - 1] = std::array::from_fn(|j| ((self.head + j) % (ORDER - 1)) * n);
        // per slot the coefficients of its group (Vector6 arithmetic over the block)
        let cv: [Vector6<f64>; ORDER] =
            std::array::from_fn(|i| Vector6::from_fn(|k, _| c[GROUP[k]][i]));
        // per slot (lanes) the upper triangle of Σ x xᵀ (row by row), Σ x y, Σ y²; summed
        // into the groups after the pass
        let mut sums = [Vector6::<f64>::zeros(); TRI + ORDER + 1];
        let all = [true; 6];
        for (b, (v, l)) in vdot.iter_mut().zip(vdot_n.iter_mut()).enumerate() {
            let m = inertial.map_or(&all, |m| &m[b]);
            let mask = Vector6::from_fn(|k, _| if m[k] { 1.0 } else { 0.0 });
            let now = *v;
            // the increment just observed, d_{n−1} = v̇_n − v̇_{n−1}, and its regressors
            // x = (v̇_{n−1}, d_{n−2}, …, d_{n−ORDER})
            let y = now - *l;
            let mut x = [*l; ORDER];
            for i in 1..ORDER {
                x[i] = self.ring[rows[i - 1] + b];
            }
            if observe && b % stride == phase {
                let mut t = 0;
                for (r, xr) in x.iter().enumerate() {
                    let xr = xr.component_mul(&mask);
                    for xq in &x[r..] {
                        sums[t] += xr.component_mul(xq);
                        t += 1;
                    }
                    sums[TRI + r] += xr.component_mul(&y);
                }
                sums[TRI + ORDER] += y.component_mul(&y).component_mul(&mask);
            }
            if extrapolate {
                // v̇_{n+1} = v̇_n + c₀ v̇_n + c₁ d_{n−1} + c₂ d_{n−2} + …
                let mut p = cv[0].component_mul(&now) + cv[1].component_mul(&y);
                for i in 2..ORDER {
                    p += cv[i].component_mul(&x[i - 1]);
                }
                *v = now + p.component_mul(&mask);
            }
            // d_{n−1} becomes the newest row (over the oldest), v̇_n the caller's v̇_n
            self.ring[rows[ORDER - 2] + b] = y;
            *l = now;
        }
        self.head = (self.head + ORDER - 2) % (ORDER - 1);
        if observe {
            let keep = 1.0 - 1.0 / MEMORY;
            for (g, fit) in self.fits.iter_mut().enumerate() {
                let mut s = [0.0; TRI + ORDER + 1];
                for (t, lanes) in sums.iter().enumerate() {
                    for k in 0..6 {
                        if GROUP[k] == g {
                            s[t] += lanes[k];
                        }
                    }
                }
                let mut t = 0;
                for r in 0..ORDER {
                    for q in r..ORDER {
                        fit.a[(r, q)] = keep * fit.a[(r, q)] + s[t];
                        fit.a[(q, r)] = fit.a[(r, q)];
                        t += 1;
                    }
                    fit.b[r] = keep * fit.b[r] + s[TRI + r];
                }
                fit.yy = keep * fit.yy + s[TRI + ORDER];
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

    /// Steps of 1 ms through the values `signal(t)` (per slot): the predictions made at the
    /// start of every step for the next.
    fn run(
        signal: impl Fn(usize) -> Vector6<f64>,
        steps: usize,
    ) -> (Extrapolation, Vec<Vector6<f64>>) {
        let mut e = Extrapolation::new(1);
        let mut vdot_n = vec![signal(0)];
        let mut predicted = vec![];
        for t in 1..steps {
            let mut vdot = vec![signal(t)];
            e.begin_step(&mut vdot, &mut vdot_n, None, false, 1e-3, true);
            assert_eq!(vdot_n[0], signal(t));
            predicted.push(vdot[0]);
        }
        (e, predicted)
    }

    /// Per slot, the RMS of the prediction errors from step `from` on against constant
    /// acceleration's; the largest over the slots.
    fn error_ratio(
        signal: impl Fn(usize) -> Vector6<f64>,
        predicted: &[Vector6<f64>],
        from: usize,
    ) -> f64 {
        (0..6)
            .map(|k| {
                let (mut err, mut err0) = (0.0, 0.0);
                for t in from..predicted.len() {
                    // predicted[t - 1] was made at step t for step t + 1
                    err += (predicted[t - 1][k] - signal(t + 1)[k]).powi(2);
                    err0 += (signal(t)[k] - signal(t + 1)[k]).powi(2);
                }
                (err / err0).sqrt()
            })
            .fold(0.0, f64::max)
    }

    fn same(f: impl Fn(usize) -> f64) -> impl Fn(usize) -> Vector6<f64> {
        move |t| Vector6::repeat(f(t))
    }

    #[test]
    fn sinusoids_are_predicted_by_their_recursion() {
        // one sinusoid at 8, 20, 60 steps per period, and sums of two and three at unrelated
        // frequencies and phases (order 2 predicts only the first exactly: measured ratio
        // 0.3–0.6 on the sums)
        let tau = 2.0 * std::f64::consts::PI;
        let cases: [&dyn Fn(f64) -> f64; 5] = [
            &|t| (tau * t / 8.0).sin(),
            &|t| (tau * t / 20.0).sin(),
            &|t| (tau * t / 60.0).sin(),
            &|t| (tau * t / 23.0).sin() + 0.7 * (tau * t / 7.3 + 1.0).sin(),
            &|t| {
                (tau * t / 41.0).sin()
                    + 0.5 * (tau * t / 11.0 + 2.0).cos()
                    + 0.3 * (tau * t / 5.1).sin()
            },
        ];
        for (i, f) in cases.iter().enumerate() {
            let x = same(|t| f(t as f64));
            let (_, predicted) = run(&x, 600);
            let ratio = error_ratio(&x, &predicted, 100);
            assert!(ratio < 0.02, "case {i}: {ratio}");
        }
    }

    #[test]
    fn translations_bending_rotations_and_twist_have_their_own_recursions() {
        // each group two sinusoids of its own (six frequencies in all, more than one
        // recursion of order 6 holds): each fit predicts its group
        let tau = 2.0 * std::f64::consts::PI;
        let periods = [[9.0, 31.0], [13.0, 47.0], [6.5, 23.0]];
        let signal = |t: usize| {
            Vector6::from_fn(|k, _| {
                let [p, q] = periods[GROUP[k]];
                let t = t as f64;
                (tau * t / p + k as f64).sin() + 0.5 * (tau * t / q).cos()
            })
        };
        let (e, predicted) = run(signal, 600);
        let ratio = error_ratio(signal, &predicted, 100);
        assert!(ratio < 0.02, "{ratio}");
        assert!(e.coefficients().iter().all(|c| c.norm() > 0.0));
    }

    #[test]
    fn ramps_constants_alternation_and_noise() {
        // a ramp: linear extrapolation, to the ridge
        let ramp = same(|t| 0.5 * t as f64);
        let (_, predicted) = run(&ramp, 100);
        assert!(error_ratio(&ramp, &predicted, 50) < 0.03);
        // a constant: nothing to fit, constant acceleration (exact)
        let (e, predicted) = run(same(|_| 3.0), 50);
        assert_eq!(e.coefficients(), [Coefficients::zeros(); GROUPS]);
        assert!(predicted.iter().all(|p| *p == Vector6::repeat(3.0)));
        // alternation (the sampling limit): −v̇_n, to the ridge
        let alt = same(|t| if t.is_multiple_of(2) { 1.0 } else { -1.0 });
        let (_, predicted) = run(&alt, 100);
        assert!(error_ratio(&alt, &predicted, 50) < 1e-2);
        // uncorrelated accelerations: better than constant acceleration (their mean is the
        // best prediction, error ratio 1/√2; six coefficients fitted to 20 steps of one
        // unknown scatter about it: measured 0.87)
        let noise = same(|t| ((t as f64 * 12.9898).sin() * 43758.5453).fract());
        let (e, predicted) = run(&noise, 2000);
        let ratio = error_ratio(&noise, &predicted, 100);
        assert!(ratio < 0.95, "{ratio}");
        // … by order 2: the higher terms explain too little of the noise to be used (`HIGHER`)
        assert_eq!(e.coefficients()[0].rows(2, ORDER - 2).norm(), 0.0);
        // too few steps: constant acceleration
        let (e, _) = run(same(|t| (t * t) as f64), ORDER + WARM_UP);
        assert_eq!(e.coefficients(), [Coefficients::zeros(); GROUPS]);
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
        // a ramp on the translations (linear extrapolation, to the ridge); no rotational
        // unknowns: nothing fitted there
        let [trans, bend, twist] = e.coefficients();
        assert!(trans.norm() > 0.0);
        assert_eq!([bend, twist], [Coefficients::zeros(); 2]);
        let vd = step(&mut e, 50, false, 1e-3);
        assert!((vd[0][0] - 51.0).abs() < 0.1, "{}", vd[0][0]);
        assert_eq!(vd[0].fixed_rows::<3>(3).sum(), 3.0 * 50.0);
        assert_eq!(vd[1], ramp(50)[1]);
        // a step of another size: constant acceleration, and the count starts again
        let vd = step(&mut e, 51, false, 5e-4);
        assert_eq!(vd, ramp(51));
        let vd = step(&mut e, 52, false, 5e-4);
        assert_eq!(
            (vd, e.coefficients()),
            (ramp(52), [Coefficients::zeros(); GROUPS])
        );
        // a restart forgets the past
        for t in 53..53 + ORDER + WARM_UP {
            step(&mut e, t, false, 5e-4);
        }
        assert_ne!(e.coefficients(), [Coefficients::zeros(); GROUPS]);
        let t = 53 + ORDER + WARM_UP;
        let vd = step(&mut e, t, true, 5e-4);
        assert_eq!(
            (vd, e.coefficients()),
            (ramp(t), [Coefficients::zeros(); GROUPS])
        );
    }
}

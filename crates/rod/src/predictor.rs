//! The dynamic step's predictor of the accelerations: v̇_{n+1} ≈ v̇_n + λ (v̇_n − v̇_{n−1}),
//! with λ learnt from the run itself.
//!
//! The Newton iteration of a step starts from predicted accelerations; its first correction
//! is the predictor's error, and the later ones shrink with it (the iteration matrix is
//! reused over many steps). Constant acceleration (λ = 0) is right where the increments
//! d_n = v̇_{n+1} − v̇_n of successive steps are uncorrelated (broadband motion near the
//! sampling limit); linear extrapolation (λ = 1) where the response is smooth at the step
//! (a PSD of a few hundred hertz at most sampled at 1 ms). The error of the prediction,
//! d_n − λ d_{n−1}, has the least mean square for λ = ⟨d_n, d_{n−1}⟩ / ⟨d_{n−1}, d_{n−1}⟩,
//! the increments' lag-one correlation: estimated from the past steps with exponential
//! forgetting (`MEMORY` steps), separately for the translational and the rotational
//! unknowns (m/s², rad/s²), and held to [0, 1] (an oscillation from step to step is not
//! extrapolated). Measured in docs/dynamics.md ("Predictor").
//!
//! The predictor changes only where Newton starts: the converged step is the same to the
//! tolerance, which bounds the iteration error by the time error.
use nalgebra::Vector6;

/// Steps of memory of the correlation estimate (forgetting factor 1 − 1/MEMORY per step).
const MEMORY: f64 = 20.0;
/// Steps observed before λ is used (constant acceleration until then).
const WARM_UP: usize = 3;

/// The extrapolation of one set of unknowns (a cable's blocks, a harness's junctions).
#[derive(Clone, Debug, Default)]
pub(crate) struct Extrapolation {
    /// v̇_{n−1} at the start of a step (from the second observed step on).
    prev: Vec<Vector6<f64>>,
    /// Exponentially weighted ⟨d_n, d_{n−1}⟩ and ⟨d_{n−1}, d_{n−1}⟩, translations and
    /// rotations.
    cross: [f64; 2],
    square: [f64; 2],
    /// Step size of the observed steps; steps observed since the last reset.
    h: f64,
    observed: usize,
}

impl Extrapolation {
    pub(crate) fn new(n: usize) -> Self {
        Extrapolation {
            prev: vec![Vector6::zeros(); n],
            ..Default::default()
        }
    }

    /// λ for translations and rotations (0 until enough steps are observed).
    pub(crate) fn lambda(&self) -> [f64; 2] {
        if self.observed < WARM_UP {
            return [0.0; 2];
        }
        [0, 1].map(|i| {
            if self.square[i] > 0.0 {
                (self.cross[i] / self.square[i]).clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
    }

    /// The start of a step of size `h`, in one pass: `vdot` holds v̇_n (the end of the step
    /// just accepted, of size `h_last`; None after a restart, which forgets the past: the last
    /// accelerations may hold a shock) and `vdot_n` v̇_{n−1}. Adds the accepted step to the
    /// correlation (d_n = v̇_n − v̇_{n−1}, d_{n−1} = v̇_{n−1} − v̇_{n−2}), sets `vdot_n` to v̇_n
    /// and, with `predict` and a step of the observed size, `vdot` to the prediction
    /// v̇_n + λ (v̇_n − v̇_{n−1}) (λ of the steps before; the unknowns with `inertial[b][k]`,
    /// None: all). Otherwise `vdot` keeps v̇_n (constant acceleration). Steps of another size
    /// restart the count (the increments scale with the step).
    pub(crate) fn begin_step(
        &mut self,
        vdot: &mut [Vector6<f64>],
        vdot_n: &mut [Vector6<f64>],
        inertial: Option<&[[bool; 6]]>,
        h_last: Option<f64>,
        h: f64,
        predict: bool,
    ) {
        match h_last {
            Some(h_last) if h_last == self.h => {}
            _ => {
                self.cross = [0.0; 2];
                self.square = [0.0; 2];
                self.observed = 0;
                self.h = h_last.unwrap_or(0.0);
            }
        }
        let lambda = if predict && h == self.h {
            self.lambda()
        } else {
            [0.0; 2]
        };
        let extrapolate = lambda != [0.0; 2];
        let observe = self.observed > 0;
        let (mut cross, mut square) = ([0.0; 2], [0.0; 2]);
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
                        cross[k / 3] += d[k] * d_old[k];
                        square[k / 3] += d_old[k] * d_old[k];
                    }
                }
            }
            if extrapolate {
                for k in 0..6 {
                    if m[k] {
                        v[k] = now[k] + lambda[k / 3] * d[k];
                    }
                }
            }
            *p = *l;
            *l = now;
        }
        if observe {
            let keep = 1.0 - 1.0 / MEMORY;
            for i in 0..2 {
                self.cross[i] = keep * self.cross[i] + cross[i];
                self.square[i] = keep * self.square[i] + square[i];
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
            e.begin_step(&mut vdot, &mut vdot_n, None, Some(1e-3), 1e-3, true);
            assert_eq!(vdot_n[0], Vector6::repeat(signal(t)));
            predicted.push(vdot[0][0]);
        }
        (e, predicted)
    }

    #[test]
    fn smooth_motion_is_extrapolated_and_alternation_is_not() {
        // a sine at 20 steps per period: the increments' lag-one correlation is cos w
        // (the exponential window of MEMORY ≈ one period weighs the phases unevenly: ± 0.02)
        let w = 2.0 * std::f64::consts::PI / 20.0;
        let x = |t: usize| (w * t as f64).sin();
        let (e, predicted) = run(x, 1000);
        let l = e.lambda();
        assert!((l[0] - w.cos()).abs() < 0.02, "{l:?}");
        assert_eq!(l[0], l[1]);
        // the prediction error against constant acceleration's: for the best fixed λ = cos w
        // its mean square is 1 − cos² w of the increments', an RMS ratio of sin w (≈ 0.31);
        // the learnt λ (one step old, varying with the phase over its window) within 5 %
        let (mut err, mut err0) = (0.0, 0.0);
        for t in 200..999 {
            err += (predicted[t - 1] - x(t + 1)).powi(2);
            err0 += (x(t) - x(t + 1)).powi(2);
        }
        let ratio = (err / err0).sqrt();
        assert!((ratio - w.sin()).abs() < 0.05 * w.sin(), "{ratio}");
        // alternating values (the sampling limit): λ held at 0, constant acceleration
        let (e, predicted) = run(|t| if t % 2 == 0 { 1.0 } else { -1.0 }, 100);
        assert_eq!(e.lambda(), [0.0; 2]);
        assert_eq!(predicted[50], if 51 % 2 == 0 { 1.0 } else { -1.0 });
        // too few steps: 0
        let (e, _) = run(|t| t as f64, WARM_UP);
        assert_eq!(e.lambda(), [0.0; 2]);
    }

    #[test]
    fn restarts_other_step_sizes_and_masks() {
        let ramp = |t: usize| vec![Vector6::repeat(t as f64), Vector6::repeat(-(t as f64))];
        let mask = [[true, true, true, false, false, false], [false; 6]];
        let mut e = Extrapolation::new(2);
        let mut vdot_n = ramp(0);
        let mut step = |e: &mut Extrapolation, t: usize, h_last: Option<f64>, h: f64| {
            let mut vdot = ramp(t);
            e.begin_step(&mut vdot, &mut vdot_n, Some(&mask), h_last, h, true);
            vdot
        };
        for t in 1..50 {
            step(&mut e, t, Some(1e-3), 1e-3);
        }
        // a ramp: λ = 1 for translations; no rotational unknowns: 0
        assert_eq!(e.lambda(), [1.0, 0.0]);
        let vd = step(&mut e, 50, Some(1e-3), 1e-3);
        assert_eq!(vd[0].fixed_rows::<3>(0).sum(), 3.0 * 51.0);
        assert_eq!(vd[0].fixed_rows::<3>(3).sum(), 3.0 * 50.0);
        assert_eq!(vd[1], ramp(50)[1]);
        // a step of another size: constant acceleration, and the count starts again
        let vd = step(&mut e, 51, Some(1e-3), 5e-4);
        assert_eq!(vd, ramp(51));
        let vd = step(&mut e, 52, Some(5e-4), 5e-4);
        assert_eq!((vd, e.lambda()), (ramp(52), [0.0; 2]));
        // a restart forgets the past
        for t in 53..60 {
            step(&mut e, t, Some(5e-4), 5e-4);
        }
        assert_eq!(e.lambda(), [1.0, 0.0]);
        let vd = step(&mut e, 60, None, 5e-4);
        assert_eq!((vd, e.lambda()), (ramp(60), [0.0; 2]));
    }
}

//! Damage of one or many series: rainflow counting + Palmgren–Miner, parallel over series.
//!
//! The hot loops stream samples through the turning-point detector into the rainflow stack
//! and add each cycle's damage on the fly: no cycle list, no turning-point array. Each rayon
//! worker owns one reused [`Rainflow`] (via `map_init`), so a batch allocates only a few
//! small stacks.

use rayon::prelude::*;

use crate::rainflow::{for_each_cycle, CountOptions, Rainflow};
use crate::wohler::Wohler;
use crate::FatigueError;

/// Miner damage of one series with reusable counter state.
#[inline]
fn damage_stream(
    samples: impl Iterator<Item = f64>,
    curve: &Wohler,
    options: &CountOptions,
    series_id: usize,
    rainflow: &mut Rainflow,
) -> Result<f64, FatigueError> {
    let mut d = 0.0;
    for_each_cycle(samples, options, series_id, rainflow, &mut |c| {
        d += c.count * curve.damage_per_cycle(c.range)
    })?;
    Ok(d)
}

/// Palmgren–Miner damage of one series.
pub fn damage(series: &[f64], curve: &Wohler, options: &CountOptions) -> Result<f64, FatigueError> {
    if series.is_empty() {
        return Err(FatigueError::param(
            "series",
            "[] (empty)",
            "needs at least one sample",
        ));
    }
    damage_stream(
        series.iter().copied(),
        curve,
        options,
        0,
        &mut Rainflow::new(),
    )
}

fn check_n_samples(n_samples: usize) -> Result<(), FatigueError> {
    if n_samples == 0 {
        return Err(FatigueError::param(
            "n_samples",
            0,
            "every series needs at least one sample",
        ));
    }
    Ok(())
}

/// Damage of `n_series = series.len() / n_samples` series stored row-major (one series per
/// row of `n_samples` samples), in parallel on the current rayon pool.
pub fn damage_many(
    series: &[f64],
    n_samples: usize,
    curve: &Wohler,
    options: &CountOptions,
) -> Result<Vec<f64>, FatigueError> {
    check_n_samples(n_samples)?;
    if !series.len().is_multiple_of(n_samples) {
        return Err(FatigueError::Shape {
            name: "series",
            detail: format!(
                "{} values are not a whole number of series of {n_samples} samples",
                series.len()
            ),
        });
    }
    series
        .par_chunks(n_samples)
        .enumerate()
        .map_init(Rainflow::new, |rf, (i, row)| {
            damage_stream(row.iter().copied(), curve, options, i, rf)
        })
        .collect()
}

/// Damage of linear combinations of channels, without materialising the combined series.
///
/// `signals` holds `n_groups` blocks of `n_samples × n_channels` values (row-major
/// (group, sample, channel)); `weights` holds `n_series × n_channels` values. Series j of
/// group g is x_t = Σ_c signals[g, t, c] · weights[j, c] — for the LDA a group is a cross
/// section, the channels are its six section loads and a series is the normal stress on one
/// critical plane at one surface point. Returns the damage as `n_groups × n_series`
/// row-major. Series are labelled g · n_series + j in errors.
pub fn damage_combined(
    signals: &[f64],
    n_groups: usize,
    n_samples: usize,
    weights: &[f64],
    n_series: usize,
    curve: &Wohler,
    options: &CountOptions,
) -> Result<Vec<f64>, FatigueError> {
    check_n_samples(n_samples)?;
    if n_groups == 0 || n_series == 0 {
        return Ok(Vec::new());
    }
    if !weights.len().is_multiple_of(n_series) {
        return Err(FatigueError::Shape {
            name: "weights",
            detail: format!("{} values for {n_series} series", weights.len()),
        });
    }
    let n_channels = weights.len() / n_series;
    if n_channels == 0 || signals.len() != n_groups * n_samples * n_channels {
        return Err(FatigueError::Shape {
            name: "signals",
            detail: format!(
                "{} values, expected n_groups·n_samples·n_channels = {n_groups}·{n_samples}·{n_channels}",
                signals.len()
            ),
        });
    }
    if let Some(i) = weights.iter().position(|w| !w.is_finite()) {
        return Err(FatigueError::param(
            "weights",
            format!("{} at flat index {i}", weights[i]),
            "all weights must be finite",
        ));
    }
    let block = n_samples * n_channels;
    (0..n_groups * n_series)
        .into_par_iter()
        .map_init(Rainflow::new, |rf, id| {
            let g = id / n_series;
            let j = id % n_series;
            let sig = &signals[g * block..(g + 1) * block];
            let w = &weights[j * n_channels..(j + 1) * n_channels];
            if n_channels == 6 {
                let w: &[f64; 6] = w.try_into().expect("six weights");
                let samples = sig.chunks_exact(6).map(|row| {
                    let row: &[f64; 6] = row.try_into().expect("six channels");
                    (row[0] * w[0] + row[1] * w[1] + row[2] * w[2])
                        + (row[3] * w[3] + row[4] * w[4] + row[5] * w[5])
                });
                damage_stream(samples, curve, options, id, rf)
            } else {
                let samples = sig
                    .chunks_exact(n_channels)
                    .map(|row| row.iter().zip(w).map(|(a, b)| a * b).sum::<f64>());
                damage_stream(samples, curve, options, id, rf)
            }
        })
        .collect()
}

/// Run `f` on a dedicated rayon pool of `threads` threads, or on the global pool for `None`.
pub fn run_with_threads<R: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> R + Send,
) -> Result<R, FatigueError> {
    match threads {
        None => Ok(f()),
        Some(0) => Err(FatigueError::param(
            "threads",
            0,
            "must be >= 1 (or None for all cores)",
        )),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| FatigueError::param("threads", n, leak(e.to_string())))?;
            Ok(pool.install(f))
        }
    }
}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rainflow::{count_cycles, Residue};

    /// A small deterministic pseudo-random generator (xorshift) for test series.
    fn noise(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed.wrapping_mul(0x9E3779B97F4A7C15) | 1;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    #[test]
    fn constant_amplitude_miner_is_n_over_n() {
        // 100 cycles of range 2 (mean 3): D = 100 / N(2) exactly
        let s: Vec<f64> = (0..201)
            .map(|i| if i % 2 == 0 { 2.0 } else { 4.0 })
            .collect();
        let w = Wohler::new(5.0, 1e6).unwrap();
        let d = damage(&s, &w, &CountOptions::default()).unwrap();
        assert!((d - 100.0 / w.cycles_to_failure(2.0)).abs() < 1e-15);
    }

    #[test]
    fn scaling_load_scales_damage_by_c_pow_k() {
        let s = noise(5000, 3);
        let w = Wohler::new(5.0, 1.0).unwrap();
        let o = CountOptions::default();
        let d1 = damage(&s, &w, &o).unwrap();
        let s3: Vec<f64> = s.iter().map(|x| 3.0 * x).collect();
        let d3 = damage(&s3, &w, &o).unwrap();
        assert!((d3 / d1 / 243.0 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn batch_equals_single_and_cycle_list() {
        let n = 700;
        let data: Vec<f64> = (0..9).flat_map(|i| noise(n, i + 1)).collect();
        let w = Wohler::new(4.0, 1e-3).unwrap();
        for residue in [
            Residue::Half,
            Residue::Discard,
            Residue::Full,
            Residue::Repeated,
        ] {
            let o = CountOptions::new(residue, 0.05).unwrap();
            let many = damage_many(&data, n, &w, &o).unwrap();
            for (i, row) in data.chunks(n).enumerate() {
                let from_list = w.miner(&count_cycles(row, &o).unwrap());
                assert!((many[i] - from_list).abs() <= 1e-12 * from_list);
                assert_eq!(many[i], damage(row, &w, &o).unwrap());
            }
        }
    }

    #[test]
    fn combined_equals_materialised_series() {
        let (groups, n, series) = (3, 500, 5);
        let signals: Vec<f64> = noise(groups * n * 6, 11);
        let weights: Vec<f64> = noise(series * 6, 12);
        let w = Wohler::new(5.0, 1.0).unwrap();
        let o = CountOptions::default();
        let d = damage_combined(&signals, groups, n, &weights, series, &w, &o).unwrap();
        for g in 0..groups {
            for j in 0..series {
                let x: Vec<f64> = (0..n)
                    .map(|t| {
                        let r = &signals[(g * n + t) * 6..(g * n + t + 1) * 6];
                        let wj = &weights[j * 6..(j + 1) * 6];
                        (r[0] * wj[0] + r[1] * wj[1] + r[2] * wj[2])
                            + (r[3] * wj[3] + r[4] * wj[4] + r[5] * wj[5])
                    })
                    .collect();
                assert_eq!(d[g * series + j], damage(&x, &w, &o).unwrap());
            }
        }
        // generic channel count
        let d3 = damage_combined(
            &signals[..groups * n * 3],
            groups,
            n,
            &weights[..15],
            5,
            &w,
            &o,
        );
        assert_eq!(d3.unwrap().len(), groups * series);
    }

    #[test]
    fn threads_and_errors() {
        let data = noise(4000, 5);
        let w = Wohler::new(5.0, 1.0).unwrap();
        let o = CountOptions::default();
        let a = run_with_threads(Some(1), || damage_many(&data, 1000, &w, &o)).unwrap();
        let b = run_with_threads(Some(2), || damage_many(&data, 1000, &w, &o)).unwrap();
        assert_eq!(a, b);
        assert!(run_with_threads(Some(0), || ()).is_err());
        assert!(damage_many(&data, 0, &w, &o).is_err());
        assert!(damage_many(&data, 3000, &w, &o).is_err());
        let mut bad = data.clone();
        bad[2500] = f64::NAN;
        let e = damage_many(&bad, 1000, &w, &o).unwrap_err();
        assert!(matches!(
            e,
            FatigueError::NonFinite {
                series: 2,
                index: 500,
                ..
            }
        ));
        assert!(e.to_string().contains("series 2") && e.to_string().contains("index 500"));
        assert!(damage(&[], &w, &o).is_err());
    }
}

//! Bindings of the fatigue kernels (crate `cablelife-fatigue`): numpy arrays in and out, the
//! counting runs without the GIL. Names are prefixed `fatigue_`; the Python wrappers live in
//! `cablelife.lda`.
use ::fatigue::{
    count_cycles, damage_combined, damage_many, run_with_threads, turning_points, CountOptions,
    FatigueError, KneeKind, Residue, Wohler,
};
use numpy::ndarray::Dimension;
use numpy::{
    PyArray1, PyArrayMethods, PyReadonlyArray, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::borrow::Cow;

fn err(e: FatigueError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn curve(k: f64, alpha: f64, knee_range: Option<f64>, knee_kind: &str) -> PyResult<Wohler> {
    let w = Wohler::new(k, alpha).map_err(err)?;
    match knee_range {
        None => Ok(w),
        Some(r) => w
            .with_knee(r, KneeKind::parse(knee_kind).map_err(err)?)
            .map_err(err),
    }
}

fn options(residue: &str, hysteresis: f64) -> PyResult<CountOptions> {
    CountOptions::new(Residue::parse(residue).map_err(err)?, hysteresis).map_err(err)
}

type TurningPointArrays<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f64>>);

/// Turning points of a 1-D series: (indices int64, values float64).
#[pyfunction]
#[pyo3(signature = (series, hysteresis=0.0))]
fn fatigue_turning_points<'py>(
    py: Python<'py>,
    series: PyReadonlyArray1<'py, f64>,
    hysteresis: f64,
) -> PyResult<TurningPointArrays<'py>> {
    let s = series.as_array().to_vec();
    let (i, v) = py.detach(|| turning_points(&s, hysteresis)).map_err(err)?;
    let i: Vec<i64> = i.into_iter().map(|j| j as i64).collect();
    Ok((PyArray1::from_vec(py, i), PyArray1::from_vec(py, v)))
}

type CycleArrays<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// Rainflow cycles of a 1-D series: (range, mean, count, from_index, to_index).
#[pyfunction]
#[pyo3(signature = (series, residue="half", hysteresis=0.0))]
fn fatigue_cycles<'py>(
    py: Python<'py>,
    series: PyReadonlyArray1<'py, f64>,
    residue: &str,
    hysteresis: f64,
) -> PyResult<CycleArrays<'py>> {
    let o = options(residue, hysteresis)?;
    let s = series.as_array().to_vec();
    let cycles = py.detach(|| count_cycles(&s, &o)).map_err(err)?;
    let col = |f: fn(&::fatigue::Cycle) -> f64| cycles.iter().map(f).collect::<Vec<f64>>();
    let idx = |f: fn(&::fatigue::Cycle) -> usize| {
        cycles.iter().map(|c| f(c) as i64).collect::<Vec<i64>>()
    };
    Ok((
        PyArray1::from_vec(py, col(|c| c.range)),
        PyArray1::from_vec(py, col(|c| c.mean)),
        PyArray1::from_vec(py, col(|c| c.count)),
        PyArray1::from_vec(py, idx(|c| c.from)),
        PyArray1::from_vec(py, idx(|c| c.to)),
    ))
}

/// Miner damage of every row of a 2-D array (n_series, n_samples), in parallel.
#[pyfunction]
#[pyo3(signature = (series, k, alpha, knee_range=None, knee_kind="haibach", residue="half",
                    hysteresis=0.0, threads=None))]
#[allow(clippy::too_many_arguments)]
fn fatigue_damage_many<'py>(
    py: Python<'py>,
    series: PyReadonlyArray2<'py, f64>,
    k: f64,
    alpha: f64,
    knee_range: Option<f64>,
    knee_kind: &str,
    residue: &str,
    hysteresis: f64,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let w = curve(k, alpha, knee_range, knee_kind)?;
    let o = options(residue, hysteresis)?;
    let n_samples = series.as_array().ncols();
    let data = row_major(&series);
    let d = py
        .detach(|| run_with_threads(threads, || damage_many(&data, n_samples, &w, &o)))
        .map_err(err)?
        .map_err(err)?;
    Ok(PyArray1::from_vec(py, d))
}

/// Miner damage of the linear combinations `signals[g] @ weights[j]` for every group g
/// (signals (n_groups, n_samples, n_channels)) and weight row j (weights (n_series,
/// n_channels)); returns (n_groups, n_series). The combined series are never stored.
#[pyfunction]
#[pyo3(signature = (signals, weights, k, alpha, knee_range=None, knee_kind="haibach",
                    residue="half", hysteresis=0.0, threads=None))]
#[allow(clippy::too_many_arguments)]
fn fatigue_damage_combined<'py>(
    py: Python<'py>,
    signals: PyReadonlyArray3<'py, f64>,
    weights: PyReadonlyArray2<'py, f64>,
    k: f64,
    alpha: f64,
    knee_range: Option<f64>,
    knee_kind: &str,
    residue: &str,
    hysteresis: f64,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let w = curve(k, alpha, knee_range, knee_kind)?;
    let o = options(residue, hysteresis)?;
    let shape = signals.as_array().shape().to_vec();
    let (n_groups, n_samples, n_channels) = (shape[0], shape[1], shape[2]);
    let (n_series, w_channels) = (weights.as_array().nrows(), weights.as_array().ncols());
    if w_channels != n_channels {
        return Err(PyValueError::new_err(format!(
            "weights has {w_channels} columns but signals has {n_channels} channels: they must match"
        )));
    }
    let (sig, wts) = (row_major(&signals), row_major(&weights));
    let d = py
        .detach(|| {
            run_with_threads(threads, || {
                damage_combined(&sig, n_groups, n_samples, &wts, n_series, &w, &o)
            })
        })
        .map_err(err)?
        .map_err(err)?;
    Ok(PyArray1::from_vec(py, d)
        .reshape([n_groups, n_series])?
        .into_any())
}

/// The array's values in row-major order: borrowed when it is C-contiguous, else copied
/// (`as_slice` alone also accepts Fortran order, whose memory is column-major).
fn row_major<'a, D: Dimension>(a: &'a PyReadonlyArray<'_, f64, D>) -> Cow<'a, [f64]> {
    match a.as_slice() {
        Ok(s) if a.as_array().is_standard_layout() => Cow::Borrowed(s),
        _ => Cow::Owned(a.as_array().iter().copied().collect()),
    }
}

/// Add the fatigue functions to the `_core` module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fatigue_turning_points, m)?)?;
    m.add_function(wrap_pyfunction!(fatigue_cycles, m)?)?;
    m.add_function(wrap_pyfunction!(fatigue_damage_many, m)?)?;
    m.add_function(wrap_pyfunction!(fatigue_damage_combined, m)?)?;
    Ok(())
}

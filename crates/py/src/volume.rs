//! Bindings of the motion-volume kernel: capsules as (M, 3) arrays of axis end points and an
//! (M,) array of radii; the kernel runs without the GIL.
use ::volume::{Capsules, Grid, Vec3};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

fn points(a: &PyReadonlyArray2<'_, f64>, what: &str) -> PyResult<Vec<Vec3>> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "{what} has shape {:?}: must be (M, 3)",
            v.shape()
        )));
    }
    Ok(v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
}

fn capsules(
    starts: &PyReadonlyArray2<'_, f64>,
    ends: &PyReadonlyArray2<'_, f64>,
    radius: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Capsules> {
    let s = points(starts, "starts")?;
    let e = points(ends, "ends")?;
    let r = radius.as_array().to_vec();
    Capsules::new(&s, &e, &r).map_err(|e| PyValueError::new_err(e.0))
}

/// Signed distance to the union of capsules on a grid, clamped to [-band, band], float32 of
/// shape `shape` (voxel (i, j, k) at origin + spacing * (i, j, k)).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn capsule_signed_distance<'py>(
    py: Python<'py>,
    starts: PyReadonlyArray2<'py, f64>,
    ends: PyReadonlyArray2<'py, f64>,
    radius: PyReadonlyArray1<'py, f64>,
    origin: [f64; 3],
    spacing: f64,
    shape: [usize; 3],
    band: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let caps = capsules(&starts, &ends, &radius)?;
    let grid = Grid {
        origin,
        spacing,
        shape,
    };
    let field = py
        .detach(|| ::volume::signed_distance(&caps, &grid, band))
        .map_err(|e| PyValueError::new_err(e.0))?;
    Ok(PyArray1::from_vec(py, field).reshape(shape)?.into_any())
}

/// Exact signed distance from each of `points` (P, 3) to the union of capsules, (P,) float64.
#[pyfunction]
fn capsule_distance<'py>(
    py: Python<'py>,
    starts: PyReadonlyArray2<'py, f64>,
    ends: PyReadonlyArray2<'py, f64>,
    radius: PyReadonlyArray1<'py, f64>,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    use rayon::prelude::*;
    let caps = capsules(&starts, &ends, &radius)?;
    let query = self::points(&points, "points")?;
    let d: Vec<f64> = py.detach(|| query.par_iter().map(|&p| caps.distance(p)).collect());
    Ok(PyArray1::from_vec(py, d))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(capsule_signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(capsule_distance, m)?)?;
    Ok(())
}

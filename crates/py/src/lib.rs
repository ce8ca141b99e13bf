//! Thin PyO3 bindings: numpy arrays in, numpy arrays out; no physics here.
use pyo3::prelude::*;

mod cable;
mod fatigue;
mod geometry;
mod harness;
mod stop;
mod volume;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    cable::register(m)?;
    volume::register(m)?;
    fatigue::register(m)?;
    stop::register(m)?;
    geometry::register(m)?;
    harness::register(m)?;
    Ok(())
}

//! Thin PyO3 bindings: numpy arrays in, numpy arrays out; no physics here.
use pyo3::prelude::*;

mod cable;
mod cpu;
mod fatigue;
mod geometry;
mod harness;
mod stop;
mod volume;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("cpu_features", cpu::features())?;
    cable::register(m)?;
    volume::register(m)?;
    fatigue::register(m)?;
    stop::register(m)?;
    geometry::register(m)?;
    harness::register(m)?;
    Ok(())
}

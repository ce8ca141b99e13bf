//! Rainflow counting and damage kernels for the comparative load data analysis (issue 5).
//!
//! - [`turning`]: turning points with an optional hysteresis gate;
//! - [`rainflow`]: ASTM E1049-85 counting (four-point stack) and residue treatments;
//! - [`wohler`]: Wöhler curve in stress ranges (optional knee), Miner sum, equivalent range;
//! - [`batch`]: damage of many series in parallel (rayon), also of linear combinations of
//!   channels computed on the fly.
//!
//! Pure Rust: no files, no Python. Conventions: ranges (not amplitudes) everywhere; counts
//! are 0.5 (half cycle) or 1.0 (full cycle).

pub mod batch;
pub mod error;
pub mod rainflow;
pub mod turning;
pub mod wohler;

pub use batch::{damage, damage_combined, damage_many, run_with_threads};
pub use error::FatigueError;
pub use rainflow::{count_cycles, CountOptions, Cycle, Rainflow, Residue};
pub use turning::{turning_points, TurningPoints};
pub use wohler::{KneeKind, Wohler};

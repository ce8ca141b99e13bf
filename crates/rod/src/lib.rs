//! Discrete geometrically exact Cosserat rod (DESIGN.md §3): the model, its strain elements
//! with exact derivatives, the block-tridiagonal Newton solver, and static/quasistatic solves.
//! Pure Rust: no files, no Python.
pub mod assembly;
pub mod bending;
pub mod block_tridiag;
pub mod conditioning;
pub mod contact;
pub mod contact_mesh;
mod contraction;
pub mod dynamics;
mod escape;
#[cfg(test)]
mod fd_check;
pub mod friction;
pub mod harness;
pub mod harness_contact;
pub mod harness_dynamics;
mod harness_escape;
pub mod harness_modal;
pub mod harness_solver;
mod impact;
pub mod junction;
pub mod modal;
pub mod model;
mod predictor;
mod projection;
pub mod rotation;
pub mod routing;
pub mod shear;
mod simd;
pub mod sliding;
pub mod stability;
pub mod state;
pub mod statics;

pub use dynamics::{ClipMotion, DynamicOptions, Dynamics, Energies, GenAlpha, StepStats};
pub use model::{CableSpec, ClipKind, ClipSpec, PointLoad, Pose, Rod, Section, SpecError};
pub use state::State;
pub use statics::{NewtonOptions, Snap, SolveError, SolveStats, Statics};

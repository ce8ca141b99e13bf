//! Errors of the fatigue kernels: every message names the parameter, the value and what is allowed.
use std::fmt;

/// An invalid input to a fatigue kernel.
#[derive(Debug, Clone, PartialEq)]
pub enum FatigueError {
    /// A scalar parameter outside its allowed range.
    InvalidParameter {
        name: &'static str,
        value: String,
        allowed: &'static str,
    },
    /// A NaN or infinite sample in an input series.
    NonFinite {
        series: usize,
        index: usize,
        value: f64,
    },
    /// Array sizes that do not fit together.
    Shape { name: &'static str, detail: String },
}

impl FatigueError {
    pub(crate) fn param(
        name: &'static str,
        value: impl fmt::Display,
        allowed: &'static str,
    ) -> Self {
        FatigueError::InvalidParameter {
            name,
            value: value.to_string(),
            allowed,
        }
    }
}

impl fmt::Display for FatigueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FatigueError::InvalidParameter {
                name,
                value,
                allowed,
            } => write!(f, "invalid {name} = {value}: {allowed}"),
            FatigueError::NonFinite {
                series,
                index,
                value,
            } => write!(
                f,
                "series {series} has a non-finite sample {value} at index {index}: \
                 all samples must be finite numbers"
            ),
            FatigueError::Shape { name, detail } => write!(f, "bad shape of {name}: {detail}"),
        }
    }
}

impl std::error::Error for FatigueError {}

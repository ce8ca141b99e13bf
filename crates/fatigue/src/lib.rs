//! Rainflow counting and damage kernels (see issue 5).

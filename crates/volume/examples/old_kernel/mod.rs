//! A frozen copy of the kernel before the speed-up (commit e8af065), for the benchmark's
//! side-by-side timing and exact comparison.
#![allow(dead_code)]
pub mod capsules;
pub mod grid;

//! The processor features this build's code may use, for the check before it loads.
//!
//! `build.rs` writes them (names as in /proc/cpuinfo, space-separated; empty where not
//! checked); they are kept in the ELF section `.cablelife_cpu`, which
//! python/cablelife/_cpu.py reads from the file without loading it: a processor without one
//! of them would stop at the first such instruction (SIGILL) instead of a clear message.

const FEATURES: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/cpu_features.txt"));

#[used]
#[unsafe(link_section = ".cablelife_cpu")]
static STAMP: [u8; FEATURES.len()] = *include_bytes!(concat!(env!("OUT_DIR"), "/cpu_features.txt"));

/// The stamped features (for tests and `cablelife._core.cpu_features`).
pub fn features() -> &'static str {
    std::str::from_utf8(&STAMP).unwrap_or("")
}

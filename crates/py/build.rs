//! Stamps the extension with the processor features its code may use (x86-64 Linux), in the
//! names of /proc/cpuinfo, so that Python can check a processor before loading it
//! (python/cablelife/_cpu.py reads the ELF section `.cablelife_cpu`; see src/cpu.rs).
//!
//! The features are the compilation's (`CARGO_CFG_TARGET_FEATURE`: those of
//! AVX and FMA from .cargo/config.toml, or those of RUSTFLAGS). Only names that the
//! building machine's /proc/cpuinfo lists are stamped, so the machine that built the
//! extension always passes the check (a feature whose name we would map wrongly is left
//! out rather than reported missing on the very machine that has it).
use std::{env, fs, path::Path};

/// Rust's name of an x86 feature → the Linux kernel's (/proc/cpuinfo), where they differ.
fn cpuinfo_name(feature: &str) -> &str {
    match feature {
        "sse3" => "pni",
        "sse4.1" => "sse4_1",
        "sse4.2" => "sse4_2",
        "lzcnt" => "abm",
        "cmpxchg16b" => "cx16",
        "sha" => "sha_ni",
        "ermsb" => "erms",
        "lahfsahf" => "lahf_lm",
        "prfchw" => "3dnowprefetch",
        "avxvnni" => "avx_vnni",
        "avx512bf16" => "avx512_bf16",
        "avx512bitalg" => "avx512_bitalg",
        "avx512fp16" => "avx512_fp16",
        "avx512vbmi2" => "avx512_vbmi2",
        "avx512vnni" => "avx512_vnni",
        "avx512vp2intersect" => "avx512_vp2intersect",
        "avx512vpopcntdq" => "avx512_vpopcntdq",
        other => other,
    }
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    for var in ["RUSTFLAGS", "CARGO_ENCODED_RUSTFLAGS"] {
        println!("cargo:rerun-if-env-changed={var}");
    }
    let var = |k: &str| env::var(k).unwrap_or_default();
    let native_linux = var("CARGO_CFG_TARGET_ARCH") == "x86_64"
        && var("CARGO_CFG_TARGET_OS") == "linux"
        && var("TARGET") == var("HOST");
    let mut stamp: Vec<String> = Vec::new();
    if native_linux {
        let cpuinfo = fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let host: Vec<&str> = cpuinfo
            .lines()
            .find(|l| l.starts_with("flags"))
            .and_then(|l| l.split_once(':'))
            .map_or(vec![], |(_, f)| f.split_whitespace().collect());
        let features = var("CARGO_CFG_TARGET_FEATURE");
        for feature in features.split(',') {
            let name = cpuinfo_name(feature);
            if host.contains(&name) && !stamp.iter().any(|s| s == name) {
                stamp.push(name.to_string());
            }
        }
    }
    let out = Path::new(&var("OUT_DIR")).join("cpu_features.txt");
    fs::write(out, stamp.join(" ")).expect("OUT_DIR is writable");
}

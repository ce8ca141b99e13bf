//! Four f64 lanes (`wide::f64x4`, AVX in the build) for the hand-written kernels of the crate
//! (`assembly::lanes`, `rotation::rotate_edges`, `shear::saved_step_strains`, the routing's
//! span length; docs/dynamics.md, session 20): gathering a value per lane and broadcasting one.
pub(crate) use wide::f64x4;

/// Four lanes from a value per lane.
#[inline(always)]
pub(crate) fn lanes(f: impl Fn(usize) -> f64) -> f64x4 {
    f64x4::new([f(0), f(1), f(2), f(3)])
}

/// One value in all four lanes.
#[inline(always)]
pub(crate) fn splat(x: f64) -> f64x4 {
    f64x4::splat(x)
}

//! Projection onto the stiff axis: the node positions relaxed with the rotations frozen.
//!
//! A finite step along a linearised mode (or a descent direction) moves the nodes along
//! straight lines while the frames turn, so it stretches the axis and shears the section at
//! second order in the step; with EA/EI = 1e8 that strain energy swamps the bending energy
//! the step gains, and an escape from an unstable state crawls (docs/solver.md, "Escape").
//! With the rotations fixed the strains Γ = Rᵀ(x_{n+1} − x_n)/Δs − e3 are linear in the
//! positions and gravity and dead loads are linear too, so the energy is quadratic in them:
//! one Newton step on the position unknowns alone (rotation slots and the free angles of
//! swivels and hinges eliminated) is its exact minimiser — the Newton projection back onto
//! the equilibrium of the stiff axial and shear strains. Further terms that are not quadratic
//! (contact, sliding guides) take a few more steps.
use crate::assembly::{KinkAt, Term, Workspace};
use crate::model::Rod;
use crate::state::State;
use nalgebra::Vector6;

/// Most Newton steps of one projection (one suffices without contact).
const MAX_STEPS: usize = 4;

/// Relaxes the node positions of `st` at load factor 1 with the rotations frozen (see the
/// module). `ws` and `delta` are scratch (a workspace of this rod, one block vector).
/// Stops when the position correction is below `tolerance` times the cable length. Returns
/// false (state as far as it got) if a factorisation is singular.
pub(crate) fn relax_positions(
    ws: &mut Workspace,
    rod: &Rod,
    st: &mut State,
    terms: &mut [&mut dyn Term],
    delta: &mut [Vector6<f64>],
    tolerance: f64,
) -> Result<bool, KinkAt> {
    let nb = rod.arc.len();
    for _ in 0..MAX_STEPS {
        ws.assemble_terms(rod, st, 1.0, true, terms)?;
        for b in 0..nb {
            let m = &rod.mask[b];
            let position = m[0] && m[1] && m[2];
            for k in 0..6 {
                if !(position && k < 3) {
                    ws.jac.eliminate_slot(b, k);
                    ws.rhs[b][k] = 0.0;
                }
            }
        }
        if ws.jac.factor().is_err() {
            return Ok(false);
        }
        let (dx, _) = ws.newton_correction(delta);
        if !dx.is_finite() {
            return Ok(false);
        }
        st.apply_increment(rod, delta, 1.0);
        if dx < tolerance * rod.spec.length {
            break;
        }
    }
    Ok(true)
}

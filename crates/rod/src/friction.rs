//! Regularised Coulomb friction shared by contact (`contact.rs`) and the sliding clips' guides
//! (`sliding.rs`): IPC's f₁ with a stick zone of width ε, and the Newton step's bound at that
//! zone.

/// φ(s) = f₁(s)/s and φ′(s) for the slip magnitude s ≥ 0, stick width ε: f₁(s) = 2s/ε − s²/ε²
/// below ε (a spring of stiffness 2/ε at rest), 1 beyond (the Coulomb force).
#[inline]
pub fn f1_over(s: f64, eps: f64) -> (f64, f64) {
    if s < eps {
        (2.0 / eps - s / (eps * eps), -1.0 / (eps * eps))
    } else {
        (1.0 / s, -1.0 / (s * s))
    }
}

/// `alpha` lowered so that a point with slip u (tangential, since the step's start) moved by
/// α d is not carried from slipping one way to slipping the other (|u| > ε before and after,
/// the slip reversed): it stops where its slip comes nearest to zero, α = −u·d/|d|². Outside
/// the stick zone the friction is a force of constant size, so Newton does not see the stick
/// spring it would jump over and cycles across the zone (measured on the guides and on contact,
/// docs/scene.md "Friction in dynamic runs"); from inside it the next iterate sees it. Given
/// by the dot products u·u, u·d, d·d (a guide's slip is a scalar along its line).
#[inline]
pub fn stick_cut(uu: f64, ud: f64, dd: f64, eps: f64, alpha: f64) -> f64 {
    let (next_u, next_next) = (uu + alpha * ud, uu + alpha * (2.0 * ud + alpha * dd));
    if uu > eps * eps && next_next > eps * eps && next_u < 0.0 {
        alpha.min(-ud / dd)
    } else {
        alpha
    }
}

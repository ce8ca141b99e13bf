//! Shared set-ups for the rod's integration tests.
#![allow(dead_code)]
use nalgebra::Vector3;
use rod::rotation::{frame_quaternion, Quat};
use rod::{CableSpec, ClipKind, ClipSpec, Pose, Section};

/// Circle of radius r, Young's modulus E, Poisson ν, density ρ; shear coefficient 6(1+ν)/(7+6ν).
pub fn circle(r: f64, e: f64, nu: f64, rho: f64) -> Section {
    let a = std::f64::consts::PI * r * r;
    let i = std::f64::consts::PI * r.powi(4) / 4.0;
    let g = e / (2.0 * (1.0 + nu));
    let kappa = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
    Section {
        shear_stiffness: Vector3::new(kappa * g * a, kappa * g * a, e * a),
        bend_stiffness: Vector3::new(e * i, e * i, g * 2.0 * i),
        mass_per_length: rho * a,
        rotary_inertia: Vector3::new(rho * i, rho * i, rho * 2.0 * i),
    }
}

pub fn pose(pos: [f64; 3], tangent: [f64; 3], normal: [f64; 3]) -> Pose {
    Pose {
        position: Vector3::from(pos),
        orientation: frame_quaternion(&Vector3::from(tangent), &Vector3::from(normal)).unwrap(),
    }
}

pub fn clip(name: &str, s: f64, length: f64, kind: ClipKind, pose: Pose) -> ClipSpec {
    ClipSpec {
        name: name.into(),
        s,
        length,
        kind,
        pose,
    }
}

/// A cantilever along +x clamped at x = 0, d1 = +z.
pub fn cantilever(length: f64, segments: usize, section: Section) -> CableSpec {
    CableSpec {
        length,
        segments,
        section,
        natural_curvature: Vector3::zeros(),
        clips: vec![clip(
            "root",
            0.0,
            0.0,
            ClipKind::Fixed,
            pose([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        )],
        loads: vec![],
        gravity: Vector3::zeros(),
    }
}

pub fn identity_pose() -> Pose {
    Pose {
        position: Vector3::zeros(),
        orientation: Quat::identity(),
    }
}

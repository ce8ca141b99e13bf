//! The assembled Jacobian equals the finite-difference derivative of the residual along the
//! Newton update (x ← x + δ, p ← p ⊗ exp(δ/2), swivel and hinge angles), for every clip type.
mod common;
use common::*;
use nalgebra::{Vector3, Vector6};
use rod::assembly::Workspace;
use rod::rotation::rotate_body;
use rod::routing::route;
use rod::{ClipKind, PointLoad, Rod};

fn check(rod: &Rod) {
    check_at(rod, route(rod, None).unwrap());
}

fn check_at(rod: &Rod, mut st: rod::State) {
    // Move away from the routed shape so every term (incl. the ½[g]× correction) is non-zero.
    for (i, x) in st.x.iter_mut().enumerate() {
        if rod.node_kind[i] == rod::model::NodeKind::Free {
            *x += Vector3::new(
                (i as f64 * 0.7).sin(),
                (i as f64 * 1.3).cos(),
                (i as f64 * 0.4).sin(),
            ) * 2e-3;
        }
    }
    for (e, p) in st.p.iter_mut().enumerate() {
        if !matches!(rod.edge_kind[e], rod::model::EdgeKind::Prescribed { .. }) {
            *p = rotate_body(
                p,
                &(Vector3::new((e as f64).sin(), (e as f64 * 2.1).cos(), 0.5) * 0.05),
            );
        }
    }
    let mut ws = Workspace::new(rod);
    ws.assemble_static(rod, &st, 1.0, true).unwrap();
    let jac = ws.jac.clone();
    let nb = rod.n_edges() + 1;
    let h = 1e-7;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    let mut residual_at = |b: usize, k: usize, step: f64| {
        let mut d = vec![Vector6::zeros(); nb];
        d[b][k] = step;
        let mut s2 = st.clone();
        s2.apply_increment(rod, &d, 1.0);
        ws.assemble_static(rod, &s2, 1.0, false).unwrap();
        ws.rhs.clone()
    };
    for b in 0..nb {
        for k in 0..6 {
            if !rod.mask[b][k] {
                continue;
            }
            let (rp, rm) = (residual_at(b, k, h), residual_at(b, k, -h));
            for r in b.saturating_sub(1)..(b + 2).min(nb) {
                let fd = (rp[r] - rm[r]) / (2.0 * h);
                let an = if r == b {
                    jac.diag[b].column(k).into_owned()
                } else if r + 1 == b {
                    jac.upper[r].column(k).into_owned()
                } else {
                    jac.lower[r].column(k).into_owned()
                };
                for i in (0..6).filter(|&i| rod.mask[r][i]) {
                    worst = worst.max((fd[i] - an[i]).abs());
                    scale = scale.max(an[i].abs());
                }
            }
        }
    }
    assert!(
        worst < 1e-6 * scale,
        "Jacobian differs from finite differences: {worst:e} (scale {scale:e})"
    );
}

#[test]
fn jacobian_fixed_clamps_gravity_and_moments() {
    let mut spec = cantilever(1.0, 12, circle(0.005, 5e7, 0.45, 1500.0));
    spec.gravity = Vector3::new(0.0, 0.0, -9.81);
    spec.natural_curvature = Vector3::new(0.5, -0.2, 0.3);
    spec.loads.push(PointLoad {
        s: 1.0,
        force: Vector3::new(0.1, 0.2, -0.3),
        moment: Vector3::new(0.01, -0.02, 0.005),
    });
    spec.loads.push(PointLoad {
        s: 0.5,
        force: Vector3::zeros(),
        moment: Vector3::new(0.0, 0.03, 0.01),
    });
    check(&Rod::new(spec).unwrap());
}

#[test]
fn jacobian_swivel_ball_and_finite_clips() {
    let mut spec = cantilever(1.0, 16, circle(0.005, 5e7, 0.45, 1500.0));
    spec.gravity = Vector3::new(0.0, 0.0, -9.81);
    spec.clips = vec![
        clip(
            "a",
            0.0,
            0.0,
            ClipKind::Swivel,
            pose([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "b",
            0.3,
            0.06,
            ClipKind::Swivel,
            pose([0.28, 0.0, 0.02], [1.0, 0.1, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "c",
            0.55,
            0.0,
            ClipKind::Ball,
            pose([0.5, 0.05, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "d",
            0.8,
            0.0,
            ClipKind::Swivel,
            pose([0.7, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "e",
            0.95,
            0.04,
            ClipKind::Fixed,
            pose([0.72, 0.2, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ),
    ];
    check(&Rod::new(spec).unwrap());
}

#[test]
fn jacobian_hinges_with_oblique_axes() {
    let mut spec = cantilever(1.0, 16, circle(0.005, 5e7, 0.45, 1500.0));
    spec.gravity = Vector3::new(0.0, 0.0, -9.81);
    spec.natural_curvature = Vector3::new(0.4, 0.1, -0.2);
    spec.loads.push(PointLoad {
        s: 1.0,
        force: Vector3::new(0.1, -0.2, 0.05),
        moment: Vector3::new(0.01, 0.0, -0.02),
    });
    spec.clips = vec![
        clip(
            "a",
            0.0,
            0.0,
            ClipKind::Hinge {
                axis: Vector3::new(0.2, 1.0, 0.3),
            },
            pose([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "b",
            0.45,
            0.0,
            ClipKind::Hinge {
                axis: Vector3::new(1.0, -0.5, 2.0),
            },
            pose([0.4, 0.05, 0.02], [1.0, 0.2, 0.0], [0.0, 0.0, 1.0]),
        ),
        clip(
            "c",
            0.8,
            0.0,
            ClipKind::Ball,
            pose([0.7, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ),
    ];
    let rod = Rod::new(spec).unwrap();
    let st = route(&rod, None).unwrap();
    // Turn the hinge ghosts off the clip frames so that the angle's terms are general.
    let mut moved = st.clone();
    for (g, ghost) in rod.ghosts.iter().enumerate() {
        let a = ghost.free_axis.unwrap();
        moved.ghost[g] = rotate_body(&moved.ghost[g], &(0.3 * a));
    }
    check_at(&rod, moved);
}

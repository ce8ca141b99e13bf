//! The junction coupling term (docs/harness.md): a cable end held by a junction is a point
//! clip whose pose is the junction's pose times the end's stress-free relative rotation. The
//! cable's assembly computes the end's residual (∂V/∂x_n at the held node, ∂V/∂φ at its
//! ghost rotation) as for any clip; this term adds the Jacobian entries of the end's six
//! unknowns (Δx_n, φ of the ghost, body frame) that a clip eliminates: the end–end block and
//! the coupling blocks between the end and the cable blocks next to it. The harness maps them
//! to the junction's unknowns and eliminates the cable onto the junction.
use crate::assembly::{Eval, KinkAt, Rates, Term, Workspace};
use crate::bending::{BendKinematics, BendViscous};
use crate::model::{EdgeKind, NodeKind, Rod, RotRef};
use crate::rotation::{skew, Quat};
use crate::shear::{ShearKinematics, ShearViscous};
use crate::state::State;
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// Where a cable end sits in the cable: its node, ghost rotation, adjacent edge and the
/// bending half cell between the ghost and that edge.
#[derive(Clone, Copy, Debug)]
pub struct EndTopology {
    pub clip: usize,
    pub node: usize,
    pub ghost: usize,
    pub edge: usize,
    pub bend_term: usize,
    /// The end is the cable's start (s = 0).
    pub at_start: bool,
}

impl EndTopology {
    /// The end held by point clip `clip` (fixed, at s = 0 or s = L, with a ghost rotation).
    pub fn new(rod: &Rod, clip: usize) -> Option<EndTopology> {
        let ghost = rod.clip_ghost.get(clip).copied().flatten()?;
        if rod.ghosts[ghost].is_free() {
            return None;
        }
        let node = rod.ghosts[ghost].node;
        let n_edges = rod.n_edges();
        let at_start = node == 0;
        if !(at_start || node == n_edges) {
            return None;
        }
        let edge = if at_start { 0 } else { n_edges - 1 };
        let bend_term = rod.bend_terms.iter().position(|t| {
            t.node == node && (t.a == RotRef::Ghost(ghost) || t.b == RotRef::Ghost(ghost))
        })?;
        Some(EndTopology {
            clip,
            node,
            ghost,
            edge,
            bend_term,
            at_start,
        })
    }

    /// The cable blocks the end couples to: the block of the adjacent edge's rotation and, at
    /// the start, the block of the next node (n = 1).
    pub fn blocks(&self) -> [usize; 2] {
        if self.at_start {
            [0, 1]
        } else {
            [self.edge, self.edge]
        }
    }
}

/// The Jacobian blocks of one held end, in the end's local unknowns (Δx_n, φ): `ee` end–end;
/// `ec[i]` rows of the end, columns of cable block `topo.blocks()[i]`; `ce[i]` the converse.
/// Inactive slots of the cable blocks are zero.
#[derive(Clone, Debug)]
pub struct EndBlocks {
    pub topo: EndTopology,
    pub ee: Matrix6<f64>,
    pub ec: [Matrix6<f64>; 2],
    pub ce: [Matrix6<f64>; 2],
}

impl EndBlocks {
    pub fn new(topo: EndTopology) -> Self {
        EndBlocks {
            topo,
            ee: Matrix6::zeros(),
            ec: [Matrix6::zeros(); 2],
            ce: [Matrix6::zeros(); 2],
        }
    }

    /// The end's residual (∂V/∂x_n − f_ext, ∂V/∂φ) after an assembly of its cable.
    pub fn residual(&self, ws: &Workspace) -> Vector6<f64> {
        let mut r = Vector6::zeros();
        r.fixed_rows_mut::<3>(0)
            .copy_from(&ws.node_grad[self.topo.node]);
        r.fixed_rows_mut::<3>(3)
            .copy_from(&ws.ghost_grad[self.topo.ghost]);
        r
    }

    fn put(
        &mut self,
        end_half: usize,
        cable: Option<(usize, usize)>,
        ec: &Matrix3<f64>,
        ce: &Matrix3<f64>,
    ) {
        let Some((slot, half)) = cable else { return };
        let mut v = self.ec[slot].fixed_view_mut::<3, 3>(3 * end_half, 3 * half);
        v += ec;
        let mut v = self.ce[slot].fixed_view_mut::<3, 3>(3 * half, 3 * end_half);
        v += ce;
    }

    /// Computes the blocks at state `st` (static: no rates); the cable's elastic assembly must
    /// have run (the ghost gradient gives the rotation-group correction ½[g]×).
    pub fn compute(&mut self, rod: &Rod, st: &State, ws: &Workspace) -> Result<(), KinkAt> {
        self.compute_with_rates(rod, st, ws, None)
    }

    /// `compute` with the Kelvin–Voigt damping of `rates` (dynamics: the viscous forces and
    /// their derivatives, `rates.damping_factor` × those along the rates, the held end's
    /// velocity and rotation rate included; derivatives along a free edge's rotation times its
    /// step's J_r, as in the cable's own blocks).
    pub fn compute_with_rates(
        &mut self,
        rod: &Rod,
        st: &State,
        ws: &Workspace,
        rates: Option<&Rates>,
    ) -> Result<(), KinkAt> {
        let t = self.topo;
        self.ee.fill(0.0);
        for m in self.ec.iter_mut().chain(self.ce.iter_mut()) {
            m.fill(0.0);
        }
        let blocks = t.blocks();
        let sec = &rod.spec.section;
        // Shear element of the adjacent edge: variables (x_a, x_b, θ).
        let e = t.edge;
        let kin = ShearKinematics::new(
            &st.x[e],
            &st.x[e + 1],
            &st.p[e],
            rod.ds_edge[e],
            &Vector3::zeros(),
        );
        let mut f = sec.shear_stiffness.component_mul(&kin.strain);
        let viscous = rates.map(|r| {
            let va: Vector3<f64> = r.v[e].fixed_rows::<3>(0).into();
            let vb: Vector3<f64> = r.v[e + 1].fixed_rows::<3>(0).into();
            let omega: Vector3<f64> = r.v[e].fixed_rows::<3>(3).into();
            f += r.shear_damping.component_mul(&kin.rate(&va, &vb, &omega));
            ShearViscous {
                coeff: r.shear_damping,
                factor: r.damping_factor,
                rate_theta: rod.edge_kind[e] == EdgeKind::Free,
                va,
                vb,
                omega,
                tangent: r.tangent_of(RotRef::Edge(e), rod),
            }
        });
        let jb = kin.jacobian(&f, &sec.shear_stiffness, viscous.as_ref());
        let (i_end, i_other, other) = if t.at_start { (0, 1, e + 1) } else { (1, 0, e) };
        {
            let mut v = self.ee.fixed_view_mut::<3, 3>(0, 0);
            v += jb.block(i_end, i_end);
        }
        let other_var =
            (rod.node_kind[other] == NodeKind::Free).then_some((usize::from(t.at_start), 0));
        self.put(
            0,
            other_var,
            &jb.block(i_end, i_other),
            &jb.block(i_other, i_end),
        );
        let edge_var = (!matches!(rod.edge_kind[e], EdgeKind::Prescribed { .. })).then_some((0, 1));
        self.put(0, edge_var, &jb.block(i_end, 2), &jb.block(2, i_end));
        // Bending half cell between the ghost and the edge.
        let bt = rod.bend_terms[t.bend_term];
        let rot = |r: RotRef| -> Quat {
            match r {
                RotRef::Edge(k) => st.p[k],
                RotRef::Ghost(g) => st.ghost[g],
            }
        };
        let bk = BendKinematics::new(&rot(bt.a), &rot(bt.b), bt.weight).map_err(|kink| KinkAt {
            node: bt.node,
            kink,
        })?;
        let mut m = sec
            .bend_stiffness
            .component_mul(&(bk.curvature - rod.spec.natural_curvature));
        let viscous = rates.map(|r| {
            let (omega_a, omega_b) = (r.omega(bt.a), r.omega(bt.b));
            m += r.bend_damping.component_mul(&bk.rate(&omega_a, &omega_b));
            // The held ghost turns with its junction: a rate too (its J_r is not tracked: the
            // junction's rotation is moved from the right by the Newton update).
            let tracked = |x: RotRef| match x {
                RotRef::Ghost(_) => true,
                RotRef::Edge(k) => rod.edge_kind[k] == EdgeKind::Free,
            };
            BendViscous {
                coeff: r.bend_damping,
                factor: r.damping_factor,
                rate_a: tracked(bt.a),
                rate_b: tracked(bt.b),
                omega_a,
                omega_b,
                tangent_a: r.tangent_of(bt.a, rod),
                tangent_b: r.tangent_of(bt.b, rod),
            }
        });
        let h = bk.jacobian(&m, &sec.bend_stiffness, viscous.as_ref());
        let (ig, io) = if bt.a == RotRef::Ghost(t.ghost) {
            (0, 1)
        } else {
            (1, 0)
        };
        {
            let mut v = self.ee.fixed_view_mut::<3, 3>(3, 3);
            v += h[ig][ig] + 0.5 * skew(&ws.ghost_grad[t.ghost]);
        }
        self.put(1, edge_var, &h[ig][io], &h[io][ig]);
        // Terms acting on the end node's position (contact): their entries at the held node.
        let held = &ws.end_jac[usize::from(!t.at_start)];
        {
            let mut v = self.ee.fixed_view_mut::<3, 3>(0, 0);
            v += held.diag;
        }
        self.put(0, other_var, &held.row, &held.col);
        // Inactive slots of the cable blocks carry no coupling.
        for (i, &b) in blocks.iter().enumerate() {
            for k in 0..6 {
                if !rod.mask[b][k] {
                    self.ec[i].column_mut(k).fill(0.0);
                    self.ce[i].row_mut(k).fill(0.0);
                }
            }
        }
        Ok(())
    }
}

/// The junction-held ends of one cable as a term of its assembly.
#[derive(Clone, Debug, Default)]
pub struct HeldEnds {
    pub ends: Vec<EndBlocks>,
}

impl Term for HeldEnds {
    fn add_residual_jacobian(
        &mut self,
        rod: &Rod,
        st: &State,
        ev: &Eval,
        ws: &mut Workspace,
    ) -> Result<(), KinkAt> {
        if !ev.want_jac {
            return Ok(());
        }
        for end in &mut self.ends {
            end.compute(rod, st, ws)?;
        }
        Ok(())
    }
}

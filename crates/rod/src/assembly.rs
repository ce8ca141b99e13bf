//! Residual and Jacobian of the static equilibrium (gradient of the potential energy in the
//! coordinates x_n and θ with p ← p ⊗ exp(θ/2)), section outputs and clip reactions.
//!
//! The Jacobian is the exact derivative of the residual along the Newton update: the symmetric
//! energy Hessian plus ½[g]× on each rotation's own block (g its energy gradient), which comes
//! from exp(δ)exp(θ) = exp(δ + θ + ½ δ×θ + …), plus the derivative of dead moments −[Rᵀ M]×.
use crate::bending::{BendKinematics, BendViscous, Kink};
use crate::block_tridiag::{Block, BlockTridiag, Singular};
use crate::model::{EdgeKind, NodeKind, Rod, RotRef, Segment};
use crate::rotation::{rotation_matrix, skew, Quat};
use crate::shear::{ShearKinematics, ShearViscous};
use crate::state::State;
use crate::statics::SolveError;
use nalgebra::{Matrix3, Vector3, Vector6};

mod lanes;
use lanes::Elements;

/// Scratch and outputs of one assembly; allocated once per cable.
#[derive(Clone, Debug)]
pub struct Workspace {
    pub jac: BlockTridiag,
    /// Residual by block, inactive slots zeroed (the Newton right-hand side is −rhs).
    pub rhs: Vec<Vector6<f64>>,
    /// ∂V/∂x_n − f_ext (global): at prescribed nodes, the force of the clip on the cable.
    pub node_grad: Vec<Vector3<f64>>,
    /// ∂V/∂θ − Rᵀ m_ext per edge (body frame).
    pub edge_grad: Vec<Vector3<f64>>,
    /// ∂V/∂θ per ghost rotation (body frame of the ghost).
    pub ghost_grad: Vec<Vector3<f64>>,
    /// Section forces on edges, material frame.
    pub edge_force: Vec<Vector3<f64>>,
    /// Section moments on nodes, material frame (average of the two half cells at a clip).
    pub node_moment: Vec<Vector3<f64>>,
    /// The viscous (Kelvin–Voigt) parts of `edge_force` and `node_moment` (outputs, with rates).
    pub edge_force_viscous: Vec<Vector3<f64>>,
    pub node_moment_viscous: Vec<Vector3<f64>>,
    node_moment_count: Vec<u8>,
    pub elastic_energy: f64,
    /// Dissipated power of the viscous damping, W (with rates).
    pub dissipation: f64,
    /// Potential of the external loads (−work), at the current load factor.
    pub load_potential: f64,
    /// Energy of the contact barrier.
    pub contact_energy: f64,
    /// Reactions of clips that hold no node (sliding clips), set by their term.
    pub held_reaction: Vec<Option<(Vector3<f64>, Vector3<f64>)>>,
    /// Jacobian entries of the terms at the cable's two end nodes (start, end) where such a
    /// node is held (the cable's own matrix has no rows or columns for it): a junction end,
    /// whose node is the junction's unknown, takes them into its blocks (`junction::EndBlocks`).
    pub end_jac: [EndNodeJacobian; 2],
    /// Whether `Part::All` assemblies store the section forces and moments and sum the elastic
    /// energy (true by default; false: residual and Jacobian only, 13 % cheaper — the Newton
    /// iterations of a harness, whose outputs are assembled on the saved steps).
    pub section_outputs: bool,
    /// The outputs pass of a dynamic step (`Dynamics::update_outputs`): section loads and
    /// energies everywhere, but the gradients only where the clip reactions and the joined ends
    /// read them (`reaction_edge`, `reaction_bend`, `reaction_block`); no residual vector and
    /// no Jacobian. The values read are those of the full assembly to the last bit (the same
    /// terms add to them in the same order).
    pub outputs_only: bool,
    /// Per edge: its shear term reaches a clip's node or edge; per bending term: it reaches a
    /// clip's edge or a ghost rotation; per block: its node and its edge are a clip's.
    reaction_edge: Vec<bool>,
    reaction_bend: Vec<bool>,
    pub(crate) reaction_block: Vec<[bool; 2]>,
}

/// Jacobian entries at a held end node of a cable (`Workspace::end_jac`): `diag` ∂r_end/∂x_end,
/// `row` ∂r_end/∂x_next, `col` ∂r_next/∂x_end with `next` the adjacent node (1 or N − 1).
#[derive(Clone, Copy, Debug, Default)]
pub struct EndNodeJacobian {
    pub diag: Matrix3<f64>,
    pub row: Matrix3<f64>,
    pub col: Matrix3<f64>,
}

/// What an assembly evaluates: the part of the cable, whether the Jacobian is wanted, the
/// rates (viscoelastic and dynamic assemblies) and the load factor of the external loads.
#[derive(Clone, Copy)]
pub struct Eval<'a> {
    pub part: Part<'a>,
    pub want_jac: bool,
    pub rates: Option<&'a Rates>,
    pub load_factor: f64,
}

/// A term of the assembly (DESIGN.md §3 "One assembly of terms over a topology"): adds its
/// residual (gradients by node, edge and ghost) and its Jacobian blocks over the cable's
/// topology. Internal forces, gravity and dead loads, and contact are terms; solvers add their
/// own (inertia) and sum them in one Newton system.
pub trait Term {
    fn add_residual_jacobian(
        &mut self,
        rod: &Rod,
        st: &State,
        ev: &Eval,
        ws: &mut Workspace,
    ) -> Result<(), KinkAt>;
}

/// Shear/extension and bending/torsion elements (with Kelvin–Voigt damping given rates).
pub struct Elastic;

/// Gravity and dead point loads, scaled by the load factor.
pub struct External;

impl Term for Elastic {
    #[inline]
    fn add_residual_jacobian(
        &mut self,
        rod: &Rod,
        st: &State,
        ev: &Eval,
        ws: &mut Workspace,
    ) -> Result<(), KinkAt> {
        ws.add_elastic_part(rod, st, ev.rates, ev.want_jac, ev.part)
    }
}

impl Term for External {
    #[inline]
    fn add_residual_jacobian(
        &mut self,
        rod: &Rod,
        st: &State,
        ev: &Eval,
        ws: &mut Workspace,
    ) -> Result<(), KinkAt> {
        ws.add_external_part(rod, st, ev.load_factor, ev.want_jac, ev.part, ev.rates);
        Ok(())
    }
}

/// An optional term (e.g. contact when enabled) adds nothing when absent.
impl<T: Term> Term for Option<T> {
    #[inline]
    fn add_residual_jacobian(
        &mut self,
        rod: &Rod,
        st: &State,
        ev: &Eval,
        ws: &mut Workspace,
    ) -> Result<(), KinkAt> {
        match self {
            Some(t) => t.add_residual_jacobian(rod, st, ev, ws),
            None => Ok(()),
        }
    }
}

/// Velocities and damping for a viscoelastic assembly.
#[derive(Clone, Debug)]
pub struct Rates {
    /// Per block: ẋ_n (global), ω_{n+½} (body frame).
    pub v: Vec<Vector6<f64>>,
    /// Body angular velocity of each ghost rotation (its clip's).
    pub ghost_omega: Vec<Vector3<f64>>,
    /// τ ∘ C^Γ and τ ∘ C^K: the viscous section coefficients.
    pub shear_damping: Vector3<f64>,
    pub bend_damping: Vector3<f64>,
    /// Factor of the damping matrix in the Jacobian (γ/(βh) in generalized-α).
    pub damping_factor: f64,
    /// Per edge, J_r(hΔθ) of the rotation's increment in the step (empty: none), by which the
    /// configuration derivatives along the edge's rotation are multiplied (the Newton update
    /// changes the increment hΔθ, not the rotation from the right).
    pub tangent: Vec<Matrix3<f64>>,
}

impl Rates {
    /// J_r of a rotation's step (free edges only: the swivel twists and hinge angles are moved by
    /// the Newton update directly).
    #[inline]
    pub(crate) fn tangent_of(&self, r: RotRef, rod: &Rod) -> Option<Matrix3<f64>> {
        match r {
            RotRef::Edge(e) if !self.tangent.is_empty() && rod.edge_kind[e] == EdgeKind::Free => {
                Some(self.tangent[e])
            }
            _ => None,
        }
    }

    pub(crate) fn omega(&self, r: RotRef) -> Vector3<f64> {
        match r {
            RotRef::Edge(e) => self.v[e].fixed_rows::<3>(3).into(),
            RotRef::Ghost(g) => self.ghost_omega[g],
        }
    }
}

/// The curvature became singular (180° between neighbouring rotations) at a node.
#[derive(Clone, Copy, Debug)]
pub struct KinkAt {
    pub node: usize,
    pub kink: Kink,
}

/// What an assembly covers: the whole cable, or one independent segment (whose residual rows
/// and Jacobian blocks are then computed alone; reactions and section outputs need `All`).
#[derive(Clone, Copy, Debug)]
pub enum Part<'a> {
    All,
    Segment(&'a Segment),
}

/// A variable of an element: where its 3 coordinates go in the block structure.
#[derive(Clone, Copy)]
enum Var {
    /// Full 3-vector at (block, half).
    Full(usize, usize),
    /// Only the component along a unit axis (body frame), stored in slot 0 of the block (the
    /// free angle of a swivel or hinge ghost).
    Axis(usize, Vector3<f64>),
    /// Not an unknown.
    None,
}

impl Workspace {
    pub fn new(rod: &Rod) -> Self {
        let n = rod.n_edges();
        // The nodes and edges whose gradients give reactions (`clip_reaction`, the joined
        // ends' residuals at their ghosts' nodes).
        let mut node_clip = vec![false; n + 1];
        let mut edge_clip = vec![false; n];
        for c in 0..rod.spec.clips.len() {
            rod.clip_nodes[c].iter().for_each(|&k| node_clip[k] = true);
            rod.clip_edges[c].iter().for_each(|&e| edge_clip[e] = true);
        }
        rod.ghosts.iter().for_each(|g| node_clip[g.node] = true);
        Workspace {
            jac: BlockTridiag::new(n + 1),
            rhs: vec![Vector6::zeros(); n + 1],
            node_grad: vec![Vector3::zeros(); n + 1],
            edge_grad: vec![Vector3::zeros(); n],
            ghost_grad: vec![Vector3::zeros(); rod.ghosts.len()],
            edge_force: vec![Vector3::zeros(); n],
            node_moment: vec![Vector3::zeros(); n + 1],
            edge_force_viscous: vec![Vector3::zeros(); n],
            node_moment_viscous: vec![Vector3::zeros(); n + 1],
            node_moment_count: vec![0; n + 1],
            elastic_energy: 0.0,
            dissipation: 0.0,
            load_potential: 0.0,
            contact_energy: 0.0,
            held_reaction: vec![None; rod.spec.clips.len()],
            end_jac: [EndNodeJacobian::default(); 2],
            section_outputs: true,
            outputs_only: false,
            reaction_edge: (0..n)
                .map(|e| node_clip[e] || node_clip[e + 1] || edge_clip[e])
                .collect(),
            reaction_bend: rod
                .bend_terms
                .iter()
                .map(|t| {
                    [t.a, t.b].iter().any(|r| match *r {
                        RotRef::Edge(e) => edge_clip[e],
                        RotRef::Ghost(_) => true,
                    })
                })
                .collect(),
            reaction_block: (0..=n)
                .map(|b| [node_clip[b], b < n && edge_clip[b]])
                .collect(),
        }
    }

    /// Adds ∂r_n/∂x_m (3×3, node rows n, node columns m, n and m equal or adjacent) of a term
    /// acting on node positions: into the cable's matrix when both nodes are free, into
    /// `end_jac` when one is a held end node, else nowhere (a clip prescribes it). Two held
    /// nodes couple nowhere: a one-segment cable joined at both ends loses the contact
    /// coupling of its two junctions (the residual stays exact; Newton converges linearly).
    pub fn add_node_block(&mut self, rod: &Rod, n: usize, m: usize, block: &Matrix3<f64>) {
        let free = |k: usize| rod.node_kind[k] == NodeKind::Free;
        match (free(n), free(m)) {
            (true, true) => self.jac.add3(n, 0, m, 0, block),
            (false, false) if n != m => {}
            (n_free, _) => {
                let end = if n_free { m } else { n }; // the held node
                let last = rod.n_edges();
                let Some(j) = (end == 0).then_some(0).or((end == last).then_some(1)) else {
                    return;
                };
                let e = &mut self.end_jac[j];
                if n == m {
                    e.diag += block;
                } else if n == end {
                    e.row += block;
                } else {
                    e.col += block;
                }
            }
        }
    }

    pub fn clear(&mut self, want_jac: bool) {
        self.clear_part(Part::All, want_jac);
    }

    /// Zeroes the gradients (and Jacobian rows) of a part and the energy sums.
    pub fn clear_part(&mut self, part: Part, want_jac: bool) {
        match part {
            Part::All => {
                if want_jac {
                    self.jac.clear();
                    self.end_jac = [EndNodeJacobian::default(); 2];
                }
                self.node_grad.iter_mut().for_each(|v| v.fill(0.0));
                self.edge_grad.iter_mut().for_each(|v| v.fill(0.0));
                self.ghost_grad.iter_mut().for_each(|v| v.fill(0.0));
                self.node_moment.iter_mut().for_each(|v| v.fill(0.0));
                self.node_moment_viscous
                    .iter_mut()
                    .for_each(|v| v.fill(0.0));
                self.node_moment_count.iter_mut().for_each(|c| *c = 0);
            }
            Part::Segment(seg) => {
                if want_jac {
                    self.jac.clear_range(seg.blocks.clone());
                    if seg.blocks.start == 0 {
                        self.end_jac[0] = EndNodeJacobian::default();
                    }
                    if seg.blocks.end >= self.edge_grad.len() {
                        self.end_jac[1] = EndNodeJacobian::default();
                    }
                }
                let n_edges = self.edge_grad.len();
                for b in seg.blocks.clone() {
                    self.node_grad[b].fill(0.0);
                    if b < n_edges {
                        self.edge_grad[b].fill(0.0);
                    }
                }
                for &g in &seg.ghosts {
                    self.ghost_grad[g].fill(0.0);
                }
            }
        }
        self.elastic_energy = 0.0;
        self.dissipation = 0.0;
        self.load_potential = 0.0;
        self.contact_energy = 0.0;
    }

    fn add(&mut self, vi: Var, vj: Var, m: &Matrix3<f64>) {
        let (bi, hi, mi) = match vi {
            Var::Full(b, h) => (b, h, *m),
            Var::Axis(b, a) => {
                let mut r = Matrix3::zeros();
                r.set_row(0, &(a.transpose() * m));
                (b, 0, r)
            }
            Var::None => return,
        };
        match vj {
            Var::Full(b, h) => self.jac.add3(bi, hi, b, h, &mi),
            Var::Axis(b, a) => {
                let mut c = Matrix3::zeros();
                c.set_column(0, &(mi * a));
                self.jac.add3(bi, hi, b, 0, &c);
            }
            Var::None => {}
        }
    }

    /// Elastic terms (shear/extension and bending/torsion) with the rotation-group correction;
    /// with `rates`, Kelvin–Voigt damping too: the section stress is C(Γ−Γ⁰) + τ∘C Γ̇ (and the
    /// same for K), the stored section forces and moments include it, and the Jacobian gets
    /// `rates.damping_factor` × the damping matrix Jᵀ τ∘C J plus the derivative of the viscous
    /// forces through the strain rates' dependence on the configuration (Jᵀ τ∘C ∂(J v)/∂q).
    pub fn add_elastic(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        want_jac: bool,
    ) -> Result<(), KinkAt> {
        self.add_elastic_part(rod, st, rates, want_jac, Part::All)
    }

    /// `add_elastic` for a part (section moments are averaged only for `All`).
    /// With `rates.tangent`, the rotation-group correction is multiplied by it too.
    pub fn add_elastic_part(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        want_jac: bool,
        part: Part,
    ) -> Result<(), KinkAt> {
        // The energy sums (elastic energy, dissipated power) in locals through the loops.
        let mut sums = (self.elastic_energy, self.dissipation);
        let terms = self.elastic_terms(rod, st, rates, want_jac, part, &mut sums);
        (self.elastic_energy, self.dissipation) = sums;
        terms?;
        if want_jac {
            let edges = match part {
                Part::All => 0..rod.n_edges(),
                Part::Segment(seg) => seg.blocks.start..seg.blocks.end.min(rod.n_edges()),
            };
            for e in edges {
                if rod.edge_kind[e] != EdgeKind::Free {
                    continue; // prescribed, or a single twist axis (whose correction is zero)
                }
                let mut corr = 0.5 * skew(&self.edge_grad[e]);
                if let Some(jr) = rates.and_then(|r| r.tangent_of(RotRef::Edge(e), rod)) {
                    corr *= jr;
                }
                add_half(&mut self.jac.diag[e], 1, 1, &corr);
            }
        }
        Ok(())
    }

    /// The shear and bending terms of `part` (`add_elastic_part`); without the Jacobian four
    /// elements at a time (`lanes`, the same values to the last bit).
    fn elastic_terms(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        want_jac: bool,
        part: Part,
        sums: &mut (f64, f64),
    ) -> Result<(), KinkAt> {
        // section outputs (averaged at the nodes) only for the whole cable
        let (edges, terms, outputs) = match part {
            Part::All => (
                Elements::Range(0, rod.n_edges()),
                Elements::Range(0, rod.bend_terms.len()),
                self.section_outputs,
            ),
            Part::Segment(seg) => (
                Elements::List(&seg.edges),
                Elements::List(&seg.bend_terms),
                false,
            ),
        };
        if want_jac {
            for k in 0..edges.len() {
                self.shear_term(rod, st, rates, true, edges.at(k), outputs, sums);
            }
            for k in 0..terms.len() {
                self.bend_term(rod, st, rates, true, terms.at(k), outputs, sums)?;
            }
        } else {
            self.shear_terms_lanes(rod, st, rates, edges, outputs, sums);
            self.bend_terms_lanes(rod, st, rates, terms, outputs, sums)?;
        }
        for n in 0..if outputs { self.node_moment.len() } else { 0 } {
            if self.node_moment_count[n] > 1 {
                let w = 1.0 / self.node_moment_count[n] as f64;
                self.node_moment[n] *= w;
                self.node_moment_viscous[n] *= w;
            }
        }
        Ok(())
    }

    /// Shear/extension element of edge e (with `outputs`, its energy and section force are
    /// stored; `sums`: the elastic energy and the dissipated power summed so far).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn shear_term(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        want_jac: bool,
        e: usize,
        outputs: bool,
        sums: &mut (f64, f64),
    ) {
        let sec = &rod.spec.section;
        let strain0 = Vector3::zeros();
        let ds = rod.ds_edge[e];
        let kin = ShearKinematics::new(&st.x[e], &st.x[e + 1], &st.p[e], ds, &strain0);
        let f_el = sec.shear_stiffness.component_mul(&kin.strain);
        if outputs {
            sums.0 += 0.5 * ds * kin.strain.dot(&f_el);
        }
        let mut f = f_el;
        let mut viscous = None;
        if let Some(r) = rates {
            let va: Vector3<f64> = r.v[e].fixed_rows::<3>(0).into();
            let vb: Vector3<f64> = r.v[e + 1].fixed_rows::<3>(0).into();
            let omega: Vector3<f64> = r.v[e].fixed_rows::<3>(3).into();
            let gd = kin.rate(&va, &vb, &omega);
            let fd = r.shear_damping.component_mul(&gd);
            sums.1 += ds * gd.dot(&fd);
            f += fd;
            if want_jac {
                viscous = Some(ShearViscous {
                    coeff: r.shear_damping,
                    factor: r.damping_factor,
                    rate_theta: rod.edge_kind[e] == EdgeKind::Free,
                    va,
                    vb,
                    omega,
                    tangent: r.tangent_of(RotRef::Edge(e), rod),
                });
            }
        }
        if outputs {
            self.edge_force[e] = f;
            self.edge_force_viscous[e] = f - f_el;
        }
        if !self.outputs_only || self.reaction_edge[e] {
            let rf = kin.r * f;
            self.node_grad[e] -= rf;
            self.node_grad[e + 1] += rf;
            self.edge_grad[e] += ds * f.cross(&kin.u);
        }
        if want_jac {
            let jb = kin.jacobian(&f, &sec.shear_stiffness, viscous.as_ref());
            let a_free = rod.node_kind[e] == NodeKind::Free;
            let b_free = rod.node_kind[e + 1] == NodeKind::Free;
            let edge = !matches!(rod.edge_kind[e], EdgeKind::Prescribed { .. });
            let jac = &mut self.jac;
            if a_free {
                add_half(&mut jac.diag[e], 0, 0, &-jb.x);
            }
            if b_free {
                add_half(&mut jac.diag[e + 1], 0, 0, &-jb.x);
            }
            if a_free && b_free {
                add_half(&mut jac.upper[e], 0, 0, &jb.x);
                add_half(&mut jac.lower[e + 1], 0, 0, &jb.x);
            }
            if edge {
                add_half(&mut jac.diag[e], 1, 1, &jb.t);
                if a_free {
                    add_half(&mut jac.diag[e], 0, 1, &-jb.y);
                    add_half(&mut jac.diag[e], 1, 0, &jb.w);
                }
                if b_free {
                    add_half(&mut jac.lower[e + 1], 0, 1, &jb.y);
                    add_half(&mut jac.upper[e], 1, 0, &-jb.w);
                }
            }
        }
    }

    /// Bending/torsion term i (with `outputs`, its section moment is added to the node's).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn bend_term(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        want_jac: bool,
        i: usize,
        outputs: bool,
        sums: &mut (f64, f64),
    ) -> Result<(), KinkAt> {
        let sec = &rod.spec.section;
        let k0 = rod.spec.natural_curvature;
        let t = &rod.bend_terms[i];
        let kin = BendKinematics::new(&rot(st, t.a), &rot(st, t.b), t.weight)
            .map_err(|kink| KinkAt { node: t.node, kink })?;
        let dk = kin.curvature - k0;
        let m_el = sec.bend_stiffness.component_mul(&dk);
        if outputs {
            sums.0 += 0.5 * t.weight * dk.dot(&m_el);
        }
        let mut m = m_el;
        let mut viscous = None;
        if let Some(r) = rates {
            let (omega_a, omega_b) = (r.omega(t.a), r.omega(t.b));
            let kd = kin.rate(&omega_a, &omega_b);
            let md = r.bend_damping.component_mul(&kd);
            sums.1 += t.weight * kd.dot(&md);
            m += md;
            if want_jac {
                viscous = Some(BendViscous {
                    coeff: r.bend_damping,
                    factor: r.damping_factor,
                    rate_a: matches!(rate_var(rod, t.a), Var::Full(..)),
                    rate_b: matches!(rate_var(rod, t.b), Var::Full(..)),
                    omega_a,
                    omega_b,
                    tangent_a: r.tangent_of(t.a, rod),
                    tangent_b: r.tangent_of(t.b, rod),
                });
            }
        }
        if outputs {
            self.node_moment[t.node] += m;
            self.node_moment_viscous[t.node] += m - m_el;
            self.node_moment_count[t.node] += 1;
        }
        if !self.outputs_only || self.reaction_bend[i] {
            let g = kin.forces(&m);
            for (r, gi) in [(t.a, g[0]), (t.b, g[1])] {
                match r {
                    RotRef::Edge(e) => self.edge_grad[e] += gi,
                    RotRef::Ghost(k) => self.ghost_grad[k] += gi,
                }
            }
        }
        if want_jac {
            let h = kin.jacobian(&m, &sec.bend_stiffness, viscous.as_ref());
            match (t.a, t.b) {
                (RotRef::Edge(ea), RotRef::Edge(eb))
                    if eb == ea + 1
                        && rod.edge_kind[ea] == EdgeKind::Free
                        && rod.edge_kind[eb] == EdgeKind::Free =>
                {
                    let jac = &mut self.jac;
                    add_half(&mut jac.diag[ea], 1, 1, &h[0][0]);
                    add_half(&mut jac.upper[ea], 1, 1, &h[0][1]);
                    add_half(&mut jac.lower[eb], 1, 1, &h[1][0]);
                    add_half(&mut jac.diag[eb], 1, 1, &h[1][1]);
                }
                _ => {
                    let vars = [rot_var(rod, t.a), rot_var(rod, t.b)];
                    for i in 0..2 {
                        for j in 0..2 {
                            self.add(vars[i], vars[j], &h[i][j]);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Gravity and point loads, scaled by `load_factor`.
    pub fn add_external(&mut self, rod: &Rod, st: &State, load_factor: f64, want_jac: bool) {
        self.add_external_part(rod, st, load_factor, want_jac, Part::All, None);
    }

    /// `add_external` for the nodes and edges of a part (the load potential only for `All`);
    /// the dead-moment derivative times `rates.tangent` if given.
    pub fn add_external_part(
        &mut self,
        rod: &Rod,
        st: &State,
        load_factor: f64,
        want_jac: bool,
        part: Part,
        rates: Option<&Rates>,
    ) {
        let g = rod.spec.gravity;
        let blocks = part_blocks(rod, part);
        let potential = matches!(part, Part::All);
        for n in blocks.clone() {
            let f = load_factor * (rod.node_mass[n] * g + rod.node_force[n]);
            self.node_grad[n] -= f;
            if potential {
                self.load_potential -= f.dot(&st.x[n]);
            }
        }
        for e in blocks.start..blocks.end.min(rod.n_edges()) {
            let m = rod.edge_moment[e];
            if m == Vector3::zeros() {
                continue;
            }
            let mb = rotation_matrix(&st.p[e]).transpose() * (load_factor * m);
            self.edge_grad[e] -= mb;
            if want_jac {
                let mut d = -skew(&mb);
                if let Some(jr) = rates.and_then(|r| r.tangent_of(RotRef::Edge(e), rod)) {
                    d *= jr;
                }
                self.jac.add3(e, 1, e, 1, &d);
            }
        }
    }

    /// Gathers the gradients into the block residual and eliminates inactive slots.
    pub fn finalize(&mut self, rod: &Rod, want_jac: bool) {
        self.finalize_part(rod, want_jac, Part::All);
    }

    /// `finalize` for the blocks of a part.
    pub fn finalize_part(&mut self, rod: &Rod, want_jac: bool, part: Part) {
        let n_edges = rod.n_edges();
        let blocks = part_blocks(rod, part);
        for n in blocks.clone() {
            let mut r = Vector6::zeros();
            r.fixed_rows_mut::<3>(0).copy_from(&self.node_grad[n]);
            if n < n_edges {
                r.fixed_rows_mut::<3>(3).copy_from(&self.edge_grad[n]);
            }
            self.rhs[n] = r;
        }
        for (k, g) in rod.ghosts.iter().enumerate() {
            if let Some(a) = g.free_axis {
                if blocks.contains(&g.node) {
                    self.rhs[g.node][0] = self.ghost_grad[k].dot(&a);
                }
            }
        }
        for n in blocks {
            if rod.mask[n] == [true; 6] {
                continue;
            }
            for k in 0..6 {
                if !rod.mask[n][k] {
                    self.rhs[n][k] = 0.0;
                    if want_jac {
                        self.jac.eliminate_slot(n, k);
                    }
                }
            }
        }
    }

    /// Full static assembly at a load factor (internal forces, gravity and dead loads).
    pub fn assemble_static(
        &mut self,
        rod: &Rod,
        st: &State,
        load_factor: f64,
        want_jac: bool,
    ) -> Result<(), KinkAt> {
        self.assemble_terms(rod, st, load_factor, want_jac, &mut [])
    }

    /// Full static assembly with further terms (e.g. contact) after the internal forces and
    /// the external loads.
    pub fn assemble_terms(
        &mut self,
        rod: &Rod,
        st: &State,
        load_factor: f64,
        want_jac: bool,
        more: &mut [&mut dyn Term],
    ) -> Result<(), KinkAt> {
        let ev = Eval {
            part: Part::All,
            want_jac,
            rates: None,
            load_factor,
        };
        self.clear(want_jac);
        Elastic.add_residual_jacobian(rod, st, &ev, self)?;
        External.add_residual_jacobian(rod, st, &ev, self)?;
        for t in more.iter_mut() {
            t.add_residual_jacobian(rod, st, &ev, self)?;
        }
        self.finalize(rod, want_jac);
        Ok(())
    }

    /// Reaction force and moment (about the clip point) of clip `c` on the cable, global frame.
    /// Valid after an assembly at the state `st`.
    pub fn clip_reaction(&self, rod: &Rod, st: &State, c: usize) -> (Vector3<f64>, Vector3<f64>) {
        if let Some(r) = self.held_reaction[c] {
            return r;
        }
        let centre = st.clip_pose[c].position;
        let mut f = Vector3::zeros();
        let mut m = Vector3::zeros();
        for &n in &rod.clip_nodes[c] {
            f += self.node_grad[n];
            m += (st.x[n] - centre).cross(&self.node_grad[n]);
        }
        for &e in &rod.clip_edges[c] {
            m += rotation_matrix(&st.p[e]) * self.edge_grad[e];
        }
        if let Some(g) = rod.clip_ghost[c] {
            m += rotation_matrix(&st.ghost[g]) * self.ghost_grad[g];
        }
        (f, m)
    }

    /// Factors the assembled Jacobian; a singular pivot is reported at its node.
    pub fn factor(&mut self, rod: &Rod) -> Result<(), SolveError> {
        self.jac
            .factor()
            .map_err(|Singular { block }| SolveError::Singular {
                node: block,
                s: rod.arc[block.min(rod.arc.len() - 1)],
            })
    }

    /// Factors the Jacobian rows of a segment (see `factor`).
    pub fn factor_segment(&mut self, rod: &Rod, seg: &Segment) -> Result<(), SolveError> {
        self.factor_segment_dir(rod, seg, false)
    }

    /// `factor_segment` eliminating towards the segment's first block with `rev`
    /// (`BlockTridiag::factor_range_dir`).
    pub fn factor_segment_dir(
        &mut self,
        rod: &Rod,
        seg: &Segment,
        rev: bool,
    ) -> Result<(), SolveError> {
        self.jac
            .factor_range_dir(seg.blocks.clone(), rev)
            .map_err(|Singular { block }| SolveError::Singular {
                node: block,
                s: rod.arc[block.min(rod.arc.len() - 1)],
            })
    }

    /// The Newton correction Δ = −J⁻¹ r with the current factorisation, and its largest
    /// position and rotation components (|Δx|, |θ|).
    pub fn newton_correction(&self, delta: &mut [Vector6<f64>]) -> (f64, f64) {
        self.newton_correction_range(0..delta.len(), delta)
    }

    /// `newton_correction` for the blocks `r` of an independent segment (its factorisation).
    pub fn newton_correction_range(
        &self,
        r: std::ops::Range<usize>,
        delta: &mut [Vector6<f64>],
    ) -> (f64, f64) {
        for b in r.clone() {
            delta[b] = -self.rhs[b];
        }
        self.jac.solve_range(r.clone(), delta);
        let (mut dx, mut dth) = (0.0f64, 0.0f64);
        for d in &delta[r] {
            dx = dx.max(d.fixed_rows::<3>(0).amax());
            dth = dth.max(d.fixed_rows::<3>(3).amax());
        }
        (dx, dth)
    }

    /// The ∞-norm of `residual_norms_range` alone (forces in N, moments divided by `length`):
    /// no squares, and the blocks' maxima taken by the vector units.
    pub fn residual_inf_range(&self, r: std::ops::Range<usize>, length: f64) -> f64 {
        let scale = Vector6::new(1.0, 1.0, 1.0, 1.0 / length, 1.0 / length, 1.0 / length);
        let mut inf = Vector6::zeros();
        for r in &self.rhs[r] {
            inf = inf.sup(&r.abs().component_mul(&scale));
        }
        inf.max()
    }

    /// Scaled residual norms (max over blocks): forces in N, moments divided by `length`.
    pub fn residual_norms(&self, length: f64) -> (f64, f64) {
        self.residual_norms_range(0..self.rhs.len(), length)
    }

    /// `residual_norms` over the blocks `r`.
    pub fn residual_norms_range(&self, r: std::ops::Range<usize>, length: f64) -> (f64, f64) {
        let mut two = 0.0;
        let mut inf = 0.0f64;
        let inv_length = 1.0 / length;
        for r in &self.rhs[r] {
            for k in 0..6 {
                let v = if k < 3 { r[k] } else { r[k] * inv_length };
                two += v * v;
                inf = inf.max(v.abs());
            }
        }
        (two.sqrt(), inf)
    }
}

/// The blocks of a part.
#[inline]
fn part_blocks(rod: &Rod, part: Part) -> std::ops::Range<usize> {
    match part {
        Part::All => 0..rod.arc.len(),
        Part::Segment(seg) => seg.blocks.clone(),
    }
}

/// Adds a 3×3 matrix to the (hi, hj) half of a 6×6 block.
#[inline(always)]
fn add_half(block: &mut Block, hi: usize, hj: usize, m: &Matrix3<f64>) {
    let mut v = block.fixed_view_mut::<3, 3>(3 * hi, 3 * hj);
    v += m;
}

#[inline]
fn rot(st: &State, r: RotRef) -> Quat {
    match r {
        RotRef::Edge(e) => st.p[e],
        RotRef::Ghost(g) => st.ghost[g],
    }
}

fn edge_var(rod: &Rod, e: usize) -> Var {
    match rod.edge_kind[e] {
        EdgeKind::Prescribed { .. } => Var::None,
        _ => Var::Full(e, 1),
    }
}

/// The rotation unknowns whose velocities the dynamics tracks (free edges): the damping matrix
/// has columns only for these (every equation depends on them); the massless swivel twists are
/// quasistatic, their rate is not modelled.
fn rate_var(rod: &Rod, r: RotRef) -> Var {
    match r {
        RotRef::Edge(e) if rod.edge_kind[e] == EdgeKind::Free => Var::Full(e, 1),
        _ => Var::None,
    }
}

fn rot_var(rod: &Rod, r: RotRef) -> Var {
    match r {
        RotRef::Edge(e) => edge_var(rod, e),
        RotRef::Ghost(g) => {
            let gh = rod.ghosts[g];
            match gh.free_axis {
                Some(a) => Var::Axis(gh.node, a),
                None => Var::None,
            }
        }
    }
}

//! The residual of the shear and bending terms (no Jacobian) four elements at a time, in the
//! f64x4 lanes of `wide` (AVX where the build has it): the Newton iterations of a dynamic step
//! and its outputs pass assemble only the residual, and these two terms were a quarter of a
//! harness run.
//!
//! Each lane performs the operations of `Workspace::shear_term` and `Workspace::bend_term`
//! (and of the `ShearKinematics` and `BendKinematics` they call) in the same order, without
//! fused multiply-adds, so the values are those of the one-element code to the last bit; the
//! sums over elements (energies, gradients, section moments) are then added element by element
//! in the same order as there (tests: `lanes_equal_the_element_code_bit_for_bit`). Elements are
//! gathered from and scattered to the per-node and per-edge arrays, so any list of elements
//! works (all, or a segment's); a block of four with a kinked bending cell is left to the
//! one-element code, which reports it.
use super::{rot, KinkAt, Workspace};
use crate::assembly::Rates;
use crate::bending::MIN_COS_HALF;
use crate::model::{Rod, RotRef};
use crate::simd::{f64x4, lanes, splat};
use crate::state::State;
use nalgebra::Vector3;

/// The elements of a part: a range (the whole cable) or a list (a segment's).
#[derive(Clone, Copy)]
pub(crate) enum Elements<'a> {
    Range(usize, usize),
    List(&'a [usize]),
}

impl Elements<'_> {
    pub(super) fn len(&self) -> usize {
        match self {
            Elements::Range(a, b) => b - a,
            Elements::List(l) => l.len(),
        }
    }

    #[inline(always)]
    pub(super) fn at(&self, k: usize) -> usize {
        match self {
            Elements::Range(a, _) => a + k,
            Elements::List(l) => l[k],
        }
    }
}

type V = f64x4;

/// A vector of three lanes.
#[derive(Clone, Copy)]
struct V3 {
    x: V,
    y: V,
    z: V,
}

impl V3 {
    #[inline(always)]
    fn gather(f: impl Fn(usize) -> Vector3<f64>) -> V3 {
        let v: [Vector3<f64>; 4] = std::array::from_fn(f);
        V3 {
            x: lanes(|l| v[l].x),
            y: lanes(|l| v[l].y),
            z: lanes(|l| v[l].z),
        }
    }

    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    #[inline(always)]
    fn scale(self, s: V) -> V3 {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Component-wise product with a constant vector.
    #[inline(always)]
    fn times(self, c: &Vector3<f64>) -> V3 {
        V3 {
            x: splat(c.x) * self.x,
            y: splat(c.y) * self.y,
            z: splat(c.z) * self.z,
        }
    }

    /// As nalgebra's dot of 3-vectors: (a0 b0 + a1 b1) + a2 b2.
    #[inline(always)]
    fn dot(self, o: V3) -> V {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn cross(self, o: V3) -> V3 {
        V3 {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }

    #[inline(always)]
    fn lanes(&self) -> [Vector3<f64>; 4] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|l| Vector3::new(x[l], y[l], z[l]))
    }
}

/// A 3 × 3 matrix of lanes, row-major.
struct M3([[V; 3]; 3]);

impl M3 {
    /// `rotation::rotation_matrix` of four quaternions.
    #[inline(always)]
    fn rotation(w: V, x: V, y: V, z: V) -> M3 {
        let (xx, yy, zz) = (x * x, y * y, z * z);
        let (xy, xz, yz) = (x * y, x * z, y * z);
        let (wx, wy, wz) = (w * x, w * y, w * z);
        let (one, two) = (splat(1.0), splat(2.0));
        M3([
            [one - two * (yy + zz), two * (xy - wz), two * (xz + wy)],
            [two * (xy + wz), one - two * (xx + zz), two * (yz - wx)],
            [two * (xz - wy), two * (yz + wx), one - two * (xx + yy)],
        ])
    }

    /// M v, each row as nalgebra's product: (m0 v0 + m1 v1) + m2 v2.
    #[inline(always)]
    fn mul(&self, v: V3) -> V3 {
        let r = |i: usize| self.0[i][0] * v.x + self.0[i][1] * v.y + self.0[i][2] * v.z;
        V3 {
            x: r(0),
            y: r(1),
            z: r(2),
        }
    }

    /// Mᵀ v.
    #[inline(always)]
    fn tr_mul(&self, v: V3) -> V3 {
        let c = |j: usize| self.0[0][j] * v.x + self.0[1][j] * v.y + self.0[2][j] * v.z;
        V3 {
            x: c(0),
            y: c(1),
            z: c(2),
        }
    }
}

impl Workspace {
    /// `shear_term` (without the Jacobian) of `edges`, four at a time; `sums` the elastic
    /// energy and the dissipated power as in `add_elastic_part`.
    pub(super) fn shear_terms_lanes(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        edges: Elements,
        outputs: bool,
        sums: &mut (f64, f64),
    ) {
        // one loop per case, without its branches
        match (rates.is_some(), outputs) {
            (true, true) => self.shear_lanes::<true, true>(rod, st, rates, edges, sums),
            (true, false) => self.shear_lanes::<true, false>(rod, st, rates, edges, sums),
            (false, true) => self.shear_lanes::<false, true>(rod, st, rates, edges, sums),
            (false, false) => self.shear_lanes::<false, false>(rod, st, rates, edges, sums),
        }
    }

    fn shear_lanes<const RATES: bool, const OUTPUTS: bool>(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        edges: Elements,
        sums: &mut (f64, f64),
    ) {
        let outputs = OUTPUTS;
        let n = edges.len();
        let full = n - n % 4;
        let sec = &rod.spec.section;
        for k in (0..full).step_by(4) {
            let e: [usize; 4] = std::array::from_fn(|l| edges.at(k + l));
            let p: [_; 4] = std::array::from_fn(|l| st.p[e[l]]);
            let xa = V3::gather(|l| st.x[e[l]]);
            let xb = V3::gather(|l| st.x[e[l] + 1]);
            let ds = lanes(|l| rod.ds_edge[e[l]]);
            // ShearKinematics::new (Γ⁰ = 0, and x − 0 is x to the last bit: Γ = u − e₃)
            let r = M3::rotation(
                lanes(|l| p[l].w),
                lanes(|l| p[l].i),
                lanes(|l| p[l].j),
                lanes(|l| p[l].k),
            );
            let inv_ds = splat(1.0) / ds;
            let u = r.tr_mul(xb.sub(xa).scale(inv_ds));
            let strain = V3 {
                x: u.x,
                y: u.y,
                z: u.z - splat(1.0),
            };
            let f_el = strain.times(&sec.shear_stiffness);
            let energy = outputs.then(|| (splat(0.5) * ds * strain.dot(f_el)).to_array());
            let mut f = f_el;
            let mut dissipated = None;
            if let Some(rt) = rates.filter(|_| RATES) {
                let va = V3::gather(|l| rt.v[e[l]].fixed_rows::<3>(0).into());
                let vb = V3::gather(|l| rt.v[e[l] + 1].fixed_rows::<3>(0).into());
                let omega = V3::gather(|l| rt.v[e[l]].fixed_rows::<3>(3).into());
                let gd = r.tr_mul(vb.sub(va).scale(inv_ds)).add(u.cross(omega));
                let fd = gd.times(&rt.shear_damping);
                dissipated = Some((ds * gd.dot(fd)).to_array());
                f = f.add(fd);
            }
            let rf = r.mul(f).lanes();
            let moment = f.cross(u).lanes();
            let (fl, f_ell) = (f.lanes(), f_el.lanes());
            let ds = ds.to_array();
            for l in 0..4 {
                let e = e[l];
                if let Some(en) = energy {
                    sums.0 += en[l];
                }
                if let Some(d) = dissipated {
                    sums.1 += d[l];
                }
                if outputs {
                    self.edge_force[e] = fl[l];
                    self.edge_force_viscous[e] = fl[l] - f_ell[l];
                }
                if !self.outputs_only || self.reaction_edge[e] {
                    self.node_grad[e] -= rf[l];
                    self.node_grad[e + 1] += rf[l];
                    self.edge_grad[e] += ds[l] * moment[l];
                }
            }
        }
        for k in full..n {
            self.shear_term(rod, st, rates, false, edges.at(k), outputs, sums);
        }
    }

    /// `bend_term` (without the Jacobian) of the bending terms `terms`, four at a time.
    pub(super) fn bend_terms_lanes(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        terms: Elements,
        outputs: bool,
        sums: &mut (f64, f64),
    ) -> Result<(), KinkAt> {
        match (rates.is_some(), outputs) {
            (true, true) => self.bend_lanes::<true, true>(rod, st, rates, terms, sums),
            (true, false) => self.bend_lanes::<true, false>(rod, st, rates, terms, sums),
            (false, true) => self.bend_lanes::<false, true>(rod, st, rates, terms, sums),
            (false, false) => self.bend_lanes::<false, false>(rod, st, rates, terms, sums),
        }
    }

    fn bend_lanes<const RATES: bool, const OUTPUTS: bool>(
        &mut self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        terms: Elements,
        sums: &mut (f64, f64),
    ) -> Result<(), KinkAt> {
        let outputs = OUTPUTS;
        let n = terms.len();
        let sec = &rod.spec.section;
        let k0 = rod.spec.natural_curvature;
        let mut k = 0;
        while k + 4 <= n {
            let i: [usize; 4] = std::array::from_fn(|l| terms.at(k + l));
            let t: [_; 4] = std::array::from_fn(|l| &rod.bend_terms[i[l]]);
            let pa: [_; 4] = std::array::from_fn(|l| rot(st, t[l].a));
            let pb: [_; 4] = std::array::from_fn(|l| rot(st, t[l].b));
            // BendKinematics::new: q = p_a* p_b (nalgebra's product), g = q.imag / q.w
            let (ax, ay, az) = (
                -lanes(|l| pa[l].i),
                -lanes(|l| pa[l].j),
                -lanes(|l| pa[l].k),
            );
            let aw = lanes(|l| pa[l].w);
            let (bx, by, bz) = (lanes(|l| pb[l].i), lanes(|l| pb[l].j), lanes(|l| pb[l].k));
            let bw = lanes(|l| pb[l].w);
            let s = aw * bw - ax * bx - ay * by - az * bz;
            let q = V3 {
                x: aw * bx + ax * bw + ay * bz - az * by,
                y: aw * by - ax * bz + ay * bw + az * bx,
                z: aw * bz + ax * by - ay * bx + az * bw,
            };
            let nv = q.dot(q);
            let limit = MIN_COS_HALF * MIN_COS_HALF;
            let kinked = (s * s).simd_lt(splat(limit) * (s * s + nv));
            if kinked.any() {
                // the one-element code, which reports the first kinked cell
                for &i in &i {
                    self.bend_term(rod, st, rates, false, i, outputs, sums)?;
                }
                k += 4;
                continue;
            }
            let g = q.scale(splat(1.0) / s);
            let w = lanes(|l| t[l].weight);
            let inv_w = splat(1.0) / w;
            let curvature = g.scale(splat(2.0) * inv_w);
            let dk = curvature.sub(V3 {
                x: splat(k0.x),
                y: splat(k0.y),
                z: splat(k0.z),
            });
            let m_el = dk.times(&sec.bend_stiffness);
            let energy = outputs.then(|| (splat(0.5) * w * dk.dot(m_el)).to_array());
            let mut m = m_el;
            let mut dissipated = None;
            if let Some(rt) = rates.filter(|_| RATES) {
                let oa = V3::gather(|l| rt.omega(t[l].a));
                let ob = V3::gather(|l| rt.omega(t[l].b));
                // BendKinematics::rate
                let d = ob.sub(oa);
                let kd = d
                    .add(g.cross(oa.add(ob)))
                    .add(g.scale(g.dot(d)))
                    .scale(inv_w);
                let md = kd.times(&rt.bend_damping);
                dissipated = Some((w * kd.dot(md)).to_array());
                m = m.add(md);
            }
            // BendKinematics::forces
            let gm = g.cross(m);
            let proj = g.scale(g.dot(m));
            let minus_m = V3 {
                x: -m.x,
                y: -m.y,
                z: -m.z,
            };
            let force_a = minus_m.sub(gm).sub(proj).lanes();
            let force_b = m.sub(gm).add(proj).lanes();
            let (ml, m_ell) = (m.lanes(), m_el.lanes());
            for l in 0..4 {
                if let Some(en) = energy {
                    sums.0 += en[l];
                }
                if let Some(d) = dissipated {
                    sums.1 += d[l];
                }
                let node = t[l].node;
                if outputs {
                    self.node_moment[node] += ml[l];
                    self.node_moment_viscous[node] += ml[l] - m_ell[l];
                    self.node_moment_count[node] += 1;
                }
                if !self.outputs_only || self.reaction_bend[i[l]] {
                    for (r, gi) in [(t[l].a, force_a[l]), (t[l].b, force_b[l])] {
                        match r {
                            RotRef::Edge(e) => self.edge_grad[e] += gi,
                            RotRef::Ghost(g) => self.ghost_grad[g] += gi,
                        }
                    }
                }
            }
            k += 4;
        }
        for k in k..n {
            self.bend_term(rod, st, rates, false, terms.at(k), outputs, sums)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Part;
    use crate::modal::Rng;
    use crate::model::{CableSpec, ClipKind, ClipSpec, Pose, Section};
    use crate::rotation::{exp_half, Quat};
    use crate::routing::route;
    use nalgebra::{Matrix3, Vector6};

    /// A random vector of entries in [−scale/2, scale/2).
    fn vec(rng: &mut Rng, scale: f64) -> Vector3<f64> {
        Vector3::new(rng.next(), rng.next(), rng.next()) * scale
    }

    fn clip(name: &str, s: f64, length: f64, kind: ClipKind, x: f64) -> ClipSpec {
        ClipSpec {
            name: name.into(),
            s,
            length,
            kind,
            pose: Pose {
                position: Vector3::new(x, 0.0, 0.0),
                orientation: Quat::new(0.5f64.sqrt(), 0.0, 0.5f64.sqrt(), 0.0),
            },
        }
    }

    /// A cable with a point clip, a swivel, a hinge (ghost rotations) and a held length;
    /// 37 segments (a tail of one element after the blocks of four).
    fn rod() -> Rod {
        let spec = CableSpec {
            length: 1.0,
            segments: 37,
            section: Section {
                shear_stiffness: Vector3::new(1e4, 1.2e4, 3e4),
                bend_stiffness: Vector3::new(0.02, 0.025, 0.015),
                mass_per_length: 0.1,
                rotary_inertia: Vector3::new(1e-7, 1e-7, 2e-7),
            },
            natural_curvature: Vector3::new(0.5, -0.2, 0.3),
            clips: vec![
                clip("a", 0.0, 0.0, ClipKind::Fixed, 0.0),
                clip("b", 0.3, 0.0, ClipKind::Swivel, 0.3),
                clip(
                    "c",
                    0.55,
                    0.0,
                    ClipKind::Hinge {
                        axis: Vector3::new(0.3, 1.0, 0.0),
                    },
                    0.55,
                ),
                clip("d", 0.85, 0.06, ClipKind::Fixed, 0.85),
            ],
            loads: vec![],
            gravity: Vector3::new(0.0, 0.0, -9.81),
        };
        Rod::new(spec).unwrap()
    }

    /// The routed state moved off it at random (positions by ~1 mm, rotations by ~0.1 rad).
    fn state(rod: &Rod, rng: &mut Rng) -> State {
        let mut st = route(rod, None).unwrap();
        st.x.iter_mut().for_each(|x| *x += vec(rng, 2e-3));
        st.p.iter_mut().for_each(|p| *p *= exp_half(&vec(rng, 0.2)));
        st.ghost
            .iter_mut()
            .for_each(|p| *p *= exp_half(&vec(rng, 0.2)));
        st
    }

    fn rates(rod: &Rod, rng: &mut Rng) -> Rates {
        Rates {
            v: (0..rod.n_edges() + 1)
                .map(|_| Vector6::from_fn(|_, _| rng.next()))
                .collect(),
            ghost_omega: (0..rod.ghosts.len()).map(|_| vec(rng, 1.0)).collect(),
            shear_damping: Vector3::new(3.0, 4.0, 5.0),
            bend_damping: Vector3::new(2e-3, 3e-3, 1e-3),
            damping_factor: 0.0,
            tangent: Vec::<Matrix3<f64>>::new(),
        }
    }

    /// A workspace whose sums hold values already (the terms add to them).
    fn workspace(rod: &Rod, rng: &mut Rng, outputs_only: bool) -> Workspace {
        let mut ws = Workspace::new(rod);
        for v in ws
            .node_grad
            .iter_mut()
            .chain(&mut ws.edge_grad)
            .chain(&mut ws.ghost_grad)
            .chain(&mut ws.node_moment)
            .chain(&mut ws.node_moment_viscous)
        {
            *v = vec(rng, 1.0);
        }
        ws.outputs_only = outputs_only;
        ws
    }

    fn same(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> bool {
        a.len() == b.len()
            && a.iter().zip(b).all(|(u, v)| {
                u.iter()
                    .zip(v.iter())
                    .all(|(x, y)| x.to_bits() == y.to_bits())
            })
    }

    fn same_workspaces(a: &Workspace, b: &Workspace) -> bool {
        same(&a.node_grad, &b.node_grad)
            && same(&a.edge_grad, &b.edge_grad)
            && same(&a.ghost_grad, &b.ghost_grad)
            && same(&a.edge_force, &b.edge_force)
            && same(&a.edge_force_viscous, &b.edge_force_viscous)
            && same(&a.node_moment, &b.node_moment)
            && same(&a.node_moment_viscous, &b.node_moment_viscous)
            && a.node_moment_count == b.node_moment_count
    }

    #[test]
    fn lanes_equal_the_element_code_bit_for_bit() {
        let rod = rod();
        assert!(
            rod.ghosts.len() >= 2,
            "ghost rotations in the bending terms"
        );
        let mut rng = Rng(11);
        let st = state(&rod, &mut rng);
        let rt = rates(&rod, &mut rng);
        let (n, m) = (rod.n_edges(), rod.bend_terms.len());
        // a segment's lists: every other element, 1 + n/2 of them
        let edges: Vec<usize> = (0..n).step_by(2).collect();
        let terms: Vec<usize> = (0..m).step_by(2).collect();
        let mut cases = 0;
        for rates in [None, Some(&rt)] {
            for outputs in [false, true] {
                for only in [false, true] {
                    for (shear, bend) in [
                        (Elements::Range(0, n), Elements::Range(0, m)),
                        (Elements::List(&edges), Elements::List(&terms)),
                    ] {
                        let mut a = workspace(&rod, &mut Rng(5), only);
                        let mut b = a.clone();
                        let (mut sa, mut sb) = ((0.25, 0.75), (0.25, 0.75));
                        for k in 0..shear.len() {
                            a.shear_term(&rod, &st, rates, false, shear.at(k), outputs, &mut sa);
                        }
                        for k in 0..bend.len() {
                            a.bend_term(&rod, &st, rates, false, bend.at(k), outputs, &mut sa)
                                .unwrap();
                        }
                        b.shear_terms_lanes(&rod, &st, rates, shear, outputs, &mut sb);
                        b.bend_terms_lanes(&rod, &st, rates, bend, outputs, &mut sb)
                            .unwrap();
                        assert!(
                            same_workspaces(&a, &b),
                            "rates {} outputs {outputs} only {only}",
                            rates.is_some()
                        );
                        assert_eq!(sa.0.to_bits(), sb.0.to_bits());
                        assert_eq!(sa.1.to_bits(), sb.1.to_bits());
                        if outputs {
                            assert!(sa.0 != 0.25, "the energy is summed");
                        }
                        if rates.is_some() {
                            assert!(sa.1 != 0.75, "the dissipation is summed");
                        }
                        cases += 1;
                    }
                }
            }
        }
        assert_eq!(cases, 16);
        // the whole assembly: lanes without the Jacobian, the element code with it
        let (mut a, mut b) = (Workspace::new(&rod), Workspace::new(&rod));
        a.clear(true);
        a.add_elastic_part(&rod, &st, Some(&rt), true, Part::All)
            .unwrap();
        b.clear(false);
        b.add_elastic_part(&rod, &st, Some(&rt), false, Part::All)
            .unwrap();
        assert!(same_workspaces(&a, &b));
        assert_eq!(a.elastic_energy.to_bits(), b.elastic_energy.to_bits());
        assert_eq!(a.dissipation.to_bits(), b.dissipation.to_bits());
    }

    /// A cell turned by 180° in the middle of a block of four: the same error (node) and the
    /// same sums of the cells before it as the element code.
    #[test]
    fn a_kinked_cell_is_reported_as_by_the_element_code() {
        let rod = rod();
        let mut st = state(&rod, &mut Rng(3));
        let t = &rod.bend_terms[6];
        let (RotRef::Edge(ea), RotRef::Edge(eb)) = (t.a, t.b) else {
            panic!("term 6 joins two edges");
        };
        st.p[eb] = st.p[ea] * Quat::new(0.0, 1.0, 0.0, 0.0);
        let rt = rates(&rod, &mut Rng(4));
        let mut a = workspace(&rod, &mut Rng(5), false);
        let mut b = a.clone();
        let (mut sa, mut sb) = ((0.0, 0.0), (0.0, 0.0));
        let m = rod.bend_terms.len();
        let ea = (0..m)
            .try_for_each(|i| a.bend_term(&rod, &st, Some(&rt), false, i, true, &mut sa))
            .unwrap_err();
        let eb = b
            .bend_terms_lanes(&rod, &st, Some(&rt), Elements::Range(0, m), true, &mut sb)
            .unwrap_err();
        assert_eq!((ea.node, eb.node), (t.node, t.node));
        assert!(same_workspaces(&a, &b));
        assert_eq!(sa.1.to_bits(), sb.1.to_bits());
    }
}

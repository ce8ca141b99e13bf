//! Contact with the surroundings against analytical references: the capstan equation, a
//! frictionless wrap (equal tensions), a cable on a table (contact carries the weight), static
//! friction on an incline (stick below tan α = μ, sliding with g(sin α − μ cos α) above), a cable
//! dropped onto a plane (comes to rest, energy never grows, no tunnelling), the Jacobian of the
//! assembly with contact against finite differences, and bad settings.
mod common;
use common::*;
use nalgebra::{Vector3, Vector6};
use rod::contact::{
    Contact, ContactOptions, Cuboid, Cylinder, Obstacle, Plane, Shape, Sphere, NO_CONTACT, SLIP,
    STICK,
};
use rod::rotation::{frame_quaternion, Quat};
use rod::{
    CableSpec, ClipKind, ClipMotion, DynamicOptions, Dynamics, NewtonOptions, PointLoad, Pose, Rod,
    Section, SolveError, State, Statics,
};
use std::f64::consts::PI;

fn at(position: Vector3<f64>, normal: Vector3<f64>) -> Pose {
    // A frame whose z axis is `normal`.
    let t = rod::rotation::any_normal(&normal);
    Pose {
        position,
        orientation: frame_quaternion(&normal, &t).unwrap(),
    }
}

fn origin() -> Pose {
    Pose {
        position: Vector3::zeros(),
        orientation: Quat::identity(),
    }
}

/// A state through the given node positions; edge frames with d3 along the chord and d1
/// perpendicular to it, as close to `up` as possible; clip poses and ghosts from the spec.
fn state_through(rod: &Rod, x: Vec<Vector3<f64>>, up: Vector3<f64>) -> State {
    let p = x
        .windows(2)
        .map(|w| {
            let t = (w[1] - w[0]).normalize();
            frame_quaternion(&t, &(up - up.dot(&t) * t)).unwrap()
        })
        .collect();
    State {
        x,
        p,
        ghost: rod
            .ghosts
            .iter()
            .map(|g| rod.spec.clips[g.clip].pose.orientation)
            .collect(),
        clip_pose: rod.spec.clips.iter().map(|c| c.pose).collect(),
    }
}

/// A section with independent stiffnesses (N, N m²) and mass per length.
fn section(axial: f64, bend: f64, mass: f64) -> Section {
    Section {
        shear_stiffness: Vector3::new(axial, axial, axial),
        bend_stiffness: Vector3::new(bend, bend, 0.7 * bend),
        mass_per_length: mass,
        rotary_inertia: Vector3::new(1e-7, 1e-7, 2e-7) * mass,
    }
}

fn contact(rod: &Rod, obstacles: Vec<Obstacle>, radius: f64) -> Contact {
    Contact::new(rod, obstacles, ContactOptions::for_radius(radius), 1).unwrap()
}

/// Cable of radius r over a fixed cylinder (axis y, radius R) with wrap angle π: free end at
/// s = 0 hanging on the left under a dead load T₁ (down), a fixed clip at the end of the right
/// span. Returns the rod and the wrapped state.
struct Capstan {
    rod: Rod,
    st: State,
    r: f64,
    big_r: f64,
    load: f64,
}

/// The capstan over a cylinder primitive of the given length (finite: flat caps with sharp
/// rims, so every edge is sampled `max_samples` = 8 times, the wrap over the smooth mantle
/// too: the chord of an edge touches the drum near its middle sample, whose trapezoid weight
/// ds/8 then carries the edge's whole load).
fn capstan_over(mu: f64, length: f64) -> (Capstan, Statics) {
    capstan_on(
        mu,
        Box::new(Cylinder {
            radius: 0.05,
            length,
        }),
        0.0,
    )
}

/// The drum as a closed triangle mesh: a prism of `sides` faces with its corners on the circle
/// of radius R (a corner at angle 0: the vertical spans leave from corners), 1 m long, axis z.
fn drum_mesh(big_r: f64, sides: usize) -> rod::contact_mesh::MeshShape {
    let half = 0.5;
    let mut v = Vec::new();
    for z in [-half, half] {
        for k in 0..sides {
            let a = 2.0 * PI * k as f64 / sides as f64;
            v.push(Vector3::new(big_r * a.cos(), big_r * a.sin(), z));
        }
    }
    v.push(Vector3::new(0.0, 0.0, -half));
    v.push(Vector3::new(0.0, 0.0, half));
    let (n, cb, ct) = (sides as u32, 2 * sides as u32, 2 * sides as u32 + 1);
    let mut f = Vec::new();
    for k in 0..n {
        let k1 = (k + 1) % n;
        f.push([k, k1, n + k1]);
        f.push([k, n + k1, n + k]);
        f.push([ct, n + k, n + k1]);
        f.push([cb, k1, k]);
    }
    rod::contact_mesh::MeshShape::new(geometry::TriMesh::new(&v, &f).unwrap(), &v)
}

/// `corner`: the deflection at the drum's sharp corners (0: smooth); the nodes over the top start
/// clear of the corners by the depth a chord of the cable cuts there.
fn capstan_on(mu: f64, drum: Box<dyn Shape>, corner: f64) -> (Capstan, Statics) {
    let (r, big_r, span, load) = (0.002, 0.05, 0.1, 10.0);
    let n = 160;
    // Nodes on a circle clear of the drum by the chords' sagitta (the chords are the cable)
    // plus half the barrier's activation distance.
    let sag = (0.37f64 / n as f64).powi(2) / (8.0 * (big_r + r));
    let rc = big_r + r + sag + 0.005 * r;
    let arc = PI * rc;
    let length = 2.0 * span + arc;
    let spec = CableSpec {
        length,
        segments: n,
        section: section(1e5, 1e-5, 0.05),
        natural_curvature: Vector3::zeros(),
        clips: vec![clip(
            "pull",
            length,
            0.0,
            ClipKind::Fixed,
            pose([rc, 0.0, -span], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
        )],
        loads: vec![PointLoad {
            s: 0.0,
            force: Vector3::new(0.0, 0.0, -load),
            moment: Vector3::zeros(),
        }],
        gravity: Vector3::zeros(),
    };
    let rod = Rod::new(spec).unwrap();
    // Stretched by the tension T₁/EA, from the clip backwards.
    let stretch = 1.0 + load / 1e5;
    let x: Vec<Vector3<f64>> = rod
        .arc
        .iter()
        .map(|&s| {
            let u = (length - s) * stretch; // from the clip
            if u <= span {
                Vector3::new(rc, 0.0, -span + u)
            } else if u <= span + arc {
                let phi = (u - span) / rc; // from the right, over the top
                Vector3::new(rc * phi.cos(), 0.0, rc * phi.sin())
            } else {
                Vector3::new(-rc, 0.0, -(u - span - arc))
            }
        })
        .collect();
    // Drum axis along global y: its frame's z axis is y.
    let o = Obstacle::new("drum", 0, drum, mu, &at(Vector3::zeros(), Vector3::y()));
    let ds = length / n as f64;
    // Over the top, the nodes at the same clearance from the drum's surface (a tessellated
    // drum is inside the circle: nodes on it would be out of reach of the barrier).
    let x = x
        .into_iter()
        .map(|p: Vector3<f64>| {
            if p.z <= 0.0 {
                return p;
            }
            let q = o.query(&p);
            p - (q.distance - (rc - big_r) - 0.5 * ds * (0.5 * corner).sin()) * q.normal
        })
        .collect();
    let st = state_through(&rod, x, Vector3::new(0.0, 1.0, 0.0));
    let mut statics = Statics::new(&rod, NewtonOptions::default());
    // The default contact settings (the automatic stiffness, scaled to the load by the static
    // solve: `Contact::adapt_stiffness`).
    statics.contact = Some(Contact::new(&rod, vec![o], ContactOptions::for_radius(r), 1).unwrap());
    (
        Capstan {
            rod,
            st,
            r,
            big_r,
            load,
        },
        statics,
    )
}

/// Tension at the clip: minus the clip's reaction on the cable (which pulls down).
fn clip_tension(s: &Statics, c: &Capstan) -> f64 {
    -s.ws.clip_reaction(&c.rod, &c.st, 0).0.z
}

#[test]
fn frictionless_wrap_keeps_the_tension() {
    for length in [f64::INFINITY, 1.0] {
        frictionless_wrap_over(length);
    }
}

fn frictionless_wrap_over(length: f64) {
    let (mut c, mut s) = capstan_over(0.0, length);
    s.solve(&c.rod, &mut c.st).unwrap();
    let n = c.rod.n_edges();
    let (t1, t2) = (s.ws.edge_force[n / 8].z, s.ws.edge_force[n - n / 8].z);
    // Equal but for the rod's bending at the ends of the wrap (EI κ²/2, κ = 1/R).
    let bending = 0.5 * c.rod.spec.section.bend_stiffness.x / (c.big_r * c.big_r);
    assert!((t1 - c.load).abs() < 1e-9 * c.load, "T1 = {t1}");
    assert!((t2 - t1).abs() < bending, "T1 = {t1}, T2 = {t2}");
    assert!((clip_tension(&s, &c) - t2).abs() < bending);
    // Section force along the wrap: the same tension everywhere.
    for e in 0..n {
        let t = s.ws.edge_force[e].z;
        assert!((t - c.load).abs() < 2e-3 * c.load, "edge {e}: {t}");
    }
    // The contact force balances the pulls: total = 2 T up.
    let ct = s.contact.as_ref().unwrap();
    let total: Vector3<f64> = ct.normal_force.iter().sum();
    assert!((total - Vector3::new(0.0, 0.0, 2.0 * c.load)).norm() < 1e-3 * c.load);
    // No penetration of the capsules beyond 1 % of r; in contact within d̂ of the surface.
    let (gap, _, _) = ct.surface_gap(&c.st);
    assert!(gap > -0.01 * c.r && gap < 0.01 * c.r, "gap {gap}");
    // The barrier scaled to the load: the tension presses the drum at T/R = 200 N/m, 400 times
    // the weight the automatic stiffness is set for; the most loaded sample then sits at about
    // d̂/2 (at least d̂/10), not at nanometres.
    let dhat = ct.opts.distance;
    assert!(
        ct.obstacle_kappa[0] > 100.0 * ct.kappa,
        "κ {:?}",
        ct.obstacle_kappa
    );
    assert!(
        ct.min_gap() > 0.1 * dhat && ct.min_gap() < dhat,
        "gap {}",
        ct.min_gap()
    );
}

/// The drum holds the cable while the clip end is pulled slowly (dynamics, 5 cm/s: inertia
/// ρAv² ≈ 1e-4 N against 10 N); once the cable slides, the ratio of the end tensions is e^{μθ}.
#[test]
fn capstan_ratio_at_slip_is_exp_mu_theta() {
    let mu = 0.3;
    let exact = (mu * PI).exp();
    for length in [f64::INFINITY, 1.0] {
        let (c, s) = capstan_over(mu, length);
        let ratio = pulled_ratio(mu, c, s);
        assert!(
            (ratio - exact).abs() < 0.02 * exact,
            "drum length {length}: ratio {ratio} vs e^(μπ) = {exact}"
        );
    }
}

/// The same capstan over a tessellated drum: a prism mesh of 512 sides with its corners on the
/// circle (the wrap of π crosses 256 sharp corners of deflection 2π/512), through the mesh's
/// BVH queries with their edge and vertex Hessians. Asserted with the smooth drum's tolerance
/// (2 %). Measured (e^{0.3π} = 2.5663): smooth drum 2.5651, 512 sides 2.5674, 128 sides 2.5698:
/// the discrete cable meets each sharp corner with the sample points of its chords, whose
/// normals (from the corner) differ from the drum's by up to half the corner's deflection.
#[test]
fn capstan_ratio_on_a_tessellated_drum_mesh() {
    let mu = 0.3;
    let sides = 512;
    let alpha = 2.0 * PI / sides as f64;
    let (c, s) = capstan_on(mu, Box::new(drum_mesh(0.05, sides)), alpha);
    let ratio = pulled_ratio(mu, c, s);
    let exact = (mu * PI).exp();
    assert!(
        (ratio - exact).abs() < 0.02 * exact,
        "ratio {ratio} vs e^(μπ) = {exact}"
    );
}

/// Pulls the clip end of a solved capstan slowly and returns the mean end-tension ratio once
/// the cable slides over the drum.
fn pulled_ratio(mu: f64, mut c: Capstan, mut s: Statics) -> f64 {
    s.solve(&c.rod, &mut c.st).unwrap();
    let v = 0.05;
    let z0 = c.st.clip_pose[0].position.z;
    let motion = |t: f64| {
        let mut pose = c.rod.spec.clips[0].pose;
        pose.position.z = z0 - v * t;
        vec![ClipMotion {
            pose,
            velocity: Vector3::new(0.0, 0.0, -v),
            angular_velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        }]
    };
    let opts = DynamicOptions {
        tau_shear: Vector3::new(1e-4, 1e-4, 1e-4),
        tau_bend: Vector3::new(1e-3, 1e-3, 1e-3),
        ..Default::default()
    };
    let mut dy = Dynamics::new(&c.rod, &c.st, &motion(0.0), opts);
    dy.contact = s.contact.clone();
    dy.start(&c.rod, &c.st).unwrap();
    let h = 1e-3;
    let mut tensions = Vec::new();
    for k in 1..=150 {
        let (from, to) = (motion((k - 1) as f64 * h), motion(k as f64 * h));
        dy.advance(&c.rod, &mut c.st, h, &from, &to, 6).unwrap();
        if k > 100 {
            tensions.push(-dy.ws.clip_reaction(&c.rod, &c.st, 0).0.z);
        }
    }
    let ratio = tensions.iter().sum::<f64>() / tensions.len() as f64 / c.load;
    let ct = dy.contact.as_ref().unwrap();
    assert!(mu == 0.0 || ct.node_state.contains(&SLIP));
    let (gap, _, _) = ct.surface_gap(&c.st);
    assert!(gap > -0.01 * c.r, "gap {gap}");
    ratio
}

/// The static equilibrium of `spec` (clamped along x, its first clip moved to height z₀,
/// gravity down) started straight at z₀ over a frictionless table z = 0 of a cable of radius r.
fn solved_on_a_table(mut spec: CableSpec, r: f64, z0: f64) -> (Rod, State, Statics) {
    spec.clips[0].pose.position = Vector3::new(0.0, 0.0, z0);
    spec.gravity = Vector3::new(0.0, 0.0, -9.81);
    let rod = Rod::new(spec).unwrap();
    let x = rod.arc.iter().map(|&s| Vector3::new(s, 0.0, z0)).collect();
    let mut st = state_through(&rod, x, Vector3::z());
    let mut s = Statics::new(&rod, NewtonOptions::default());
    let table = Obstacle::new("table", 0, Box::new(Plane), 0.0, &origin());
    s.contact = Some(contact(&rod, vec![table], r));
    s.solve(&rod, &mut st).unwrap();
    (rod, st, s)
}

/// A cantilever along x clamped at height z₀ over a table, gravity down: the contact forces
/// and the clip reaction carry the weight, and the cable lies on the table.
#[test]
fn cable_on_a_table_carries_its_weight_in_contact() {
    let r = 0.005;
    let l = 1.0;
    let z0 = r + 0.005 * r;
    let spec = cantilever(l, 100, section(1e5, 2e-3, 0.2));
    let (rod, st, mut s) = solved_on_a_table(spec, r, z0);
    s.assemble(&rod, &st, 1.0, false).unwrap();
    let weight = 0.2 * l * 9.81;
    let ct = s.contact.as_ref().unwrap();
    let contact_z: f64 = ct.normal_force.iter().map(|f| f.z).sum();
    let reaction_z = s.ws.clip_reaction(&rod, &st, 0).0.z;
    assert!(
        (contact_z + reaction_z - weight).abs() < 1e-6 * weight,
        "{contact_z} + {reaction_z} vs {weight}"
    );
    // Away from the clip (whose bending decays within a few edges) the cable lies flat: each
    // node's contact force is its weight.
    for n in 20..rod.arc.len() {
        let w = rod.node_mass[n] * 9.81;
        let f = ct.normal_force[n];
        assert!(
            (f.z - w).abs() < 1e-6 * w && f.xy().norm() < 1e-9 * w,
            "node {n}: {f} vs {w}"
        );
    }
    assert!((ct.body_force[0].z - contact_z).abs() < 1e-9 * weight);
    for n in 1..rod.arc.len() {
        assert!(
            ct.node_state[n] != NO_CONTACT,
            "node {n} not in contact: z = {}",
            st.x[n].z
        );
        assert!(st.x[n].z - r > -0.01 * r && st.x[n].z - r < 0.01 * r);
    }
}

/// A free cable lying down the slope of an incline (angle α) at rest, gravity down: dynamics.
/// Returns the distance slid down the slope after `t` seconds.
fn incline(alpha: f64, mu: f64, t: f64, r: f64) -> f64 {
    let n = 30;
    let rod = free_cable(0.3, n);
    let normal = Vector3::new(-alpha.sin(), 0.0, alpha.cos());
    let down = Vector3::new(-alpha.cos(), 0.0, -alpha.sin());
    // At the gap where the barrier carries the weight's normal part (κ = ρA g/d̂, automatic).
    let dhat = ContactOptions::for_radius(r).distance;
    let (mut lo, mut hi) = (1e-6 * dhat, dhat);
    for _ in 0..100 {
        let g = 0.5 * (lo + hi);
        if -rod::contact::barrier(g, dhat).1 / dhat > alpha.cos() {
            lo = g;
        } else {
            hi = g;
        }
    }
    let lift = (r + lo) * normal;
    let x = rod.arc.iter().map(|&s| lift - s * down).collect();
    let mut st = state_through(&rod, x, normal);
    let slope = Obstacle::new(
        "slope",
        0,
        Box::new(Plane),
        mu,
        &at(Vector3::zeros(), normal),
    );
    let mut dy = Dynamics::new(&rod, &st, &[], DynamicOptions::default());
    dy.contact = Some(contact(&rod, vec![slope], r));
    dy.start(&rod, &st).unwrap();
    let start = st.x[n / 2];
    let h = 1e-3;
    for _ in 0..(t / h).round() as usize {
        dy.advance(&rod, &mut st, h, &[], &[], 6).unwrap();
    }
    let ct = dy.contact.as_ref().unwrap();
    let (gap, _, _) = ct.surface_gap(&st);
    assert!(gap > -0.01 * r, "gap {gap}");
    (st.x[n / 2] - start).dot(&down)
}

#[test]
fn friction_holds_on_an_incline_below_the_friction_angle_and_slides_above() {
    let (mu, t, r) = (0.5, 0.3, 0.003);
    let g = 9.81;
    // Sliding: s = ½ g (sin α − μ cos α) t².
    let alpha = 35f64.to_radians();
    let exact = 0.5 * g * (alpha.sin() - mu * alpha.cos()) * t * t;
    let slid = incline(alpha, mu, t, r);
    assert!(
        (slid - exact).abs() < 0.02 * exact,
        "slid {slid} vs {exact}"
    );
    // Sticking: tan α = 0.36 < μ: at rest but for the creep within the stick zone, whose
    // tangential speed is below ε_v.
    let alpha = 20f64.to_radians();
    let stuck = incline(alpha, mu, t, r);
    let creep = ContactOptions::for_radius(r).stick_velocity * t;
    assert!(
        stuck.abs() < creep,
        "moved {stuck} (sliding would be {exact})"
    );
    // Frictionless: slides with g sin α.
    let free = incline(alpha, 0.0, t, r);
    let exact = 0.5 * g * alpha.sin() * t * t;
    assert!((free - exact).abs() < 0.02 * exact, "{free} vs {exact}");
}

/// A cable dropped from 2 cm (its slope `tilt`; 0: level) onto a plane with friction μ, the
/// Newton corrections shortened by the line search or the 90 % bound: total energy never
/// grows, the capsules never go through the plane, and it comes to rest on it (frictionless:
/// the horizontal momentum of a tilted impact stays; with friction it is stopped too). A
/// solver error fails with its step (the energy bounds are asserted on every step before it).
fn drop(r: f64, mu: f64, line_search: bool, tilt: f64) {
    let (rod, st, dy) = drop_run(r, mu, line_search, tilt, 3000).unwrap_or_else(|e| panic!("{e}"));
    let drop_energy = rod.node_mass.iter().sum::<f64>() * 9.81 * 0.02;
    // At rest on the floor after 3 s: vertical motion below 1e-4 of the drop energy (frictionless, the horizontal momentum
    // the tilted impact gave it stays), lying on the floor within 1 % of r.
    let vertical: f64 = dy
        .velocities()
        .iter()
        .zip(&rod.node_mass)
        .map(|(v, m)| 0.5 * m * v[2] * v[2])
        .sum();
    assert!(
        vertical < 1e-4 * drop_energy,
        "r = {r}: still bouncing, {vertical} J"
    );
    if mu > 0.0 {
        // Friction stops the sliding too: every node at rest within the stick zone's creep.
        let v_max = dy
            .velocities()
            .iter()
            .map(|v| v.fixed_rows::<3>(0).norm())
            .fold(0.0, f64::max);
        let creep = ContactOptions::for_radius(r).stick_velocity;
        assert!(
            v_max < creep,
            "r = {r}, μ = {mu}: still sliding at {v_max} m/s"
        );
    }
    assert!(st.x.iter().all(|x| (x.z - r).abs() < 0.01 * r));
    let ct = dy.contact.as_ref().unwrap();
    assert!(ct.node_state.iter().all(|&s| s == STICK));
}

/// The drop of `drop` for `steps` steps of 1 ms: Err names the first violation — a solver
/// error, the total energy above the start, a step whose energy grew by more than the step
/// guard's bound (with `strict`, any such step; else only one the guard did not report as an
/// unresolved impact, `StepStats::unresolved_gain`), or the capsules through the plane.
fn drop_run(
    r: f64,
    mu: f64,
    line_search: bool,
    tilt: f64,
    steps: usize,
) -> Result<(Rod, State, Dynamics), String> {
    let l = 0.4;
    let n = 40;
    let rho = 1500.0;
    let sec = circle(r, 5e7, 0.45, rho);
    let spec = CableSpec {
        length: l,
        segments: n,
        section: sec.clone(),
        natural_curvature: Vector3::zeros(),
        clips: vec![],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    let x = rod
        .arc
        .iter()
        .map(|&s| Vector3::new(s, 0.0, r + 0.02 + tilt * s))
        .collect();
    let mut st = state_through(&rod, x, Vector3::z());
    let floor = Obstacle::new("floor", 0, Box::new(Plane), mu, &origin());
    let opts = DynamicOptions {
        tau_bend: Vector3::new(1e-3, 1e-3, 1e-3),
        tau_shear: Vector3::new(1e-4, 1e-4, 1e-4),
        contact_line_search: line_search,
        ..Default::default()
    };
    let mut dy = Dynamics::new(&rod, &st, &[], opts);
    dy.contact = Some(contact(&rod, vec![floor], r));
    dy.start(&rod, &st).unwrap();
    let total = |d: &Dynamics| {
        let e = d.energies;
        e.kinetic + e.elastic + e.load_potential + e.contact
    };
    let e0 = total(&dy);
    let drop_energy = sec.mass_per_length * l * 9.81 * 0.02;
    let mut last = e0;
    let (mut last_kinetic, mut last_elastic, mut last_contact) = (0.0, dy.energies.elastic, 0.0);
    let h = 1e-3;
    let mut min_gap = f64::INFINITY;
    let case = format!("r = {r}, μ = {mu}, tilt {tilt}, line search {line_search}");
    for k in 0..steps {
        let stats = dy
            .advance(&rod, &mut st, h, &[], &[], 6)
            .map_err(|e| format!("{case}: step {k}: {e}"))?;
        let e = total(&dy);
        let en = dy.energies;
        // Never above the start; per step, within the step guard's bound on the growth of the
        // energy in motion (`energy_tolerance` = 1e-3 of the energies at play, a larger growth
        // splits the step; its scale differs from this one by the clip work and the start's
        // contact energy: a factor 2 of margin; measured 1.13e-3 (r = 1 mm), 1.22e-3 (30 mm)).
        if e > e0 + 1e-6 * drop_energy {
            return Err(format!("{case}: step {k}: {e} > {e0}"));
        }
        // With friction too (before the contact's normal damping, session 8, the μ = 0.3 drop
        // gained 0.67 % of the energy in motion at step 248 and was exempt).
        let scale = last_kinetic + en.kinetic + last_elastic.abs() + last_contact;
        if e > last + 2e-3 * scale || stats.unresolved_gain > 0.0 {
            return Err(format!(
                "{case}: energy grew at step {k}: {last} → {e} (scale {scale}, {en:?}; \
                 unresolved gain {})",
                stats.unresolved_gain
            ));
        }
        (last, last_kinetic, last_elastic, last_contact) = (e, en.kinetic, en.elastic, en.contact);
        let ct = dy.contact.as_ref().unwrap();
        min_gap = min_gap.min(ct.surface_gap(&st).0);
    }
    if min_gap <= -0.01 * r {
        return Err(format!("{case}: tunnelled to gap {min_gap}"));
    }
    Ok((rod, st, dy))
}

/// Thin cables dropped flat or tilted, with and without the line search (r = 0.9–2 mm, tilt
/// 0–0.02; 50 drops of 0.3 s through the impact and the first bounces): every run completes,
/// never rises above its start, never goes through the plane, no step's energy grows beyond
/// the guard's bound, and no sub-step is accepted with a gain: the gains of sub-steps at the
/// guard's deepest split are given back from the motion near the contact (`impact::take_gain`;
/// up to 19 % of the energies at play, docs/contact.md). Without that 46 of the runs accept
/// sub-steps that gained (reported as unresolved impacts), and in 4 of them a step's energy
/// grows beyond the bound. Before session
/// 10's smooth damping saturation 5 of these runs stopped with Newton not converging (a
/// period-4 cycle at h/64) and 4 gained energy unreported; the named drop tests above had
/// passed by their parameters.
#[test]
fn thin_cables_dropped_any_way_complete_and_report_what_they_gain() {
    drop_sweep(&[0.0009, 0.001, 0.0011, 0.0015, 0.002], &[0.0]);
}

/// The same sweep over the rest of the documented radius range (3–30 mm; the defaults need no
/// tuning for cables of 1–30 mm), frictionless and with μ = 0.5 (100 drops): every drop
/// completes, never gains energy beyond the guard's bound, never goes through the plane.
/// Without the impact remedy (`impact::take_gain`) 66 of the 100 accept a sub-step at the
/// guard's deepest split that gained energy (reported as an unresolved impact).
#[test]
fn cables_of_the_documented_radii_dropped_any_way_never_gain_energy() {
    drop_sweep(&[0.003, 0.005, 0.01, 0.02, 0.03], &[0.0, 0.5]);
}

/// `drop_run` for every radius and friction coefficient given, five tilts (0–0.02), with and
/// without the line search, 0.3 s each; all must pass.
fn drop_sweep(radii: &[f64], frictions: &[f64]) {
    let mut failures = Vec::new();
    let mut runs = 0;
    for &r in radii {
        for tilt in [0.0, 0.005, 0.01, 0.015, 0.02] {
            for line_search in [false, true] {
                for &mu in frictions {
                    runs += 1;
                    if let Err(e) = drop_run(r, mu, line_search, tilt, 300) {
                        failures.push(e);
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {runs}: {failures:#?}",
        failures.len()
    );
}

#[test]
fn dropped_cable_comes_to_rest_without_gaining_energy_or_tunnelling() {
    for r in [0.001, 0.03] {
        drop(r, 0.0, false, 0.01);
    }
    drop(0.003, 0.3, false, 0.01);
}

/// The impact at the step guard's deepest sub-step (docs/contact.md, "The impact energy at the
/// guard's deepest sub-step"): with the line search (`contact_line_search`) the r = 1 mm drop
/// gained 5.7 % of the energy in motion at step 70, in a sub-step of h/64 the guard accepts
/// unchecked; the contact's normal damping (τ_c) removes that rebound (fails with τ_c = 0).
#[test]
fn impact_never_gains_energy_at_the_deepest_sub_step() {
    drop(0.001, 0.0, true, 0.01);
}

/// A level drop (every node hits at once): without the contact's normal damping the r = 5 mm
/// cable gains 2.4 % of the energy in motion at step 65 on the default path.
#[test]
fn level_drop_never_gains_energy() {
    drop(0.005, 0.0, false, 0.0);
}

/// The assembled Jacobian with contact and friction equals the finite-difference derivative
/// of the residual (a cable pressed onto a sphere, sliding).
#[test]
#[allow(clippy::needless_range_loop)]
fn jacobian_with_contact_matches_finite_differences() {
    let r = 0.004;
    let big_r = 0.05;
    let spec = CableSpec {
        length: 0.3,
        segments: 30,
        section: section(1e3, 1e-3, 0.1),
        natural_curvature: Vector3::zeros(),
        clips: vec![clip(
            "a",
            0.0,
            0.0,
            ClipKind::Fixed,
            pose([-0.15, 0.0, big_r + r], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        )],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    // Over the sphere's top, some samples inside the barrier, a few penetrating.
    let x: Vec<Vector3<f64>> = rod
        .arc
        .iter()
        .map(|&s| {
            let u = s - 0.15;
            Vector3::new(
                u,
                0.002 * u,
                big_r + r - 3.0 * u * u + 2e-5 * (40.0 * u).sin(),
            )
        })
        .collect();
    let st = state_through(&rod, x.clone(), Vector3::z());
    let ball = Obstacle::new(
        "ball",
        0,
        Box::new(Sphere { radius: big_r }),
        0.4,
        &origin(),
    );
    let mut ct = contact(&rod, vec![ball], r);
    // Friction reference: shifted along x (sliding) and a little (sticking) at alternate nodes.
    let reference: Vec<Vector3<f64>> = x
        .iter()
        .enumerate()
        .map(|(i, p)| p - Vector3::new(if i % 2 == 0 { 1e-3 } else { 1e-6 }, 0.0, 0.0))
        .collect();
    ct.begin_step(&reference, None);
    let mut ws = rod::assembly::Workspace::new(&rod);
    ws.assemble_terms(&rod, &st, 1.0, true, &mut [&mut ct])
        .unwrap();
    assert!(ct.normal_force.iter().any(|f| f.norm() > 0.0));
    let jac = ws.jac.clone();
    let nb = rod.n_edges() + 1;
    let h = 1e-8;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for b in 0..nb {
        for k in 0..3 {
            if !rod.mask[b][k] {
                continue;
            }
            let mut rows = Vec::new();
            for step in [h, -h] {
                let mut d = vec![Vector6::zeros(); nb];
                d[b][k] = step;
                let mut s2 = st.clone();
                s2.apply_increment(&rod, &d, 1.0);
                ws.assemble_terms(&rod, &s2, 1.0, false, &mut [&mut ct])
                    .unwrap();
                rows.push(ws.rhs.clone());
            }
            for rr in b.saturating_sub(1)..(b + 2).min(nb) {
                let fd = (rows[0][rr] - rows[1][rr]) / (2.0 * h);
                let an = if rr == b {
                    jac.diag[b].column(k).into_owned()
                } else if rr + 1 == b {
                    jac.upper[rr].column(k).into_owned()
                } else {
                    jac.lower[rr].column(k).into_owned()
                };
                worst = worst.max((fd - an).amax());
                scale = scale.max(an.amax());
            }
        }
    }
    assert!(worst < 1e-5 * scale, "worst {worst:e} of {scale:e}");
}

#[test]
fn bad_contact_settings_are_named() {
    let rod = Rod::new(cantilever(1.0, 10, section(1e4, 1e-3, 0.1))).unwrap();
    let o = |mu: f64| {
        Obstacle::new(
            "bracket",
            0,
            Box::new(Plane) as Box<dyn Shape>,
            mu,
            &origin(),
        )
    };
    let e = Contact::new(&rod, vec![o(-0.2)], ContactOptions::for_radius(0.005), 1).unwrap_err();
    assert!(e.0.contains("'bracket'") && e.0.contains("-0.2"), "{e}");
    let mut opts = ContactOptions::for_radius(0.005);
    opts.distance = -1.0;
    let e = Contact::new(&rod, vec![o(0.1)], opts, 1).unwrap_err();
    assert!(e.0.contains("distance") && e.0.contains("-1"), "{e}");
    let e = Contact::new(&rod, vec![o(0.1)], ContactOptions::for_radius(f64::NAN), 1).unwrap_err();
    assert!(e.0.contains("radius"), "{e}");
}

/// A cantilever (r = 4 mm, along x, clamped at x = 0) whose straight start ends in a box, 8 mm
/// below its top face: deeper than the barrier's reach (r + d̂ + half an edge), where a mesh's
/// bounded broad phase sees nothing. Never a silent answer inside the box: as a box primitive
/// and as a box mesh, the static solve either pushes the cable out or fails with the
/// penetration error naming a node inside the box — and both shapes give the same outcome.
/// Since the push-out continuation (`Statics::solve`) both push it out above the top face
/// (tip at z = 29.9 mm, the face at 8 mm; the same to round-off), which the test now
/// requires; before, both failed (the barrier alone could not push 12 mm out).
#[test]
fn a_cable_starting_deep_inside_a_box_or_mesh_is_never_a_silent_answer() {
    let r = 0.004;
    let half = Vector3::new(0.1, 0.05, 0.02);
    let centre = Vector3::new(0.25, 0.0, -0.02 + 0.008);
    let shapes: [Box<dyn Shape>; 2] = [
        Box::new(Cuboid { half }),
        Box::new(rod::contact_mesh::box_mesh(half)),
    ];
    let mut outcomes = Vec::new();
    for shape in shapes {
        let rod = Rod::new(cantilever(0.3, 60, section(1e5, 1e-2, 0.1))).unwrap();
        let x = rod.arc.iter().map(|&s| Vector3::new(s, 0.0, 0.0)).collect();
        let mut st = state_through(&rod, x, Vector3::z());
        let o = Obstacle::new("box", 0, shape, 0.0, &at(centre, Vector3::z()));
        let mut s = Statics::new(&rod, NewtonOptions::default());
        s.contact = Some(contact(&rod, vec![o], r));
        assert!(s.contact.as_ref().unwrap().penetrates(&rod, &st));
        match s.solve(&rod, &mut st) {
            Ok(_) => {
                let ct = s.contact.as_ref().unwrap();
                let (gap, _, _) = ct.surface_gap(&st);
                assert!(gap > -0.01 * r, "Ok, but still inside: gap {gap}");
                assert!(ct.deepest_penetration(&st).is_none());
                outcomes.push(Ok(st.x[60]));
            }
            Err(e @ SolveError::Penetration { .. }) => {
                let SolveError::Penetration { node, depth, .. } = &e else {
                    unreachable!()
                };
                assert!(rod.arc[*node] > 0.15 - r && *depth > 0.01 * r, "{e}");
                assert!(e.to_string().contains("'box'"));
                outcomes.push(Err(*node));
            }
            Err(e) => panic!("not the penetration error: {e}"),
        }
    }
    match (&outcomes[0], &outcomes[1]) {
        (Ok(a), Ok(b)) => {
            assert!((a - b).norm() < 1e-6, "{a} vs {b}");
            assert!(a.z > centre.z + half.z, "tip not above the top face: {a}");
        }
        _ => panic!("not pushed out onto the box: {outcomes:?}"),
    }
}

/// A clip inside a box mesh (the cable cannot leave it): a clear error naming the geometry and
/// the node, not an equilibrium inside the solid.
#[test]
fn a_cable_held_inside_a_mesh_is_an_error_naming_node_and_geometry() {
    let r = 0.004;
    let rod = Rod::new(cantilever(0.3, 60, section(1e5, 1e-2, 0.1))).unwrap();
    let x = rod.arc.iter().map(|&s| Vector3::new(s, 0.0, 0.0)).collect();
    let mut st = state_through(&rod, x, Vector3::z());
    let mesh = rod::contact_mesh::box_mesh(Vector3::new(0.05, 0.05, 0.05));
    let o = Obstacle::new("engine block", 0, Box::new(mesh), 0.0, &origin());
    let mut s = Statics::new(&rod, NewtonOptions::default());
    s.contact = Some(contact(&rod, vec![o], r));
    match s.solve(&rod, &mut st) {
        Err(e @ SolveError::Penetration { .. }) => {
            let SolveError::Penetration { node, depth, .. } = &e else {
                unreachable!()
            };
            assert!(rod.arc[*node] < 0.05 && *depth > 0.01 * r, "{e}");
            let msg = e.to_string();
            assert!(msg.contains("'engine block'") && msg.contains(&format!("node {node}")));
        }
        other => panic!("expected a penetration error, got {other:?}"),
    }
}

/// The step bound of a Newton correction from the last assembly's queries (kept per edge with
/// its end points and the obstacle's pose) equals the one from fresh queries, on a plane and a
/// cylinder (8 samples per edge), also after the obstacle moved (the kept queries then unused).
#[test]
fn step_bound_from_the_assembly_queries_equals_fresh_queries() {
    let (r, l, n) = (0.003, 0.3, 30);
    let spec = CableSpec {
        length: l,
        segments: n,
        section: circle(r, 5e7, 0.45, 1500.0),
        natural_curvature: Vector3::zeros(),
        clips: vec![],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    let dhat = ContactOptions::for_radius(r).distance;
    // Over a cylinder (axis y, radius 2 cm, top at z = 0) and a plane at z = −0.05: the middle
    // nodes within the barrier of the cylinder, the ends near the plane.
    let x: Vec<_> = rod
        .arc
        .iter()
        .map(|&s| {
            let u = s - 0.5 * l;
            Vector3::new(u, 0.0, r + 0.5 * dhat + 40.0 * u * u * u.abs().min(0.02))
        })
        .collect();
    let st = state_through(&rod, x, Vector3::z());
    let cylinder = Pose {
        position: Vector3::new(0.0, 0.0, -0.02),
        orientation: frame_quaternion(&Vector3::y(), &Vector3::z()).unwrap(),
    };
    let plane = at(Vector3::new(0.0, 0.0, -0.05), Vector3::z());
    let obstacles = |pose: &Pose| {
        vec![
            Obstacle::new(
                "pipe",
                0,
                Box::new(Cylinder {
                    radius: 0.02,
                    length: 0.4,
                }),
                0.3,
                pose,
            ),
            Obstacle::new("floor", 0, Box::new(Plane), 0.0, &plane),
        ]
    };
    let mut dy = Dynamics::new(&rod, &st, &[], DynamicOptions::default());
    dy.contact = Some(contact(&rod, obstacles(&cylinder), r));
    dy.start(&rod, &st).unwrap(); // assembles the whole cable: the queries are kept
    let assembled = dy.contact.as_mut().unwrap();
    assert!(assembled.active > 0, "no sample inside the barrier");
    // Down by up to 2 d̂, twisted along the cable.
    let dx = |k: usize| {
        let u = k as f64 / n as f64;
        Vector3::new(1e-4 * u, 2e-4 * (1.0 - u), -2.0 * dhat * (0.3 + u))
    };
    let fresh = contact(&rod, obstacles(&cylinder), r);
    let alpha = assembled.step_bound(&st.x, dx, 0..n);
    assert!(alpha < 0.9, "the bound does not act: {alpha}");
    assert_eq!(alpha, fresh.step_bound(&st.x, dx, 0..n));
    // Per edge too (the bound of each edge alone).
    for e in 0..n {
        assert_eq!(
            assembled.step_bound(&st.x, dx, e..e + 1),
            fresh.step_bound(&st.x, dx, e..e + 1),
            "edge {e}"
        );
    }
    // The pipe moved 0.4 d̂ up since the assembly: the kept queries are stale.
    let mut moved = cylinder;
    moved.position.z += 0.4 * dhat;
    assembled.set_obstacle_poses(&[moved, plane]);
    let fresh = contact(&rod, obstacles(&moved), r);
    let alpha_moved = assembled.step_bound(&st.x, dx, 0..n);
    assert_eq!(alpha_moved, fresh.step_bound(&st.x, dx, 0..n));
    assert!(alpha_moved < alpha, "{alpha_moved} vs {alpha}");
}

/// The line search (`DynamicOptions::contact_line_search`, off by default) on a straight edge
/// above a plane moved straight down by its whole gap g₀ (Newton towards zero gap): with the
/// rest of the system flat (decrement R below the barrier's own curvature S), the step stops
/// where the barrier's force has grown by R/(κ ds a) — the minimiser of the merit along the
/// line — well short of the feasible bound 0.9; moving away, the full step.
#[test]
fn line_search_stops_where_the_barrier_balances_the_decrement() {
    let (r, l, n) = (0.003, 0.3, 30);
    let spec = CableSpec {
        length: l,
        segments: n,
        section: circle(r, 5e7, 0.45, 1500.0),
        natural_curvature: Vector3::zeros(),
        clips: vec![],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    let dhat = ContactOptions::for_radius(r).distance;
    let g0 = 0.5 * dhat;
    let x: Vec<_> = rod
        .arc
        .iter()
        .map(|&s| Vector3::new(s, 0.0, r + g0))
        .collect();
    let floor = Obstacle::new("floor", 0, Box::new(Plane), 0.0, &origin());
    let mut c = contact(&rod, vec![floor], r);
    let down = |_: usize| Vector3::new(0.0, 0.0, -g0);
    let (_, b1, b2) = rod::contact::barrier(g0, dhat);
    let (kds, a) = (c.kappa * rod.ds_edge[0], g0);
    let s = kds * b2 * a * a;
    let decrement = 0.5 * s;
    let alpha = c.line_search(&x, down, 0..1, &rod.ds_edge, decrement, false);
    assert!(alpha > 0.0 && alpha < 0.85, "{alpha}");
    // −b'(g₀(1 − α)) = −b'(g₀) + R/(κ ds a), to the search's resolution (1e-3 of the bound).
    let target = -b1 + decrement / (kds * a);
    let force = |al: f64| -rod::contact::barrier(g0 * (1.0 - al), dhat).1;
    assert!(
        force(alpha - 1e-3) <= target && target <= force(alpha + 1e-3),
        "α = {alpha}: {} .. {} vs {target}",
        force(alpha - 1e-3),
        force(alpha + 1e-3)
    );
    let up = |_: usize| Vector3::new(0.0, 0.0, g0);
    assert_eq!(
        c.line_search(&x, up, 0..1, &rod.ds_edge, decrement, false),
        1.0
    );
}

/// A route through a table: the hose's sag without contact reaches 9 cm below the table top,
/// far beyond the barrier's reach. The static solve pushes it out (the geometry shrunk until
/// the cable is clear, grown back in halving stages, the nodes it reaches moved out) onto the
/// table: nothing inside, the weight carried, and the same equilibrium as the table rising
/// from below into place in 45 quasistatic steps (frictionless: one equilibrium).
#[test]
fn a_route_through_a_table_is_pushed_out_onto_it() {
    let r = 0.005;
    let spec = CableSpec {
        length: 1.0,
        segments: 40,
        section: circle(r, 5e7, 0.45, 1500.0),
        natural_curvature: Vector3::zeros(),
        clips: vec![
            clip(
                "a",
                0.0,
                0.0,
                ClipKind::Fixed,
                pose([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            ),
            clip(
                "b",
                1.0,
                0.0,
                ClipKind::Fixed,
                pose([0.8, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            ),
        ],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let rod = Rod::new(spec).unwrap();
    let table_z = -0.05;
    let table = |z: f64| {
        Obstacle::new(
            "table",
            0,
            Box::new(Plane),
            0.0,
            &at(Vector3::new(0.0, 0.0, z), Vector3::z()),
        )
    };
    // Without contact the hose hangs through the table.
    let mut free = rod::routing::route(&rod, None).unwrap();
    Statics::new(&rod, NewtonOptions::default())
        .solve(&rod, &mut free)
        .unwrap();
    let sag = free.x.iter().map(|x| x.z).fold(f64::INFINITY, f64::min);
    assert!(sag < table_z - 0.08, "sag {sag}");
    // Pushed out by the static solve.
    let mut st = rod::routing::route(&rod, None).unwrap();
    let mut s = Statics::new(&rod, NewtonOptions::default());
    s.contact = Some(contact(&rod, vec![table(table_z)], r));
    s.solve(&rod, &mut st).unwrap();
    let ct = s.contact.as_ref().unwrap();
    assert!(ct.surface_gap(&st).0 > -0.01 * r);
    s.assemble(&rod, &st, 1.0, false).unwrap();
    let ct = s.contact.as_ref().unwrap();
    let carried: f64 = ct.normal_force.iter().map(|f| f.z).sum::<f64>()
        + (0..2)
            .map(|c| s.ws.clip_reaction(&rod, &st, c).0.z)
            .sum::<f64>();
    let weight = rod.node_mass.iter().sum::<f64>() * 9.81;
    assert!(
        (carried - weight).abs() < 1e-6 * weight,
        "{carried} vs {weight}"
    );
    // The table rising from below (clear of the hose) into place.
    let mut reference = rod::routing::route(&rod, None).unwrap();
    let mut q = Statics::new(&rod, NewtonOptions::default());
    q.contact = Some(contact(&rod, vec![table(-0.5)], r));
    q.solve(&rod, &mut reference).unwrap();
    let targets: Vec<Pose> = rod.spec.clips.iter().map(|c| c.pose).collect();
    for k in 1..=45 {
        let z = -0.5 + (table_z + 0.5) * k as f64 / 45.0;
        let pose = at(Vector3::new(0.0, 0.0, z), Vector3::z());
        q.contact.as_mut().unwrap().set_obstacle_poses(&[pose]);
        q.sequence_step(&rod, &mut reference, &targets).unwrap();
    }
    // The barrier scales to the contact load (`Contact::adapt_stiffness`), and the table
    // pressing up on its way raised the reference's stiffness further: the push-out's
    // equilibrium solved again at that stiffness is the same state.
    let kappa = q.contact.as_ref().unwrap().obstacle_kappa.clone();
    assert!(kappa[0] > s.contact.as_ref().unwrap().obstacle_kappa[0]);
    s.contact.as_mut().unwrap().obstacle_kappa = kappa;
    s.solve(&rod, &mut st).unwrap();
    // The same state up to the scene's mirror symmetry y → −y: the 0.2 m of slack lies on the
    // table bent to one side, and which side a solve reaches is decided by round-off (the two
    // paths chose opposite sides in a build for another CPU target, session 11).
    let apart = |mirror: f64| {
        st.x.iter()
            .zip(&reference.x)
            .map(|(a, b)| (a - Vector3::new(b.x, mirror * b.y, b.z)).norm())
            .fold(0.0, f64::max)
    };
    let bulge = st.x.iter().map(|x| x.y.abs()).fold(0.0, f64::max);
    assert!(bulge > 0.05, "the slack bends sideways: {bulge} m");
    let worst = apart(1.0).min(apart(-1.0));
    assert!(worst < 1e-6, "push-out vs rising table: {worst} m");
}

/// A free cable (no clips) of `n` segments, gravity down (the incline's section).
fn free_cable(length: f64, n: usize) -> Rod {
    Rod::new(CableSpec {
        length,
        segments: n,
        section: section(1e4, 1e-3, 0.1),
        natural_curvature: Vector3::zeros(),
        clips: vec![],
        loads: vec![],
        gravity: Vector3::new(0.0, 0.0, -9.81),
    })
    .unwrap()
}

/// A free straight cable lying on a plane, released a little above its resting gap: it rocks
/// rigidly on the barrier (every sample alike) with ω² = κ b''(g₀)/(ρA), and the contact's
/// normal damping (a time constant τ_c on the barrier's stiffness) gives the oscillation the
/// damping ratio ζ = ω τ_c / 2 = π f τ_c (docs/contact.md). Measured by the logarithmic
/// decrement of the gap over the first two periods, at 100 and 200 steps per period.
#[test]
fn contact_oscillation_has_the_damping_ratio_of_its_time_constant() {
    let r = 0.005;
    let zeta_of = |steps_per_period: f64| -> (f64, f64) {
        let n = 10;
        let rod = free_cable(0.2, n);
        let sec = rod.spec.section.clone();
        // The resting gap: κ (−b') = ρA g with the automatic κ = ρA g/d̂, i.e. −b'(g₀) = d̂.
        let dhat = ContactOptions::for_radius(r).distance;
        let (mut lo, mut hi) = (1e-6 * dhat, dhat);
        for _ in 0..100 {
            let g = 0.5 * (lo + hi);
            if -rod::contact::barrier(g, dhat).1 / dhat > 1.0 {
                lo = g;
            } else {
                hi = g;
            }
        }
        let g0 = lo;
        let kappa = sec.mass_per_length * 9.81 / dhat;
        let omega = (kappa * rod::contact::barrier(g0, dhat).2 / sec.mass_per_length).sqrt();
        let tau = 0.1 / omega; // ζ = 0.05
        let lift = 0.005 * g0; // small against g₀: the barrier is nearly linear over it
        let x = rod
            .arc
            .iter()
            .map(|&s| Vector3::new(s, 0.0, r + g0 + lift))
            .collect();
        let mut st = state_through(&rod, x, Vector3::z());
        let floor = Obstacle::new("floor", 0, Box::new(Plane), 0.0, &origin());
        let mut opts = ContactOptions::for_radius(r);
        opts.damping = tau;
        let mut dy = Dynamics::new(&rod, &st, &[], DynamicOptions::default());
        dy.contact = Some(Contact::new(&rod, vec![floor], opts, 1).unwrap());
        dy.start(&rod, &st).unwrap();
        let h = 2.0 * PI / omega / steps_per_period;
        let mut z = vec![st.x[n / 2].z - r - g0];
        for _ in 0..(4.0 * steps_per_period) as usize {
            dy.advance(&rod, &mut st, h, &[], &[], 6).unwrap();
            z.push(st.x[n / 2].z - r - g0);
        }
        // Peaks (parabola through the three samples about each local maximum).
        let peaks: Vec<f64> = (1..z.len() - 1)
            .filter(|&k| z[k] > z[k - 1] && z[k] >= z[k + 1] && z[k] > 0.0)
            .map(|k| {
                let (a, b, c) = (z[k - 1], z[k], z[k + 1]);
                b + (a - c) * (a - c) / (8.0 * (2.0 * b - a - c))
            })
            .collect();
        assert!(peaks.len() >= 3, "peaks {peaks:?}");
        let decrement = (peaks[0] / peaks[2]).ln() / 2.0;
        let zeta = decrement / (4.0 * PI * PI + decrement * decrement).sqrt();
        (zeta, 0.5 * omega * tau)
    };
    let (z100, exact) = zeta_of(100.0);
    let (z200, _) = zeta_of(200.0);
    eprintln!("ζ exact {exact}, 100 steps/period {z100}, 200: {z200}");
    // Measured: ζ − exact = 9.4e-4 ζ and 1.4e-3 ζ at 100 and 200 steps per period with the
    // lift 0.5 % of g₀, 4.0e-3 ζ and 4.5e-3 ζ with 2 %: the error is the barrier's nonlinearity
    // over the amplitude (proportional to it), the time step's part is below 5e-4 ζ.
    for z in [z100, z200] {
        assert!((z - exact).abs() < 3e-3 * exact, "ζ {z} vs {exact}");
    }
    assert!((z100 - z200).abs() < 1e-3 * exact, "ζ {z100} vs {z200}");
}

/// A cable lying on a table with friction μ = 0.5 while the table moves sideways as
/// x_t = A (1 − cos ωt) (peak acceleration 0.2 g, below μ g): friction carries the cable along
/// (it sticks to the moving table, up to the stick zone's creep ε_v t), as friction acts on the
/// motion relative to the geometry.
#[test]
fn friction_carries_a_cable_on_a_moving_table() {
    let r = 0.003;
    let n = 30;
    let rod = free_cable(0.3, n);
    let dhat = ContactOptions::for_radius(r).distance;
    let x = rod
        .arc
        .iter()
        .map(|&s| Vector3::new(0.0, s, r + 0.5 * dhat))
        .collect();
    let mut st = state_through(&rod, x, Vector3::z());
    let table = Obstacle::new("table", 0, Box::new(Plane), 0.5, &origin());
    let mut dy = Dynamics::new(&rod, &st, &[], DynamicOptions::default());
    dy.contact = Some(contact(&rod, vec![table], r));
    // Settle on the still table first.
    let h = 1e-3;
    for _ in 0..100 {
        dy.advance(&rod, &mut st, h, &[], &[], 6).unwrap();
    }
    let start = st.x[n / 2];
    let omega = 2.0 * PI * 5.0;
    let amplitude = 0.2 * 9.81 / (omega * omega); // 2 mm: the table travels 4 mm
    let mut worst = 0.0f64;
    let steps = 200;
    for k in 1..=steps {
        let t = k as f64 * h;
        let shift = amplitude * (1.0 - (omega * t).cos());
        let pose = Pose {
            position: Vector3::new(shift, 0.0, 0.0),
            orientation: Quat::identity(),
        };
        dy.contact.as_mut().unwrap().set_obstacle_poses(&[pose]);
        dy.advance(&rod, &mut st, h, &[], &[], 6).unwrap();
        worst = worst.max(((st.x[n / 2] - start).x - shift).abs());
    }
    let creep = ContactOptions::for_radius(r).stick_velocity * steps as f64 * h;
    assert!(
        worst < creep,
        "the cable lags the table by up to {worst} m (creep bound {creep} m, travel {} m)",
        2.0 * amplitude
    );
    let ct = dy.contact.as_ref().unwrap();
    assert!(ct.node_state.iter().all(|&s| s == STICK));
}

/// Modes about an equilibrium in contact (`lowest_modes_with_contact`): a straight cable
/// clamped at both ends lying on a frictionless table under gravity. The table carries the
/// vertical motion (the barrier's stiffness), so the two lowest modes are the horizontal
/// bending modes of a clamped–clamped beam, ω_n = (β_n L)² √(EI/(ρA L⁴)), β₁L = 4.7300,
/// β₂L = 7.8532, converging at second order in the segment length (measured: mode 1 −0.25 %
/// at 40 segments); without the contact stiffness the vertical twin of mode 1 comes second.
#[test]
fn modes_on_a_table_are_the_horizontal_beam_modes() {
    let r = 0.005;
    let l: f64 = 0.5;
    let (ei, mass): (f64, f64) = (1e-3, 0.1);
    let beam = |beta_l: f64| beta_l * beta_l * (ei / (mass * l.powi(4))).sqrt();
    let exact = [beam(4.7300), beam(7.8532)];
    let errors = |n: usize| -> [f64; 2] {
        let dhat = ContactOptions::for_radius(r).distance;
        let z0 = r + 0.5 * dhat;
        let mut spec = cantilever(l, n, section(1e5, ei, mass));
        let tip = pose([l, 0.0, z0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        spec.clips.push(clip("tip", l, 0.0, ClipKind::Fixed, tip));
        let (rod, st, mut s) = solved_on_a_table(spec, r, z0);
        let with = rod::modal::lowest_modes_with_contact(
            &rod,
            &st,
            2,
            s.contact.as_mut(),
            rod::modal::TOLERANCE,
        )
        .unwrap();
        let without = rod::modal::lowest_modes(&rod, &st, 2).unwrap();
        let horizontal = |m: &rod::modal::Mode| {
            let u = m.displacements(&rod);
            let y: f64 = u.iter().map(|v| v.y * v.y).sum();
            let all: f64 = u.iter().map(|v| v.norm_squared()).sum();
            y / all
        };
        for m in &with {
            assert!(
                horizontal(m) > 0.999,
                "n = {n}: ω {} not horizontal",
                m.omega
            );
        }
        // Without the contact stiffness: the vertical twin of mode 1 (EI₁ = EI₂) comes second.
        assert!((without[1].omega - with[0].omega).abs() < 1e-2 * with[0].omega);
        assert!(horizontal(&without[0]).min(horizontal(&without[1])) < 0.01);
        [0, 1].map(|k| (with[k].omega - exact[k]) / exact[k])
    };
    let (coarse, fine) = (errors(40), errors(80));
    eprintln!("relative errors: 40 segments {coarse:?}, 80 segments {fine:?}");
    for k in 0..2 {
        let order = (coarse[k] / fine[k]).abs().log2();
        assert!(order > 1.8 && order < 2.2, "mode {k}: order {order}");
        assert!(fine[k].abs() < 2e-3, "mode {k}: {}", fine[k]);
    }
}

/// A clip that drives the cable's end into a table (its node prescribed, 30 % of r deep at
/// 50 Hz): the barrier's force at that node goes to the clip's reaction, and Newton keeps
/// converging. (The contact damping's saturation below d̂/100 was needed by
/// `bench_harness.py --contact` — Newton stalled with 100 N left at the node next to a clip on
/// the shaken engine — which this single cable does not reproduce: it passes either way.)
#[test]
fn a_clip_driven_into_the_geometry_keeps_newton_converging() {
    let r = 0.005;
    let (l, n) = (0.3, 30);
    let z0 = r + 0.2 * ContactOptions::for_radius(r).distance;
    let spec = cantilever(l, n, section(1e4, 1e-3, 0.1));
    let (rod, mut st, s) = solved_on_a_table(spec, r, z0);
    let (w, depth) = (2.0 * PI * 50.0, 0.3 * r);
    let motion = |t: f64| {
        let mut pose = rod.spec.clips[0].pose;
        let a = 0.5 * depth * (1.0 - (w * t).cos());
        pose.position.z = z0 - a;
        vec![ClipMotion {
            pose,
            velocity: Vector3::new(0.0, 0.0, -0.5 * depth * w * (w * t).sin()),
            angular_velocity: Vector3::zeros(),
            acceleration: Vector3::new(0.0, 0.0, -0.5 * depth * w * w * (w * t).cos()),
            angular_acceleration: Vector3::zeros(),
        }]
    };
    let mut dy = Dynamics::new(&rod, &st, &motion(0.0), DynamicOptions::default());
    dy.contact = s.contact.clone();
    dy.start(&rod, &st).unwrap();
    let h = 1e-3;
    for k in 1..=100 {
        let (from, to) = (motion((k - 1) as f64 * h), motion(k as f64 * h));
        if let Err(e) = dy.advance(&rod, &mut st, h, &from, &to, 6) {
            panic!("step {k}: {e}");
        }
    }
}

/// The broad phase's bounds are of one surface: an edge found beyond the barrier's reach while
/// the obstacles are shrunk (the push-out continuation, `Contact::set_shrink`) is queried
/// again once they are restored. A cable lying 0.5 d̂ above a plane: shrunk by two edge
/// lengths no sample is within reach (and the edges' bounds show it); restored, every sample
/// (both ends of every edge) is in the barrier again.
#[test]
fn restoring_shrunk_obstacles_forgets_the_far_bounds() {
    let r = 0.003;
    let n = 10;
    let rod = free_cable(0.2, n);
    let dhat = ContactOptions::for_radius(r).distance;
    let x = rod
        .arc
        .iter()
        .map(|&s| Vector3::new(s, 0.0, r + 0.5 * dhat))
        .collect();
    let st = state_through(&rod, x, Vector3::z());
    let table = Obstacle::new("table", 0, Box::new(Plane), 0.0, &origin());
    let mut ct = contact(&rod, vec![table], r);
    ct.begin_step(&st.x, None);
    let mut ws = rod::assembly::Workspace::new(&rod);
    let mut touching = |ct: &mut Contact| {
        ws.assemble_terms(&rod, &st, 1.0, false, &mut [&mut *ct])
            .unwrap();
        ct.active
    };
    assert_eq!(touching(&mut ct), 2 * n);
    ct.set_shrink(2.0 * rod.ds_edge[0]);
    assert_eq!(touching(&mut ct), 0);
    assert_eq!(touching(&mut ct), 0);
    ct.set_shrink(0.0);
    assert_eq!(touching(&mut ct), 2 * n);
}

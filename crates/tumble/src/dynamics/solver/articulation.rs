//! Joint trees in reduced coordinates: Featherstone's articulated-body algorithm (ABA),
//! chosen with `SolverSettings::joint_trees` = [`JointTrees::Reduced`].
//!
//! Why: the soft step keeps six coordinates a body and takes the locked ones out again
//! with impulses every substep. A cart-pole (2 bodies, 2 freedoms) cost it 29,600
//! instructions a step, 3 µs, where MuJoCo's step of the same model in its 2 generalised
//! coordinates takes 1.9 µs; and a joint held by impulses gives a little under load (a
//! chain stretches). In a tree's own coordinates, a hinge's angle and a slider's travel,
//! there is nothing to hold together: the bodies' poses follow from the coordinates, and
//! the coordinates' accelerations from one pass up and one down the tree (O(bodies)).
//!
//! What is solved so: each island (bodies joined by acting joints) that
//! - hangs from the ground (the world or a static body) by exactly one joint,
//! - is a tree (one joint fewer than bodies),
//! - has only hinges and sliders without limits, motor, spring or servo (armatures and
//!   break forces are kept), ball joints without cone or twist limits, and fixed joints,
//! - has awake, dynamic, non-planar bodies, none in a contact the step solves and none
//!   joined to a kinematic body.
//!
//! Every other island, and a tree in a step where a contact touches it, goes through the
//! soft step as before: a tree that swings into the floor is solved there for the steps
//! it touches. No state is kept between steps (only the trees' structure, found again
//! whenever the joints or the bodies' kinds change): the coordinates and rates are read
//! from the bodies' poses and velocities when a step begins (so snapshots, setters and a
//! switch of solver need nothing), and the poses are then made from them, which also puts
//! bodies that a setter moved off their joints back on them. Velocities the joints do not
//! allow (a kick given to one body) become the rates an inelastic impulse through the
//! joints would leave (`project_rates`).
//!
//! Each substep of h: the forces at the substep's start (the solver's kick evaluates
//! them for every body), the ABA's q̈ (gyroscopic terms, gravity, applied forces and
//! torques, damping as forces), then semi-implicit Euler: q̇ += h q̈, q += h q̇, the
//! poses and velocities from the new q and q̇ (MuJoCo's default `Euler` at the step of
//! the substep). Each joint reports the force it carried, averaged over the substeps.

use super::body::{BodySim, BodyState};
use super::spatial::{outer, Inertia, Spatial, Twist};
use crate::collision::contact::Contact;
use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::force::Wrench;
use crate::dynamics::joint::coords::{self, BodyMotion};
use crate::dynamics::joint::{Joint, JointCoordinate, JointImpulses, JointKind};
use crate::math::{Mat3, Quat, Real, Vec3};
use std::ops::Range;

/// The freedom a link has relative to its parent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Freedom {
    Hinge,
    Slider,
    /// Three: a ball joint without limits (see [`Ball`]).
    Ball,
    Weld,
}

/// A ball joint's coordinates and the algorithm's quantities for its three freedoms: the
/// link's orientation relative to its parent (`rel`, q_link = q_parent · rel) and its
/// angular velocity relative to the parent in its own frame (`w`: MuJoCo's ball qvel,
/// integrated as MuJoCo does, rel ← rel · exp(h w)). The motion subspace's columns are
/// rotations about the link's own axes through the anchor.
#[derive(Debug, Clone, Copy, Default)]
struct Ball {
    rel: Quat,
    w: Vec3,
    s: [Twist; 3],
    u: [Spatial; 3],
    inv_d: Mat3,
    bias: Vec3,
    tau: Vec3,
    wdd: Vec3,
}

/// A body of a tree with the joint to its parent: the joint's frames as seen from the
/// parent (the link's pose is `parent ∘ joint(q)`), its coordinate and the algorithm's
/// quantities at the current poses.
#[derive(Debug, Clone, Copy)]
struct Link {
    body: usize,
    /// The parent's index among the links (`None`: the ground).
    parent: Option<usize>,
    joint: usize,
    freedom: Freedom,
    /// +1 when the link is the joint's `body`, −1 when it is its `other` (the joint's
    /// coordinate then turns or slides the parent relative to the link).
    sigma: Real,
    /// The joint's anchor in the parent's frame and in the link's (body origins).
    parent_anchor: Vec3,
    child_anchor: Vec3,
    /// The hinge's or slider's axis in the parent's frame.
    axis: Vec3,
    /// The link's orientation relative to the parent's at q = 0.
    offset: Quat,
    armature: Real,
    q: Real,
    qd: Real,
    /// The joint's motion subspace (one freedom), the joint's own motion S q̇ and the
    /// link's velocity (spatial).
    s: Twist,
    vj: Twist,
    v: Twist,
    ball: Ball,
    /// Where the joint's `other` anchor is, for the reaction's torque.
    other_anchor: Vec3,
    // The algorithm's quantities (see `Articulations::accelerate`).
    ia: Inertia,
    pa: Spatial,
    c: Twist,
    u: Spatial,
    inv_d: Real,
    bias: Real,
    /// The joint's generalised force (N·m or N) and the coordinate's acceleration.
    tau: Real,
    qdd: Real,
    a: Twist,
    /// The link's velocity when the step began, as given (see `consistent`).
    given: Twist,
    /// The force the parent applied through the joint, summed over the substeps.
    reaction: Spatial,
}

/// A tree: its links (parent before child) and its ground (a static body, or the world)
/// and that's pose this step.
#[derive(Debug, Clone)]
struct Tree {
    links: Range<usize>,
    ground_body: Option<usize>,
    ground: (Vec3, Quat),
    /// The point spatial vectors are taken about: the ground joint's anchor.
    origin: Vec3,
}

/// The trees the joints make and those a step solves, and the searches' scratch, kept so
/// that a step allocates nothing.
#[derive(Default)]
pub(crate) struct Articulations {
    /// Every tree of the joints, whether or not a step can solve it (asleep, or in
    /// contact): found again only when the joints or the bodies' kinds change (`Found`).
    trees: Vec<Tree>,
    links: Vec<Link>,
    /// The trees this step solves.
    active: Vec<usize>,
    found: Found,
    search: Search,
}

/// What the trees were found from: the bodies' kinds, the joints and their bodies. The
/// search and the links' frames (a third of a cart-pole's step here) are made again only
/// when one of these changed.
#[derive(Default)]
struct Found {
    valid: bool,
    bodies: Vec<(BodyKind, bool)>,
    joints: Vec<Joint>,
    links: Vec<[Option<usize>; 2]>,
}

impl Found {
    fn unchanged(&self, input: &TreeInput<'_>) -> bool {
        let kind = |b: &Body| (b.kind, b.planar);
        self.valid
            && self.links == input.links
            && self.bodies.len() == input.bodies.len()
            && self
                .bodies
                .iter()
                .zip(input.bodies)
                .all(|(k, b)| *k == kind(b))
            && self.joints.len() == input.joints.len()
            && self
                .joints
                .iter()
                .zip(input.joints)
                .all(|(a, b)| same_joint(a, b))
    }

    fn keep(&mut self, input: &TreeInput<'_>) {
        self.valid = true;
        self.bodies.clear();
        self.bodies
            .extend(input.bodies.iter().map(|b| (b.kind, b.planar)));
        self.links.clear();
        self.links.extend_from_slice(input.links);
        self.joints.truncate(input.joints.len());
        for (i, j) in input.joints.iter().enumerate() {
            match self.joints.get_mut(i) {
                Some(kept) => kept.clone_from(j),
                None => self.joints.push(j.clone()),
            }
        }
    }
}

/// Whether two joints make the same link: everything `Link::new` and the search read.
fn same_joint(a: &Joint, b: &Joint) -> bool {
    let (d, e) = (&a.def, &b.def);
    a.acts() == b.acts()
        && (d.kind, d.body, d.other, d.armature) == (e.kind, e.body, e.other, e.armature)
        && (d.anchor, d.other_anchor) == (e.anchor, e.other_anchor)
        && (a.axis, a.other_axis, a.reference) == (b.axis, b.other_axis, b.reference)
        && (a.other_reference, a.relative_rotation) == (b.other_reference, b.relative_rotation)
}

/// Per body: its island's representative (union–find), whether it rules its island out
/// (not dynamic, planar, or on a joint the trees do not take), and per representative the
/// island's counts; the tree joints as adjacency lists.
#[derive(Default)]
struct Search {
    root: Vec<u32>,
    bad: Vec<bool>,
    size: Vec<u32>,
    edges: Vec<u32>,
    grounds: Vec<u32>,
    start: Vec<u32>,
    fill: Vec<u32>,
    adjacent: Vec<u32>,
    /// Per body, in a contact the step solves.
    touched: Vec<bool>,
}

/// What the search reads of the world.
pub(crate) struct TreeInput<'a> {
    pub bodies: &'a [Body],
    pub sims: &'a [BodySim],
    pub states: &'a [BodyState],
    pub joints: &'a [Joint],
    pub links: &'a [[Option<usize>; 2]],
    pub contacts: &'a [Contact],
    pub ghosts: &'a [bool],
}

impl Articulations {
    /// Whether the step has a tree to solve.
    pub fn is_empty(&self) -> bool {
        self.active.is_empty()
    }

    /// Finds the step's trees (see the module header): the joints' trees whose bodies
    /// all move and touch no contact; sets each one's links' coordinates and rates from
    /// the bodies' state.
    pub fn find(&mut self, input: &TreeInput<'_>) {
        self.active.clear();
        if !self.found.unchanged(input) {
            self.find_trees(input);
            self.found.keep(input);
        }
        if self.trees.is_empty() {
            return;
        }
        self.search.touch(input);
        for t in 0..self.trees.len() {
            let links = &self.links[self.trees[t].links.clone()];
            let free = |l: &Link| input.sims[l.body].moves && !self.search.touched[l.body];
            if links.iter().all(free) {
                self.read(t, input);
                self.active.push(t);
            }
        }
    }

    /// Tree `t`'s ground pose, and its links' coordinates and rates.
    fn read(&mut self, t: usize, input: &TreeInput<'_>) {
        let tree = &mut self.trees[t];
        let ground = tree.ground_body.map_or((Vec3::ZERO, Quat::IDENTITY), |g| {
            origin_pose(&input.bodies[g], &input.sims[g])
        });
        tree.ground = ground;
        tree.origin = ground.0 + ground.1 * self.links[tree.links.start].parent_anchor;
        let (range, origin) = (tree.links.clone(), tree.origin);
        for i in range {
            let parent = self.links[i].parent.map(|p| self.links[p].body);
            self.links[i].read_coordinate(input, parent, (ground, origin));
        }
    }

    /// Every tree the joints make (see the module header; whether its bodies move or
    /// touch a contact is the step's to say).
    fn find_trees(&mut self, input: &TreeInput<'_>) {
        self.trees.clear();
        self.links.clear();
        if !input.joints.iter().any(|j| j.acts()) {
            return;
        }
        self.search.islands(input);
        for (k, joint) in input.joints.iter().enumerate() {
            let Some(body) = ground_end(input, k, joint) else {
                continue;
            };
            let r = self.search.find(body) as usize;
            let s = &self.search;
            // One joint to the ground, and connected with one joint fewer than bodies:
            // a tree.
            if !s.bad[r] && s.grounds[r] == 1 && s.edges[r] + 1 == s.size[r] {
                self.grow(input, k, body);
            }
        }
    }

    /// Adds the tree hanging from the ground by joint `k` at `body`, breadth first.
    fn grow(&mut self, input: &TreeInput<'_>, k: usize, body: usize) {
        let first = self.links.len();
        let joint = &input.joints[k];
        let child_is_a = input.links[k][0] == Some(body);
        // The joint's other end: `other` (index 1) when the link is its `body`.
        let ground_body = input.links[k][child_is_a as usize];
        self.links.push(Link::new(joint, k, body, child_is_a, None));
        let mut next = first;
        while next < self.links.len() {
            let (at, from) = (self.links[next].body, self.links[next].joint);
            let (a, b) = (self.search.start[at], self.search.start[at + 1]);
            for e in a..b {
                let j = self.search.adjacent[e as usize] as usize;
                if j == from {
                    continue;
                }
                let [ja, jb] = input.links[j];
                let (child, child_is_a) = if ja == Some(at) {
                    (jb, false)
                } else {
                    (ja, true)
                };
                let child = child.expect("a tree joint joins two bodies");
                self.links.push(Link::new(
                    &input.joints[j],
                    j,
                    child,
                    child_is_a,
                    Some(next),
                ));
            }
            next += 1;
        }
        self.trees.push(Tree {
            links: first..self.links.len(),
            ground_body,
            ground: (Vec3::ZERO, Quat::IDENTITY),
            origin: Vec3::ZERO,
        });
    }

    /// Takes the trees' bodies from the soft step (it leaves bodies that do not move)
    /// and puts them on their joints at the coordinates read.
    pub fn begin(&mut self, bodies: &[Body], sims: &mut [BodySim], states: &mut [BodyState]) {
        for k in 0..self.active.len() {
            for l in &mut self.links[self.trees[self.active[k]].links.clone()] {
                sims[l.body].moves = false;
                l.reaction = Spatial::default();
            }
        }
        for k in 0..self.active.len() {
            let t = self.active[k];
            self.place(t, bodies, sims, states);
            if !self.consistent(t) {
                // A setter (or a step of the soft step) left velocities the joints do
                // not allow: the rates that keep the momenta instead of the ones read.
                self.project_rates(t, bodies, sims);
                self.place(t, bodies, sims, states);
            }
        }
    }

    /// One substep of `h` for every tree, with the forces `wrench` (by body).
    pub fn substep(
        &mut self,
        (bodies, wrench): (&[Body], &[Wrench]),
        sims: &mut [BodySim],
        states: &mut [BodyState],
        h: Real,
    ) {
        for k in 0..self.active.len() {
            let t = self.active[k];
            self.accelerate(t, (bodies, wrench), sims, h);
            for l in &mut self.links[self.trees[t].links.clone()] {
                l.q += h * l.qd;
                if l.freedom == Freedom::Ball {
                    l.ball.rel = (l.ball.rel * Quat::from_scaled_axis(l.ball.w * h)).normalize();
                }
                states[l.body].turned += l.v.w * h;
            }
            self.place(t, bodies, sims, states);
        }
    }

    /// Hands the bodies back (moving), and reports each joint's force: its average over
    /// the step's `substeps`. The bodies' inverse inertias and drift records are left
    /// as they were: the step's last reader of them, the soft step's rows, is done (and
    /// turning them cost a twentieth of a cart-pole's step).
    pub fn finish(&mut self, sims: &mut [BodySim], joints: &mut [Joint], substeps: u32) {
        for t in self.active.iter().map(|&t| &self.trees[t]) {
            for l in &self.links[t.links.clone()] {
                sims[l.body].moves = true;
                let f = l.reaction.scale(1.0 / substeps as Real);
                let torque = f.moment_about(l.other_anchor - t.origin);
                // The force on the link; the joint reports the one on its `other`.
                let (force, torque) = if l.sigma < 0.0 {
                    (f.f, torque)
                } else {
                    (-f.f, -torque)
                };
                report(&mut joints[l.joint], force, torque);
            }
        }
    }

    /// The links' poses, motion subspaces and velocities from their coordinates and
    /// rates, root first; written into the bodies' step state.
    fn place(&mut self, t: usize, bodies: &[Body], sims: &mut [BodySim], states: &mut [BodyState]) {
        let tree = &self.trees[t];
        let o = tree.origin;
        for i in tree.links.clone() {
            let (xp, qp, vp) = match self.links[i].parent {
                Some(p) => {
                    let pb = self.links[p].body;
                    let (x, q) = origin_pose(&bodies[pb], &sims[pb]);
                    (x, q, self.links[p].v)
                }
                None => (tree.ground.0, tree.ground.1, Twist::default()),
            };
            let l = &mut self.links[i];
            let (q, anchor) = l.pose((xp, qp), o, sims[l.body].q);
            l.v = vp.add(l.vj);
            let body = &bodies[l.body];
            let (sim, state) = (&mut sims[l.body], &mut states[l.body]);
            let origin = anchor - q * l.child_anchor;
            sim.x = origin + q * body.local_center;
            sim.q = q;
            if !(body.isotropic || body.planar) {
                // I = Σ mᵢ aᵢ aᵢᵀ over the principal axes aᵢ in the world: a third of the
                // products of R I_body Rᵀ. (The inverse is made once, in `finish`: the
                // algorithm needs I alone.)
                let axes = Mat3::from_quat(q * body.principal_rotation);
                let m = body.principal_moments;
                sim.inertia = outer(axes.x_axis * m.x, axes.x_axis)
                    + outer(axes.y_axis * m.y, axes.y_axis)
                    + outer(axes.z_axis * m.z, axes.z_axis);
            }
            state.v = l.v.at(sim.x - o);
            state.w = l.v.w;
            sim.l = sim.inertia * state.w;
            sim.w_synced = state.w;
        }
    }

    /// The articulated-body algorithm on tree `t` at the current poses: q̈ of every
    /// link, then q̇ += h q̈; each joint's force added to its reaction.
    fn accelerate(
        &mut self,
        t: usize,
        (bodies, wrench): (&[Body], &[Wrench]),
        sims: &[BodySim],
        h: Real,
    ) {
        let (range, o) = (self.trees[t].links.clone(), self.trees[t].origin);
        for l in &mut self.links[range.clone()] {
            let (body, sim) = (&bodies[l.body], &sims[l.body]);
            let r = sim.x - o;
            let inertia = Inertia::rigid(body.mass, r, sim.inertia);
            let (mut force, mut torque) = (wrench[l.body].force, wrench[l.body].torque);
            if body.linear_damping != 0.0 || body.angular_damping != 0.0 {
                force -= l.v.at(r) * (body.linear_damping * body.mass);
                torque -= sim.inertia * l.v.w * body.angular_damping;
            }
            l.ia = inertia;
            let gyroscopic = l.v.cross_force(inertia.apply(l.v));
            l.pa = gyroscopic.sub(Spatial::at(r, force, torque));
            l.c = l.v.cross_motion(l.vj);
            l.tau = 0.0;
            l.ball.tau = Vec3::ZERO;
        }
        self.solve(range.clone());
        for l in &mut self.links[range] {
            l.qd += h * l.qdd;
            l.ball.w += h * l.ball.wdd;
            l.reaction = l.reaction.add(l.ia.apply(l.a).add(l.pa));
        }
    }

    /// The articulated-body algorithm's two passes over `range`, each link's rigid
    /// inertia `ia`, bias force `pa`, velocity-product acceleration `c` and joint force
    /// `tau` given: leaves to root, the inertia and bias of each subtree as its parent
    /// feels them through the joint; root to leaves, the accelerations `qdd` and `a`.
    fn solve(&mut self, range: Range<usize>) {
        for i in range.clone().rev() {
            let l = &mut self.links[i];
            let (ia, pa) = match l.freedom {
                Freedom::Weld => (l.ia, l.pa.add(l.ia.apply(l.c))),
                Freedom::Ball => l.ball.articulate(&l.ia, l.pa, l.c),
                _ => {
                    l.u = l.ia.apply(l.s);
                    l.inv_d = 1.0 / (l.s.dot(l.u) + l.armature);
                    l.bias = l.tau - l.s.dot(l.pa);
                    let ia = l.ia.less_outer(l.u, l.inv_d);
                    (ia, l.pa.add(ia.apply(l.c)).add(l.u.scale(l.bias * l.inv_d)))
                }
            };
            if let Some(p) = l.parent {
                self.links[p].ia.add(&ia);
                self.links[p].pa = self.links[p].pa.add(pa);
            }
        }
        for i in range {
            let a_parent = self.links[i]
                .parent
                .map_or(Twist::default(), |p| self.links[p].a);
            let l = &mut self.links[i];
            let a = a_parent.add(l.c);
            (l.qdd, l.a) = match l.freedom {
                Freedom::Weld => (0.0, a),
                Freedom::Ball => (0.0, l.ball.accelerate(a)),
                _ => {
                    let qdd = (l.bias - a.dot(l.u)) * l.inv_d;
                    (qdd, a.add(l.s.scale(qdd)))
                }
            };
        }
    }

    /// Whether the bodies of tree `t` moved as its joints allow when the step began:
    /// each link's velocity from the rates read (`v`, after `place`) is the one it had
    /// (`given`), to a part in 10⁹ of the tree's speeds.
    fn consistent(&self, t: usize) -> bool {
        let links = &self.links[self.trees[t].links.clone()];
        let size = |m: Twist| m.w.length() + m.v.length();
        let scale = links.iter().map(|l| size(l.given)).fold(0.0, Real::max);
        let limit = 1e-9 * (1.0 + scale);
        links
            .iter()
            .all(|l| size(l.v.add(l.given.scale(-1.0))) <= limit)
    }

    /// The joint rates closest to the velocities the bodies were given, in their kinetic
    /// energy's metric: q̇ = H⁻¹ Jᵀ M V, what a perfectly inelastic impulse through the
    /// joints leaves (the generalised momentum of each subtree along its joint is kept).
    /// Solved as the algorithm's passes with no velocity and the momenta as joint forces.
    fn project_rates(&mut self, t: usize, bodies: &[Body], sims: &[BodySim]) {
        let (range, o) = (self.trees[t].links.clone(), self.trees[t].origin);
        for l in &mut self.links[range.clone()] {
            let sim = &sims[l.body];
            l.ia = Inertia::rigid(bodies[l.body].mass, sim.x - o, sim.inertia);
            // The subtree's momentum, gathered below.
            l.pa = l.ia.apply(l.given);
            l.c = Twist::default();
        }
        for i in range.clone().rev() {
            let (momentum, parent) = (self.links[i].pa, self.links[i].parent);
            let l = &mut self.links[i];
            l.tau = l.s.dot(momentum) + l.armature * l.qd;
            let [s0, s1, s2] = l.ball.s;
            l.ball.tau = Vec3::new(s0.dot(momentum), s1.dot(momentum), s2.dot(momentum));
            if let Some(p) = parent {
                self.links[p].pa = self.links[p].pa.add(momentum);
            }
        }
        for l in &mut self.links[range.clone()] {
            l.pa = Spatial::default();
        }
        self.solve(range.clone());
        for l in &mut self.links[range] {
            l.qd = l.qdd;
            l.ball.w = l.ball.wdd;
        }
    }
}

impl Ball {
    /// The backward pass's step for three freedoms: U = I_A S, D = Sᵀ U, u = τ − Sᵀ p_A;
    /// returns I_A − U D⁻¹ Uᵀ and p_A + I_a c + U D⁻¹ u, what the parent feels.
    fn articulate(&mut self, ia: &Inertia, pa: Spatial, c: Twist) -> (Inertia, Spatial) {
        let s = self.s;
        self.u = s.map(|s| ia.apply(s));
        let column = |u: Spatial| Vec3::new(s[0].dot(u), s[1].dot(u), s[2].dot(u));
        let d = Mat3::from_cols(column(self.u[0]), column(self.u[1]), column(self.u[2]));
        self.inv_d = d.inverse();
        self.bias = self.tau - Vec3::new(s[0].dot(pa), s[1].dot(pa), s[2].dot(pa));
        // U D⁻¹: three force vectors, each a mix of the u's.
        let u = self.u;
        let mix = |m: Vec3| u[0].scale(m.x).add(u[1].scale(m.y)).add(u[2].scale(m.z));
        let w = [0, 1, 2].map(|j| mix(self.inv_d.row(j)));
        let mut articulated = *ia;
        for j in 0..3 {
            articulated = articulated.less(w[j], u[j]);
        }
        let pa = pa
            .add(articulated.apply(c))
            .add(mix(self.inv_d * self.bias));
        (articulated, pa)
    }

    /// The forward pass's step: ẇ = D⁻¹ (u − Uᵀ a′); returns a′ + S ẇ.
    fn accelerate(&mut self, a: Twist) -> Twist {
        let u = self.u;
        let ua = Vec3::new(a.dot(u[0]), a.dot(u[1]), a.dot(u[2]));
        self.wdd = self.inv_d * (self.bias - ua);
        let [s0, s1, s2] = self.s;
        a.add(s0.scale(self.wdd.x))
            .add(s1.scale(self.wdd.y))
            .add(s2.scale(self.wdd.z))
    }
}

impl Link {
    /// The link of `body` hanging from its parent by joint `k` (see [`Link`]).
    fn new(joint: &Joint, k: usize, body: usize, child_is_a: bool, parent: Option<usize>) -> Link {
        let def = &joint.def;
        let (freedom, rel) = match def.kind {
            JointKind::Hinge { .. } => (Freedom::Hinge, joint.relative_rotation),
            JointKind::Slider { .. } => (Freedom::Slider, joint.relative_rotation),
            JointKind::Ball { .. } => (Freedom::Ball, joint.relative_rotation),
            _ => (Freedom::Weld, joint.relative_rotation),
        };
        // Frames that coincide when the hinge's angle is zero: axis, reference, their
        // cross product (see `coords::raw_hinge_angle`).
        let frame = |a: Vec3, r: Vec3| Mat3::from_cols(a, r, a.cross(r));
        let fa = frame(joint.axis, joint.reference);
        let fb = frame(joint.other_axis, joint.other_reference);
        let (sigma, parent_anchor, child_anchor, axis, offset) = if child_is_a {
            let offset = match freedom {
                Freedom::Hinge => Quat::from_mat3(&(fb * fa.transpose())),
                _ => rel.inverse(),
            };
            let axis = match freedom {
                Freedom::Hinge => joint.other_axis,
                _ => rel.inverse() * joint.axis,
            };
            (1.0, def.other_anchor, def.anchor, axis, offset)
        } else {
            let offset = match freedom {
                Freedom::Hinge => Quat::from_mat3(&(fa * fb.transpose())),
                _ => rel,
            };
            (-1.0, def.anchor, def.other_anchor, joint.axis, offset)
        };
        Link {
            body,
            parent,
            joint: k,
            freedom,
            sigma,
            parent_anchor,
            child_anchor,
            axis,
            offset: offset.normalize(),
            armature: def.armature,
            q: 0.0,
            qd: 0.0,
            s: Twist::default(),
            vj: Twist::default(),
            v: Twist::default(),
            ball: Ball::default(),
            other_anchor: Vec3::ZERO,
            ia: Inertia::default(),
            pa: Spatial::default(),
            c: Twist::default(),
            u: Spatial::default(),
            inv_d: 0.0,
            bias: 0.0,
            tau: 0.0,
            qdd: 0.0,
            a: Twist::default(),
            given: Twist::default(),
            reaction: Spatial::default(),
        }
    }

    /// The link's orientation and anchor from its parent's pose (`xp` the origin, `qp`)
    /// and the joint's coordinates; sets the motion subspace, the joint's motion S q̇ and
    /// where the joint's `other` anchor is. `was`: the link's orientation before.
    fn pose(&mut self, (xp, qp): (Vec3, Quat), o: Vec3, was: Quat) -> (Quat, Vec3) {
        let q = match self.freedom {
            Freedom::Hinge => {
                qp * Quat::from_axis_angle(self.axis, self.sigma * self.q) * self.offset
            }
            Freedom::Ball => qp * self.ball.rel,
            _ => qp * self.offset,
        }
        .normalize();
        // The same turn as ±q: the sign the body had, so that its quaternion moves
        // continuously (a reader of [x, y, z, w] sees no jump).
        let q = if q.dot(was) < 0.0 { -q } else { q };
        let p = xp + qp * self.parent_anchor;
        let arm = p - o;
        let anchor = match self.freedom {
            Freedom::Hinge => {
                let n = qp * self.axis * self.sigma;
                self.s = Twist::new(n, arm.cross(n));
                p
            }
            Freedom::Slider => {
                let h = qp * self.axis * self.sigma;
                self.s = Twist::new(Vec3::ZERO, h);
                p + h * self.q
            }
            Freedom::Ball => {
                let r = Mat3::from_quat(q);
                let column = |a: Vec3| Twist::new(a, arm.cross(a));
                self.ball.s = [column(r.x_axis), column(r.y_axis), column(r.z_axis)];
                let w = q * self.ball.w;
                self.vj = Twist::new(w, arm.cross(w));
                p
            }
            Freedom::Weld => {
                self.s = Twist::default();
                p
            }
        };
        if self.freedom != Freedom::Ball {
            self.vj = self.s.scale(self.qd);
        }
        self.other_anchor = if self.sigma < 0.0 { anchor } else { p };
        (q, anchor)
    }

    /// The joint's coordinate and rate at the bodies' state (`parent`: the parent's body,
    /// `None` for the ground at `ground`), and the link's velocity as given (about `o`).
    fn read_coordinate(
        &mut self,
        input: &TreeInput<'_>,
        parent: Option<usize>,
        (ground, o): ((Vec3, Quat), Vec3),
    ) {
        let state = &input.states[self.body];
        let r = input.sims[self.body].x - o;
        self.given = Twist::new(state.w, state.v - state.w.cross(r));
        let motion = |k: Option<usize>| match k {
            Some(k) => {
                let (x, q) = origin_pose(&input.bodies[k], &input.sims[k]);
                let state = &input.states[k];
                BodyMotion {
                    x,
                    q,
                    com: input.sims[k].x,
                    v: state.v,
                    w: state.w,
                }
            }
            None => BodyMotion {
                x: ground.0,
                q: ground.1,
                com: ground.0,
                ..BodyMotion::WORLD
            },
        };
        let (child, parent) = (motion(Some(self.body)), motion(parent));
        if self.freedom == Freedom::Ball {
            self.ball.rel = (parent.q.inverse() * child.q).normalize();
            self.ball.w = child.q.inverse() * (child.w - parent.w);
            return;
        }
        let (a, b) = if self.sigma > 0.0 {
            (child, parent)
        } else {
            (parent, child)
        };
        let joint = &input.joints[self.joint];
        let scalar = |c: JointCoordinate| c.scalar().unwrap_or(0.0);
        (self.q, self.qd) = match self.freedom {
            // `coords::velocity`'s rate of a hinge, without its anchors.
            Freedom::Hinge => (
                coords::raw_hinge_angle(joint, a.q, b.q),
                (a.q * joint.axis).dot(a.w - b.w),
            ),
            Freedom::Slider => (
                scalar(coords::position(joint, &a, &b)),
                scalar(coords::velocity(joint, &a, &b)),
            ),
            Freedom::Weld | Freedom::Ball => (0.0, 0.0),
        };
    }
}

impl Search {
    /// Union–find of the dynamic bodies by acting joints, with each island's counts
    /// and whether something rules it out; then the adjacency lists of the joints
    /// between dynamic bodies.
    fn islands(&mut self, input: &TreeInput<'_>) {
        let n = input.bodies.len();
        self.root.clear();
        self.root.extend(0..n as u32);
        self.bad.clear();
        let bad = |b: &Body| b.kind != BodyKind::Dynamic || b.planar;
        self.bad.extend(input.bodies.iter().map(bad));
        for (k, joint) in input.joints.iter().enumerate() {
            if !joint.acts() {
                continue;
            }
            let [a, b] = input.links[k];
            let kinematic =
                |e: Option<usize>| e.is_some_and(|i| input.bodies[i].kind == BodyKind::Kinematic);
            let bad = !supported(joint) || a == b || kinematic(a) || kinematic(b);
            for e in [a, b].into_iter().flatten() {
                self.bad[e] |= bad;
            }
            if let (Some(a), Some(b)) = (dynamic(input, a), dynamic(input, b)) {
                self.union(a, b);
            }
        }
        self.count(input);
    }

    /// Marks the bodies in a contact the step solves.
    fn touch(&mut self, input: &TreeInput<'_>) {
        self.touched.clear();
        self.touched.resize(input.bodies.len(), false);
        for (i, c) in input.contacts.iter().enumerate() {
            if !c.manifold.is_empty() && !input.ghosts.get(i).copied().unwrap_or(false) {
                self.touched[c.index_a as usize] = true;
                self.touched[c.index_b as usize] = true;
            }
        }
    }

    fn count(&mut self, input: &TreeInput<'_>) {
        let n = input.bodies.len();
        for v in [&mut self.size, &mut self.edges, &mut self.grounds] {
            v.clear();
            v.resize(n, 0);
        }
        self.start.clear();
        self.start.resize(n + 1, 0);
        for i in 0..n {
            let r = self.find(i) as usize;
            self.size[r] += 1;
            self.bad[r] |= self.bad[i];
        }
        for (k, joint) in input.joints.iter().enumerate() {
            if !joint.acts() {
                continue;
            }
            let [a, b] = input.links[k];
            match (dynamic(input, a), dynamic(input, b)) {
                (Some(a), Some(b)) => {
                    let r = self.find(a) as usize;
                    self.edges[r] += 1;
                    self.start[a + 1] += 1;
                    self.start[b + 1] += 1;
                }
                (Some(x), None) | (None, Some(x)) => {
                    let r = self.find(x) as usize;
                    self.grounds[r] += 1;
                }
                (None, None) => {}
            }
        }
        for i in 0..n {
            self.start[i + 1] += self.start[i];
        }
        self.adjacent.clear();
        self.adjacent.resize(self.start[n] as usize, 0);
        // Filled from each list's end down to its start.
        let end = &mut self.fill;
        end.clear();
        end.extend_from_slice(&self.start[1..]);
        for (k, joint) in input.joints.iter().enumerate().rev() {
            if !joint.acts() {
                continue;
            }
            let [a, b] = input.links[k];
            if let (Some(a), Some(b)) = (dynamic(input, a), dynamic(input, b)) {
                for e in [a, b] {
                    end[e] -= 1;
                    self.adjacent[end[e] as usize] = k as u32;
                }
            }
        }
    }

    fn find(&mut self, mut i: usize) -> u32 {
        while self.root[i] as usize != i {
            let up = self.root[self.root[i] as usize];
            self.root[i] = up;
            i = up as usize;
        }
        i as u32
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.root[hi as usize] = lo;
        }
    }
}

/// Whether a joint's kind and options are ones the trees solve.
fn supported(joint: &Joint) -> bool {
    match joint.def.kind {
        JointKind::Hinge {
            limits,
            motor,
            spring,
            servo,
        }
        | JointKind::Slider {
            limits,
            motor,
            spring,
            servo,
        } => limits.is_none() && motor.is_none() && spring.is_none() && servo.is_none(),
        JointKind::Ball { cone, twist } => cone.is_none() && twist.is_none(),
        JointKind::Fixed => true,
        JointKind::Distance { .. } => false,
    }
}

/// `e` if it is a dynamic body (a static body, or none, is the ground).
fn dynamic(input: &TreeInput<'_>, e: Option<usize>) -> Option<usize> {
    e.filter(|&i| input.bodies[i].kind != BodyKind::Static)
}

/// For an acting joint with one dynamic end and the other on the ground: that end.
fn ground_end(input: &TreeInput<'_>, k: usize, joint: &Joint) -> Option<usize> {
    if !joint.acts() {
        return None;
    }
    let [a, b] = input.links[k];
    match (dynamic(input, a), dynamic(input, b)) {
        (Some(x), None) | (None, Some(x)) => Some(x),
        _ => None,
    }
}

/// A body's origin (where joints' anchors are measured from) and orientation.
fn origin_pose(body: &Body, sim: &BodySim) -> (Vec3, Quat) {
    (sim.x - sim.q * body.local_center, sim.q)
}

/// Writes a tree joint's reaction, breaks it past its limit (as the soft step's
/// `JointConstraint::store`), and clears its impulses: a soft step that takes the joint
/// back starts cold.
fn report(joint: &mut Joint, force: Vec3, torque: Vec3) {
    joint.impulses = JointImpulses::default();
    joint.reaction_force = force;
    joint.reaction_torque = torque;
    if let Some(limit) = joint.def.break_force {
        if force.length() > limit {
            joint.broken = true;
        }
    }
}

//! The step's one representation of a body, split as in Box2D v3: a small `BodyState`
//! that every constraint pass reads and writes (velocities and the motion since the step
//! began), and a `BodySim` with what changes only between substeps.
//!
//! Every body of the world has one of each for the whole step ([`SolverBodies`]): gathered
//! from its `Body` once when the step begins, advanced in place by the free integrator
//! (bodies touching nothing), the solver (bodies in contact or joined), the prescribed
//! motion of kinematic bodies and the continuous-collision sweep, and scattered back once
//! when the step ends. `x0`, `q0` stay the pose at the step's start throughout.

use crate::dynamics::body::{Body, BodyKind, Motion};
use crate::math::{Mat3, Quat, Real, Vec3};
use crate::threads::Par;

/// Fewest bodies worth a piece of a per-body loop on another thread (a body's is some
/// 50 ns: a piece of 256 is over ten times a hand-off's cost).
pub(crate) const BODIES_A_PIECE: usize = 256;

/// Every body of the world as the step sees it, in the world's dense order.
#[derive(Default)]
pub(crate) struct SolverBodies {
    pub sims: Vec<BodySim>,
    pub states: Vec<BodyState>,
}

impl SolverBodies {
    /// Gathers every body at the step's start; `solved[i]` marks the bodies the solver
    /// will move (their world inertia is needed; the others' is left zero).
    /// In pieces on the step's team: one after another it was 0.22 ms of the rain's
    /// step on two threads (its world inertias are two rotations a body).
    pub fn gather(&mut self, bodies: &[Body], solved: &[bool], par: Par) {
        let n = bodies.len().min(solved.len());
        let Some(first) = bodies.first().filter(|_| n > 0) else {
            self.sims.clear();
            self.states.clear();
            return;
        };
        // Sized without a write to what is already there: every slot is set below (and
        // the filler made only when the lists grow).
        if self.sims.len() != n || self.states.len() != n {
            let (sim, state) = BodySim::new(first, solved[0]);
            self.sims.truncate(n);
            self.sims.resize(n, sim);
            self.states.truncate(n);
            self.states.resize(n, state);
        }
        let size = n.div_ceil(par.pieces(n, BODIES_A_PIECE));
        let pair = (&mut self.sims[..], &mut self.states[..]);
        crate::team::chunks2(par.threads, pair, size, &|start, sims, states| {
            for (j, (sim, state)) in sims.iter_mut().zip(states).enumerate() {
                (*sim, *state) = BodySim::new(&bodies[start + j], solved[start + j]);
            }
        });
    }

    /// Body `i`'s state as the integrators' ODE vector sees it.
    pub fn motion(&self, i: usize) -> Motion {
        let (s, st) = (&self.sims[i], &self.states[i]);
        Motion {
            x: s.x,
            q: s.q,
            v: st.v,
            l: s.l,
            w: st.w,
        }
    }

    /// Sets body `i`'s state from an integrator's result.
    pub fn set_motion(&mut self, i: usize, m: &Motion) {
        let (s, st) = (&mut self.sims[i], &mut self.states[i]);
        s.x = m.x;
        s.q = m.q;
        s.l = m.l;
        st.v = m.v;
        st.w = m.w;
    }
}

/// What constraint passes touch: kept small and contiguous.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BodyState {
    pub v: Vec3,
    pub w: Vec3,
    /// Displacement of the centre of mass since the step began.
    pub dp: Vec3,
    /// Rotation since the step began.
    pub dr: Mat3,
    /// ∫ω dt since the step began (rad): how far a round body has rolled (see
    /// `rows::Moved::tangent`), which ΔR cannot tell past a half turn.
    pub turned: Vec3,
}

impl BodyState {
    /// The state a joint's partner without one sees (the world, or the body itself for a
    /// joint from a body to itself): still, unturned. Written to and dropped.
    #[inline(always)]
    pub fn still() -> BodyState {
        BodyState {
            v: Vec3::ZERO,
            w: Vec3::ZERO,
            dp: Vec3::ZERO,
            dr: Mat3::IDENTITY,
            turned: Vec3::ZERO,
        }
    }
}

/// Two body states at once, for a joint's rows: a slice when one thread has them all,
/// [`SharedStates`] when a joint colour is split over threads.
pub(crate) trait PairAccess {
    /// `f` on the states of `a` and `b`; a still copy ([`BodyState::still`]) stands in for
    /// `None` (the world) and for both sides of a joint whose two sides are one body.
    fn with_pair<R>(
        &mut self,
        a: Option<usize>,
        b: Option<usize>,
        f: impl FnOnce(&mut BodyState, &mut BodyState) -> R,
    ) -> R;
}

impl PairAccess for [BodyState] {
    #[inline(always)]
    fn with_pair<R>(
        &mut self,
        a: Option<usize>,
        b: Option<usize>,
        f: impl FnOnce(&mut BodyState, &mut BodyState) -> R,
    ) -> R {
        // The still copies are made only when needed: two of these per call cost the
        // joint grid a tenth of its time in copies.
        match (a, b) {
            (Some(a), Some(b)) => match self.get_disjoint_mut([a, b]) {
                Ok([x, y]) => f(x, y),
                Err(_) => f(&mut BodyState::still(), &mut BodyState::still()),
            },
            (Some(a), None) => f(&mut self[a], &mut BodyState::still()),
            (None, Some(b)) => f(&mut BodyState::still(), &mut self[b]),
            (None, None) => f(&mut BodyState::still(), &mut BodyState::still()),
        }
    }
}

impl PairAccess for SharedStates<'_> {
    #[inline(always)]
    fn with_pair<R>(
        &mut self,
        a: Option<usize>,
        b: Option<usize>,
        f: impl FnOnce(&mut BodyState, &mut BodyState) -> R,
    ) -> R {
        let len = self.len;
        let ptr = self.ptr;
        // SAFETY (each use below): `k` is in bounds (asserted), and by `new`'s contract
        // element `k` is touched through this copy alone while it may write it; `a` and
        // `b` are distinct where both are taken, so the two references never overlap.
        let at = |k: usize| {
            assert!(k < len);
            unsafe { &mut *ptr.add(k) }
        };
        match (a, b) {
            (Some(a), Some(b)) if a != b => f(at(a), at(b)),
            (Some(a), None) => f(at(a), &mut BodyState::still()),
            (None, Some(b)) => f(&mut BodyState::still(), at(b)),
            _ => f(&mut BodyState::still(), &mut BodyState::still()),
        }
    }
}

/// Access to the step's body states by index, for the contact passes: a slice when one
/// thread has them all, [`SharedStates`] when the manifolds of a graph colour are split
/// over threads.
pub(crate) trait StateAccess {
    fn state(&self, i: usize) -> &BodyState;
    fn set_velocity(&mut self, i: usize, v: Vec3, w: Vec3);
}

impl StateAccess for [BodyState] {
    #[inline(always)]
    fn state(&self, i: usize) -> &BodyState {
        &self[i]
    }

    #[inline(always)]
    fn set_velocity(&mut self, i: usize, v: Vec3, w: Vec3) {
        let s = &mut self[i];
        (s.v, s.w) = (v, w);
    }
}

/// The body states seen by several threads at once, each of which touches a set of
/// bodies of its own. Built only by [`SharedStates::new`], whose caller promises that set
/// (see there); every access is one element through the pointer, never a slice, so that
/// no reference ever covers an element another thread writes.
#[derive(Clone, Copy)]
pub(crate) struct SharedStates<'a> {
    ptr: *mut BodyState,
    len: usize,
    _borrow: std::marker::PhantomData<&'a mut [BodyState]>,
}

// SAFETY: a `SharedStates` is a `&mut [BodyState]` (which is `Send`) split between
// threads; sending or sharing it is sound under `new`'s contract, which rules out two
// threads touching one element while either writes it.
unsafe impl Send for SharedStates<'_> {}
unsafe impl Sync for SharedStates<'_> {}

impl<'a> SharedStates<'a> {
    /// Shares `states`, borrowed exclusively for `'a`, between threads.
    ///
    /// # Safety
    /// While copies of the result are used on several threads at once, every element a
    /// copy writes (`set_velocity`) must be read or written through no other copy, and an
    /// element one copy reads may be written by none. `ContactLanes` checks this of each
    /// run of groups it splits (each moving body in one lane of one group, no body both
    /// moving in one lane and read in another) before any run is split; the joints split
    /// a colour's stripes, which share no body at all (`joint_colours.rs`).
    pub unsafe fn new(states: &'a mut [BodyState]) -> SharedStates<'a> {
        SharedStates {
            ptr: states.as_mut_ptr(),
            len: states.len(),
            _borrow: std::marker::PhantomData,
        }
    }
}

impl StateAccess for SharedStates<'_> {
    #[inline(always)]
    fn state(&self, i: usize) -> &BodyState {
        assert!(i < self.len);
        // SAFETY: `i` is in bounds of the borrowed slice, and by `new`'s contract no
        // other thread writes element `i` while this copy may read it.
        unsafe { &*self.ptr.add(i) }
    }

    #[inline(always)]
    fn set_velocity(&mut self, i: usize, v: Vec3, w: Vec3) {
        assert!(i < self.len);
        // SAFETY: in bounds, and by `new`'s contract element `i` is touched by this copy
        // alone while it may write it; the reference lives for these two writes only.
        let s = unsafe { &mut *self.ptr.add(i) };
        (s.v, s.w) = (v, w);
    }
}

/// The rest of a body's solver data.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BodySim {
    pub x: Vec3,
    pub q: Quat,
    pub x0: Vec3,
    pub q0: Quat,
    /// Angular momentum, the integrated rotational state.
    pub l: Vec3,
    /// ω at which `l` was last brought up to date (see [`BodySim::sync_momentum`]).
    pub w_synced: Vec3,
    pub inv_mass: Real,
    /// Which linear directions an impulse may change (planar bodies lose z).
    pub linear_mask: Vec3,
    /// World inertia and its inverse at the body's current pose, made again after every
    /// drift (`turn_inertia`). Contacts prepare their rows once a step with the step's
    /// first; joints read these at each pose.
    pub inertia: Mat3,
    pub inv_inertia: Mat3,
    /// True for awake dynamic bodies the solver moves.
    pub moves: bool,
    /// The body's friction and restitution coefficients and centre of mass in its frame,
    /// copied here so that preparing contacts, which visits bodies in no particular
    /// order, does not fetch each one's whole `Body`.
    pub friction: Real,
    pub restitution: Real,
    pub local_center: Vec3,
    /// Rolling resistance (dimensionless) and torsional friction (m); see `BodyDef`.
    pub rolling_resistance: Real,
    pub torsional_friction: Real,
    /// The body's multiplier of gravity (see `BodyDef::gravity_scale`).
    pub gravity_scale: Real,
    /// The shape's `Shape::round_radius`, or `None` for a compound, whose children differ,
    /// and a cylinder, round only where it touches on its side (`Shape::round_toward`):
    /// read here, the step's other contacts need not reach into the bodies' shapes.
    pub round: Option<Real>,
}

impl BodySim {
    pub fn new(body: &Body, solved: bool) -> (BodySim, BodyState) {
        let m = Motion::of(body);
        let moves = solved && body.kind == BodyKind::Dynamic;
        let (inertia, inv_inertia) = if !moves {
            (Mat3::ZERO, Mat3::ZERO)
        } else if body.planar {
            let i = body.planar_inertia;
            (
                Mat3::from_diagonal(Vec3::new(0.0, 0.0, i)),
                Mat3::from_diagonal(Vec3::new(0.0, 0.0, 1.0 / i)),
            )
        } else {
            world_inertia(body, m.q)
        };
        let sim = BodySim {
            x: m.x,
            q: m.q,
            x0: m.x,
            q0: m.q,
            l: m.l,
            w_synced: m.w,
            inv_mass: if moves { body.inv_mass } else { 0.0 },
            linear_mask: if body.planar {
                Vec3::new(1.0, 1.0, 0.0)
            } else {
                Vec3::ONE
            },
            inertia,
            inv_inertia,
            moves,
            friction: body.friction,
            restitution: body.restitution,
            local_center: body.local_center,
            rolling_resistance: body.rolling_resistance,
            torsional_friction: body.torsional_friction,
            gravity_scale: body.gravity_scale,
            round: match body.shape {
                crate::collision::shape::Shape::Compound(_)
                | crate::collision::shape::Shape::Cylinder { .. } => None,
                ref shape => Some(shape.round_radius(0)),
            },
        };
        let state = BodyState {
            v: m.v,
            w: m.w,
            dp: Vec3::ZERO,
            dr: Mat3::IDENTITY,
            turned: Vec3::ZERO,
        };
        (sim, state)
    }

    /// Turns the world inertia with the body after a drift: I = R I_body Rᵀ at the new q.
    ///
    /// Why: ω is made from L after each drift with the inertia at the new pose, so the rows
    /// of the next substep must see the body answer an impulse with that inertia too. Kept
    /// at the step's start instead, a thin body spinning fast (a ragdoll's forearm rolling
    /// under the torso at 90 rad/s turns 1.5 rad a step) had its impulses sized for an
    /// inertia up to 20 times the one that then turned it: each correction overshot, and
    /// the ragdoll falling down the stairs, kicked by 1 cm/s, blew up in 8 runs of 30
    /// (none after). Bodies whose tensor is a multiple of the identity, and planar ones
    /// (z-inertia only), keep theirs.
    #[inline]
    pub fn turn_inertia(&mut self, body: &Body) {
        if body.isotropic || body.planar {
            return;
        }
        (self.inertia, self.inv_inertia) = world_inertia(body, self.q);
    }

    /// Impulses changed ω by I⁻¹ ΣΔL; the same ΣΔL goes into L: ΔL = I (ω − ω_synced).
    /// (A contact's row, prepared with the step's first inertia, puts in I I₀⁻¹ ΔL: off
    /// by how far the body has turned since the step began, and consistent with the ω
    /// change its row saw.)
    #[inline]
    pub fn sync_momentum(&mut self, state: &BodyState) {
        if self.moves {
            self.l += self.inertia * (state.w - self.w_synced);
            self.w_synced = state.w;
        }
    }
}

/// A body's world inertia and its inverse at orientation `q`: R I_body Rᵀ and R I_body⁻¹ Rᵀ.
fn world_inertia(body: &Body, q: Quat) -> (Mat3, Mat3) {
    let r = Mat3::from_quat(q);
    (
        r * body.inertia_local * r.transpose(),
        r * body.inv_inertia_local * r.transpose(),
    )
}

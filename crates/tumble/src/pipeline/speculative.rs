//! Speculative contacts that will not be touched: dropped for the step.
//!
//! A speculative point lets the solver close a gap s at up to s/h per substep along the
//! manifold's normal, taken as fixed for the step. Near an edge or a corner that normal
//! turns as the bodies move past each other, so a path that clears the edge by millimetres
//! looks, to the fixed plane, as if it crossed it: the solver stops the body short of
//! something it never touches (a ghost collision; measured: a ball skimming 5 mm over the
//! edge of a box lost a quarter of its speed and was thrown upward).
//!
//! So before the solver runs, each speculative manifold whose gap the bodies could close
//! this step is checked against their actual motion: the shapes are swept over the step
//! (present velocity, gravity's kick, present spin) by conservative advancement, and if
//! they never come within a small tolerance the manifold sits this step out. Manifolds
//! already touching, or whose gap cannot close, cost one dot product.

use crate::collision::contact::Contact;
use crate::collision::geometry::Pose;
use crate::collision::narrow_phase::within;
use crate::collision::query::{sweep_shapes, Stop, Sweep};
use crate::collision::shape::Convex;
use crate::collision::shape::Shape;
use crate::dynamics::body::{Body, BodyKind};
use crate::math::{Real, Vec3};
use crate::threads::Par;

/// Contacts a piece of [`find_ghosts`] looks at on the step's team. Most contacts cost a
/// few dot products, the ones swept some µs; a thousand of the rain's is about 0.1–0.5 ms.
const CONTACTS_A_PIECE: usize = 512;

/// Marks in `ghost` the contacts whose speculative points the bodies will not reach within
/// `horizon` (true = leave out of the solver). The horizon is the step plus one substep:
/// the last relax pass runs after the last drift and already limits the closing speed
/// for the substep after it. Each contact's answer is its own, so pieces of the list go to
/// the step's team (1 ms of the rain's 13 ms step on one thread).
pub(crate) fn find_ghosts(
    bodies: &[Body],
    contacts: &[Contact],
    (gravity, horizon, slop): (Vec3, Real, Real),
    ghost: &mut Vec<bool>,
    par: Par,
) {
    ghost.clear();
    ghost.resize(contacts.len(), false);
    let size = contacts
        .len()
        .div_ceil(par.pieces(contacts.len(), CONTACTS_A_PIECE));
    crate::team::chunks(par.threads, ghost, size, &|start, part| {
        for (k, g) in part.iter_mut().enumerate() {
            *g = is_ghost(bodies, &contacts[start + k], gravity, horizon, slop);
        }
    });
}

fn is_ghost(bodies: &[Body], c: &Contact, gravity: Vec3, dt: Real, slop: Real) -> bool {
    let gap = c
        .manifold
        .points()
        .iter()
        .map(|p| p.separation)
        .fold(Real::INFINITY, Real::min);
    if gap.is_nan() || gap <= 0.0 {
        // Touching already (or no points): the solver must see it.
        return false;
    }
    let (a, b) = (&bodies[c.index_a as usize], &bodies[c.index_b as usize]);
    if matches!(a.shape, Shape::Plane { .. }) || matches!(b.shape, Shape::Plane { .. }) {
        // A plane's normal is the same everywhere: no edge to skim past.
        return false;
    }
    let (kick_a, kick_b) = (kick(a, gravity, dt), kick(b, gravity, dt));
    let n = c.manifold.normal;
    let spin = |body: &Body| body.angular_velocity.length() * reach(body);
    let approach = (a.velocity - b.velocity)
        .dot(n)
        .max((a.velocity + kick_a - b.velocity - kick_b).dot(n))
        + spin(a)
        + spin(b);
    if gap >= approach * dt {
        return false;
    }
    // Straight sweeps stand in for the parabolas gravity makes; they part by at most
    // |Δa| dt²/8 mid-step, which the tolerance absorbs.
    let bend = 0.125 * (kick_a - kick_b).length() * dt;
    let target = bend + 0.1 * slop;
    let (sa, sb) = (sweep(a, kick_a, dt), sweep(b, kick_b, dt));
    if meet_by_the_end(&a.shape, &sa, &b.shape, &sb, 0.5 * target) {
        return false;
    }
    // The sweep routine takes meshes, height fields and compounds' partners on its B side.
    let hit = if matches!(a.shape, Shape::TriMesh(_) | Shape::HeightField(_)) {
        sweep_shapes(&b.shape, &sb, &a.shape, &sa, Stop::At(target), 1.0)
    } else {
        sweep_shapes(&a.shape, &sa, &b.shape, &sb, Stop::At(target), 1.0)
    };
    hit.is_none()
}

/// Whether two convex shapes end their sweeps within `near` (< the sweep's target) of
/// each other: then they come within the target during the step, and the sweep would say
/// so, since conservative advancement never steps past the first moment they do (its t
/// stays below it, and it cannot stop for want of approach: the gap along any fixed normal
/// still has to close). This answers in one distance query what the sweep takes from a
/// handful to its 50-step cap to find: spin enters its bound as |ω|·reach whichever way the
/// body turns, so for tumbling bodies each step covers a fraction of the gap (14 steps on
/// average as the rain lands, most of them for pairs that do meet). The margin between
/// `near` and the target keeps the answer the sweep's to far beyond rounding.
fn meet_by_the_end(a: &Shape, sa: &Sweep, b: &Shape, sb: &Sweep, near: Real) -> bool {
    match (Convex::from_shape(a), Convex::from_shape(b)) {
        (Some(ca), Some(cb)) => within(&ca, &sa.at(1.0), &cb, &sb.at(1.0), near),
        _ => false,
    }
}

/// The velocity gravity (times the body's `gravity_scale`) adds to a body over the step.
fn kick(body: &Body, gravity: Vec3, dt: Real) -> Vec3 {
    if body.kind == BodyKind::Dynamic && body.awake {
        let g = if body.planar {
            Vec3::new(gravity.x, gravity.y, 0.0)
        } else {
            gravity
        };
        g * (body.gravity_scale * dt)
    } else {
        Vec3::ZERO
    }
}

/// How far any point of the body lies from its centre of mass, at most.
fn reach(body: &Body) -> Real {
    body.shape.bounding_radius() + body.local_center.length()
}

/// The body's motion over the step, velocity and spin held, plus half gravity's kick.
fn sweep(body: &Body, kick: Vec3, dt: Real) -> Sweep {
    let moving = body.kind != BodyKind::Static && body.awake;
    let (v, w) = if moving {
        (body.velocity + 0.5 * kick, body.angular_velocity)
    } else {
        (Vec3::ZERO, Vec3::ZERO)
    };
    Sweep {
        start: Pose::new(
            body.com - body.orientation * body.local_center,
            body.orientation,
        ),
        translation: v * dt,
        rotation: w * dt,
        local_center: body.local_center,
    }
}

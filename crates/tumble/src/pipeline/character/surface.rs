//! What the character's capsule meets: the surfaces near it (each a [`Touch`]: a normal,
//! a separation, a point, whose plane the solver keeps the character outside), and the
//! first surface a straight move would bring it within its skin of ([`sweep`]).
//!
//! Every body the filter lets through is taken apart into the convex pieces the narrow
//! phase already measures: a convex shape is one piece, a compound its children, a
//! triangle mesh or height field the triangles near the capsule, and a plane its
//! half-space (in closed form). The distance between the capsule and a piece is GJK's
//! (`narrow_phase::closest_points`), signed: negative is a depth, with the normal of least
//! penetration.

use crate::collision::geometry::{Aabb, Pose};
use crate::collision::narrow_phase::closest_points;
use crate::collision::shape::{Convex, Shape};
use crate::dynamics::body::BodyKind;
use crate::id::BodyId;
use crate::math::{Quat, Real, Vec3};
use crate::pipeline::hooks::ONE_WAY_COS;
use crate::pipeline::world::query::QueryFilter;
use crate::pipeline::world::World;

/// Conservative advancement steps of a sweep against one piece before it settles for the
/// (still conservative) fraction reached.
const MAX_ADVANCES: usize = 32;

/// The capsule and the settings the queries need, fixed for a controller's life.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Capsule {
    /// Radius (m).
    pub radius: Real,
    /// Half the length of the segment between the two sphere centres (m).
    pub half_height: Real,
    /// Unit up: the capsule's axis.
    pub up: Vec3,
    /// The rotation taking the shape's y axis to `up`.
    pub rotation: Quat,
    /// The gap kept to every surface (m).
    pub skin: Real,
    /// Which bodies block it.
    pub filter: QueryFilter,
}

/// A surface near the capsule: the plane through `point` with unit `normal` (pointing
/// from the surface to the capsule), `separation` (m) between them along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Touch {
    /// The body the surface belongs to.
    pub body: BodyId,
    /// Unit normal from the surface towards the capsule.
    pub normal: Vec3,
    /// Distance from the capsule to the surface (m); negative: a depth.
    pub separation: Real,
    /// The surface point nearest the capsule (m, world).
    pub point: Vec3,
    /// Whether the body is dynamic (so it can be pushed), and its mass (kg).
    pub dynamic: Option<Real>,
}

/// The first surface a sweep stops at: the fraction `t` of the move, and the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Hit {
    pub t: Real,
    pub touch: Touch,
}

/// One convex piece of a body, or a plane's half-space n·(x − origin) <= offset.
enum Piece<'a> {
    Solid(Convex<'a>, Pose),
    HalfSpace {
        normal: Vec3,
        origin: Vec3,
        offset: Real,
    },
}

/// The distance from the capsule to a piece: signed, the unit normal from the capsule to
/// the piece, and the piece's nearest point.
struct Gap {
    distance: Real,
    normal: Vec3,
    point: Vec3,
}

impl Capsule {
    /// The shape as the narrow phase sees it.
    pub fn convex(&self) -> Convex<'static> {
        Convex::Capsule {
            radius: self.radius,
            half_height: self.half_height,
        }
    }

    /// The shape for `Shape`-taking calls (a proxy body, validation).
    pub fn shape(&self) -> Shape {
        Shape::capsule(self.radius, self.half_height)
    }

    /// The capsule's pose with its centre at `center`.
    pub fn pose(&self, center: Vec3) -> Pose {
        Pose::new(center, self.rotation)
    }

    /// Its bounding box at `center`: the segment's ends, each grown by the radius.
    pub fn aabb(&self, center: Vec3) -> Aabb {
        let reach = (self.up * self.half_height).abs() + Vec3::splat(self.radius);
        Aabb::from_center(center, reach)
    }

    fn gap(&self, center: Vec3, piece: &Piece<'_>) -> Gap {
        match piece {
            Piece::Solid(convex, at) => {
                let c = closest_points(&self.convex(), &self.pose(center), convex, at);
                Gap {
                    distance: c.distance,
                    normal: c.normal,
                    point: c.point_b,
                }
            }
            Piece::HalfSpace {
                normal,
                origin,
                offset,
            } => {
                // The capsule's deepest point along −n: the lower sphere's, past its centre
                // by the radius.
                let pose = self.pose(center);
                let local = self
                    .convex()
                    .support(pose.inverse_transform_vector(-*normal));
                let deepest = pose.transform_point(local);
                let distance = normal.dot(deepest - *origin) - offset;
                Gap {
                    distance,
                    normal: -*normal,
                    point: deepest - *normal * distance,
                }
            }
        }
    }
}

/// Calls `f` with every piece of `shape` at `pose` that may meet the world box `region`.
fn for_each_piece(shape: &Shape, pose: &Pose, region: &Aabb, f: &mut dyn FnMut(&Piece<'_>)) {
    let local = || region.mapped(|c| pose.inverse_transform_point(c));
    match shape {
        Shape::Compound(children) => {
            for c in children {
                let child = pose.mul(&Pose::new(c.position, c.orientation));
                for_each_piece(&c.shape, &child, region, f);
            }
        }
        Shape::Plane { normal, offset } => f(&Piece::HalfSpace {
            normal: pose.transform_vector(*normal),
            origin: pose.position,
            offset: *offset,
        }),
        Shape::TriMesh(mesh) => mesh.for_each_triangle_in(&local(), |i| {
            f(&Piece::Solid(Convex::Triangle(mesh.triangle(i)), *pose));
        }),
        Shape::HeightField(field) => field.for_each_triangle_in(&local(), |_, tri| {
            f(&Piece::Solid(Convex::Triangle(tri), *pose));
        }),
        _ => {
            if let Some(convex) = Convex::from_shape(shape) {
                f(&Piece::Solid(convex, *pose));
            }
        }
    }
}

/// The body a piece belongs to, as the character's queries see it.
#[derive(Clone, Copy)]
struct Owner {
    id: BodyId,
    /// Its mass if it is dynamic (so it can be pushed).
    dynamic: Option<Real>,
    /// A one-way body's normal in the world frame (see [`Owner::blocks`]).
    one_way: Option<Vec3>,
}

impl Owner {
    /// Whether a surface of this body with unit `normal` (towards the capsule) and
    /// `separation` blocks the capsule. Every surface does but a one-way body's, which
    /// blocks only from its own side as the contact hooks decide for bodies
    /// (`pipeline/hooks.rs`): a normal within 60° of the body's, and the capsule not sunk
    /// more than a skin into it. A character jumping up through a platform is thus neither
    /// stopped by its underside nor pushed out sideways while inside it, and lands on it
    /// once above.
    fn blocks(&self, normal: Vec3, separation: Real, skin: Real) -> bool {
        self.one_way
            .is_none_or(|n| normal.dot(n) >= ONE_WAY_COS && separation >= -skin)
    }
}

/// Calls `f(owner, piece)` for every piece of every body the capsule's filter lets
/// through whose bounding box meets `region`, in body order. Sensors are passed over:
/// they detect bodies but stop none, and a character walks through a trigger volume.
fn for_each_body_piece(
    world: &World,
    capsule: &Capsule,
    region: &Aabb,
    f: &mut dyn FnMut(Owner, &Piece<'_>),
) {
    for id in world.query_aabb(region, &capsule.filter) {
        let Ok(body) = world.body(id) else { continue };
        if body.is_sensor() {
            continue;
        }
        let pose = body.pose();
        let owner = Owner {
            id,
            dynamic: (body.kind() == BodyKind::Dynamic).then(|| body.mass()),
            one_way: body.one_way().map(|n| pose.transform_vector(n)),
        };
        for_each_piece(body.shape(), &pose, region, &mut |piece| f(owner, piece));
    }
}

/// The surfaces within `margin` of the capsule at `center`, nearest first (ties in body
/// order, then the order of the pieces: the same world gives the same list).
pub(super) fn touches(world: &World, capsule: &Capsule, center: Vec3, margin: Real) -> Vec<Touch> {
    let region = capsule.aabb(center).expanded(margin);
    let mut found = Vec::new();
    for_each_body_piece(world, capsule, &region, &mut |owner, piece| {
        let gap = capsule.gap(center, piece);
        let blocks = || owner.blocks(-gap.normal, gap.distance, capsule.skin);
        if gap.distance < margin && gap.normal.is_finite() && blocks() {
            found.push(Touch {
                body: owner.id,
                normal: -gap.normal,
                separation: gap.distance,
                point: gap.point,
                dynamic: owner.dynamic,
            });
        }
    });
    // A stable sort keeps the discovery order among equal separations.
    found.sort_by(|a, b| a.separation.total_cmp(&b.separation));
    found
}

/// The first surface the capsule at `from`, moved straight by `delta`, stops at, and
/// the fraction of `delta` it gets (see [`advance`] for where it stops); `None` if the
/// whole move is free.
pub(super) fn sweep(world: &World, capsule: &Capsule, from: Vec3, delta: Vec3) -> Option<Hit> {
    let region = capsule
        .aabb(from)
        .union(&capsule.aabb(from + delta))
        .expanded(2.0 * capsule.skin);
    let mut first: Option<Hit> = None;
    for_each_body_piece(world, capsule, &region, &mut |owner, piece| {
        // A one-way body stops only a move into it from its side.
        if owner.one_way.is_some_and(|n| delta.dot(n) >= 0.0) {
            return;
        }
        let Some((t, gap)) = advance(capsule, from, delta, piece) else {
            return;
        };
        if first.is_none_or(|f| t < f.t) && owner.blocks(-gap.normal, gap.distance, capsule.skin) {
            let touch = Touch {
                body: owner.id,
                normal: -gap.normal,
                separation: gap.distance,
                point: gap.point,
                dynamic: owner.dynamic,
            };
            first = Some(Hit { t, touch });
        }
    });
    first
}

/// Conservative advancement of the capsule along `delta` against one piece (the argument
/// of `collision/query/toi.rs`, with no rotation: the gap along the fixed normal n closes
/// at exactly delta·n per unit t, and the true distance never falls below it, so stepping
/// t by (d − target)/(delta·n) never passes the first moment the distance reaches the
/// target). Where it stops depends on where the pair starts, d₀ apart:
///
/// - farther than 1.1 skins: at one skin, the gap the controller keeps;
/// - within that, and apart: at half of d₀ (the plane solver has already kept the move
///   out of this surface's plane; this only catches the curvature of an edge or a round
///   body the plane does not see, and the next pass pushes back out to the skin);
/// - overlapping: a quarter skin deeper than d₀ (the solver is pushing the capsule out
///   of it; a move that slides along it must not be stopped by it).
///
/// Each target is strictly below d₀, and a sweep counts as arrived within 5 % of a skin
/// of it, or once it has covered 90 % of the way if that is closer, so a start on a
/// boundary never stops at t = 0 for nothing. `None`: the piece is never reached within
/// the move.
fn advance(capsule: &Capsule, from: Vec3, delta: Vec3, piece: &Piece<'_>) -> Option<(Real, Gap)> {
    let skin = capsule.skin;
    let mut gap = capsule.gap(from, piece);
    let d0 = gap.distance;
    if !d0.is_finite() {
        return None;
    }
    let target = if d0 > 1.1 * skin {
        skin
    } else if d0 > 0.0 {
        0.5 * d0
    } else {
        d0 - 0.25 * skin
    };
    let arrived = target + (0.1 * (d0 - target)).min(0.05 * skin);
    let mut t: Real = 0.0;
    for _ in 0..MAX_ADVANCES {
        if gap.distance <= arrived {
            return Some((t, gap));
        }
        let closing = delta.dot(gap.normal);
        if closing.is_nan() || closing <= 0.0 {
            return None;
        }
        t += (gap.distance - target) / closing;
        if t.is_nan() || t >= 1.0 {
            return None;
        }
        gap = capsule.gap(from + delta * t, piece);
    }
    Some((t, gap))
}

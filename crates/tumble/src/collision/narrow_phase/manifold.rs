//! Contact manifolds: what the narrow phase reports and the solver consumes.

use crate::math::{Real, Vec3};

/// Identifies which features of the two shapes made a contact point (a face, edge or
/// vertex on each), so a point can be recognised in the next step and warm-started.
/// Pair routines build it with [`feature_id`]; its value has no meaning beyond equality.
pub type FeatureId = u32;

/// Packs the feature kinds and indices of both shapes into one id.
/// `kind`s: 0 vertex, 1 edge, 2 face; indices are truncated to 14 bits.
#[inline]
pub fn feature_id(kind_a: u32, index_a: u32, kind_b: u32, index_b: u32) -> FeatureId {
    ((kind_a & 3) << 30) | ((index_a & 0x3fff) << 16) | ((kind_b & 3) << 14) | (index_b & 0x3fff)
}

/// The same id seen with the shapes swapped.
#[inline]
pub fn swap_feature(id: FeatureId) -> FeatureId {
    id.rotate_left(16)
}

/// One point of contact.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactPoint {
    /// The contact point on the surface of shape A, world frame (m).
    pub point_a: Vec3,
    /// The contact point on the surface of shape B, world frame (m).
    pub point_b: Vec3,
    /// (point_b − point_a) · normal: negative when penetrating (m).
    pub separation: Real,
    /// Which features touch.
    pub feature: FeatureId,
    /// The solver's accumulated normal impulse of the last substep (N·s), kept to warm
    /// start the next step.
    pub normal_impulse: Real,
    /// The same for friction along the contact's two tangents (N·s).
    pub tangent_impulse: [Real; 2],
    /// Normal impulse applied over the whole last step (N·s): the mean contact force
    /// times dt.
    pub total_normal_impulse: Real,
    /// Friction impulse applied over the whole last step, world frame (N·s).
    pub total_tangent_impulse: Vec3,
    /// Where the contact first held, as a point of each body's frame (friction anchors):
    /// while the contact sticks, the solver pulls these two back together, so a resting
    /// body does not creep.
    pub anchor_a: Vec3,
    /// The anchor in body B's frame.
    pub anchor_b: Vec3,
    /// Whether the anchors hold (false for a new point, or one that slid last step).
    pub anchored: bool,
    /// Whether friction reached its cone at this point last step, or (for pairs that can
    /// roll: a sphere or capsule on either side, or rolling resistance or torsional
    /// friction) its anchors had rolled away: either way it is re-anchored where it now
    /// touches.
    pub sliding: bool,
}

/// Most points a manifold holds: four span any flat contact patch stably.
pub const MAX_MANIFOLD_POINTS: usize = 4;

/// Whether a pair's depth is its own to recover from (see `dynamics::solver::overlap`):
/// only a pair found deeper than its motion explains, when its contact was new, was
/// created overlapping; it recovers until no point of it is deep any more.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Overlap {
    /// The contact's first step: not yet looked at.
    #[default]
    New,
    /// Found overlapping and not yet pushed out.
    Recovering,
    /// Met by motion, or pushed out: the solver alone resolves its depth.
    Clear,
}

/// The contact between two (sub-)shapes: one normal and up to four points.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Manifold {
    /// Unit normal, world frame, pointing from shape A to shape B.
    pub normal: Vec3,
    /// Compound child or triangle index on A (0 for simple shapes).
    pub subshape_a: u32,
    /// Compound child or triangle index on B.
    pub subshape_b: u32,
    /// The solver's accumulated angular impulse of the last substep on B (−it on A), world
    /// frame (N·m·s): rolling resistance about the tangents, torsional friction about the
    /// normal. Zero unless a body of the pair has either; kept to warm start the next step.
    pub angular_impulse: Vec3,
    /// Whether the pair was found interpenetrating, kept from step to step.
    pub(crate) overlap: Overlap,
    /// How many times finer than the world's substeps the solver last ran this contact
    /// (a tall stack's, see `dynamics::solver::stacks`; 0 or 1: the world's own). Its
    /// warm-start impulses are per such substep, and its depth was sunk at that stiffness.
    pub(crate) fine: u8,
    points: [ContactPoint; MAX_MANIFOLD_POINTS],
    count: u8,
}

impl ContactPoint {
    /// `ContactPoint::default()`, usable in constants.
    const ZERO: ContactPoint = ContactPoint {
        point_a: Vec3::ZERO,
        point_b: Vec3::ZERO,
        separation: 0.0,
        feature: 0,
        normal_impulse: 0.0,
        tangent_impulse: [0.0; 2],
        total_normal_impulse: 0.0,
        total_tangent_impulse: Vec3::ZERO,
        anchor_a: Vec3::ZERO,
        anchor_b: Vec3::ZERO,
        anchored: false,
        sliding: false,
    };
}

impl Manifold {
    /// `Manifold::default()` as a constant, for `Contact::BLANK`: a contact filled in its
    /// place in a list starts from it.
    pub(crate) const EMPTY: Manifold = Manifold {
        normal: Vec3::ZERO,
        subshape_a: 0,
        subshape_b: 0,
        angular_impulse: Vec3::ZERO,
        overlap: Overlap::New,
        fine: 0,
        points: [ContactPoint::ZERO; MAX_MANIFOLD_POINTS],
        count: 0,
    };

    /// An empty manifold with this normal.
    pub fn new(normal: Vec3) -> Manifold {
        Manifold {
            normal,
            ..Default::default()
        }
    }

    /// The points.
    pub fn points(&self) -> &[ContactPoint] {
        &self.points[..self.count as usize]
    }

    /// The points, mutably.
    pub fn points_mut(&mut self) -> &mut [ContactPoint] {
        &mut self.points[..self.count as usize]
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.count as usize
    }

    /// True with no points.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Adds a point from the two surface points; the separation is derived along the
    /// normal. Ignored once the manifold is full (routines reduce before pushing).
    pub fn push(&mut self, point_a: Vec3, point_b: Vec3, feature: FeatureId) {
        if (self.count as usize) < MAX_MANIFOLD_POINTS {
            self.points[self.count as usize] = ContactPoint {
                point_a,
                point_b,
                separation: (point_b - point_a).dot(self.normal),
                feature,
                ..Default::default()
            };
            self.count += 1;
        }
    }

    /// Removes every point.
    pub fn clear(&mut self) {
        self.count = 0;
    }

    /// Keeps only the points for which `keep` is true.
    pub fn retain(&mut self, mut keep: impl FnMut(&ContactPoint) -> bool) {
        let mut n = 0;
        for i in 0..self.count as usize {
            if keep(&self.points[i]) {
                self.points[n] = self.points[i];
                n += 1;
            }
        }
        self.count = n as u8;
    }

    /// The manifold seen from the other shape: normal flipped, points and features
    /// swapped.
    pub fn swapped(&self) -> Manifold {
        let mut m = *self;
        m.swap();
        m
    }

    /// [`Manifold::swapped`] in place (the narrow phase's flipped pairs: a copy of the
    /// whole manifold each was 0.35 % of the rain's step).
    pub fn swap(&mut self) {
        self.normal = -self.normal;
        self.angular_impulse = -self.angular_impulse;
        std::mem::swap(&mut self.subshape_a, &mut self.subshape_b);
        for p in self.points_mut() {
            std::mem::swap(&mut p.point_a, &mut p.point_b);
            p.feature = swap_feature(p.feature);
        }
    }

    /// Deepest (most negative) separation, or +∞ when empty.
    pub fn min_separation(&self) -> Real {
        self.points()
            .iter()
            .map(|p| p.separation)
            .fold(Real::INFINITY, Real::min)
    }
}

/// A candidate contact before reduction: both surface points and the feature id.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// On shape A, world frame.
    pub point_a: Vec3,
    /// On shape B, world frame.
    pub point_b: Vec3,
    /// Feature id.
    pub feature: FeatureId,
}

/// Fills `out` (whose normal is set) with at most four of `candidates` that keep the
/// contact patch as large as possible: the deepest point (it carries the most load), the
/// point farthest from it, the one that makes the largest triangle with those two, and the
/// one adding the most area beyond that triangle. Candidates separated by more than
/// `margin` are dropped first. Selection ties go to the lower index, so the result is
/// deterministic.
///
/// Distances are measured in the contact plane: a point's row along the normal depends
/// on where it lies across the normal only (moving r along n leaves r × n unchanged), so
/// two points one above the other are the same row, and the deeper one is the one that
/// binds. Measured in space, a 1.8 cm thick plate on the ground had its four top corners
/// within the speculative margin; the farthest point from the deepest bottom corner was
/// the top corner diagonally across, which took a bottom corner's place, and the plate,
/// held on three corners, rocked onto the missing one, sank 16 mm into the floor and spun
/// at 10 rad/s when pushed at 0.5 m/s (any box under about 2.4 cm thick, any width).
pub fn reduce(candidates: &[Candidate], margin: Real, out: &mut Manifold) {
    let n = out.normal;
    let sep = |c: &Candidate| (c.point_b - c.point_a).dot(n);
    let across = |d: Vec3| d - n * d.dot(n);
    // Clipping two nearly aligned faces of equal size cuts every corner into two points a
    // hair apart; which twin the selection below keeps would flip from step to step and
    // take the warm start with it. Twins closer than a quarter of the margin are one point.
    let twin = 0.25 * margin;
    let Some(first) = candidates.first() else {
        return;
    };
    // On the stack for the usual handful of candidates: a heap list per pair and step
    // showed in profiles.
    let mut stack = [first; 16];
    let mut heap = Vec::new();
    let store: &mut [&Candidate] = if candidates.len() <= stack.len() {
        &mut stack
    } else {
        heap.resize(candidates.len(), first);
        &mut heap
    };
    let mut len = 0;
    for c in candidates.iter().filter(|c| sep(c) <= margin) {
        match store[..len]
            .iter_mut()
            .find(|k| across(k.point_a - c.point_a).length_squared() < twin * twin)
        {
            Some(k) if sep(c) < sep(k) => *k = c,
            Some(_) => {}
            None => {
                store[len] = c;
                len += 1;
            }
        }
    }
    let kept = &store[..len];
    if kept.len() <= MAX_MANIFOLD_POINTS {
        for c in kept {
            out.push(c.point_a, c.point_b, c.feature);
        }
        return;
    }
    let argmax = |score: &dyn Fn(&Candidate) -> Real| {
        let mut best = 0;
        for (i, c) in kept.iter().enumerate() {
            if score(c) > score(kept[best]) {
                best = i;
            }
        }
        best
    };
    let i0 = argmax(&|c| -sep(c));
    let p0 = kept[i0].point_a;
    let i1 = argmax(&|c| across(c.point_a - p0).length_squared());
    let p1 = kept[i1].point_a;
    let area = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).dot(n);
    let i2 = argmax(&|c| area(p0, p1, c.point_a).abs());
    let p2 = kept[i2].point_a;
    // The fourth point lies on the other side of whichever triangle edge it extends most.
    let sign = area(p0, p1, p2).signum();
    let i3 = argmax(&|c| {
        let q = c.point_a;
        -(sign * area(p0, p1, q))
            .min(sign * area(p1, p2, q))
            .min(sign * area(p2, p0, q))
    });
    for i in [i0, i1, i2, i3] {
        if !out
            .points()
            .iter()
            .any(|p| p.feature == kept[i].feature && p.point_a == kept[i].point_a)
        {
            out.push(kept[i].point_a, kept[i].point_b, kept[i].feature);
        }
    }
}

impl Manifold {
    /// Whether a manifold read from a snapshot holds at most [`MAX_MANIFOLD_POINTS`]
    /// points: `points()` slices the array by the count.
    pub(crate) fn count_fits(&self) -> bool {
        self.count as usize <= MAX_MANIFOLD_POINTS
    }
}

crate::codec::codec_struct!(ContactPoint {
    point_a,
    point_b,
    separation,
    feature,
    normal_impulse,
    tangent_impulse,
    total_normal_impulse,
    total_tangent_impulse,
    anchor_a,
    anchor_b,
    anchored,
    sliding
});
crate::codec::codec_unit_enum!(Overlap {
    New,
    Recovering,
    Clear
});
crate::codec::codec_struct!(Manifold {
    normal,
    subshape_a,
    subshape_b,
    angular_impulse,
    overlap,
    fine,
    points,
    count
});

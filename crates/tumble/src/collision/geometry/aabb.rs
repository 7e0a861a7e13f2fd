//! Axis-aligned bounding boxes.

use crate::math::{Real, Vec3};

/// An axis-aligned box, world or local frame as the context says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner (m).
    pub min: Vec3,
    /// Upper corner (m).
    pub max: Vec3,
}

impl Aabb {
    /// The box with these corners.
    pub fn new(min: Vec3, max: Vec3) -> Aabb {
        Aabb { min, max }
    }

    /// The box around a centre with half extents.
    pub fn from_center(center: Vec3, half_extents: Vec3) -> Aabb {
        Aabb {
            min: center - half_extents,
            max: center + half_extents,
        }
    }

    /// The smallest box holding every point; `None` for no points.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Option<Aabb> {
        let mut it = points.into_iter();
        let first = it.next()?;
        Some(it.fold(Aabb::new(first, first), |b, p| {
            Aabb::new(b.min.min(p), b.max.max(p))
        }))
    }

    /// The box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Grown by `margin` on every side.
    pub fn expanded(&self, margin: Real) -> Aabb {
        Aabb {
            min: self.min - Vec3::splat(margin),
            max: self.max + Vec3::splat(margin),
        }
    }

    /// Whether the boxes share any point (touching counts).
    #[inline]
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.x <= other.max.x
            && self.max.x >= other.min.x
            && self.min.y <= other.max.y
            && self.max.y >= other.min.y
            && self.min.z <= other.max.z
            && self.max.z >= other.min.z
    }

    /// Whether the boxes stand more than `gap` apart along some axis. NaN compares false:
    /// such a pair is not apart.
    #[inline]
    pub fn apart(&self, other: &Aabb, gap: Real) -> bool {
        self.min.x - other.max.x > gap
            || other.min.x - self.max.x > gap
            || self.min.y - other.max.y > gap
            || other.min.y - self.max.y > gap
            || self.min.z - other.max.z > gap
            || other.min.z - self.max.z > gap
    }

    /// Whether the bodies these boxes bound may be sunk into each other, not just touching:
    /// the boxes overlap on every axis by more than `depth`, or than a quarter of either
    /// box's thinnest side where that is less. How deep two convex bodies interpenetrate is at most
    /// their boxes' least overlap (moving one that far along that axis parts the boxes),
    /// so a pair this says no to is shallow for sure; resting contacts overlap by the
    /// slop, a few millimetres. Bodies created inside each other overlap by their size.
    /// NaN says no.
    pub fn sunk_into(&self, other: &Aabb, depth: Real) -> bool {
        let overlap = self.max.min(other.max) - self.min.max(other.min);
        let thinnest = (self.max - self.min)
            .min_element()
            .min((other.max - other.min).min_element());
        overlap.min_element() > depth.min(0.25 * thinnest)
    }

    /// Whether `other` lies entirely inside.
    pub fn contains(&self, other: &Aabb) -> bool {
        self.min.cmple(other.min).all() && self.max.cmpge(other.max).all()
    }

    /// Whether the point lies inside or on the boundary.
    pub fn contains_point(&self, p: Vec3) -> bool {
        self.min.cmple(p).all() && self.max.cmpge(p).all()
    }

    /// The eight corners.
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The box around this box's corners after `map` (a rigid transform of them, say).
    pub fn mapped(&self, map: impl Fn(Vec3) -> Vec3) -> Aabb {
        let c = self.corners().map(map);
        c[1..].iter().fold(Aabb::new(c[0], c[0]), |b, p| {
            Aabb::new(b.min.min(*p), b.max.max(*p))
        })
    }

    /// Centre.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the side lengths.
    pub fn half_extents(&self) -> Vec3 {
        (self.max - self.min) * 0.5
    }

    /// Surface area, the cost measure of tree building.
    pub fn surface_area(&self) -> Real {
        let d = self.max - self.min;
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Entry and exit parameters of the ray `origin + t·dir` through the box (slab test),
    /// clipped to [0, max_t]; `None` if it misses.
    pub fn ray_interval(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<(Real, Real)> {
        let mut t0: Real = 0.0;
        let mut t1 = max_t;
        for axis in 0..3 {
            let (o, d, lo, hi) = (origin[axis], dir[axis], self.min[axis], self.max[axis]);
            if d == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d;
            let (mut a, mut b) = ((lo - o) * inv, (hi - o) * inv);
            if a > b {
                std::mem::swap(&mut a, &mut b);
            }
            t0 = t0.max(a);
            t1 = t1.min(b);
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }
}

crate::codec::codec_struct!(Aabb { min, max });

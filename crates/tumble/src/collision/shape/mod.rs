//! Collision and mass shapes. Each shape is defined in its body's local frame; capsules and
//! cylinders run along the local y axis.

mod bounds;
mod convex;
mod heightfield;
mod hull;
mod mass;
mod trimesh;

pub use bounds::{convex_aabb, PLANE_EXTENT};
pub use convex::Convex;
pub use heightfield::HeightField;
pub use hull::ConvexHull;
pub use mass::MassProperties;
pub use trimesh::{EdgeKind, TriMesh, FLAT_EDGE_ANGLE};

use crate::error::{check, Error, Result};
use crate::math::{Quat, Real, Vec3};

/// A child of a [`Shape::Compound`], placed in the compound's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CompoundChild {
    /// The child's shape.
    pub shape: Shape,
    /// Offset of the child's frame in the parent frame (m).
    pub position: Vec3,
    /// Rotation of the child's frame in the parent frame, [x, y, z, w].
    pub orientation: Quat,
}

/// A body's shape.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A ball centred on the origin.
    Sphere {
        /// Radius (m).
        radius: Real,
    },
    /// A box centred on the origin.
    Box {
        /// Half the side lengths along x, y, z (m).
        half_extents: Vec3,
    },
    /// A cylinder with hemispherical caps, along the local y axis.
    Capsule {
        /// Radius of the caps and the shaft (m).
        radius: Real,
        /// Half the length of the shaft, caps excluded (m).
        half_height: Real,
    },
    /// A solid circular cylinder along the local y axis.
    Cylinder {
        /// Radius (m).
        radius: Real,
        /// Half the length (m).
        half_height: Real,
    },
    /// The convex hull of a point cloud.
    ConvexHull(ConvexHull),
    /// Several shapes rigidly joined.
    Compound(Vec<CompoundChild>),
    /// The half-space n·x ≤ offset (body frame): an infinite floor or wall. Static only.
    Plane {
        /// Outward unit normal (normalised on validation).
        normal: Vec3,
        /// Distance of the surface from the origin along the normal (m).
        offset: Real,
    },
    /// A triangle mesh. Static only.
    TriMesh(TriMesh),
    /// A height-field terrain. Static only.
    HeightField(HeightField),
}

/// How far from square to its axis a contact normal may be for a cylinder's side to count
/// as round ([`Shape::round_toward`]): the sine of 5°. A lying cylinder's normal is square
/// to its axis to rounding; past this it stands on a rim, whose lowest point is off the
/// normal through its axis, and the round model's lift (ρ along the normal) would be off
/// by ρ sin² of the tilt.
pub const SIDE_SIN: Real = 0.087;

impl Shape {
    /// A sphere of `radius` (m).
    pub fn sphere(radius: Real) -> Shape {
        Shape::Sphere { radius }
    }

    /// A box of the given half extents (m).
    pub fn cuboid(half_extents: Vec3) -> Shape {
        Shape::Box { half_extents }
    }

    /// A capsule along y.
    pub fn capsule(radius: Real, half_height: Real) -> Shape {
        Shape::Capsule {
            radius,
            half_height,
        }
    }

    /// A cylinder along y.
    pub fn cylinder(radius: Real, half_height: Real) -> Shape {
        Shape::Cylinder {
            radius,
            half_height,
        }
    }

    /// The convex hull of `points`; fails on fewer than 4 non-coplanar points.
    pub fn convex_hull(points: &[Vec3]) -> Result<Shape> {
        Ok(Shape::ConvexHull(ConvexHull::from_points(points)?))
    }

    /// Short lowercase name of the kind, as in scene files.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "sphere",
            Shape::Box { .. } => "box",
            Shape::Capsule { .. } => "capsule",
            Shape::Cylinder { .. } => "cylinder",
            Shape::ConvexHull(_) => "convex_hull",
            Shape::Compound(_) => "compound",
            Shape::Plane { .. } => "plane",
            Shape::TriMesh(_) => "trimesh",
            Shape::HeightField(_) => "heightfield",
        }
    }

    /// A plane with outward normal `normal` at `offset` along it.
    pub fn plane(normal: Vec3, offset: Real) -> Shape {
        Shape::Plane { normal, offset }
    }

    /// True for shapes without a finite volume or mass (plane, mesh, height field), which
    /// only static bodies may have.
    pub fn is_static_only(&self) -> bool {
        matches!(
            self,
            Shape::Plane { .. } | Shape::TriMesh(_) | Shape::HeightField(_)
        )
    }

    /// The radius by which sub-shape `sub` (a compound's child index, as manifolds name
    /// it; ignored otherwise) is round about its core: a sphere's or a capsule's radius.
    /// A contact point on such a surface is its core's nearest point moved by this radius
    /// along the contact normal, so as the body turns it stays where the normal says
    /// rather than turning with the body. Zero for every other shape (box, hull and
    /// cylinder contacts sit at body-fixed corners and edges; planes, meshes and height
    /// fields are static) and for a compound child that is itself a compound (manifolds
    /// name only the outer child).
    pub fn round_radius(&self, sub: u32) -> Real {
        match self {
            Shape::Sphere { radius } | Shape::Capsule { radius, .. } => *radius,
            Shape::Compound(children) => match children.get(sub as usize).map(|c| &c.shape) {
                Some(Shape::Sphere { radius } | Shape::Capsule { radius, .. }) => *radius,
                _ => 0.0,
            },
            _ => 0.0,
        }
    }

    /// [`Shape::round_radius`] for a contact of normal `normal` (world) on a body turned by
    /// `rotation`: a cylinder (or a compound's cylinder child) touching on its side, the
    /// normal within [`SIDE_SIN`] of square to its axis, is round about its axis there,
    /// as a capsule is, and rolls on it. Measured before: a cylinder rolling at 0.5 m/s
    /// reported 0.08 m/s into the floor and ran 0.4 mm low (dt 1/60 s), as balls did
    /// before they were round (`rows::Moved::normal`). On its caps or rims it is not.
    pub fn round_toward(&self, sub: u32, rotation: Quat, normal: Vec3) -> Real {
        let side = |radius: Real, turn: Quat| {
            let axis = rotation * (turn * Vec3::Y);
            if axis.dot(normal).abs() < SIDE_SIN {
                radius
            } else {
                0.0
            }
        };
        match self {
            Shape::Cylinder { radius, .. } => side(*radius, Quat::IDENTITY),
            Shape::Compound(children) => match children.get(sub as usize) {
                Some(CompoundChild {
                    shape: Shape::Cylinder { radius, .. },
                    orientation,
                    ..
                }) => side(*radius, *orientation),
                _ => self.round_radius(sub),
            },
            _ => self.round_radius(sub),
        }
    }

    /// Checks sizes and nesting; field paths are relative to the shape itself.
    pub fn validate(&self) -> Result<()> {
        match self {
            Shape::Sphere { radius } => check::positive("radius", *radius),
            Shape::Box { half_extents } => check::positive_vec3("half_extents", *half_extents),
            Shape::Capsule {
                radius,
                half_height,
            } => {
                check::positive("radius", *radius)?;
                check::non_negative("half_height", *half_height)
            }
            Shape::Cylinder {
                radius,
                half_height,
            } => {
                check::positive("radius", *radius)?;
                check::positive("half_height", *half_height)
            }
            // Hulls, meshes and height fields are validated when built.
            Shape::ConvexHull(_) | Shape::TriMesh(_) | Shape::HeightField(_) => Ok(()),
            Shape::Plane { normal, offset } => {
                check::vec3("normal", *normal)?;
                if normal.length() < 1e-6 {
                    return Err(Error::invalid("normal", "must be a non-zero vector"));
                }
                check::finite("offset", *offset)
            }
            Shape::Compound(children) => {
                if children.is_empty() {
                    return Err(Error::invalid("children", "must not be empty"));
                }
                for (i, child) in children.iter().enumerate() {
                    let at = format!("children[{i}]");
                    if child.shape.is_static_only() {
                        return Err(Error::invalid(
                            format!("{at}.shape.type"),
                            "planes, meshes and height fields cannot be compound children",
                        ));
                    }
                    child
                        .shape
                        .validate()
                        .map_err(|e| e.within(&format!("{at}.shape")))?;
                    check::vec3("position", child.position).map_err(|e| e.within(&at))?;
                    check::rotation("orientation", child.orientation).map_err(|e| e.within(&at))?;
                }
                Ok(())
            }
        }
    }

    /// Checks a shape read from a snapshot: its numbers as [`Shape::validate`] checks
    /// them, and the indices a hull, mesh or height field holds (checked when built, but
    /// read back they are whatever the bytes say), in compounds' children too.
    pub(crate) fn check_saved(&self) -> Result<()> {
        self.validate()?;
        match self {
            Shape::ConvexHull(hull) => hull.check_saved(),
            Shape::TriMesh(mesh) => mesh.check_saved(),
            Shape::HeightField(field) => field.check_saved(),
            Shape::Compound(children) => children.iter().enumerate().try_for_each(|(i, c)| {
                let at = format!("children[{i}].shape");
                c.shape.check_saved().map_err(|e| e.within(&at))
            }),
            _ => Ok(()),
        }
    }

    /// Mass, centre of mass and inertia tensor (about the centre of mass, in the shape's
    /// frame) for a uniform `density` (kg/m³). The shape must be valid. Static-only shapes
    /// have no volume; they report a unit placeholder that nothing integrates.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        match self {
            Shape::Sphere { radius } => MassProperties::sphere(density, *radius),
            Shape::Box { half_extents } => MassProperties::cuboid(density, *half_extents),
            Shape::Capsule {
                radius,
                half_height,
            } => MassProperties::capsule(density, *radius, *half_height),
            Shape::Cylinder {
                radius,
                half_height,
            } => MassProperties::cylinder(density, *radius, *half_height),
            Shape::ConvexHull(hull) => hull.mass_properties(density),
            Shape::Plane { .. } | Shape::TriMesh(_) | Shape::HeightField(_) => {
                MassProperties::diagonal(1.0, Vec3::ONE)
            }
            Shape::Compound(children) => MassProperties::sum(children.iter().map(|c| {
                c.shape
                    .mass_properties(density)
                    .transformed(c.position, c.orientation.normalize())
            })),
        }
    }

    /// Volume (m³).
    pub fn volume(&self) -> Real {
        self.mass_properties(1.0).mass
    }

    /// The radius of the smallest sphere about the shape's origin that holds the shape;
    /// used for automatic cameras and, later, bounding volumes.
    pub fn bounding_radius(&self) -> Real {
        match self {
            Shape::Sphere { radius } => *radius,
            Shape::Box { half_extents } => half_extents.length(),
            Shape::Capsule {
                radius,
                half_height,
            } => radius + half_height,
            Shape::Cylinder {
                radius,
                half_height,
            } => (radius * radius + half_height * half_height).sqrt(),
            Shape::ConvexHull(hull) => hull
                .vertices()
                .iter()
                .map(|v| v.length())
                .fold(0.0, Real::max),
            Shape::Compound(children) => children
                .iter()
                .map(|c| c.position.length() + c.shape.bounding_radius())
                .fold(0.0, Real::max),
            Shape::Plane { .. } => Real::INFINITY,
            Shape::TriMesh(m) => m.vertices().iter().map(|v| v.length()).fold(0.0, Real::max),
            Shape::HeightField(h) => {
                let b = h.local_aabb();
                b.min.length().max(b.max.length())
            }
        }
    }
}

crate::codec::codec_struct!(CompoundChild {
    shape,
    position,
    orientation
});

impl crate::codec::Code for Shape {
    fn put(&self, w: &mut crate::codec::Writer) {
        match self {
            Shape::Sphere { radius } => (0u8, *radius).put(w),
            Shape::Box { half_extents } => (1u8, *half_extents).put(w),
            Shape::Capsule {
                radius,
                half_height,
            } => (2u8, (*radius, *half_height)).put(w),
            Shape::Cylinder {
                radius,
                half_height,
            } => (3u8, (*radius, *half_height)).put(w),
            Shape::ConvexHull(hull) => {
                4u8.put(w);
                hull.put(w);
            }
            Shape::Compound(children) => {
                5u8.put(w);
                children.put(w);
            }
            Shape::Plane { normal, offset } => (6u8, (*normal, *offset)).put(w),
            Shape::TriMesh(mesh) => {
                7u8.put(w);
                mesh.put(w);
            }
            Shape::HeightField(field) => {
                8u8.put(w);
                field.put(w);
            }
        }
    }

    fn get(r: &mut crate::codec::Reader<'_>) -> crate::codec::Decoded<Self> {
        use crate::codec::Code;
        let get_pair = |r: &mut crate::codec::Reader<'_>| <(Real, Real)>::get(r);
        Ok(match u8::get(r)? {
            0 => Shape::Sphere {
                radius: Code::get(r)?,
            },
            1 => Shape::Box {
                half_extents: Code::get(r)?,
            },
            2 => {
                let (radius, half_height) = get_pair(r)?;
                Shape::Capsule {
                    radius,
                    half_height,
                }
            }
            3 => {
                let (radius, half_height) = get_pair(r)?;
                Shape::Cylinder {
                    radius,
                    half_height,
                }
            }
            4 => Shape::ConvexHull(Code::get(r)?),
            5 => Shape::Compound(Code::get(r)?),
            6 => {
                let (normal, offset) = Code::get(r)?;
                Shape::Plane { normal, offset }
            }
            7 => Shape::TriMesh(Code::get(r)?),
            8 => Shape::HeightField(Code::get(r)?),
            t => return Err(r.bad_tag("shape", t)),
        })
    }
}

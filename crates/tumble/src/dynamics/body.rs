//! Bodies: their definition (what a user fills in) and their state (what the integrators
//! advance).
//!
//! The state is the seed's: centre-of-mass position x, orientation q, linear momentum
//! p = m v (kept as v, the same thing scaled) and angular momentum L. The angular velocity
//! is derived, ω = I_world⁻¹ L with I_world = R I_body Rᵀ, because L, not ω, is what a
//! torque-free body conserves.

use crate::collision::shape::{MassProperties, Shape};
use crate::error::{check, Error, Result};
use crate::math::{Mat3, Quat, Real, Vec3};

/// How a body moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BodyKind {
    /// Never moves; infinite mass.
    Static,
    /// Moves with the velocity it is given, unaffected by forces; infinite mass.
    Kinematic,
    /// Moves under forces.
    #[default]
    Dynamic,
}

impl BodyKind {
    /// The kind named as in scene files: `static`, `kinematic` or `dynamic`.
    pub fn from_name(name: &str) -> Option<BodyKind> {
        match name {
            "static" => Some(BodyKind::Static),
            "kinematic" => Some(BodyKind::Kinematic),
            "dynamic" => Some(BodyKind::Dynamic),
            _ => None,
        }
    }
}

/// Where a body's mass comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MassSpec {
    /// Uniform density (kg/m³) over the shape's volume.
    Density(Real),
    /// Total mass (kg), spread uniformly over the shape.
    Mass(Real),
}

impl Default for MassSpec {
    /// Water: 1000 kg/m³.
    fn default() -> Self {
        MassSpec::Density(1000.0)
    }
}

/// A user-given inertia tensor about the centre of mass, in body axes (kg·m²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InertiaSpec {
    /// Principal moments along the body's x, y, z axes.
    Principal(Vec3),
    /// A full symmetric tensor.
    Tensor(Mat3),
}

/// Everything needed to create a body; `Default` gives a resting dynamic body at the
/// origin with the density of water.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyDef {
    /// Optional unique name (scene files refer to bodies by name).
    pub name: Option<String>,
    /// Static, kinematic or dynamic.
    pub kind: BodyKind,
    /// World position of the body's frame, the frame the shape is defined in (m).
    pub position: Vec3,
    /// Orientation of the body's frame, [x, y, z, w]; normalised on creation.
    pub orientation: Quat,
    /// World velocity of the centre of mass (m/s).
    pub linear_velocity: Vec3,
    /// World angular velocity (rad/s).
    pub angular_velocity: Vec3,
    /// Density or total mass.
    pub mass: MassSpec,
    /// Overrides the inertia computed from the shape (about the centre of mass).
    pub inertia: Option<InertiaSpec>,
    /// Overrides the centre of mass computed from the shape (body frame, m).
    pub center_of_mass: Option<Vec3>,
    /// Restricts the body to the XY plane, turning only about z (the seed's 2D dynamics).
    pub planar: bool,
    /// Collision layers the body is in (bits); default layer 1.
    pub collision_group: u32,
    /// Layers it collides with (bits); two bodies collide when each one's group meets the
    /// other's mask. Default: all.
    pub collision_mask: u32,
    /// Bodies with the same non-zero owner never collide with each other, whatever their
    /// groups and masks (the links of one model: `World::unused_collision_owner` gives a
    /// number no body has); with every other body, group and mask decide. Default 0: no
    /// owner.
    pub collision_owner: u32,
    /// Coulomb friction coefficient (dimensionless); a pair uses √(μ_a μ_b). Default 0.6.
    pub friction: Real,
    /// Coefficient of restitution in [0, 1]; a pair uses the larger. Default 0.
    pub restitution: Real,
    /// Rolling resistance coefficient (dimensionless, as Box2D v3's `rollingResistance`
    /// and the engineering C_rr): a contact resists the two bodies' relative rolling with
    /// a torque of at most μ_r r N, N its normal force and r its rolling radius (the
    /// distance from a moving body's centre of mass to the contact plane, the smaller of
    /// two: a ball's radius). A pair uses max(μ_a, μ_b). A ball rolling on a plane then
    /// slows at (5/7) μ_r g. Default 0: none, at no cost.
    pub rolling_resistance: Real,
    /// Torsional (spinning) friction (m, as MuJoCo's torsional coefficient): a contact
    /// resists the two bodies' relative spin about its normal with a torque of at most
    /// μ_t N. A flat patch of radius a pressed evenly, with friction μ, has μ_t = (2/3) μ a.
    /// A pair uses max(μ_a, μ_b). Default 0: none, at no cost.
    pub torsional_friction: Real,
    /// Continuous collision against every body that is not a bullet, not only static ones,
    /// for fast projectiles (swept after the other fast bodies, along their motion).
    pub bullet: bool,
    /// Linear damping c (1/s, finite, >= 0): besides the forces, dv/dt = −c v, so a free
    /// body's velocity decays as exp(−c t). Default 0: none, at no cost.
    pub linear_damping: Real,
    /// Angular damping c (1/s, finite, >= 0): dL/dt = −c L besides the torques, which at
    /// fixed orientation is dω/dt = −c ω. Default 0.
    pub angular_damping: Real,
    /// Multiplier of the world's gravity for this body (dimensionless, finite, |s| <=
    /// `limits::MAX_GRAVITY_SCALE`; negative rises). Default 1.
    pub gravity_scale: Real,
    /// A sensor detects the bodies it overlaps and reports when each starts and stops
    /// overlapping (`World::sensor_events`), with no contact response: it neither pushes
    /// nor is pushed, and a dynamic sensor still falls. Sensors do not detect each other.
    /// Default false.
    pub sensor: bool,
    /// A one-way body (a platform) collides only with bodies that come at it from the side
    /// its normal points to (body frame; any non-zero length, normalised on creation):
    /// they land on it, while bodies from below or the sides pass through. `None`
    /// (default): an ordinary body.
    pub one_way: Option<Vec3>,
}

impl Default for BodyDef {
    fn default() -> Self {
        BodyDef {
            name: None,
            kind: BodyKind::Dynamic,
            position: Vec3::ZERO,
            orientation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            mass: MassSpec::default(),
            inertia: None,
            center_of_mass: None,
            planar: false,
            collision_group: 1,
            collision_mask: u32::MAX,
            collision_owner: 0,
            friction: 0.6,
            restitution: 0.0,
            rolling_resistance: 0.0,
            torsional_friction: 0.0,
            bullet: false,
            linear_damping: 0.0,
            angular_damping: 0.0,
            gravity_scale: 1.0,
            sensor: false,
            one_way: None,
        }
    }
}

/// A body in a world: its fixed properties and its current state.
#[derive(Debug, Clone)]
pub struct Body {
    pub(crate) name: Option<String>,
    pub(crate) kind: BodyKind,
    pub(crate) shape: Shape,
    pub(crate) planar: bool,
    pub(crate) filter: crate::collision::broad_phase::Filter,
    pub(crate) friction: Real,
    pub(crate) restitution: Real,
    pub(crate) rolling_resistance: Real,
    pub(crate) torsional_friction: Real,
    pub(crate) bullet: bool,
    /// Linear and angular damping (1/s; see [`BodyDef::linear_damping`]).
    pub(crate) linear_damping: Real,
    pub(crate) angular_damping: Real,
    /// Multiplier of the world's gravity (see [`BodyDef::gravity_scale`]).
    pub(crate) gravity_scale: Real,
    /// Whether the body is a sensor (see [`BodyDef::sensor`]).
    pub(crate) sensor: bool,
    /// A one-way body's unit normal in its own frame (see [`BodyDef::one_way`]).
    pub(crate) one_way: Option<Vec3>,
    /// A kinematic body's pose to reach at the end of the next step (centre of mass,
    /// orientation), resolved into velocities when that step begins (see
    /// `World::set_kinematic_target`).
    pub(crate) kinematic_target: Option<(Vec3, Quat)>,
    /// Half the body's thinnest extent: moving farther in a step makes it a CCD candidate.
    pub(crate) ccd_extent: Real,
    /// How far any point of the shape lies from the centre of mass, at most (m): what a
    /// turn moves points by, for the same test.
    pub(crate) ccd_reach: Real,
    /// False while the body's island sleeps.
    pub(crate) awake: bool,
    /// How long the body has been below the sleep thresholds (s).
    pub(crate) sleep_time: Real,
    /// The sleeping island the body belongs to.
    pub(crate) island_tag: u32,
    // Mass properties (dynamic bodies; zero inverse mass otherwise).
    pub(crate) mass: Real,
    pub(crate) inv_mass: Real,
    pub(crate) local_center: Vec3,
    pub(crate) inertia_local: Mat3,
    pub(crate) inv_inertia_local: Mat3,
    /// Principal moments and the body-frame unit axes they belong to (columns, det +1).
    pub(crate) principal_moments: Vec3,
    pub(crate) principal_axes: Mat3,
    /// The same axes as a rotation from the principal frame to the body frame.
    pub(crate) principal_rotation: Quat,
    /// All principal moments equal (spheres, cubes): the inertia tensor is a multiple
    /// of the identity in every frame.
    pub(crate) isotropic: bool,
    /// For planar bodies, I_zz of the world tensor, constant under rotations about z.
    pub(crate) planar_inertia: Real,
    // State.
    pub(crate) com: Vec3,
    pub(crate) orientation: Quat,
    pub(crate) velocity: Vec3,
    pub(crate) angular_momentum: Vec3,
    /// Derived from L for dynamic bodies; prescribed for kinematic ones.
    pub(crate) angular_velocity: Vec3,
}

impl Body {
    pub(crate) fn new(def: &BodyDef, shape: Shape) -> Result<Body> {
        validate_def(def)?;
        shape.validate().map_err(|e| e.within("shape"))?;
        if shape.is_static_only() && def.kind != BodyKind::Static {
            return Err(Error::invalid(
                "kind",
                format!("a {} shape needs a static body", shape.kind_name()),
            ));
        }
        let shape = normalise_plane(shape);
        let orientation = check::rotation("orientation", def.orientation)?;
        let props = mass_properties(def, &shape)?;
        let (moments, axes) = crate::math::symmetric_eigen(props.inertia);
        let dynamic = def.kind == BodyKind::Dynamic;
        let mut body = Body {
            name: def.name.clone(),
            kind: def.kind,
            shape,
            planar: def.planar,
            filter: crate::collision::broad_phase::Filter {
                group: def.collision_group,
                mask: def.collision_mask,
                owner: def.collision_owner,
            },
            friction: def.friction,
            restitution: def.restitution,
            rolling_resistance: def.rolling_resistance,
            torsional_friction: def.torsional_friction,
            bullet: def.bullet,
            linear_damping: def.linear_damping,
            angular_damping: def.angular_damping,
            gravity_scale: def.gravity_scale,
            sensor: def.sensor,
            one_way: def.one_way.map(check_one_way).transpose()?,
            kinematic_target: None,
            ccd_extent: 0.0,
            ccd_reach: 0.0,
            awake: true,
            sleep_time: 0.0,
            island_tag: 0,
            mass: props.mass,
            inv_mass: if dynamic { 1.0 / props.mass } else { 0.0 },
            local_center: props.center,
            inertia_local: props.inertia,
            inv_inertia_local: axes * Mat3::from_diagonal(moments.recip()) * axes.transpose(),
            principal_moments: moments,
            principal_axes: axes,
            principal_rotation: Quat::from_mat3(&axes).normalize(),
            isotropic: moments.max_element() - moments.min_element()
                <= 1e-12 * moments.max_element(),
            planar_inertia: 0.0,
            com: def.position + orientation * props.center,
            orientation,
            velocity: def.linear_velocity,
            angular_momentum: Vec3::ZERO,
            angular_velocity: def.angular_velocity,
        };
        body.ccd_extent = ccd_extent(&body.shape);
        body.ccd_reach = body.shape.bounding_radius() + body.local_center.length();
        let r = Mat3::from_quat(orientation);
        body.planar_inertia = (r * props.inertia * r.transpose()).z_axis.z;
        if body.planar {
            body.velocity.z = 0.0;
            body.angular_velocity = Vec3::new(0.0, 0.0, body.angular_velocity.z);
        }
        body.set_angular_velocity_internal(body.angular_velocity);
        Ok(body)
    }

    /// The body's name, if it has one.
    pub fn name(&self) -> Option<&str> {
        self.name.as_deref()
    }
    /// Static, kinematic or dynamic.
    pub fn kind(&self) -> BodyKind {
        self.kind
    }
    /// The shape, in the body frame.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }
    /// The body's frame as a pose (origin and orientation), which its shape is placed by.
    pub fn pose(&self) -> crate::collision::geometry::Pose {
        crate::collision::geometry::Pose::new(self.position(), self.orientation)
    }
    /// Whether the body is a bullet (swept against moving bodies too).
    pub fn is_bullet(&self) -> bool {
        self.bullet
    }
    /// False while the body's island sleeps.
    pub fn is_awake(&self) -> bool {
        self.awake
    }
    /// Friction coefficient.
    pub fn friction(&self) -> Real {
        self.friction
    }
    /// Coefficient of restitution.
    pub fn restitution(&self) -> Real {
        self.restitution
    }
    /// Rolling resistance coefficient (dimensionless; see [`BodyDef::rolling_resistance`]).
    pub fn rolling_resistance(&self) -> Real {
        self.rolling_resistance
    }
    /// Torsional friction (m; see [`BodyDef::torsional_friction`]).
    pub fn torsional_friction(&self) -> Real {
        self.torsional_friction
    }
    /// Linear damping (1/s; see [`BodyDef::linear_damping`]).
    pub fn linear_damping(&self) -> Real {
        self.linear_damping
    }
    /// Angular damping (1/s; see [`BodyDef::angular_damping`]).
    pub fn angular_damping(&self) -> Real {
        self.angular_damping
    }
    /// Multiplier of the world's gravity (see [`BodyDef::gravity_scale`]).
    pub fn gravity_scale(&self) -> Real {
        self.gravity_scale
    }
    /// Whether the body is a sensor (see [`BodyDef::sensor`]).
    pub fn is_sensor(&self) -> bool {
        self.sensor
    }
    /// A one-way body's unit normal, body frame (see [`BodyDef::one_way`]).
    pub fn one_way(&self) -> Option<Vec3> {
        self.one_way
    }
    /// The pose (frame origin, orientation) a kinematic body was told to reach at the end
    /// of the next step, until that step takes it (see `World::set_kinematic_target`).
    pub fn kinematic_target(&self) -> Option<(Vec3, Quat)> {
        self.kinematic_target
            .map(|(com, q)| (com - q * self.local_center, q))
    }
    /// Collision layers (group) and the layers it collides with (mask).
    pub fn collision_filter(&self) -> (u32, u32) {
        (self.filter.group, self.filter.mask)
    }
    /// The body's collision owner (see `BodyDef::collision_owner`; 0: none).
    pub fn collision_owner(&self) -> u32 {
        self.filter.owner
    }
    /// The filter of the body's broad-phase proxy: its own, or for a sensor one that
    /// pairs with nothing (sensors find their overlaps themselves).
    pub(crate) fn proxy_filter(&self) -> crate::collision::broad_phase::Filter {
        if self.sensor {
            crate::collision::broad_phase::Filter::NONE
        } else {
            self.filter
        }
    }
    /// A quarter of the body's thinnest extent (m): the depth past which contact and
    /// continuous collision treat a thin body as sunk, where that is less than their own
    /// bound (`pipeline/ccd.rs`, `pipeline/contact_cache.rs`, the tall stacks' supports).
    pub(crate) fn quarter_thickness(&self) -> Real {
        0.5 * self.ccd_extent
    }
    /// Whether the body is confined to the XY plane.
    pub fn is_planar(&self) -> bool {
        self.planar
    }
    /// Mass (kg); for static and kinematic bodies the mass their shape would have.
    pub fn mass(&self) -> Real {
        self.mass
    }
    /// Centre of mass in the body frame (m).
    pub fn local_center_of_mass(&self) -> Vec3 {
        self.local_center
    }
    /// Inertia tensor about the centre of mass, body axes (kg·m²).
    pub fn inertia_local(&self) -> Mat3 {
        self.inertia_local
    }
    /// Principal moments of inertia (kg·m²) and their axes (columns, body frame).
    pub fn principal_inertia(&self) -> (Vec3, Mat3) {
        (self.principal_moments, self.principal_axes)
    }
    /// Inertia tensor in world axes, R I_body Rᵀ (kg·m²).
    pub fn inertia_world(&self) -> Mat3 {
        let r = Mat3::from_quat(self.orientation);
        r * self.inertia_local * r.transpose()
    }
    /// World position of the body frame's origin (m).
    pub fn position(&self) -> Vec3 {
        self.com - self.orientation * self.local_center
    }
    /// World position of the centre of mass (m).
    pub fn center_of_mass(&self) -> Vec3 {
        self.com
    }
    /// Orientation, body frame to world.
    pub fn orientation(&self) -> Quat {
        self.orientation
    }
    /// Velocity of the centre of mass (m/s).
    pub fn linear_velocity(&self) -> Vec3 {
        self.velocity
    }
    /// Angular velocity, world frame (rad/s).
    pub fn angular_velocity(&self) -> Vec3 {
        self.angular_velocity
    }
    /// Linear momentum p = m v (kg·m/s); zero for non-dynamic bodies.
    pub fn linear_momentum(&self) -> Vec3 {
        if self.kind == BodyKind::Dynamic {
            self.velocity * self.mass
        } else {
            Vec3::ZERO
        }
    }
    /// Angular momentum about the centre of mass, world frame (kg·m²/s).
    pub fn angular_momentum(&self) -> Vec3 {
        self.angular_momentum
    }
    /// Velocity of a world point moving with the body: v + ω × (p − x).
    pub fn velocity_at_point(&self, world_point: Vec3) -> Vec3 {
        self.velocity + self.angular_velocity.cross(world_point - self.com)
    }
    /// Kinetic energy ½ m v² + ½ ω·L (J); zero for non-dynamic bodies.
    pub fn kinetic_energy(&self) -> Real {
        if self.kind != BodyKind::Dynamic {
            return 0.0;
        }
        0.5 * self.mass * self.velocity.length_squared()
            + 0.5 * self.angular_velocity.dot(self.angular_momentum)
    }

    /// The factors by which damping scales v and L (and ω) over `tau` seconds, the exact
    /// solution of dv/dt = −c v: (exp(−c_v τ), exp(−c_ω τ)); `None` for a body without
    /// damping or not dynamic, so that undamped bodies are stepped exactly as before.
    #[inline]
    pub(crate) fn damping_factors(&self, tau: Real) -> Option<(Real, Real)> {
        if self.kind != BodyKind::Dynamic
            || (self.linear_damping == 0.0 && self.angular_damping == 0.0)
        {
            return None;
        }
        Some((
            (-self.linear_damping * tau).exp(),
            (-self.angular_damping * tau).exp(),
        ))
    }

    /// ω from L for this body at orientation `q`: ω = R I⁻¹ Rᵀ L, or for a planar body
    /// the seed's 2D rule ω_z = L_z / I_zz. A ball-like body (all principal moments equal,
    /// as spheres and cubes are) takes ω = L / I without turning L into the body frame
    /// and back: the same ω its drift turns with (`integrate::rotation::drift`), and two
    /// quaternion rotations fewer in every kick and drift of every such body (they were
    /// 11 % of the joint grid's step).
    #[inline]
    pub(crate) fn omega_from_momentum(&self, q: Quat, l: Vec3) -> Vec3 {
        if self.planar {
            Vec3::new(0.0, 0.0, l.z / self.planar_inertia)
        } else if self.isotropic {
            l / self.principal_moments.x
        } else {
            q * (self.inv_inertia_local * (q.inverse() * l))
        }
    }

    /// L = I_world ω (with the planar and ball-like rules of `omega_from_momentum`).
    pub(crate) fn momentum_from_omega(&self, q: Quat, w: Vec3) -> Vec3 {
        if self.planar {
            Vec3::new(0.0, 0.0, w.z * self.planar_inertia)
        } else if self.isotropic {
            w * self.principal_moments.x
        } else {
            q * (self.inertia_local * (q.inverse() * w))
        }
    }

    pub(crate) fn set_angular_velocity_internal(&mut self, w: Vec3) {
        let w = if self.planar {
            Vec3::new(0.0, 0.0, w.z)
        } else {
            w
        };
        if self.kind == BodyKind::Dynamic {
            self.angular_momentum = self.momentum_from_omega(self.orientation, w);
            self.angular_velocity =
                self.omega_from_momentum(self.orientation, self.angular_momentum);
        } else {
            self.angular_momentum = Vec3::ZERO;
            self.angular_velocity = if self.kind == BodyKind::Static {
                Vec3::ZERO
            } else {
                w
            };
        }
    }
}

/// A body's coefficients by their setters' rules, named as a definition names them:
/// `[friction, restitution, gravity_scale]`, then `[rolling_resistance,
/// torsional_friction, linear_damping, angular_damping]` (finite, within the magnitude
/// limit, and not negative). Shared by a new body's definition and a saved body.
fn check_coefficients(
    [friction, restitution, gravity_scale]: [Real; 3],
    rest: [Real; 4],
) -> Result<()> {
    check_friction(friction)?;
    check_restitution(restitution)?;
    check_gravity_scale(gravity_scale)?;
    let fields = [
        "rolling_resistance",
        "torsional_friction",
        "linear_damping",
        "angular_damping",
    ];
    for (field, x) in fields.into_iter().zip(rest) {
        check::non_negative(field, x)?;
    }
    Ok(())
}

fn validate_def(def: &BodyDef) -> Result<()> {
    use crate::limits::MAX_COORDINATE;
    check::vec3_at_most("position", def.position, MAX_COORDINATE, "m")?;
    check::vec3("velocity", def.linear_velocity)?;
    check::vec3("angular_velocity", def.angular_velocity)?;
    if let Some(c) = def.center_of_mass {
        check::vec3_at_most("center_of_mass", c, MAX_COORDINATE, "m")?;
    }
    check_coefficients(
        [def.friction, def.restitution, def.gravity_scale],
        [
            def.rolling_resistance,
            def.torsional_friction,
            def.linear_damping,
            def.angular_damping,
        ],
    )?;
    match def.mass {
        MassSpec::Density(d) => check::positive("density", d),
        MassSpec::Mass(m) => check::positive("mass", m),
    }
}

impl Body {
    /// Checks a body read from a snapshot by the rules its definition and setters follow
    /// (fields relative to the body): its shape ([`Shape::check_saved`]), a plane, mesh or
    /// height field only on a static body, its coefficients in their ranges (a negative
    /// friction or damping would make a solver's clamp bounds cross), a one-way normal
    /// that is a direction. Its state may be anything: a step refuses non-finite results.
    pub(crate) fn check_saved(&self) -> Result<()> {
        self.shape.check_saved().map_err(|e| e.within("shape"))?;
        if self.shape.is_static_only() && self.kind != BodyKind::Static {
            let shape = self.shape.kind_name();
            return Err(Error::invalid(
                "kind",
                format!("a {shape} shape needs a static body"),
            ));
        }
        // The same rules as plain comparisons first: a call per named check was half the
        // cost of checking a 2,000-body snapshot, and only a failure needs the names.
        let coefficient = |x: Real| (0.0..=crate::limits::MAX_MAGNITUDE).contains(&x);
        let plain = [
            self.friction,
            self.rolling_resistance,
            self.torsional_friction,
            self.linear_damping,
            self.angular_damping,
        ]
        .into_iter()
        .all(coefficient)
            && (0.0..=1.0).contains(&self.restitution)
            && self.gravity_scale.abs() <= crate::limits::MAX_GRAVITY_SCALE;
        if !plain {
            check_coefficients(
                [self.friction, self.restitution, self.gravity_scale],
                [
                    self.rolling_resistance,
                    self.torsional_friction,
                    self.linear_damping,
                    self.angular_damping,
                ],
            )?;
        }
        if let Some(n) = self.one_way {
            check_one_way(n)?;
        }
        Ok(())
    }
}

/// The rule for `friction`, at creation and in `World::set_friction`.
pub(crate) fn check_friction(x: Real) -> Result<()> {
    check::non_negative("friction", x)?;
    check::at_most("friction", x, crate::limits::MAX_MAGNITUDE, "")
}

/// The rule for `restitution`: in [0, 1].
pub(crate) fn check_restitution(x: Real) -> Result<()> {
    check::non_negative("restitution", x)?;
    if x > 1.0 {
        return Err(Error::invalid("restitution", "must be <= 1"));
    }
    Ok(())
}

/// The rule for `gravity_scale`: finite, at most `MAX_GRAVITY_SCALE` either way.
pub(crate) fn check_gravity_scale(x: Real) -> Result<()> {
    check::at_most("gravity_scale", x, crate::limits::MAX_GRAVITY_SCALE, "")
}

/// The rule for `one_way`: a finite, non-zero vector, returned normalised.
pub(crate) fn check_one_way(n: Vec3) -> Result<Vec3> {
    check::vec3("one_way", n)?;
    // Scaled by its largest component first, so that neither a tiny nor a huge vector
    // under- or overflows its length.
    let scale = n.abs().max_element();
    if scale == 0.0 {
        return Err(Error::invalid("one_way", "must be a non-zero vector"));
    }
    let n = n / scale;
    Ok(n / n.length())
}

/// Planes are stored with a unit normal so every routine can rely on it.
fn normalise_plane(shape: Shape) -> Shape {
    match shape {
        Shape::Plane { normal, offset } => {
            let len = normal.length();
            Shape::Plane {
                normal: normal / len,
                offset: offset / len,
            }
        }
        other => other,
    }
}

/// Mass properties from the shape and the def's density or mass, then the overrides.
fn mass_properties(def: &BodyDef, shape: &Shape) -> Result<MassProperties> {
    if shape.is_static_only() {
        return Ok(shape.mass_properties(1.0));
    }
    let mut props = match def.mass {
        MassSpec::Density(d) => shape.mass_properties(d),
        MassSpec::Mass(m) => shape.mass_properties(1.0).with_mass(m),
    };
    if let Some(c) = def.center_of_mass {
        props.center = c;
    }
    if let Some(spec) = def.inertia {
        props.inertia = validate_inertia(spec)?;
    }
    check_mass_came_out(def, shape, &props)?;
    Ok(props)
}

/// Valid sizes can still multiply out to nothing or to infinity (a 1e-120 m sphere has no
/// volume in floating point, 1e308 kg/m³ times a litre overflows), or to a mass whose
/// inverse overflows a step (a density of 1e-300); such a body would turn NaN on its
/// first step. The mass must lie in `limits`' [`MIN_MASS`, `MAX_MASS`], each principal
/// moment in [`MIN_MOMENT`, `MAX_MOMENT`]; the error names the factor out of range.
fn check_mass_came_out(def: &BodyDef, shape: &Shape, props: &MassProperties) -> Result<()> {
    use crate::limits::{short, MAX_MASS, MAX_MOMENT, MIN_MASS, MIN_MOMENT};
    let (moments, _) = crate::math::symmetric_eigen(props.inertia);
    let good = |x: Real| x.is_finite() && x > 0.0;
    // Only a dynamic body's mass enters a step: a static ground may weigh what it likes.
    let (mass_ok, moment_ok): (&dyn Fn(Real) -> bool, &dyn Fn(Real) -> bool) =
        if def.kind == BodyKind::Dynamic {
            (&|m| (MIN_MASS..=MAX_MASS).contains(&m), &|x| {
                (MIN_MOMENT..=MAX_MOMENT).contains(&x)
            })
        } else {
            (&good, &good)
        };
    if mass_ok(props.mass) && moments.to_array().into_iter().all(moment_ok) {
        return Ok(());
    }
    let unit = shape.mass_properties(1.0);
    let (unit_moments, _) = crate::math::symmetric_eigen(unit.inertia);
    let field = if !good(unit.mass)
        || !good(unit_moments.min_element())
        || !good(unit_moments.max_element())
    {
        "shape"
    } else {
        match def.mass {
            MassSpec::Density(_) => "density",
            MassSpec::Mass(_) => "mass",
        }
    };
    Err(Error::invalid(
        field,
        format!(
            "mass and inertia come out at {} kg, principal moments [{}, {}, {}] kg·m²: the mass must be in [{}, {}] kg, each moment in [{}, {}] kg·m²",
            short(props.mass),
            short(moments.x),
            short(moments.y),
            short(moments.z),
            short(MIN_MASS),
            short(MAX_MASS),
            short(MIN_MOMENT),
            short(MAX_MOMENT)
        ),
    ))
}

/// A tensor must be symmetric, positive definite and physically possible: no principal
/// moment may exceed the sum of the other two (the triangle inequality every real mass
/// distribution satisfies).
pub(crate) fn validate_inertia(spec: InertiaSpec) -> Result<Mat3> {
    let m = match spec {
        InertiaSpec::Principal(d) => {
            check::positive_vec3("inertia", d)?;
            Mat3::from_diagonal(d)
        }
        InertiaSpec::Tensor(m) => {
            let cols = [m.x_axis, m.y_axis, m.z_axis];
            if cols.iter().any(|c| !crate::math::vec3_is_finite(*c)) {
                return Err(Error::invalid("inertia", "must be finite numbers"));
            }
            let scale = cols
                .iter()
                .map(|c| c.abs().max_element())
                .fold(0.0, Real::max);
            let asym = (m - m.transpose())
                .to_cols_array()
                .iter()
                .fold(0.0 as Real, |a, b| a.max(b.abs()));
            if asym > 1e-9 * scale.max(crate::math::EPSILON) {
                return Err(Error::invalid("inertia", "must be a symmetric 3x3 matrix"));
            }
            m
        }
    };
    let (moments, _) = crate::math::symmetric_eigen(m);
    if moments.min_element() <= crate::limits::ZERO_MOMENT_SHARE * moments.max_element() {
        return Err(Error::invalid("inertia", "must be positive definite"));
    }
    let sum = moments.x + moments.y + moments.z;
    let slack = 1e-9 * sum;
    let largest = moments.max_element();
    if largest > sum - largest + slack {
        return Err(Error::invalid(
            "inertia",
            "violates the triangle inequality: no principal moment may exceed the sum of the other two",
        ));
    }
    Ok(m)
}

/// One body's dynamic state at some time (a step's start, or an integrator's stage).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Motion {
    /// Centre of mass (m).
    pub x: Vec3,
    /// Orientation.
    pub q: Quat,
    /// Velocity of the centre of mass (m/s).
    pub v: Vec3,
    /// Angular momentum about the centre of mass (kg·m²/s).
    pub l: Vec3,
    /// Angular velocity (rad/s): derived from `l` for dynamic bodies.
    pub w: Vec3,
}

impl Motion {
    pub(crate) fn of(body: &Body) -> Motion {
        Motion {
            x: body.com,
            q: body.orientation,
            v: body.velocity,
            l: body.angular_momentum,
            w: body.angular_velocity,
        }
    }
}

/// The thickness below which a step's travel counts as fast: half the smallest extent of
/// the shape's bounding box, or of its thinnest compound child; for a hull, the radius of
/// the largest ball about its vertices' mean that it holds (the box overstates a hull
/// turned in its frame: an octahedron's box is √3 times its inner ball, and a face-on
/// octahedron moving just under its box's half extent a step would take its centre past
/// a surface before any contact saw it).
fn ccd_extent(shape: &Shape) -> Real {
    match shape {
        Shape::Compound(children) => children
            .iter()
            .map(|c| ccd_extent(&c.shape))
            .fold(Real::INFINITY, Real::min),
        Shape::ConvexHull(hull) => {
            let v = hull.vertices();
            let mean = v.iter().copied().sum::<Vec3>() / v.len().max(1) as Real;
            hull.face_planes()
                .iter()
                .map(|(n, d)| d - n.dot(mean))
                .fold(Real::INFINITY, Real::min)
        }
        _ => shape
            .aabb(&crate::collision::geometry::Pose::IDENTITY)
            .half_extents()
            .min_element(),
    }
}

crate::codec::codec_unit_enum!(BodyKind {
    Static,
    Kinematic,
    Dynamic
});
crate::codec::codec_struct!(Body {
    name,
    kind,
    shape,
    planar,
    filter,
    friction,
    restitution,
    rolling_resistance,
    torsional_friction,
    bullet,
    linear_damping,
    angular_damping,
    gravity_scale,
    sensor,
    one_way,
    kinematic_target,
    ccd_extent,
    ccd_reach,
    awake,
    sleep_time,
    island_tag,
    mass,
    inv_mass,
    local_center,
    inertia_local,
    inv_inertia_local,
    principal_moments,
    principal_axes,
    principal_rotation,
    isotropic,
    planar_inertia,
    com,
    orientation,
    velocity,
    angular_momentum,
    angular_velocity
});

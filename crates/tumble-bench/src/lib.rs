//! Tumble against rapier3d on the same scenes.
//!
//! A scene is described once, engine-neutrally and in `f64` ([`SceneSpec`]: every body's
//! kind, shape, position and orientation, and every ball joint's bodies and anchors), then
//! built in each engine by
//! [`tumble_engine::build`], [`rapier_f32::build`] or [`rapier_f64::build`], so the two
//! engines start from the same numbers. Every engine gets the same settings:
//!
//! | setting     | Tumble                                   | rapier3d 0.36                          |
//! |-------------|------------------------------------------|----------------------------------------|
//! | dt          | `world.step(1/60)`                       | `IntegrationParameters::dt = 1/60`     |
//! | substeps    | `SolverSettings { substeps: 4, iterations: 1 }` (one biased solve and one relax pass per substep) | `num_solver_iterations = 4` (rapier's substep count: it divides dt by it), `num_internal_pgs_iterations = 1` (biased solve), `num_internal_stabilization_iterations = 1` (relax) |
//! | softness    | 30 Hz, ζ = 10 (default)                  | 30 Hz, ζ = 10 (default; 60 Hz against fixed bodies) |
//! | friction    | 0.5 on every body (pair: √(μa μb) = 0.5) | 0.5 on every collider (pair: average = 0.5) |
//! | restitution | 0                                        | 0                                      |
//! | density     | 1000 kg/m³                               | 1000 kg/m³                             |
//! | gravity     | (0, −9.81, 0) m/s²                       | (0, −9.81, 0) m/s²                     |
//! | sleeping    | `WorldDef { sleep: false }`              | `RigidBodyBuilder::can_sleep(false)`   |
//! | threads     | one (`--threads N` in `compare`: N)      | the same count: rapier's `parallel` feature, each world's step run in a rayon pool of that many threads ([`rayon_pool`]) |
//! | ball joints | `JointKind::Ball` without limits, `collide_connected: false` (default) | `SphericalJointBuilder` as an impulse joint, `contacts_enabled(false)` (rapier's default is true) |
//!
//! Everything else is each engine's default (rapier: contact recycling and clustering on,
//! the simplified friction model, CCD against fixed colliders, joints stiff (10⁶ Hz,
//! ζ = 1) and not warm-started; Tumble: symplectic Euler, CCD against static bodies,
//! joints' drift corrected at 1000 Hz capped at a quarter of the substep rate, ζ = 0.5,
//! and warm-started).
//!
//! | scene     | what                                                    | built by          |
//! |-----------|---------------------------------------------------------|-------------------|
//! | `pyramid` | 385 unit boxes in a 10×10-base pyramid on the ground    | [`pyramid`]       |
//! | `rain`    | 2,000 spheres and boxes dropped into a walled container | [`rain`]          |
//! | `joints`  | 30 × 30 balls joined by 1,739 ball joints into a net hanging from one edge | [`joint_grid()`] |
//!
//! and, at Box3D's published sizes ([`scale`]; `compare --scale`):
//!
//! | scene              | what                                                    | built by               |
//! |--------------------|---------------------------------------------------------|------------------------|
//! | `large_pyramid`    | 5,050 unit cubes, a 100-base pyramid one cube thick     | [`large_pyramid`]      |
//! | `many_pyramids`    | 14 × 14 pyramids of base 10, 10,780 cubes               | [`many_pyramids`]      |
//! | `joint_grid_large` | the joint grid at 100 × 100: 10,000 balls, 19,800 joints | [`joint_grid_large()`] |
//! | `rain_large`       | the rain at 10,000 bodies in a 25 m × 25 m container     | [`rain_large`]         |

use std::sync::{Arc, Mutex};
use std::time::Instant;

pub mod joint_grid;
pub mod scale;
pub mod scenes;
pub use joint_grid::{
    joint_grid, joint_grid_large, joint_grid_of, measure_joint_grid, JointGridResult,
    JOINT_GRID_LARGE_SIZE, JOINT_GRID_SETTLE_STEPS, JOINT_GRID_TIMED_STEPS,
};
pub use scale::{
    large_pyramid, many_pyramids, rain_large, RAIN_LARGE_HALF_WIDTH, RAIN_LARGE_TIMED_STEPS,
    SCALE_JOINT_GRID_SETTLE_STEPS, SCALE_JOINT_GRID_TIMED_STEPS, SCALE_PYRAMID_SETTLE_STEPS,
    SCALE_PYRAMID_TIMED_STEPS,
};

/// Time step of every scene (s).
pub const DT: f64 = 1.0 / 60.0;
/// Gravity along y in every scene (m/s²).
pub const GRAVITY_Y: f64 = -9.81;
/// Substeps per step in both engines.
pub const SUBSTEPS: u32 = 4;

/// Rapier's substeps when `compare --rapier-substeps N` asks for other than [`SUBSTEPS`]:
/// Tumble solves a tall stack's island at up to eight times its substeps
/// (`dynamics/solver/stacks.rs`), so the large pyramid's time is also worth comparing
/// with rapier's at the substeps that hold it as still.
static RAPIER_SUBSTEPS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(SUBSTEPS);

/// Sets rapier's substeps for the worlds built after (see [`RAPIER_SUBSTEPS`]).
pub fn set_rapier_substeps(n: u32) {
    RAPIER_SUBSTEPS.store(n.max(1), std::sync::atomic::Ordering::Relaxed);
}

/// Rapier's substeps (see [`RAPIER_SUBSTEPS`]).
pub fn rapier_substeps() -> u32 {
    RAPIER_SUBSTEPS.load(std::sync::atomic::Ordering::Relaxed)
}
/// Friction coefficient of every body.
pub const FRICTION: f64 = 0.5;
/// Density of every body (kg/m³).
pub const DENSITY: f64 = 1000.0;

/// The shape of one body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShapeSpec {
    /// A sphere of this radius (m).
    Sphere(f64),
    /// A box of these half extents (m).
    Cuboid([f64; 3]),
    /// The ground y ≤ 0 (static only): Tumble's plane, rapier's half-space.
    Ground,
}

/// One body of a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySpec {
    /// Dynamic, or static (fixed) if false.
    pub dynamic: bool,
    /// The body's shape, centred on its origin.
    pub shape: ShapeSpec,
    /// Position of the body's origin (m).
    pub position: [f64; 3],
    /// Orientation as a rotation vector: axis times angle (rad).
    pub rotation: [f64; 3],
}

/// A ball (spherical) joint between two bodies of a scene: the two anchors are held
/// together, rotation is free, and the two bodies do not collide with each other.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallJointSpec {
    /// Indices of the two bodies in [`SceneSpec::bodies`].
    pub bodies: [usize; 2],
    /// Each body's anchor, in that body's frame (m).
    pub anchors: [[f64; 3]; 2],
}

/// A scene: its bodies, static ones included, in creation order, and its joints.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSpec {
    /// Short name (`pyramid`, `rain`, `joints`, or a [`scale`] scene's).
    pub name: &'static str,
    /// Every body, static ones included.
    pub bodies: Vec<BodySpec>,
    /// Every joint, in creation order (after all the bodies).
    pub joints: Vec<BallJointSpec>,
}

impl SceneSpec {
    /// Number of dynamic bodies.
    pub fn dynamic_count(&self) -> usize {
        self.bodies.iter().filter(|b| b.dynamic).count()
    }
}

fn fixed(shape: ShapeSpec, position: [f64; 3]) -> BodySpec {
    BodySpec {
        dynamic: false,
        shape,
        position,
        rotation: [0.0; 3],
    }
}

/// Layers of the pyramid; layer k has (10 − k)² boxes.
pub const PYRAMID_BASE: usize = 10;

/// 385 unit boxes in a square pyramid with a 10×10 base on the ground y = 0, each layer
/// centred on the one below (so offset by half a box), every box exactly touching its
/// neighbours and layer k at y = 0.5 + k.
pub fn pyramid() -> SceneSpec {
    let mut bodies = vec![fixed(ShapeSpec::Ground, [0.0; 3])];
    for k in 0..PYRAMID_BASE {
        let n = PYRAMID_BASE - k;
        let first = -0.5 * (n as f64 - 1.0);
        for i in 0..n {
            for j in 0..n {
                bodies.push(BodySpec {
                    dynamic: true,
                    shape: ShapeSpec::Cuboid([0.5; 3]),
                    position: [first + i as f64, 0.5 + k as f64, first + j as f64],
                    rotation: [0.0; 3],
                });
            }
        }
    }
    SceneSpec {
        name: "pyramid",
        bodies,
        joints: Vec::new(),
    }
}

/// Inner half width of the rain container (m): the walls enclose 10 m × 10 m.
pub const RAIN_HALF_WIDTH: f64 = 5.0;
/// Wall height (m).
pub const RAIN_WALL_HEIGHT: f64 = 3.0;

/// SplitMix64, so the rain's jitter is the same on every run and in every engine.
fn splitmix(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// 1,000 spheres (radius 0.25) and 1,000 boxes (half extents 0.25) in a 10 × 10 × 20 grid
/// above a walled container: a floor box (top at y = 0; 40 m × 40 m, so bodies that spill
/// over the walls, about 1 in 40, stay on it) and four 3 m walls, 0.5 m thick, around a
/// 10 m × 10 m inside.
///
/// Grid spacing is 1 m across and 0.9 m up, the bottom layer at y = 4, shapes in a
/// checkerboard; each body is jittered by up to ±5 cm across and turned by a random
/// rotation. A box's half diagonal is 0.433 m, so no two bodies start overlapping
/// (0.866 < 0.9 m) and every body starts inside the walls (4.5 + 0.05 + 0.433 < 5).
pub fn rain() -> SceneSpec {
    rain_grid("rain", 10, 20)
}

/// The rain with `columns` × `columns` bodies per layer and `layers` layers: the grid is
/// 1 m across, so the container's inside is `columns` m wide (half width `columns / 2`),
/// the floor box reaches 15 m past the walls on every side, and the jitter comes from the
/// same generator and seed, drawn in the same order (layer, then x, then z), so
/// `rain_grid("rain", 10, 20)` is exactly [`rain`].
pub fn rain_grid(name: &'static str, columns: usize, layers: usize) -> SceneSpec {
    let (h, t, wall) = (0.5 * columns as f64, 0.25, RAIN_WALL_HEIGHT);
    let floor = h + 15.0;
    let mut bodies = vec![
        fixed(ShapeSpec::Cuboid([floor, 0.5, floor]), [0.0, -0.5, 0.0]),
        fixed(
            ShapeSpec::Cuboid([t, wall / 2.0, h + 2.0 * t]),
            [-h - t, wall / 2.0, 0.0],
        ),
        fixed(
            ShapeSpec::Cuboid([t, wall / 2.0, h + 2.0 * t]),
            [h + t, wall / 2.0, 0.0],
        ),
        fixed(
            ShapeSpec::Cuboid([h, wall / 2.0, t]),
            [0.0, wall / 2.0, -h - t],
        ),
        fixed(
            ShapeSpec::Cuboid([h, wall / 2.0, t]),
            [0.0, wall / 2.0, h + t],
        ),
    ];
    let mut rng = 0x5EED_u64;
    let mut jitter = |scale: f64| scale * (2.0 * splitmix(&mut rng) - 1.0);
    let first = -0.5 * (columns as f64 - 1.0);
    for k in 0..layers {
        for i in 0..columns {
            for j in 0..columns {
                let shape = if (i + j + k) % 2 == 0 {
                    ShapeSpec::Sphere(0.25)
                } else {
                    ShapeSpec::Cuboid([0.25; 3])
                };
                let position = [
                    first + i as f64 + jitter(0.05),
                    4.0 + 0.9 * k as f64,
                    first + j as f64 + jitter(0.05),
                ];
                let axis = [jitter(1.0), jitter(1.0), jitter(1.0)];
                let norm = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
                let angle = std::f64::consts::PI * (jitter(1.0) + 1.0) / 2.0;
                let s = if norm > 1e-9 { angle / norm } else { 0.0 };
                bodies.push(BodySpec {
                    dynamic: true,
                    shape,
                    position,
                    rotation: [axis[0] * s, axis[1] * s, axis[2] * s],
                });
            }
        }
    }
    SceneSpec {
        name,
        bodies,
        joints: Vec::new(),
    }
}

/// A built scene in one engine, as the benchmark drives it.
pub trait Simulation {
    /// `Tumble` or `rapier3d`.
    fn engine(&self) -> &'static str;
    /// `f64` or `f32`.
    fn precision(&self) -> &'static str;
    /// Advances one step of [`DT`].
    fn step(&mut self);
    /// Positions of the dynamic bodies, in scene order (m).
    fn dynamic_positions(&self) -> Vec<[f64; 3]>;
    /// For each joint, in scene order, the distance between its two anchors in world
    /// coordinates (m): zero for a joint that holds.
    fn joint_gaps(&self) -> Vec<f64>;
    /// How many threads a step runs on, as the engine reports it from where its step runs
    /// (Tumble: `World::threads`; rapier: `rayon::current_num_threads()` inside its pool).
    fn threads(&self) -> usize;
}

/// The shared rayon pool of `threads` threads (at least one) that rapier's steps run in,
/// made on first use: every rapier world of a run with the same count shares it, as
/// Tumble's worlds share theirs.
pub fn rayon_pool(threads: usize) -> Arc<rayon::ThreadPool> {
    static POOLS: Mutex<Vec<(usize, Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());
    let threads = threads.max(1);
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, pool)) = pools.iter().find(|(n, _)| *n == threads) {
        return pool.clone();
    }
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("bench-rapier-{i}"))
            .build()
            .expect("a rayon thread pool"),
    );
    pools.push((threads, pool.clone()));
    pool
}

/// Distance between two points (m).
pub fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// The precision of `T` as a name.
fn precision_of<T>() -> &'static str {
    if std::mem::size_of::<T>() == 4 {
        "f32"
    } else {
        "f64"
    }
}

/// Tumble, at the precision of `tumble::Real` (f64 unless built with `--features tumble/f32`).
pub mod tumble_engine {
    use super::{BallJointSpec, BodySpec, SceneSpec, ShapeSpec, Simulation};
    use tumble::prelude::*;
    use tumble::SolverSettings;

    /// A ready Tumble world and the handles of its bodies, in scene order.
    pub struct TumbleScene {
        /// The world.
        pub world: World,
        /// Every body, static ones included, in scene order.
        pub bodies: Vec<BodyId>,
        /// The dynamic bodies, in scene order.
        pub dynamic_bodies: Vec<BodyId>,
        /// Every joint, in scene order.
        pub joints: Vec<JointId>,
    }

    fn v(a: [f64; 3]) -> Vec3 {
        Vec3::new(a[0] as Real, a[1] as Real, a[2] as Real)
    }

    /// `Real` to `f64` (a no-op in the default build, which clippy would flag).
    #[allow(clippy::unnecessary_cast)]
    fn wide(x: Real) -> f64 {
        x as f64
    }

    fn body_def(b: &BodySpec) -> BodyDef {
        BodyDef {
            kind: if b.dynamic {
                BodyKind::Dynamic
            } else {
                BodyKind::Static
            },
            position: v(b.position),
            orientation: Quat::from_scaled_axis(v(b.rotation)),
            mass: MassSpec::Density(super::DENSITY as Real),
            friction: super::FRICTION as Real,
            restitution: 0.0,
            ..Default::default()
        }
    }

    fn shape(s: &ShapeSpec) -> Shape {
        match *s {
            ShapeSpec::Sphere(r) => Shape::sphere(r as Real),
            ShapeSpec::Cuboid(h) => Shape::cuboid(v(h)),
            ShapeSpec::Ground => Shape::plane(Vec3::Y, 0.0),
        }
    }

    /// A ball joint without limits; joined bodies do not collide (`collide_connected`
    /// false, the default).
    fn joint_def(j: &BallJointSpec, bodies: &[BodyId]) -> JointDef {
        let mut def = JointDef::new(
            JointKind::Ball {
                cone: None,
                twist: None,
            },
            bodies[j.bodies[0]],
        );
        def.anchor = v(j.anchors[0]);
        def.other = Some(bodies[j.bodies[1]]);
        def.other_anchor = v(j.anchors[1]);
        def
    }

    /// World position of the point `local` of `body` (m).
    fn world_point(world: &World, body: BodyId, local: Vec3) -> [f64; 3] {
        let b = world.body(body).expect("live body");
        let p = b.position() + b.orientation() * local;
        [wide(p.x), wide(p.y), wide(p.z)]
    }

    /// Builds `spec` on one thread, or on as many as `TUMBLE_THREADS` asks for.
    pub fn build(spec: &SceneSpec) -> TumbleScene {
        let threads = tumble::threads::threads_from_env()
            .ok()
            .flatten()
            .unwrap_or(1);
        build_with_threads(spec, threads)
    }

    /// Builds `spec`: 4 substeps of 1 iteration, sleeping off, gravity −9.81 m/s², steps
    /// on `threads` threads (clamped to Tumble's 1 to `MAX_THREADS`).
    pub fn build_with_threads(spec: &SceneSpec, threads: usize) -> TumbleScene {
        let threads = threads.clamp(1, tumble::threads::MAX_THREADS);
        let mut world = World::try_new(&WorldDef {
            gravity: Vec3::new(0.0, super::GRAVITY_Y as Real, 0.0),
            solver: SolverSettings {
                substeps: super::SUBSTEPS,
                iterations: 1,
                ..Default::default()
            },
            sleep: false,
            threads: Some(threads),
            ..Default::default()
        })
        .expect("valid world settings");
        let mut bodies = Vec::with_capacity(spec.bodies.len());
        let mut dynamic_bodies = Vec::new();
        for b in &spec.bodies {
            let id = world
                .create_body(&body_def(b), shape(&b.shape))
                .expect("valid body");
            bodies.push(id);
            if b.dynamic {
                dynamic_bodies.push(id);
            }
        }
        let joints = spec
            .joints
            .iter()
            .map(|j| {
                world
                    .create_joint(&joint_def(j, &bodies))
                    .expect("valid joint")
            })
            .collect();
        TumbleScene {
            world,
            bodies,
            dynamic_bodies,
            joints,
        }
    }

    impl Simulation for TumbleScene {
        fn engine(&self) -> &'static str {
            "Tumble"
        }
        fn precision(&self) -> &'static str {
            super::precision_of::<Real>()
        }
        fn step(&mut self) {
            self.world.step(super::DT as Real).expect("step");
        }
        fn dynamic_positions(&self) -> Vec<[f64; 3]> {
            self.dynamic_bodies
                .iter()
                .map(|id| {
                    let p = self.world.body(*id).expect("live body").position();
                    [wide(p.x), wide(p.y), wide(p.z)]
                })
                .collect()
        }
        fn joint_gaps(&self) -> Vec<f64> {
            self.joints
                .iter()
                .map(|id| {
                    let def = self.world.joint(*id).expect("live joint").def();
                    let other = def.other.expect("joined to a body");
                    super::distance(
                        world_point(&self.world, def.body, def.anchor),
                        world_point(&self.world, other, def.other_anchor),
                    )
                })
                .collect()
        }
        fn threads(&self) -> usize {
            self.world.threads()
        }
    }
}

/// The same builder for rapier3d and rapier3d-f64, whose APIs are identical.
macro_rules! rapier_engine {
    ($module:ident, $krate:ident, $doc:literal) => {
        #[doc = $doc]
        pub mod $module {
            use super::{BallJointSpec, BodySpec, SceneSpec, ShapeSpec, Simulation};
            use $krate::prelude::*;

            /// A ready rapier world and the handles of its bodies, in scene order.
            pub struct RapierScene {
                /// The world.
                pub world: PhysicsWorld,
                /// Every body, fixed ones included, in scene order.
                pub bodies: Vec<RigidBodyHandle>,
                /// The dynamic bodies, in scene order.
                pub dynamic_bodies: Vec<RigidBodyHandle>,
                /// Every joint, in scene order.
                pub joints: Vec<ImpulseJointHandle>,
            }

            fn v(a: [f64; 3]) -> Vector {
                Vector::new(a[0] as Real, a[1] as Real, a[2] as Real)
            }

            fn collider(s: &ShapeSpec) -> ColliderBuilder {
                let builder = match *s {
                    ShapeSpec::Sphere(r) => ColliderBuilder::ball(r as Real),
                    ShapeSpec::Cuboid(h) => {
                        ColliderBuilder::cuboid(h[0] as Real, h[1] as Real, h[2] as Real)
                    }
                    ShapeSpec::Ground => ColliderBuilder::new(SharedShape::halfspace(Vector::Y)),
                };
                builder
                    .friction(super::FRICTION as Real)
                    .restitution(0.0)
                    .density(super::DENSITY as Real)
            }

            fn body(b: &BodySpec) -> RigidBodyBuilder {
                let builder = if b.dynamic {
                    RigidBodyBuilder::dynamic()
                } else {
                    RigidBodyBuilder::fixed()
                };
                builder
                    .translation(v(b.position))
                    .rotation(v(b.rotation))
                    .can_sleep(false)
            }

            /// A spherical impulse joint. Contacts between the joined bodies are switched
            /// off explicitly: rapier's joints leave them on by default.
            fn joint(j: &BallJointSpec) -> SphericalJointBuilder {
                SphericalJointBuilder::new()
                    .local_anchor1(v(j.anchors[0]))
                    .local_anchor2(v(j.anchors[1]))
                    .contacts_enabled(false)
            }

            /// World position of the point `local` of `body` (m).
            fn world_point(world: &PhysicsWorld, body: RigidBodyHandle, local: Vector) -> [f64; 3] {
                let p = world.bodies[body].position().transform_point(local);
                [p.x as f64, p.y as f64, p.z as f64]
            }

            /// The integration parameters of every scene: dt = 1/60 s and 4 substeps (unless
            /// `--rapier-substeps` says otherwise), each one biased solve and one relax
            /// (stabilisation) pass.
            pub fn integration_parameters() -> IntegrationParameters {
                IntegrationParameters {
                    dt: super::DT as Real,
                    num_solver_iterations: super::rapier_substeps() as usize,
                    num_internal_pgs_iterations: 1,
                    num_internal_stabilization_iterations: 1,
                    ..Default::default()
                }
            }

            /// Builds `spec` on one thread (a rayon pool of one: with the `parallel`
            /// feature a world without a pool would use rayon's global pool, every core).
            pub fn build(spec: &SceneSpec) -> RapierScene {
                build_with_threads(spec, 1)
            }

            /// Builds `spec` with [`integration_parameters`], sleeping off, gravity −9.81 m/s²;
            /// every step runs inside the shared pool of `threads` threads
            /// ([`crate::rayon_pool`]; rapier's step is `pool.install(...)`).
            pub fn build_with_threads(spec: &SceneSpec, threads: usize) -> RapierScene {
                let mut world = PhysicsWorld::new();
                world.set_thread_pool(Some(super::rayon_pool(threads)));
                world.gravity = Vector::new(0.0, super::GRAVITY_Y as Real, 0.0);
                world.integration_parameters = integration_parameters();
                let mut bodies = Vec::with_capacity(spec.bodies.len());
                let mut dynamic_bodies = Vec::new();
                for b in &spec.bodies {
                    let (handle, _) = world.insert(body(b), collider(&b.shape));
                    bodies.push(handle);
                    if b.dynamic {
                        dynamic_bodies.push(handle);
                    }
                }
                let joints = spec
                    .joints
                    .iter()
                    .map(|j| {
                        world.impulse_joints.insert(
                            bodies[j.bodies[0]],
                            bodies[j.bodies[1]],
                            joint(j),
                            true,
                        )
                    })
                    .collect();
                RapierScene {
                    world,
                    bodies,
                    dynamic_bodies,
                    joints,
                }
            }

            impl Simulation for RapierScene {
                fn engine(&self) -> &'static str {
                    "rapier3d"
                }
                fn precision(&self) -> &'static str {
                    super::precision_of::<Real>()
                }
                fn step(&mut self) {
                    self.world.step();
                }
                fn dynamic_positions(&self) -> Vec<[f64; 3]> {
                    self.dynamic_bodies
                        .iter()
                        .map(|h| {
                            let p = self.world.bodies[*h].translation();
                            [p.x as f64, p.y as f64, p.z as f64]
                        })
                        .collect()
                }
                fn joint_gaps(&self) -> Vec<f64> {
                    self.joints
                        .iter()
                        .map(|h| {
                            let j = self.world.impulse_joints.get(*h).expect("live joint");
                            super::distance(
                                world_point(&self.world, j.body1(), j.data.local_anchor1()),
                                world_point(&self.world, j.body2(), j.data.local_anchor2()),
                            )
                        })
                        .collect()
                }
                fn threads(&self) -> usize {
                    // Asked from inside the pool the step runs in, as rapier's own
                    // parallel loops ask.
                    self.world
                        .thread_pool()
                        .map_or(0, |pool| pool.install(rayon::current_num_threads))
                }
            }
        }
    };
}

rapier_engine!(rapier_f32, rapier3d, "rapier3d (f32).");
rapier_engine!(rapier_f64, rapier3d_f64, "rapier3d-f64 (f64).");

/// Timings of a run of steps (ms per step).
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    /// Wall time of each timed step (ms).
    pub steps_ms: Vec<f64>,
}

impl Timing {
    /// Mean ms per step.
    pub fn mean(&self) -> f64 {
        self.steps_ms.iter().sum::<f64>() / self.steps_ms.len().max(1) as f64
    }
    /// Median ms per step.
    pub fn median(&self) -> f64 {
        median(&self.steps_ms)
    }
}

/// Median of `xs` (NaN if empty).
pub fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// Steps `sim` `n` times, timing each step.
pub fn timed_steps(sim: &mut dyn Simulation, n: usize) -> Timing {
    let mut steps_ms = Vec::with_capacity(n);
    for _ in 0..n {
        let start = Instant::now();
        sim.step();
        steps_ms.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Timing { steps_ms }
}

/// The pyramid measurement: steps 0–60 settle untimed, steps 60–660 are timed, and the
/// drift is the largest distance any box moves between t = 1 s and t = 11 s (also from
/// t = 0, which adds the first second's settling under load: about 2.5 mm in rapier).
#[derive(Debug, Clone, PartialEq)]
pub struct PyramidResult {
    /// Steps 60–660.
    pub timing: Timing,
    /// Largest displacement of any box from t = 1 s to t = 11 s (m).
    pub drift: f64,
    /// Largest displacement of any box from t = 0 to t = 11 s, settling included (m).
    pub drift_from_start: f64,
}

/// Steps before the pyramid's timed window (one simulated second).
pub const PYRAMID_SETTLE_STEPS: usize = 60;
/// Timed pyramid steps (ten simulated seconds).
pub const PYRAMID_TIMED_STEPS: usize = 600;
/// Timed rain steps (five simulated seconds, from the drop).
pub const RAIN_TIMED_STEPS: usize = 300;

/// Runs the pyramid measurement on a freshly built pyramid.
pub fn measure_pyramid(sim: &mut dyn Simulation, settle: usize, timed: usize) -> PyramidResult {
    let start = sim.dynamic_positions();
    for _ in 0..settle {
        sim.step();
    }
    let before = sim.dynamic_positions();
    let timing = timed_steps(sim, timed);
    let after = sim.dynamic_positions();
    PyramidResult {
        timing,
        drift: max_displacement(&before, &after),
        drift_from_start: max_displacement(&start, &after),
    }
}

/// Largest distance between matching points (m); NaN if any point is not finite.
pub fn max_displacement(before: &[[f64; 3]], after: &[[f64; 3]]) -> f64 {
    before
        .iter()
        .zip(after)
        .map(|(a, b)| distance(*a, *b))
        .fold(
            0.0,
            |m: f64, d| if d.is_nan() { f64::NAN } else { m.max(d) },
        )
}

/// What the rain left where: bodies inside the container, outside it on the wide floor,
/// and below the floor's top: a few spheres that spill over the walls roll off the floor's
/// edge within 5 s in both engines; a body falling through would count here too.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RainCount {
    /// Inside the walls, above the floor.
    pub inside: usize,
    /// Spilled over the walls onto the floor outside.
    pub outside: usize,
    /// Below the floor's top (y < −0.25 m) or not finite.
    pub off_floor: usize,
}

/// Counts where the rain's bodies are.
pub fn count_rain(positions: &[[f64; 3]]) -> RainCount {
    count_rain_in(positions, RAIN_HALF_WIDTH)
}

/// Counts where a rain's bodies are, for a container of inner half width `half_width`
/// (m): [`RAIN_HALF_WIDTH`] for [`rain`], [`RAIN_LARGE_HALF_WIDTH`] for [`rain_large`].
pub fn count_rain_in(positions: &[[f64; 3]], half_width: f64) -> RainCount {
    let mut c = RainCount {
        inside: 0,
        outside: 0,
        off_floor: 0,
    };
    for p in positions {
        if !p.iter().all(|x| x.is_finite()) || p[1] < -0.25 {
            c.off_floor += 1;
        } else if p[0].abs() < half_width && p[2].abs() < half_width {
            c.inside += 1;
        } else {
            c.outside += 1;
        }
    }
    c
}

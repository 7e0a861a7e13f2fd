//! [`Model`] -> bodies and joints. Everything is worked out first, as a [`Plan`] of
//! engine definitions (the tree, each link's pose at zero joint positions, merged mass
//! properties, shapes with their meshes read and hulled); only then is the world touched,
//! and if the engine refuses anything, what was created is removed again.
//!
//! Frames: a body per link (or per group of links joined by fixed joints, when those are
//! merged), whose frame is the group's first link's frame, so that a joint's anchor on its
//! child is the child's origin and its axis is URDF's axis as written (URDF puts the joint
//! frame at the child link's frame). The joint's `body` is the child and `other` the
//! parent, so that the engine's coordinate (the child relative to the parent, zero at
//! creation) is URDF's joint position.

use std::collections::BTreeMap;
use std::path::PathBuf;

use tumble::shape::{CompoundChild, MassProperties, TriMesh};
use tumble::{
    BodyDef, BodyId, BodyKind, InertiaSpec, JointCoordinate, JointDef, JointId, JointKind,
    MassSpec, Mat3, Motor, Quat, Real, Servo, Shape, Vec3, World,
};

use super::parse::{Geometry, JointType, Model, Pose};
use super::UrdfOptions;
use crate::error::{printable, Result, SceneError};
use crate::mesh_file::{read_mesh, MeshData};

/// The largest torque (force) a joint's damper may exert: unlimited in practice (the
/// engine's largest, `limits::MAX_MAGNITUDE`), so that it is URDF's pure viscous damping,
/// τ = −c q̇.
const UNLIMITED: Real = tumble::limits::MAX_MAGNITUDE;

/// Radius (m) of the placeholder sphere given to a link with no collision geometry (it
/// collides with nothing and its mass properties are the file's).
const NO_SHAPE_RADIUS: Real = 0.01;

pub(crate) struct PlannedBody {
    pub at: String,
    pub color: Option<[u8; 3]>,
    pub def: BodyDef,
    pub shape: Shape,
}

pub(crate) struct PlannedJoint {
    pub at: String,
    pub name: String,
    pub kind: JointKind,
    pub body: usize,
    pub other: usize,
    pub other_anchor: Vec3,
    pub axis: Vec3,
    pub other_axis: Vec3,
    /// Where the joint starts when the file's zero pose is outside its limits: the
    /// nearer limit (a limit row would otherwise snap it there in one step).
    pub start: Option<Real>,
}

pub(crate) struct Plan {
    pub bodies: Vec<PlannedBody>,
    pub joints: Vec<PlannedJoint>,
    /// Every link, in the file's order, and the body (index into `bodies`) it is part of.
    pub links: Vec<(String, usize)>,
    pub warnings: Vec<String>,
}

/// The tree: links in depth-first order from the root, each link's parent joint.
struct Tree {
    order: Vec<usize>,
    parent_joint: Vec<Option<usize>>,
}

fn index_links(model: &Model) -> Result<BTreeMap<&str, usize>> {
    let mut index = BTreeMap::new();
    for (i, link) in model.links.iter().enumerate() {
        if index.insert(link.name.as_str(), i).is_some() {
            return Err(SceneError::new(
                format!("{}: name", link.at),
                "another link has this name",
            ));
        }
    }
    Ok(index)
}

fn tree(model: &Model, index: &BTreeMap<&str, usize>) -> Result<Tree> {
    let n = model.links.len();
    let mut parent_joint = vec![None; n];
    let mut children: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for (j, joint) in model.joints.iter().enumerate() {
        let find = |field: &str, name: &str| {
            index.get(name).copied().ok_or_else(|| {
                SceneError::new(
                    format!("{}: {field}", joint.at),
                    format!("no link named '{}'", printable(name)),
                )
            })
        };
        let (p, c) = (
            find("parent.link", &joint.parent)?,
            find("child.link", &joint.child)?,
        );
        if parent_joint[c].replace(j).is_some() {
            return Err(SceneError::new(
                format!("{}: child.link", joint.at),
                format!(
                    "link '{}' already has a parent joint",
                    printable(&joint.child)
                ),
            ));
        }
        children[p].push((j, c));
    }
    let roots: Vec<usize> = (0..n).filter(|&l| parent_joint[l].is_none()).collect();
    let Some(&root) = roots.first() else {
        return Err(SceneError::new(
            model.links[0].at.clone(),
            "the joints form a loop: no link is without a parent",
        ));
    };
    if let Some(&second) = roots.get(1) {
        return Err(SceneError::new(
            model.links[second].at.clone(),
            format!(
                "is not joined to the root link '{}': a URDF model is one tree",
                printable(&model.links[root].name)
            ),
        ));
    }
    let mut order = Vec::with_capacity(n);
    let mut stack = vec![root];
    while let Some(l) = stack.pop() {
        order.push(l);
        stack.extend(children[l].iter().rev().map(|&(_, c)| c));
    }
    if let Some(l) = (0..n).find(|l| !order.contains(l)) {
        return Err(SceneError::new(
            model.links[l].at.clone(),
            "is on a loop of joints, not in the tree below the root link",
        ));
    }
    Ok(Tree {
        order,
        parent_joint,
    })
}

/// Works out every body and joint `model` becomes under `opts`, touching no world.
pub(crate) fn plan(model: &Model, opts: &UrdfOptions) -> Result<Plan> {
    let index = index_links(model)?;
    let tree = tree(model, &index)?;
    let n = model.links.len();
    let root_pose = Pose {
        position: opts.position,
        rotation: opts.orientation.normalize(),
    };
    let (mut host, mut offset, mut pose) =
        (vec![0; n], vec![Pose::IDENTITY; n], vec![root_pose; n]);
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for &l in &tree.order {
        if let Some(j) = tree.parent_joint[l] {
            let joint = &model.joints[j];
            let p = index[joint.parent.as_str()];
            pose[l] = pose[p].then(&joint.origin);
            if joint.kind == JointType::Fixed && opts.merge_fixed {
                host[l] = host[p];
                offset[l] = offset[p].then(&joint.origin);
                groups[host[l]].push(l);
                continue;
            }
        }
        host[l] = groups.len();
        groups.push(vec![l]);
    }
    let mut meshes = MeshCache::default();
    let mut bodies = Vec::with_capacity(groups.len());
    let mut warnings = model.warnings.clone();
    for group in &groups {
        let is_root = group[0] == tree.order[0];
        let mut planned = body(
            model,
            group,
            &offset,
            is_root,
            &mut meshes,
            opts,
            &mut warnings,
        )?;
        planned.def.position = pose[group[0]].position;
        planned.def.orientation = pose[group[0]].rotation;
        bodies.push(planned);
    }
    let joints = plan_joints(
        model,
        &tree,
        &index,
        (&host, &offset),
        opts,
        &mut bodies,
        &mut warnings,
    );
    let links = model
        .links
        .iter()
        .enumerate()
        .map(|(i, link)| (link.name.clone(), host[i]))
        .collect();
    Ok(Plan {
        bodies,
        joints,
        links,
        warnings,
    })
}

/// Every joint between two bodies (fixed joints merged away are none), parents first.
/// A planar joint adds two light bodies to `bodies` (see [`planar`]).
fn plan_joints(
    model: &Model,
    tree: &Tree,
    index: &BTreeMap<&str, usize>,
    (host, offset): (&[usize], &[Pose]),
    opts: &UrdfOptions,
    bodies: &mut Vec<PlannedBody>,
    warnings: &mut Vec<String>,
) -> Vec<PlannedJoint> {
    let mut joints = Vec::new();
    for &l in &tree.order[1..] {
        let j = tree.parent_joint[l].expect("every link below the root has a parent joint");
        let joint = &model.joints[j];
        let p = index[joint.parent.as_str()];
        if host[l] == host[p] || joint.kind == JointType::Floating {
            continue;
        }
        let parent_frame = offset[p].then(&joint.origin);
        if joint.kind == JointType::Planar {
            let ends = (host[l], host[p]);
            joints.extend(planar(joint, ends, &parent_frame, &opts.prefix, bodies));
            continue;
        }
        let start = joint
            .limits
            .filter(|[lo, hi]| *lo > 0.0 || *hi < 0.0)
            .map(|[lo, hi]| if lo > 0.0 { lo } else { hi });
        if let Some(q) = start {
            warnings.push(format!(
                "{}: limit: the file's zero pose is outside the limits; the joint starts at {q}",
                joint.at
            ));
        }
        joints.push(PlannedJoint {
            start,
            at: joint.at.clone(),
            name: format!("{}{}", opts.prefix, joint.name),
            kind: joint_kind(joint),
            body: host[l],
            other: host[p],
            other_anchor: parent_frame.position,
            axis: joint.axis,
            other_axis: parent_frame.rotation * joint.axis,
        });
    }
    joints
}

/// A light body's share of the body it carries: 1/100 of its mass and largest moment.
const LIGHT: Real = 1e-2;

/// URDF's planar joint (the child moves in the plane normal to the axis and turns about
/// it): a slider along the joint frame's first in-plane direction (x for an axis along z),
/// one along the second (n × that) and a hinge about the axis, chained through two light
/// bodies at the child's frame that collide with nothing. The child gives up the light
/// bodies' mass, so that the model weighs what the file says and the first slider moves
/// the child's mass (added on top, the light bodies made it 2 % heavier). The three are named
/// `name/x`, `name/y` and `name/theta` (MoveIt's names for a planar joint's variables);
/// damping and friction act on each.
fn planar(
    joint: &super::parse::Joint,
    (child, parent): (usize, usize),
    parent_frame: &Pose,
    prefix: &str,
    bodies: &mut Vec<PlannedBody>,
) -> Vec<PlannedJoint> {
    let n = joint.axis;
    let u = (Vec3::X - n * n.x)
        .try_normalize()
        .unwrap_or_else(|| (Vec3::Y - n * n.y).normalize());
    let v = n.cross(u);
    let carried = &bodies[child].def;
    let mass = match carried.mass {
        MassSpec::Mass(m) => m,
        _ => 1.0,
    };
    let moment = match carried.inertia {
        Some(InertiaSpec::Tensor(t)) => tumble::math::symmetric_eigen(t).0.max_element(),
        _ => mass,
    };
    let light = BodyDef {
        name: None,
        kind: BodyKind::Dynamic,
        mass: MassSpec::Mass(LIGHT * mass),
        center_of_mass: Some(Vec3::ZERO),
        inertia: Some(InertiaSpec::Tensor(tumble::Mat3::from_diagonal(
            Vec3::splat(LIGHT * moment),
        ))),
        collision_group: 0,
        collision_mask: 0,
        ..carried.clone()
    };
    if let MassSpec::Mass(m) = &mut bodies[child].def.mass {
        *m -= 2.0 * LIGHT * mass;
    }
    let first = bodies.len();
    for _ in 0..2 {
        bodies.push(PlannedBody {
            at: joint.at.clone(),
            color: None,
            def: light.clone(),
            shape: Shape::sphere(NO_SHAPE_RADIUS),
        });
    }
    let drive = joint_kind(&super::parse::Joint {
        kind: JointType::Prismatic,
        limits: None,
        ..joint.clone()
    });
    let turn = joint_kind(&super::parse::Joint {
        kind: JointType::Continuous,
        limits: None,
        ..joint.clone()
    });
    let links = [
        ("x", drive, first, parent, u),
        ("y", drive, first + 1, first, v),
        ("theta", turn, child, first + 1, n),
    ];
    links
        .into_iter()
        .map(|(var, kind, body, other, axis)| {
            let on_parent = other == parent;
            PlannedJoint {
                start: None,
                at: joint.at.clone(),
                name: format!("{prefix}{}/{var}", joint.name),
                kind,
                body,
                other,
                other_anchor: if on_parent {
                    parent_frame.position
                } else {
                    Vec3::ZERO
                },
                axis,
                other_axis: if on_parent {
                    parent_frame.rotation * axis
                } else {
                    axis
                },
            }
        })
        .collect()
}

/// URDF's joint as the engine's kind: limits as given, `<dynamics damping>` as a pure
/// damper (a servo of zero stiffness, τ = −c q̇) and `friction` as a motor held at zero
/// speed whose largest torque is the friction (Coulomb friction: it holds the joint
/// until the load exceeds it, then resists with exactly that torque).
fn joint_kind(joint: &super::parse::Joint) -> JointKind {
    let motor = (joint.friction > 0.0).then_some(Motor {
        speed: 0.0,
        max_force: joint.friction,
    });
    let servo = (joint.damping > 0.0).then_some(Servo {
        target: 0.0,
        stiffness: 0.0,
        damping: joint.damping,
        max_force: UNLIMITED,
    });
    let limits = joint.limits;
    match joint.kind {
        JointType::Prismatic => JointKind::Slider {
            limits,
            motor,
            spring: None,
            servo,
        },
        JointType::Fixed => JointKind::Fixed,
        JointType::Spherical => JointKind::Ball {
            cone: None,
            twist: None,
        },
        _ => JointKind::Hinge {
            limits,
            motor,
            spring: None,
            servo,
        },
    }
}

/// Meshes read once per file, whatever number of links use them.
#[derive(Default)]
struct MeshCache(BTreeMap<PathBuf, MeshData>);

impl MeshCache {
    fn get(&mut self, file: &PathBuf, at: &str) -> Result<&MeshData> {
        if !self.0.contains_key(file) {
            let mesh = read_mesh(file)
                .map_err(|e| SceneError::new(format!("{at}: geometry.mesh"), e.to_string()))?;
            self.0.insert(file.clone(), mesh);
        }
        Ok(&self.0[file])
    }
}

/// One body: the links of `group` (the first gives the frame), their masses summed about
/// the common centre (parallel axes), their collision geometry as one shape. The root
/// group is static with a fixed base, or when it has no mass (PyBullet's convention).
fn body(
    model: &Model,
    group: &[usize],
    offset: &[Pose],
    is_root: bool,
    meshes: &mut MeshCache,
    opts: &UrdfOptions,
    warnings: &mut Vec<String>,
) -> Result<PlannedBody> {
    let first = &model.links[group[0]];
    let has_mass = group.iter().any(|&l| {
        let link = &model.links[l];
        link.inertial.as_ref().is_some_and(|i| i.mass > 0.0)
    });
    let is_static = is_root && (opts.fixed_base || !has_mass);
    let mut parts = Vec::new();
    for &l in group {
        let link = &model.links[l];
        let Some(i) = link.inertial.as_ref().filter(|i| i.mass > 0.0) else {
            continue;
        };
        let from_geometry = |meshes: &mut MeshCache| -> Result<tumble::Mat3> {
            let alone = vec![Pose::IDENTITY; model.links.len()];
            let (shape, _) = shape(model, &[l], &alone, false, meshes)?;
            Ok(shape.mass_properties(1.0).with_mass(i.mass).inertia)
        };
        let inertia = match (i.inertia, &i.problem) {
            // A static body's mass properties are never used: nothing to refuse.
            (Some(_), Some(problem)) if is_static => {
                warnings.push(format!(
                    "{}: inertial.inertia: {problem}; not used (the link does not move)",
                    link.at
                ));
                continue;
            }
            (Some(tensor), Some(problem)) if link.collisions.is_empty() => {
                warnings.push(format!(
                    "{}: inertial.inertia: {problem}; the link has no collision geometry to take one from, so its principal moments are raised to at least {} of the largest",
                    link.at, LEAST_MOMENT
                ));
                possible(tensor)
            }
            (Some(_), Some(problem)) => {
                warnings.push(format!(
                    "{}: inertial.inertia: {problem}; taken from the collision geometry at uniform density, as PyBullet does",
                    link.at
                ));
                from_geometry(meshes)?
            }
            (Some(tensor), None) => tensor,
            (None, _) => {
                warnings.push(format!(
                    "{}: inertial.inertia: all zero; taken from the collision geometry at uniform density, as PyBullet does",
                    link.at
                ));
                from_geometry(meshes)?
            }
        };
        let local = MassProperties {
            mass: i.mass,
            center: i.center,
            inertia,
        };
        parts.push(local.transformed(offset[l].position, offset[l].rotation));
    }
    let (shape, has_geometry) = shape(model, group, offset, is_static, meshes)?;
    let mut def = BodyDef {
        name: Some(format!("{}{}", opts.prefix, first.name)),
        kind: if is_static {
            BodyKind::Static
        } else {
            BodyKind::Dynamic
        },
        ..BodyDef::default()
    };
    if !has_geometry {
        // Nothing to collide with: the body is in no layer and meets none.
        def.collision_group = 0;
        def.collision_mask = 0;
    }
    if !is_static {
        if parts.is_empty() {
            return Err(SceneError::new(
                format!("{}: inertial.mass", first.at),
                "a link that moves must have a mass > 0 (it has no <inertial>, or mass 0)",
            ));
        }
        let total = MassProperties::sum(parts);
        def.mass = MassSpec::Mass(total.mass);
        def.center_of_mass = Some(total.center);
        // R I Rᵀ and the parallel-axis sums are symmetric only to rounding, which in f32
        // can exceed the engine's symmetry check: the mean of the two halves is exact.
        let i = total.inertia;
        def.inertia = Some(InertiaSpec::Tensor((i + i.transpose()) * 0.5));
    }
    Ok(PlannedBody {
        at: first.at.clone(),
        color: first.color,
        def,
        shape,
    })
}

/// The least principal moment [`possible`] leaves, as a share of the largest.
const LEAST_MOMENT: Real = 1e-3;

/// The nearest tensor to `t` that the engine takes as a body's: the same principal axes,
/// each moment raised to at least [`LEAST_MOMENT`] of the largest, and the largest
/// lowered to the sum of the other two where it exceeded it. For a link without
/// collision geometry whose file tensor is impossible (biped2d_pybullet.urdf's sliders
/// give a rod's, one moment zero): a 1 cm placeholder sphere's instead would make the
/// link 10⁶ times lighter to turn than the file says.
fn possible(t: Mat3) -> Mat3 {
    let (moments, axes) = tumble::math::symmetric_eigen(t);
    let largest = moments.max_element().max(Real::MIN_POSITIVE);
    let raised = moments.max(Vec3::splat(LEAST_MOMENT * largest));
    let [a, b, c] = raised.to_array();
    let fitted = Vec3::new(a.min(b + c), b.min(a + c), c.min(a + b));
    axes * Mat3::from_diagonal(fitted) * axes.transpose()
}

/// The group's collision geometry in the frame of its first link, and whether it has
/// any. A static body whose only geometry is a mesh keeps the mesh's triangles; every
/// other mesh becomes its convex hull (the engine's moving shapes are convex).
fn shape(
    model: &Model,
    group: &[usize],
    offset: &[Pose],
    is_static: bool,
    meshes: &mut MeshCache,
) -> Result<(Shape, bool)> {
    let all: Vec<(Pose, &super::parse::Collision)> = group
        .iter()
        .flat_map(|&l| {
            let link = &model.links[l];
            link.collisions
                .iter()
                .map(move |c| (offset[l].then(&c.origin), c))
        })
        .collect();
    let mut children = Vec::with_capacity(all.len());
    for (pose, c) in &all {
        // URDF's cylinders and capsules lie along z, the engine's along y: turned a
        // quarter about x, y goes to z.
        let along_z = pose.rotation * Quat::from_rotation_x(std::f64::consts::FRAC_PI_2 as Real);
        let (shape, rotation) = match &c.geometry {
            Geometry::Box { half_extents } => (Shape::cuboid(*half_extents), pose.rotation),
            Geometry::Sphere { radius } => (Shape::sphere(*radius), pose.rotation),
            Geometry::Cylinder { radius, length } => {
                (Shape::cylinder(*radius, 0.5 * length), along_z)
            }
            Geometry::Capsule { radius, length } => {
                (Shape::capsule(*radius, 0.5 * length), along_z)
            }
            Geometry::Plane { normal } => {
                if !is_static || all.len() != 1 {
                    return Err(SceneError::new(
                        format!("{}: geometry.plane", c.at),
                        "only a static link whose only collision geometry it is may be a plane",
                    ));
                }
                let normal = pose.rotation * *normal;
                return Ok((Shape::plane(normal, normal.dot(pose.position)), true));
            }
            Geometry::Mesh { file, scale } => {
                let mesh = meshes.get(file, &c.at)?;
                if is_static && all.len() == 1 {
                    return Ok((static_mesh(mesh, *scale, pose, &c.at)?, true));
                }
                (hull(mesh, *scale, file, &c.at)?, pose.rotation)
            }
        };
        children.push(CompoundChild {
            shape,
            position: pose.position,
            orientation: rotation,
        });
    }
    match children.len() {
        0 => Ok((Shape::sphere(NO_SHAPE_RADIUS), false)),
        1 if children[0].position == Vec3::ZERO && children[0].orientation == Quat::IDENTITY => {
            Ok((children.remove(0).shape, true))
        }
        _ => Ok((Shape::Compound(children), true)),
    }
}

fn hull(mesh: &MeshData, scale: Vec3, file: &std::path::Path, at: &str) -> Result<Shape> {
    let points: Vec<Vec3> = mesh.vertices.iter().map(|v| *v * scale).collect();
    Shape::convex_hull(&points).map_err(|e| {
        SceneError::new(
            format!("{at}: geometry.mesh"),
            format!(
                "'{}' has no volume to take a convex hull of ({})",
                printable(&file.display().to_string()),
                SceneError::from_engine(e, "").reason
            ),
        )
    })
}

/// A static body's one mesh as the engine's mesh shape: its triangles of zero area (after
/// scaling) dropped, as the MJCF reader does.
fn static_mesh(mesh: &MeshData, scale: Vec3, pose: &Pose, at: &str) -> Result<Shape> {
    let vertices: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| pose.position + pose.rotation * (*v * scale))
        .collect();
    let triangles = crate::mesh_file::with_area(&vertices, &mesh.triangles);
    TriMesh::new(vertices, triangles)
        .map(Shape::TriMesh)
        .map_err(|e| SceneError::from_engine(e, "").within_at(at, "geometry.mesh"))
}

/// Creates the planned bodies, then joints; on the first refusal removes what it made
/// and returns the refusal, naming the element it came from.
pub(crate) fn create(
    world: &mut World,
    plan: &Plan,
    owner: u32,
) -> Result<(Vec<BodyId>, Vec<JointId>)> {
    let mut bodies = Vec::with_capacity(plan.bodies.len());
    let mut joints = Vec::with_capacity(plan.joints.len());
    let result = create_all(world, plan, owner, &mut bodies, &mut joints);
    if let Err(e) = result {
        for id in joints.into_iter().rev() {
            let _ = world.remove_joint(id);
        }
        for id in bodies.into_iter().rev() {
            let _ = world.remove_body(id);
        }
        return Err(e);
    }
    Ok((bodies, joints))
}

fn create_all(
    world: &mut World,
    plan: &Plan,
    owner: u32,
    bodies: &mut Vec<BodyId>,
    joints: &mut Vec<JointId>,
) -> Result<()> {
    for b in &plan.bodies {
        let def = BodyDef {
            collision_owner: owner,
            ..b.def.clone()
        };
        let id = world
            .create_body(&def, b.shape.clone())
            .map_err(|e| SceneError::from_engine(e, "").within_at(&b.at, ""))?;
        bodies.push(id);
    }
    for j in &plan.joints {
        let def = JointDef {
            name: Some(j.name.clone()),
            kind: j.kind,
            body: bodies[j.body],
            anchor: Vec3::ZERO,
            axis: j.axis,
            other: Some(bodies[j.other]),
            other_anchor: j.other_anchor,
            other_axis: j.other_axis,
            collide_connected: false,
            break_force: None,
            armature: 0.0,
        };
        let id = world
            .create_joint(&def)
            .map_err(|e| SceneError::from_engine(e, "").within_at(&j.at, ""))?;
        joints.push(id);
    }
    // Parents before children (the plan's order), each posing its child's side.
    for (j, &id) in plan.joints.iter().zip(joints.iter()) {
        if let Some(q) = j.start {
            world
                .set_joint_position(id, JointCoordinate::Scalar(q))
                .map_err(|e| SceneError::from_engine(e, "").within_at(&j.at, "limit"))?;
        }
    }
    Ok(())
}

impl SceneError {
    /// This error, raised at element `at`, under `field` there (may be empty).
    pub(crate) fn within_at(self, at: &str, field: &str) -> SceneError {
        let inner = match (field, self.field.as_str()) {
            ("", "") => String::new(),
            ("", f) | (f, "") => format!(": {f}"),
            (a, b) => format!(": {a}.{b}"),
        };
        SceneError::new(format!("{at}{inner}"), self.reason)
    }
}

//! The checked plan into the world: bodies (compound shapes, the file's mass properties,
//! collision filters), joints, the excluded pairs (`World::exclude_contacts`). A failure removes
//! what was created, so the world is left as it was.

use std::collections::BTreeSet;

use tumble::{
    BodyDef, BodyId, BodyKind, CompoundChild, InertiaSpec, JointDef, JointId, JointKind,
    MassProperties, MassSpec, Quat, Real, Servo, Shape, TriMesh, Vec3, World,
};

use super::build::{Plan, PlanBody, PlanJoint, LIGHT};
use super::{ImportedMjcf, MjcfActuator, MjcfJoint, MjcfOptions, Warning};
use crate::error::{Result, SceneError};

/// Radius of the stand-in shape of a body with no colliding geom (m); it collides with
/// nothing (group and mask 0), so only its bounds matter.
const NO_SHAPE_RADIUS: Real = 0.01;

/// What was created so far, to undo on failure.
#[derive(Default)]
struct Made {
    bodies: Vec<BodyId>,
    joints: Vec<JointId>,
    /// Each created body's colour (its first geom's `rgba`), creation order.
    colors: Vec<(BodyId, Option<[u8; 3]>)>,
}

/// Creates the plan in `world`; on an error, removes what it created.
pub(crate) fn create(plan: Plan, world: &mut World, options: &MjcfOptions) -> Result<ImportedMjcf> {
    let mut made = Made::default();
    match create_all(&plan, world, &mut made, &options.prefix) {
        Ok(ids) => {
            if options.world_settings {
                world
                    .set_gravity(plan.settings.gravity)
                    .map_err(|e| SceneError::from_engine(e, "option.gravity"))?;
                world.set_integrator(plan.settings.integrator);
            }
            Ok(imported(plan, ids, made.colors))
        }
        Err(e) => {
            for j in made.joints.iter().rev() {
                let _ = world.remove_joint(*j);
            }
            for b in made.bodies.iter().rev() {
                let _ = world.remove_body(*b);
            }
            Err(e)
        }
    }
}

/// Handles of the plan's bodies (`None`: a static body with nothing to collide) and
/// joints.
struct Ids {
    bodies: Vec<Option<BodyId>>,
    joints: Vec<JointId>,
}

fn create_all(plan: &Plan, world: &mut World, made: &mut Made, prefix: &str) -> Result<Ids> {
    let filters = if plan.settings.contacts {
        filters(plan)
    } else {
        vec![(0, 0); plan.bodies.len()]
    };
    let mut bodies = Vec::with_capacity(plan.bodies.len());
    for (i, b) in plan.bodies.iter().enumerate() {
        let id = create_body(plan, (i, b), filters[i], prefix, world, made)?;
        bodies.push(id);
    }
    let mut joints = Vec::new();
    for (i, j) in plan.joints.iter().enumerate() {
        let mut def = joint_def(plan, j, plan.servos[i], &bodies, world)?;
        def.name = Some(format!("{prefix}{}", j.name));
        let id = world
            .create_joint(&def)
            .map_err(|e| SceneError::new(j.label.clone(), e.to_string()))?;
        made.joints.push(id);
        joints.push(id);
    }
    // As data, not a contact filter: a second model keeps the first's, and the world can
    // still be copied (Batch), snapshotted and saved.
    for &(a, b) in &plan.excluded {
        if let (Some(a), Some(b)) = (bodies[a], bodies[b]) {
            if a != b {
                world
                    .exclude_contacts(a, b)
                    .map_err(|e| SceneError::new("contact.exclude", e.to_string()))?;
            }
        }
    }
    Ok(Ids { bodies, joints })
}

/// The body's mass properties: its parts', or for an intermediate body a thousandth of
/// the body it carries, but never below the engine's least mass and moment (a marker
/// body of 4e-10 kg, as Gymnasium's pusher goal, would otherwise give 4e-13 kg, which
/// the engine refuses though the body it carries is taken). A body carried by
/// intermediate bodies gives up their mass, so that the model weighs what the file
/// says: added on top, they made a humanoid 0.07 % and a planar cheetah 0.09 % heavier
/// than MuJoCo's, and the chain's first slide moved M + 2m where MuJoCo moves M.
fn mass_of(plan: &Plan, index: usize) -> MassProperties {
    use tumble::limits::{MIN_MASS, MIN_MOMENT};
    let light = |m: Real| (m * LIGHT).max(MIN_MASS);
    let b = &plan.bodies[index];
    match b.light_of {
        Some(carried) => {
            let m = super::build::sum(plan.bodies[carried].mass.iter().copied());
            MassProperties {
                mass: light(m.mass),
                center: Vec3::ZERO,
                inertia: tumble::Mat3::from_diagonal(Vec3::splat(
                    (crate::mjcf::build::largest_moment(&m) * LIGHT).max(MIN_MOMENT),
                )),
            }
        }
        None => {
            let mut m = super::build::sum(b.mass.iter().copied());
            // Not where they were raised to the least mass (a marker's).
            if m.mass * LIGHT >= MIN_MASS {
                let carriers = plan.bodies.iter().filter(|c| c.light_of == Some(index));
                m.mass -= carriers.count() as Real * light(m.mass);
            }
            m
        }
    }
}

fn create_body(
    plan: &Plan,
    (index, b): (usize, &PlanBody),
    filter: (u32, u32),
    prefix: &str,
    world: &mut World,
    made: &mut Made,
) -> Result<Option<BodyId>> {
    let children: Vec<CompoundChild> = b
        .geoms
        .iter()
        .filter(|g| g.contype | g.conaffinity != 0)
        .filter_map(|g| {
            g.shape.clone().map(|shape| CompoundChild {
                shape,
                position: g.position,
                orientation: g.orientation,
            })
        })
        .collect();
    let mut def = BodyDef {
        name: b.name.as_ref().map(|n| format!("{prefix}{n}")),
        position: b.position,
        orientation: b.orientation,
        collision_group: filter.0,
        collision_mask: filter.1,
        friction: b.geoms.iter().map(|g| g.friction).fold(0.0, Real::max),
        torsional_friction: b.geoms.iter().map(|g| g.torsional).fold(0.0, Real::max),
        rolling_resistance: rolling_resistance(b),
        ..BodyDef::default()
    };
    if b.geoms.is_empty() {
        def.friction = 1.0;
    }
    if !b.dynamic {
        static_planes(b, &def, world, made)?;
        static_meshes(b, &def, world, made)?;
        if children.is_empty() {
            return Ok(None);
        }
        def.kind = BodyKind::Static;
    } else {
        let m = mass_of(plan, index);
        let (moments, _) = tumble::math::symmetric_eigen(m.inertia);
        // Written so that NaN fails too.
        let positive = m.mass > 0.0 && moments.min_element() > 0.0;
        if !positive {
            return Err(SceneError::new(
                b.label.clone(),
                format!(
                    "mass and inertia of a moving body must be > 0 (its geoms and <inertial> give {} kg)",
                    m.mass
                ),
            ));
        }
        def.mass = MassSpec::Mass(m.mass);
        def.center_of_mass = Some(m.center);
        def.inertia = Some(InertiaSpec::Tensor(m.inertia));
    }
    let shape = match children.len() {
        0 => Shape::sphere(NO_SHAPE_RADIUS),
        _ => Shape::Compound(children),
    };
    let id = world
        .create_body(&def, shape)
        .map_err(|e| SceneError::new(b.label.clone(), e.to_string()))?;
    made.bodies.push(id);
    made.colors.push((id, b.geoms.iter().find_map(|g| g.rgb)));
    Ok(Some(id))
}

/// The body's rolling resistance: the largest of its colliding geoms' rolling friction
/// over the radius each rolls on (see `geom::rolling_radius`). A static body's is left
/// to the body that rolls on it: Tumble's radius is the moving body's.
fn rolling_resistance(b: &PlanBody) -> Real {
    if !b.dynamic {
        return 0.0;
    }
    let each = b
        .geoms
        .iter()
        .filter(|g| g.rolling > 0.0 && g.contype | g.conaffinity != 0);
    each.filter_map(|g| Some(g.rolling / super::geom::rolling_radius(g.shape.as_ref()?)?))
        .fold(0.0, Real::max)
}

/// A static body's planes, each a static body of its own (planes join no compound).
fn static_planes(b: &PlanBody, def: &BodyDef, world: &mut World, made: &mut Made) -> Result<()> {
    for g in &b.geoms {
        let Some((normal, offset)) = g.plane else {
            continue;
        };
        let plane_def = BodyDef {
            name: None,
            kind: BodyKind::Static,
            friction: g.friction,
            torsional_friction: g.torsional,
            rolling_resistance: 0.0,
            collision_group: def.collision_group,
            collision_mask: def.collision_mask,
            ..def.clone()
        };
        let id = world
            .create_body(&plane_def, Shape::plane(normal, offset))
            .map_err(|e| SceneError::new(b.label.clone(), e.to_string()))?;
        made.bodies.push(id);
        made.colors.push((id, g.rgb));
    }
    Ok(())
}

/// A static body's colliding mesh geoms, each a static body of its own with the mesh's
/// triangles (meshes join no compound).
fn static_meshes(b: &PlanBody, def: &BodyDef, world: &mut World, made: &mut Made) -> Result<()> {
    for g in &b.geoms {
        let Some(mesh) = &g.triangles else {
            continue;
        };
        let vertices = mesh
            .0
            .iter()
            .map(|p| g.position + g.orientation * *p)
            .collect();
        let shape = TriMesh::new(vertices, mesh.1.clone())
            .map(Shape::TriMesh)
            .map_err(|e| {
                SceneError::new(g.label.clone(), SceneError::from_engine(e, "").to_string())
            })?;
        let mesh_def = BodyDef {
            name: None,
            kind: BodyKind::Static,
            friction: g.friction,
            torsional_friction: g.torsional,
            rolling_resistance: 0.0,
            ..def.clone()
        };
        let id = world
            .create_body(&mesh_def, shape)
            .map_err(|e| SceneError::new(g.label.clone(), e.to_string()))?;
        made.bodies.push(id);
        made.colors.push((id, g.rgb));
    }
    Ok(())
}

/// The joint between the created bodies; the other side's anchor and axis are the
/// child's, seen from the other body (or the world).
fn joint_def(
    plan: &Plan,
    j: &PlanJoint,
    servo: Option<Servo>,
    ids: &[Option<BodyId>],
    _world: &World,
) -> Result<JointDef> {
    let b = &plan.bodies[j.body];
    let body =
        ids[j.body].ok_or_else(|| SceneError::new(j.label.clone(), "joint on a static body"))?;
    let anchor_w = b.position + b.orientation * j.anchor;
    let axis_w = b.orientation * j.axis;
    let (other, o_pos, o_rot) = match j.other.and_then(|o| ids[o].map(|id| (o, id))) {
        Some((o, id)) => (
            Some(id),
            plan.bodies[o].position,
            plan.bodies[o].orientation,
        ),
        None => (None, Vec3::ZERO, Quat::IDENTITY),
    };
    let inv = o_rot.inverse();
    let kind = match j.def {
        JointKind::Hinge { limits, .. } => JointKind::Hinge {
            limits,
            motor: None,
            spring: None,
            servo,
        },
        JointKind::Slider { limits, .. } => JointKind::Slider {
            limits,
            motor: None,
            spring: None,
            servo,
        },
        other => other,
    };
    Ok(JointDef {
        name: Some(j.name.clone()),
        kind,
        body,
        anchor: j.anchor,
        axis: j.axis,
        other,
        other_anchor: inv * (anchor_w - o_pos),
        other_axis: inv * axis_w,
        collide_connected: false,
        break_force: None,
        armature: j.armature,
    })
}

/// Collision group and mask per plan body, exact for MuJoCo's rule at the level of
/// bodies: geoms a and b touch when (contype_a & conaffinity_b) || (contype_b &
/// conaffinity_a); Tumble's bodies touch when (group_a & mask_b) && (group_b & mask_a).
/// Each distinct set of (contype, conaffinity) pairs among the bodies gets a bit of its
/// own as its group, and its mask holds the bits of every set it would touch: the rule
/// is symmetric, so Tumble's `&&` of the two directions is MuJoCo's answer. More than 32
/// sets fall back to group = OR of contypes, mask = OR of conaffinities (warned).
fn filters(plan: &Plan) -> Vec<(u32, u32)> {
    let sets: Vec<BTreeSet<(u32, u32)>> = plan
        .bodies
        .iter()
        .map(|b| {
            b.geoms
                .iter()
                .filter(|g| g.contype | g.conaffinity != 0)
                .map(|g| (g.contype, g.conaffinity))
                .collect()
        })
        .collect();
    let mut classes: Vec<&BTreeSet<(u32, u32)>> = sets.iter().filter(|s| !s.is_empty()).collect();
    classes.sort();
    classes.dedup();
    let touch = |a: &BTreeSet<(u32, u32)>, b: &BTreeSet<(u32, u32)>| {
        a.iter()
            .any(|x| b.iter().any(|y| x.0 & y.1 != 0 || y.0 & x.1 != 0))
    };
    sets.iter()
        .map(|s| {
            if s.is_empty() {
                return (0, 0);
            }
            if classes.len() > 32 {
                return s.iter().fold((0, 0), |acc, x| (acc.0 | x.0, acc.1 | x.1));
            }
            let me = classes.iter().position(|c| *c == s).unwrap_or(0);
            let mask = classes
                .iter()
                .enumerate()
                .filter(|(_, c)| touch(s, c))
                .fold(0u32, |m, (i, _)| m | (1 << i));
            (1u32 << me, mask)
        })
        .collect()
}

fn imported(plan: Plan, ids: Ids, colors: Vec<(BodyId, Option<[u8; 3]>)>) -> ImportedMjcf {
    let mut joints: Vec<MjcfJoint> = plan
        .joints
        .iter()
        .zip(&ids.joints)
        .filter_map(|(j, id)| {
            Some(MjcfJoint {
                name: j.name.clone(),
                kind: j.kind.clone(),
                id: Some(*id),
                body: ids.bodies[j.body]?,
                reference: j.reference,
                spring: j.spring,
            })
        })
        .collect();
    for (name, b) in &plan.free {
        if let Some(body) = ids.bodies[*b] {
            joints.push(MjcfJoint {
                name: name.clone(),
                kind: "free".to_string(),
                id: None,
                body,
                reference: 0.0,
                spring: (0.0, 0.0, 0.0),
            });
        }
    }
    let actuators = plan
        .actuators
        .iter()
        .map(|a| MjcfActuator {
            name: a.name.clone(),
            kind: a.kind.clone(),
            joint: plan.joints[a.joint].name.clone(),
            id: ids.joints[a.joint],
            gain: a.gain,
            damping: a.damping,
            ctrl_range: a.ctrl_range,
            force_range: a.force_range,
            control: 0.0,
        })
        .collect();
    let mut warnings: Vec<Warning> = plan.warnings;
    let mixed = plan.bodies.iter().find(|b| {
        let s: BTreeSet<(u32, u32)> = b
            .geoms
            .iter()
            .filter(|g| g.contype | g.conaffinity != 0)
            .map(|g| (g.contype, g.conaffinity))
            .collect();
        s.len() > 1
    });
    if let Some(b) = mixed {
        warnings.push(Warning {
            place: b.label.clone(),
            message: "geoms of one body differ in contype/conaffinity: the body collides \
                      where any of its geoms would"
                .to_string(),
        });
    }
    ImportedMjcf {
        model: plan.model,
        bodies: plan
            .names
            .iter()
            .filter_map(|(n, i)| Some((n.clone(), ids.bodies[*i]?)))
            .collect(),
        joints,
        actuators,
        timestep: plan.settings.timestep,
        warnings,
        colors,
    }
}

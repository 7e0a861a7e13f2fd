//! Shapes: `{"type": "sphere", "radius": 0.1}` and friends.
//!
//! Only the form is checked here (keys, types, finite numbers). Sizes are checked by the
//! engine when the body is created, so the rules (`radius: must be > 0`) live in one place;
//! its errors come back relative to the shape and are prefixed with the body's path.

use tumble::{CompoundChild, HeightField, Quat, Real, Shape, TriMesh, Vec3};

use crate::error::{printable, Result, SceneError};
use crate::reader::{Node, Obj};

/// Every shape type, in the order the documentation lists them.
pub const SHAPE_TYPES: [&str; 9] = [
    "sphere",
    "box",
    "capsule",
    "cylinder",
    "convex_hull",
    "compound",
    "plane",
    "trimesh",
    "heightfield",
];

const CHILD_KEYS: [&str; 3] = ["shape", "position", "orientation"];

/// Reads a shape object.
pub(crate) fn shape(node: &Node<'_>) -> Result<Shape> {
    let obj = node.object()?;
    let kind = obj.required("type")?.str()?;
    match kind {
        "sphere" => {
            obj.only(&["type", "radius"])?;
            Ok(Shape::sphere(obj.required("radius")?.real()?))
        }
        "box" => {
            obj.only(&["type", "half_extents"])?;
            Ok(Shape::cuboid(obj.required("half_extents")?.vec3()?))
        }
        "capsule" | "cylinder" => {
            obj.only(&["type", "radius", "half_height"])?;
            let radius = obj.required("radius")?.real()?;
            let half_height = obj.required("half_height")?.real()?;
            Ok(if kind == "capsule" {
                Shape::capsule(radius, half_height)
            } else {
                Shape::cylinder(radius, half_height)
            })
        }
        "convex_hull" => {
            obj.only(&["type", "points"])?;
            convex_hull(&obj)
        }
        "compound" => {
            obj.only(&["type", "children"])?;
            compound(&obj)
        }
        "plane" => {
            obj.only(&["type", "normal", "offset"])?;
            let normal = obj.required("normal")?.vec3()?;
            Ok(Shape::plane(normal, obj.real("offset")?.unwrap_or(0.0)))
        }
        "trimesh" => {
            obj.only(&["type", "vertices", "indices"])?;
            trimesh(&obj)
        }
        "heightfield" => {
            obj.only(&["type", "heights", "scale"])?;
            heightfield(&obj)
        }
        other => Err(obj.err_at(
            "type",
            format!(
                "unknown shape type '{}' (expected one of: {})",
                printable(other),
                SHAPE_TYPES.join(", ")
            ),
        )),
    }
}

fn convex_hull(obj: &Obj<'_>) -> Result<Shape> {
    let points = obj
        .required("points")?
        .array()?
        .iter()
        .map(Node::vec3)
        .collect::<Result<Vec<Vec3>>>()?;
    // The engine decides what a degenerate cloud is; its field (`points`) is relative to
    // the shape.
    Shape::convex_hull(&points).map_err(|e| SceneError::from_engine(e, obj.node().path()))
}

fn trimesh(obj: &Obj<'_>) -> Result<Shape> {
    let vertices = obj
        .required("vertices")?
        .array()?
        .iter()
        .map(Node::vec3)
        .collect::<Result<Vec<Vec3>>>()?;
    let indices = obj
        .required("indices")?
        .array()?
        .iter()
        .map(triangle_indices)
        .collect::<Result<Vec<[u32; 3]>>>()?;
    TriMesh::new(vertices, indices)
        .map(Shape::TriMesh)
        .map_err(|e| SceneError::from_engine(e, obj.node().path()))
}

fn triangle_indices(node: &Node<'_>) -> Result<[u32; 3]> {
    let items = node.array()?;
    if items.len() != 3 {
        return Err(node.err("expected 3 vertex indices"));
    }
    let mut out = [0u32; 3];
    for (o, n) in out.iter_mut().zip(&items) {
        *o = n.whole(u32::MAX as u64)? as u32;
    }
    Ok(out)
}

/// `heights` is a list of rows, all of one length: rows run along z, columns along x.
fn heightfield(obj: &Obj<'_>) -> Result<Shape> {
    let rows_node = obj.required("heights")?;
    let rows = rows_node.array()?;
    let mut heights = Vec::new();
    let mut cols = None;
    for row in &rows {
        let values = row
            .array()?
            .iter()
            .map(Node::real)
            .collect::<Result<Vec<Real>>>()?;
        if *cols.get_or_insert(values.len()) != values.len() {
            return Err(row.err("every row must have the same number of heights"));
        }
        heights.extend(values);
    }
    let scale = obj.vec3("scale")?.unwrap_or(Vec3::ONE);
    HeightField::new(heights, rows.len(), cols.unwrap_or(0), scale)
        .map(Shape::HeightField)
        .map_err(|e| SceneError::from_engine(e, obj.node().path()))
}

fn compound(obj: &Obj<'_>) -> Result<Shape> {
    let children = obj
        .required("children")?
        .array()?
        .iter()
        .map(child)
        .collect::<Result<Vec<CompoundChild>>>()?;
    Ok(Shape::Compound(children))
}

fn child(node: &Node<'_>) -> Result<CompoundChild> {
    let obj = node.object()?;
    obj.only(&CHILD_KEYS)?;
    Ok(CompoundChild {
        shape: shape(&obj.required("shape")?)?,
        position: obj.vec3("position")?.unwrap_or(Vec3::ZERO),
        orientation: obj.quat("orientation")?.unwrap_or(Quat::IDENTITY),
    })
}

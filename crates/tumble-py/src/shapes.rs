//! Shapes: one Python class per kind, all subclasses of `tumble.Shape`, each checked by the
//! engine when made, so a bad size fails where it is written.

use pyo3::prelude::*;
use pyo3::types::PyTuple;
use tumble::{CompoundChild, HeightField, Shape, TriMesh, Vec3};

use crate::convert::{
    engine, invalid, not_real, points, quat_or, real, unreal_dtype, vec3, vec3_or, wide, wrong_type,
};

/// A collision shape. Make one with a subclass: Sphere, Box, Capsule, Cylinder, ConvexHull,
/// Compound, Plane, TriMesh or HeightField. Shapes are immutable and may be shared by bodies.
#[pyclass(module = "tumble", name = "Shape", subclass, frozen)]
pub struct PyShape {
    pub inner: Shape,
}

#[pymethods]
impl PyShape {
    /// The kind, as named in scene files: "sphere", "box", "capsule", ...
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.kind_name()
    }

    /// Volume (m³); 0 for the static-only shapes (plane, mesh, height field).
    #[getter]
    fn volume(&self) -> f64 {
        if self.inner.is_static_only() {
            0.0
        } else {
            wide(self.inner.volume())
        }
    }

    fn __repr__(&self) -> String {
        let v = |v: Vec3| format!("({}, {}, {})", v.x, v.y, v.z);
        match &self.inner {
            Shape::Sphere { radius } => format!("tumble.Sphere({radius})"),
            Shape::Box { half_extents } => format!("tumble.Box({})", v(*half_extents)),
            Shape::Capsule {
                radius,
                half_height,
            } => format!("tumble.Capsule({radius}, {half_height})"),
            Shape::Cylinder {
                radius,
                half_height,
            } => format!("tumble.Cylinder({radius}, {half_height})"),
            Shape::ConvexHull(h) => {
                format!("<tumble.ConvexHull of {} vertices>", h.vertices().len())
            }
            Shape::Compound(c) => format!("<tumble.Compound of {} children>", c.len()),
            Shape::Plane { normal, offset } => format!("tumble.Plane({}, {offset})", v(*normal)),
            Shape::TriMesh(m) => format!("<tumble.TriMesh of {} triangles>", m.len()),
            Shape::HeightField(h) => format!(
                "<tumble.HeightField of {} x {} samples>",
                h.rows(),
                h.cols()
            ),
        }
    }
}

/// The shape inside any `tumble.Shape`, or a TypeError naming `field`.
pub fn shape_of(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Shape> {
    match obj.cast::<PyShape>() {
        Ok(s) => Ok(s.get().inner.clone()),
        Err(_) => Err(wrong_type(field, "a tumble shape (Sphere, Box, ...)", obj)),
    }
}

fn checked(shape: Shape) -> PyResult<PyClassInitializer<PyShape>> {
    shape.validate().map_err(engine)?;
    Ok(PyClassInitializer::from(PyShape { inner: shape }))
}

/// A ball of `radius` (m) centred on the body's origin.
#[pyclass(module = "tumble", extends = PyShape, frozen)]
pub struct Sphere;

#[pymethods]
impl Sphere {
    #[new]
    fn new(radius: f64) -> PyResult<PyClassInitializer<Self>> {
        Ok(checked(Shape::sphere(real(radius)))?.add_subclass(Sphere))
    }
}

/// A box with the given half extents [x, y, z] (m), centred on the body's origin.
#[pyclass(module = "tumble", name = "Box", extends = PyShape, frozen)]
pub struct BoxShape;

#[pymethods]
impl BoxShape {
    #[new]
    fn new(half_extents: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let h = vec3(half_extents, "half_extents")?;
        Ok(checked(Shape::cuboid(h))?.add_subclass(BoxShape))
    }
}

/// A capsule along the local y axis: a shaft of half length `half_height` (m, caps
/// excluded) with hemispherical caps of `radius` (m).
#[pyclass(module = "tumble", extends = PyShape, frozen)]
pub struct Capsule;

#[pymethods]
impl Capsule {
    #[new]
    fn new(radius: f64, half_height: f64) -> PyResult<PyClassInitializer<Self>> {
        Ok(checked(Shape::capsule(real(radius), real(half_height)))?.add_subclass(Capsule))
    }
}

/// A solid cylinder along the local y axis, of `radius` and half length `half_height` (m).
#[pyclass(module = "tumble", extends = PyShape, frozen)]
pub struct Cylinder;

#[pymethods]
impl Cylinder {
    #[new]
    fn new(radius: f64, half_height: f64) -> PyResult<PyClassInitializer<Self>> {
        Ok(checked(Shape::cylinder(real(radius), real(half_height)))?.add_subclass(Cylinder))
    }
}

/// The convex hull of `points`, an (N, 3) array or list of [x, y, z] (m, body frame): at
/// least 4 points, not all in one plane.
#[pyclass(module = "tumble", extends = PyShape, frozen)]
pub struct ConvexHull;

#[pymethods]
impl ConvexHull {
    #[new]
    fn new(points: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let pts = crate::convert::points(points, "points")?;
        let shape = Shape::convex_hull(&pts).map_err(|e| engine(e.within("points")))?;
        Ok(checked(shape)?.add_subclass(ConvexHull))
    }
}

/// Several shapes rigidly joined: `children` is a list of shapes or of tuples
/// (shape, position) or (shape, position, orientation), placing each child's frame in the
/// compound's (m; quaternion [x, y, z, w]). No planes, meshes or height fields.
#[pyclass(module = "tumble", extends = PyShape, frozen)]
pub struct Compound;

#[pymethods]
impl Compound {
    #[new]
    fn new(children: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let items: Vec<Bound<'_, PyAny>> = children.extract().map_err(|_| {
            wrong_type(
                "children",
                "a list of (shape, position, orientation)",
                children,
            )
        })?;
        let mut out = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let field = format!("children[{i}]");
            out.push(child(item, &field)?);
        }
        Ok(checked(Shape::Compound(out))?.add_subclass(Compound))
    }
}

fn child(item: &Bound<'_, PyAny>, field: &str) -> PyResult<CompoundChild> {
    if let Ok(tuple) = item.cast::<PyTuple>() {
        if tuple.is_empty() || tuple.len() > 3 {
            return Err(invalid(
                field,
                "expected (shape, position) or (shape, position, orientation)",
            ));
        }
        let position = tuple.get_item(1).ok();
        let orientation = tuple.get_item(2).ok();
        return Ok(CompoundChild {
            shape: shape_of(&tuple.get_item(0)?, &format!("{field}.shape"))?,
            position: vec3_or(position.as_ref(), &format!("{field}.position"), Vec3::ZERO)?,
            orientation: quat_or(orientation.as_ref(), &format!("{field}.orientation"))?,
        });
    }
    Ok(CompoundChild {
        shape: shape_of(item, field)?,
        position: Vec3::ZERO,
        orientation: tumble::Quat::IDENTITY,
    })
}

/// The half-space normal·x ≤ offset in the body's frame: an infinite floor or wall
/// (normal [x, y, z], offset in m). Static bodies only.
#[pyclass(module = "tumble", extends = PyShape, frozen)]
pub struct Plane;

#[pymethods]
impl Plane {
    #[new]
    #[pyo3(signature = (normal, offset = 0.0))]
    fn new(normal: &Bound<'_, PyAny>, offset: f64) -> PyResult<PyClassInitializer<Self>> {
        let n = vec3(normal, "normal")?;
        Ok(checked(Shape::plane(n, real(offset)))?.add_subclass(Plane))
    }
}

/// A triangle mesh: `vertices` (N, 3) in m and `indices` (M, 3) of vertex numbers, each
/// triangle counter-clockwise seen from its front. Static bodies only.
#[pyclass(module = "tumble", name = "TriMesh", extends = PyShape, frozen)]
pub struct TriMeshShape;

#[pymethods]
impl TriMeshShape {
    #[new]
    fn new(
        vertices: &Bound<'_, PyAny>,
        indices: &Bound<'_, PyAny>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let v = points(vertices, "vertices")?;
        let rows: Vec<Bound<'_, PyAny>> = indices.extract().map_err(|_| {
            wrong_type(
                "indices",
                "an array of shape (M, 3) of vertex numbers",
                indices,
            )
        })?;
        let mut idx = Vec::with_capacity(rows.len());
        for (i, row) in rows.iter().enumerate() {
            let t: [u32; 3] = row
                .extract()
                .map_err(|_| wrong_type(&format!("indices[{i}]"), "3 vertex numbers >= 0", row))?;
            idx.push(t);
        }
        let mesh = TriMesh::new(v, idx).map_err(engine)?;
        Ok(checked(Shape::TriMesh(mesh))?.add_subclass(TriMeshShape))
    }
}

/// A height-field terrain: `heights` is a 2-D array (rows along z, columns along x);
/// sample (r, c) sits at x = (c − (cols−1)/2)·sx, z = (r − (rows−1)/2)·sz, y = h·sy, with
/// `scale` = [sx, sy, sz] (m). Solid below. Static bodies only.
#[pyclass(module = "tumble", name = "HeightField", extends = PyShape, frozen)]
pub struct HeightFieldShape;

#[pymethods]
impl HeightFieldShape {
    #[new]
    #[pyo3(signature = (heights, scale = None))]
    fn new(
        heights: &Bound<'_, PyAny>,
        scale: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let expected = "a 2-D array of heights (rows, cols)";
        if heights.is_instance_of::<pyo3::types::PyString>() {
            return Err(wrong_type("heights", expected, heights));
        }
        if let Some(got) = unreal_dtype(heights) {
            return Err(not_real("heights", expected, &got));
        }
        let rows: Vec<Vec<f64>> = heights
            .extract()
            .map_err(|_| wrong_type("heights", expected, heights))?;
        let cols = rows.first().map_or(0, Vec::len);
        if let Some(r) = rows.iter().position(|r| r.len() != cols) {
            return Err(invalid(
                &format!("heights[{r}]"),
                "every row must have the same number of heights",
            ));
        }
        let flat = rows.iter().flatten().map(|&h| real(h)).collect();
        let scale = vec3_or(scale, "scale", Vec3::ONE)?;
        let field = HeightField::new(flat, rows.len(), cols, scale).map_err(engine)?;
        Ok(checked(Shape::HeightField(field))?.add_subclass(HeightFieldShape))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyShape>()?;
    m.add_class::<Sphere>()?;
    m.add_class::<BoxShape>()?;
    m.add_class::<Capsule>()?;
    m.add_class::<Cylinder>()?;
    m.add_class::<ConvexHull>()?;
    m.add_class::<Compound>()?;
    m.add_class::<Plane>()?;
    m.add_class::<TriMeshShape>()?;
    m.add_class::<HeightFieldShape>()?;
    Ok(())
}

//! `<asset><mesh>` and mesh geoms, as MuJoCo compiles them.
//!
//! A mesh's vertices (an OBJ or STL file under the compiler's `meshdir`, else `assetdir`,
//! else the model's folder; or the `vertex` attribute) are moved by `refpos`, turned by
//! `refquat`'s inverse and multiplied by `scale`. Its volume, centre and inertia come from
//! its triangles by MuJoCo's algorithm for the mesh's `inertia` mode (`legacy`, MuJoCo's
//! default: pyramids from the area-weighted centroid of the faces to every face, each
//! volume counted positive, so exact for meshes star-shaped about that point; `exact`:
//! signed volumes, exact for any closed mesh; `convex`: the convex hull's). The vertices
//! are then recentred at that centre: a mesh geom's frame sits at its mesh's centre of
//! mass, as MuJoCo's `geom_pos` does (MuJoCo also turns it to the principal axes; Tumble
//! keeps the file's axes, the same body either way). Moving bodies collide with the
//! mesh's convex hull (as MuJoCo does); a mesh welded to the world keeps its triangles.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use tumble::{MassProperties, Mat3, Quat, Real, Shape, Vec3};

use super::frame::vec3;
use super::parse::{Defaults, Elem, View, MAIN};
use super::Warnings;
use crate::error::{printable, Result, SceneError};
use crate::mesh_file::{read_mesh, MeshData};

/// How a mesh's mass properties are computed (`<mesh inertia>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Legacy,
    Exact,
    Convex,
}

/// A mesh asset as declared, read from its file on first use.
#[derive(Debug)]
struct Declared {
    elem: Elem,
    file: Option<PathBuf>,
    scale: Vec3,
    refpos: Vec3,
    refquat: Quat,
    mode: Mode,
}

/// A mesh ready for geoms: recentred vertices, triangles, unit-density mass properties.
#[derive(Debug)]
pub(crate) struct Processed {
    /// Vertices in the geom's frame (the mesh's centre of mass at the origin).
    pub points: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Where the centre of mass was in the mesh's own (transformed) frame.
    pub center: Vec3,
    /// Volume and inertia about the centre at density 1 (centre at the origin).
    pub unit: MassProperties,
    /// The convex hull of `points`, made when a colliding geom first needs it.
    hull: Option<Shape>,
}

/// The file's mesh assets by name.
#[derive(Debug, Default)]
pub(crate) struct Meshes {
    declared: BTreeMap<String, Declared>,
    done: BTreeMap<String, Processed>,
}

/// The folder mesh files are found in: `meshdir`, else `assetdir`, against the model's.
pub(crate) fn mesh_dir(model_dir: &Path, meshdir: Option<&str>, assetdir: Option<&str>) -> PathBuf {
    match meshdir.or(assetdir) {
        Some(d) => model_dir.join(d),
        None => model_dir.to_path_buf(),
    }
}

impl Meshes {
    /// Every `<asset><mesh>` of the file (none is read yet).
    pub fn collect(
        root: &Elem,
        defaults: &Defaults,
        dir: &Path,
        strip_path: bool,
        warn: &mut Warnings,
    ) -> Result<Meshes> {
        let mut out = Meshes::default();
        for m in root.kids("asset").flat_map(|a| a.kids("mesh")) {
            let v = View::new(m, MAIN, defaults)?;
            let (name, declared) = declare(&v, dir, strip_path, warn)?;
            if out.declared.contains_key(&name) {
                return Err(v.err(
                    "name",
                    format!("mesh '{}' is defined twice", printable(&name)),
                ));
            }
            out.declared.insert(name, declared);
        }
        Ok(out)
    }

    /// The mesh `name`, read and processed on first use; `hull` when the geom collides.
    pub fn get(
        &mut self,
        v: &View<'_>,
        name: &str,
        hull: bool,
    ) -> Result<(&Processed, Option<Shape>)> {
        if !self.done.contains_key(name) {
            let d = self
                .declared
                .get(name)
                .ok_or_else(|| v.err("mesh", format!("no mesh asset '{}'", printable(name))))?;
            let p = process(d)?;
            self.done.insert(name.to_string(), p);
        }
        let p = self.done.get_mut(name).expect("just inserted");
        if hull && p.hull.is_none() {
            let shape = Shape::convex_hull(&p.points).map_err(|e| {
                let d = &self.declared[name];
                d.elem.err(format!(
                    "has no volume to take a convex hull of ({})",
                    SceneError::from_engine(e, "").reason
                ))
            })?;
            p.hull = Some(shape);
        }
        let shape = if hull { p.hull.clone() } else { None };
        Ok((&self.done[name], shape))
    }
}

/// One `<mesh>`: its name (the file's stem when unnamed) and settings.
fn declare(
    v: &View<'_>,
    dir: &Path,
    strip_path: bool,
    warn: &mut Warnings,
) -> Result<(String, Declared)> {
    let file = v.elem.own("file");
    let name = match (v.elem.own("name"), file) {
        (Some(n), _) => n.to_string(),
        (None, Some(f)) => Path::new(f)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        (None, None) => return Err(v.err("name", "missing (and no file to name it after)")),
    };
    let file = file.map(|f| {
        let f = Path::new(f);
        match (strip_path, f.file_name()) {
            (true, Some(base)) => dir.join(base),
            _ => dir.join(f),
        }
    });
    if file.is_none() && v.get("vertex").is_none() {
        return Err(v.err("file", "missing (or vertex)"));
    }
    let scale = v.reals("scale", &[3])?.map_or(Vec3::ONE, |s| vec3(&s));
    if scale.x * scale.y * scale.z == 0.0 {
        return Err(v.err("scale", "must not be zero"));
    }
    let refpos = v.reals("refpos", &[3])?.map_or(Vec3::ZERO, |s| vec3(&s));
    let refquat = match v.reals("refquat", &[4])? {
        None => Quat::IDENTITY,
        Some(q) => {
            let q = Quat::from_xyzw(q[1], q[2], q[3], q[0]);
            if q.length() < 1e-12 {
                return Err(v.err("refquat", "must not be zero"));
            }
            q.normalize()
        }
    };
    let mode = match v.get("inertia") {
        None | Some("legacy") => Mode::Legacy,
        Some("exact") => Mode::Exact,
        Some("convex") => Mode::Convex,
        Some("shell") => {
            warn.add(
                v.elem,
                "mesh inertia=\"shell\": not read (the volume's inertia used)",
            );
            Mode::Legacy
        }
        Some(t) => {
            return Err(v.err(
                "inertia",
                format!(
                    "'{}' is not one of convex, exact, legacy, shell",
                    printable(t)
                ),
            ))
        }
    };
    for key in ["maxhullvert", "smoothnormal", "builtin", "params"] {
        if v.get(key).is_some() {
            warn.add(v.elem, &format!("mesh {key}: not read"));
        }
    }
    let declared = Declared {
        elem: v.elem.clone(),
        file,
        scale,
        refpos,
        refquat,
        mode,
    };
    Ok((name, declared))
}

/// Reads the mesh and computes what its geoms need.
fn process(d: &Declared) -> Result<Processed> {
    let mut mesh = raw(d)?;
    let turn = d.refquat.inverse();
    for p in &mut mesh.vertices {
        *p = turn * (*p - d.refpos) * d.scale;
    }
    // A mirroring scale turns the faces inside out: their winding is reversed.
    if d.scale.x * d.scale.y * d.scale.z < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    if mesh.vertices.len() < 4 {
        return Err(d.elem.err("a mesh needs at least 4 vertices"));
    }
    let (center, unit) = match d.mode {
        Mode::Convex => {
            let hull = tumble::ConvexHull::from_points(&mesh.vertices).map_err(|e| {
                d.elem.err(format!(
                    "has no volume to take a convex hull of ({})",
                    SceneError::from_engine(e, "").reason
                ))
            })?;
            let faces = MeshData {
                vertices: hull.vertices().to_vec(),
                triangles: hull.triangles().to_vec(),
            };
            mass_properties(&faces, false, &d.elem)?
        }
        mode => mass_properties(&mesh, mode == Mode::Legacy, &d.elem)?,
    };
    for p in &mut mesh.vertices {
        *p -= center;
    }
    Ok(Processed {
        points: mesh.vertices,
        triangles: mesh.triangles,
        center,
        unit,
        hull: None,
    })
}

/// The vertices and triangles, from the file or the `vertex`/`face` attributes (no faces:
/// the convex hull's, as MuJoCo makes them).
fn raw(d: &Declared) -> Result<MeshData> {
    if let Some(file) = &d.file {
        return read_mesh(file).map_err(|e| d.elem.err(format!("file: {e}")));
    }
    let v = |key: &str| -> Result<Option<Vec<Real>>> {
        let Some(text) = d.elem.own(key) else {
            return Ok(None);
        };
        text.split_whitespace()
            .map(|w| {
                w.parse::<Real>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        d.elem
                            .err(format!("{key}: '{}' is not a number", printable(w)))
                    })
            })
            .collect::<Result<Vec<Real>>>()
            .map(Some)
    };
    let numbers = v("vertex")?.unwrap_or_default();
    if numbers.len() % 3 != 0 {
        return Err(d
            .elem
            .err("vertex: the number of values must be a multiple of 3"));
    }
    let vertices: Vec<Vec3> = numbers.chunks_exact(3).map(vec3).collect();
    let triangles = match v("face")? {
        Some(f) => faces(d, &f, vertices.len())?,
        None => {
            let hull = tumble::ConvexHull::from_points(&vertices).map_err(|e| {
                d.elem
                    .err(format!("vertex: {}", SceneError::from_engine(e, "").reason))
            })?;
            return Ok(MeshData {
                vertices: hull.vertices().to_vec(),
                triangles: hull.triangles().to_vec(),
            });
        }
    };
    Ok(MeshData {
        vertices,
        triangles,
    })
}

fn faces(d: &Declared, f: &[Real], count: usize) -> Result<Vec<[u32; 3]>> {
    if f.len() % 3 != 0 {
        return Err(d
            .elem
            .err("face: the number of values must be a multiple of 3"));
    }
    f.chunks_exact(3)
        .map(|t| {
            let mut out = [0u32; 3];
            for (slot, x) in out.iter_mut().zip(t) {
                if x.fract() != 0.0 || *x < 0.0 || *x as usize >= count {
                    return Err(d
                        .elem
                        .err(format!("face: index {x} out of range ({count} vertices)")));
                }
                *slot = *x as u32;
            }
            Ok(out)
        })
        .collect()
}

/// Area, centroid and unit normal of a triangle.
fn triangle(a: Vec3, b: Vec3, c: Vec3) -> (Real, Vec3, Vec3) {
    let n = (b - a).cross(c - a);
    let twice = n.length();
    let normal = if twice > 0.0 { n / twice } else { Vec3::ZERO };
    (0.5 * twice, (a + b + c) / 3.0, normal)
}

/// MuJoCo's mesh mass properties at density 1: the centre from pyramids with their apex at
/// the faces' area-weighted centroid, then volume and inertia from pyramids with their apex
/// at that centre. `legacy` counts every pyramid's volume positive.
fn mass_properties(mesh: &MeshData, legacy: bool, elem: &Elem) -> Result<(Vec3, MassProperties)> {
    let tri = |t: &[u32; 3]| t.map(|i| mesh.vertices[i as usize]);
    let (mut area, mut facecen) = (0.0, Vec3::ZERO);
    for t in &mesh.triangles {
        let [a, b, c] = tri(t);
        let (s, centre, _) = triangle(a, b, c);
        area += s;
        facecen += s * centre;
    }
    if area <= 0.0 {
        return Err(elem.err("mesh surface area is zero"));
    }
    facecen /= area;
    let signed = |v: Real| if legacy { v.abs() } else { v };
    let (mut volume, mut com) = (0.0, Vec3::ZERO);
    for t in &mesh.triangles {
        let [a, b, c] = tri(t);
        let (s, centre, normal) = triangle(a, b, c);
        let v = signed((centre - facecen).dot(normal) * s / 3.0);
        volume += v;
        com += v * (0.75 * centre + 0.25 * facecen);
    }
    check_volume(volume, elem)?;
    com /= volume;
    // Second moments ∫ x_j x_k of pyramids from the centre (apex at the origin).
    let (mut volume, mut p) = (0.0, Mat3::ZERO);
    for t in &mesh.triangles {
        let [a, b, c] = tri(t).map(|x| x - com);
        let (s, centre, normal) = triangle(a, b, c);
        let v = signed(centre.dot(normal) * s / 3.0);
        volume += v;
        let sum = a + b + c;
        let outer = |x: Vec3, y: Vec3| Mat3::from_cols(x * y.x, x * y.y, x * y.z);
        p += (outer(a, a) + outer(b, b) + outer(c, c) + outer(sum, sum)) * (v / 20.0);
    }
    check_volume(volume, elem)?;
    let trace = p.x_axis.x + p.y_axis.y + p.z_axis.z;
    let inertia = Mat3::from_diagonal(Vec3::splat(trace)) - p;
    let inertia = (inertia + inertia.transpose()) * 0.5;
    let (m, _) = tumble::math::symmetric_eigen(inertia);
    let tol = 1e-6 * m.max_element();
    let bad = m.min_element() <= 0.0
        || m.x + m.y + tol < m.z
        || m.y + m.z + tol < m.x
        || m.x + m.z + tol < m.y;
    if bad {
        return Err(
            elem.err("the mesh's inertia is impossible (its faces are not a closed surface)")
        );
    }
    Ok((
        com,
        MassProperties {
            mass: volume,
            center: Vec3::ZERO,
            inertia,
        },
    ))
}

fn check_volume(volume: Real, elem: &Elem) -> Result<()> {
    if volume < 0.0 {
        return Err(elem.err("mesh volume is negative (its triangles face inwards)"));
    }
    if volume.is_nan() || volume <= 1e-15 {
        return Err(elem.err("mesh has no volume"));
    }
    Ok(())
}

/// A mesh's vertices and its triangles of non-zero area (a static mesh's, in the geom's
/// frame), by the test of `TriMesh::new`.
pub(crate) fn nondegenerate(points: &[Vec3], triangles: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    (
        points.to_vec(),
        crate::mesh_file::with_area(points, triangles),
    )
}

/// Shared mesh data a static geom keeps for its triangles, in the geom's frame.
pub(crate) type Triangles = Rc<(Vec<Vec3>, Vec<[u32; 3]>)>;

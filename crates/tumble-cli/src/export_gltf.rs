//! `tumble export-gltf`: a run as a glTF 2.0 asset, for Blender, three.js, model viewers.
//!
//! One node per body, named as the body, holding its shape as a mesh (the triangles
//! `tumble render` draws, tumble-render's `mesh::tessellate`, in the body frame; a plane is
//! one large quad) with its colour as a material; every body that is not static has its
//! translation and rotation keyframed at each recorded step as LINEAR samplers of one
//! animation, times in seconds. The steps recorded are those of `tumble run --out` with
//! the same options (step 0, every K-th, the last), and the keyframes are its x,y,z and
//! qx,qy,qz,qw rounded to f32, glTF's only float: a file and a CSV of one run agree to the
//! last bit of an f32.
//!
//! glTF is y-up and in metres, as Tumble's scenes are by default. A z-up scene (a model
//! from URDF or MJCF, gravity along −z) keeps its bodies' nodes and keyframes as they are,
//! under one more node that turns +z to +y (`--up`).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::{json, Value};
use tumble::{BodyKind, Real, Shape, World};
use tumble_render::mesh::Geometry;
use tumble_render::{Model, Rgb};
use tumble_scene::{printable, RunPlan, Scene, SceneError};

use crate::args::{whole, Span};
use crate::glb::{self, Buffer, ARRAY_BUFFER};
use crate::output::{check_distinct, inputs, scene_file, Staged, Target};
use crate::progress::Progress;
use crate::Failure;

/// The most keyframe data a file may hold (bytes): 1 GiB, a quarter of what a GLB's u32
/// length allows, so meshes fit beside it and base64 (4/3 larger) stays under 2 GiB.
const MAX_KEYFRAME_BYTES: u64 = 1 << 30;
/// Half the side of a plane's quad at the least (m), and how many times the run's reach
/// it spans otherwise.
const PLANE_MIN_HALF_SIDE: f32 = 5.0;
const PLANE_REACH: f32 = 2.0;

/// Options of `tumble export-gltf`.
#[derive(Args, Debug)]
pub struct GltfArgs {
    /// Scene: a built-in name (see `tumble scenes`) or a JSON scene file.
    #[arg(value_name = "SCENE")]
    pub scene: String,

    /// The file to write: FILE.glb (binary glTF) or FILE.gltf (JSON with the binary data
    /// embedded as base64); written as FILE.partial and renamed when complete.
    #[arg(long, value_name = "FILE.glb")]
    pub out: PathBuf,

    /// --duration, --steps, --dt.
    #[command(flatten)]
    pub span: Span,

    /// Keyframe every K-th step; step 0 and the last step are always keyframed (and, when
    /// a step fails, the last good one), as `tumble run --every` records them.
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1,
        allow_negative_numbers = true,
        value_parser = |t: &str| whole(t, 1, u64::MAX)
    )]
    pub every: u64,

    /// Threads the steps run on (default: TUMBLE_THREADS, else every core); results are
    /// bit-identical for every count.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = crate::args::threads)]
    pub threads: Option<usize>,

    /// The scene's up axis: y (written as it is) or z (the bodies' nodes placed under one
    /// node "z-up" that turns +z to glTF's +y, so models from URDF or MJCF files stand
    /// up in viewers); auto, the default: z when gravity points mostly along −z.
    #[arg(long, value_name = "AXIS", default_value = "auto", value_parser = ["auto", "y", "z"])]
    pub up: String,

    /// Print nothing on standard output and show no progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The two ways of writing the asset, chosen by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Format {
    Glb,
    Gltf,
}

impl Format {
    fn of(path: &Path) -> Result<Format, Failure> {
        let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
        match ext.as_deref() {
            Some("glb") => Ok(Format::Glb),
            Some("gltf") => Ok(Format::Gltf),
            _ => Err(Failure::Input(format!(
                "out: '{}': must end in .glb (binary glTF) or .gltf (JSON, buffer embedded)",
                printable(&path.display().to_string())
            ))),
        }
    }
}

/// `tumble export-gltf`. Everything that can be refused is refused before the run (the
/// path, the scene, the options, a file that would be too large or whose f32 times would
/// not increase); a step that fails ends the run, and the file keeps it up to the last
/// good step (exit 1), as `tumble run` does.
pub fn export(args: &GltfArgs) -> Result<(), Failure> {
    let target = Target::file("out", &args.out)?;
    let format = Format::of(&args.out)?;
    check_distinct(&[&target], &inputs(&scene_file(&args.scene)))?;
    let mut scene = tumble_scene::load(&args.scene)?;
    if let Some(n) = args.threads {
        scene
            .world
            .set_threads(n)
            .map_err(|e| Failure::Input(e.to_string()))?;
    }
    let plan = args.span.plan(&scene)?;
    let moving = scene
        .world
        .bodies()
        .filter(|(_, b)| b.kind() != BodyKind::Static)
        .count();
    check_frames(&plan, args.every, moving)?;
    let (staged, file) = Staged::create(target)?;
    let mut recording = Recording::new(&scene.world);
    let mut progress = Progress::new(plan.steps, "recording", args.quiet);
    let stopped = record(&mut scene, &plan, args.every, &mut recording, &mut progress);
    progress.finish();
    let z_up = match args.up.as_str() {
        "z" => true,
        "y" => false,
        _ => {
            let g = scene.world.gravity();
            g.z < 0.0 && g.z.abs() > g.x.abs().max(g.y.abs())
        }
    };
    let (doc, buffer) = document(&scene, &recording, z_up);
    let bytes = match format {
        Format::Glb => glb::glb(doc, buffer).map_err(|e| Failure::Input(format!("out: {e}")))?,
        Format::Gltf => glb::gltf(doc, buffer),
    };
    let mut out = std::io::BufWriter::new(file);
    out.write_all(&bytes)
        .and_then(|()| out.flush())
        .map_err(|e| staged.target().write_error(e))?;
    drop(out);
    let shown = staged.target().shown().to_string();
    staged.commit()?;
    if !args.quiet {
        writeln!(
            std::io::stdout(),
            "wrote '{shown}' ({} kB: {} bodies, {} keyframes)",
            bytes.len().div_ceil(1024),
            recording.poses.len(),
            recording.times.len()
        )
        .map_err(crate::stdout_failure)?;
    }
    stopped.map_or(Ok(()), Err)
}

/// The steps recorded: 0, every `every`-th and the last.
fn recorded(plan: &RunPlan, every: u64) -> impl Iterator<Item = u64> + '_ {
    let last = plan.steps;
    (0..=last / every)
        .map(move |i| i * every)
        .chain((last % every != 0).then_some(last))
}

/// Refuses, before the run, a recording larger than [`MAX_KEYFRAME_BYTES`] and one whose
/// times, rounded to f32, would not strictly increase (glTF requires it of an
/// animation's input): a long run with a fine step needs a coarser --every.
fn check_frames(plan: &RunPlan, every: u64, moving: usize) -> Result<(), SceneError> {
    let frames = plan.steps / every + 2;
    let bytes = frames.saturating_mul(4 + 28 * moving as u64);
    if bytes > MAX_KEYFRAME_BYTES {
        return Err(SceneError::new(
            "every",
            format!(
                "{frames} keyframes of {moving} moving {} would take {bytes} bytes, more than \
                 the {MAX_KEYFRAME_BYTES} allowed; keyframe fewer steps with a larger --every",
                if moving == 1 { "body" } else { "bodies" }
            ),
        ));
    }
    if moving == 0 {
        // No animation: the times are not written.
        return Ok(());
    }
    let mut before: Option<(u64, f32)> = None;
    for k in recorded(plan, every) {
        let t = f(plan.time_after(k));
        if let Some((j, s)) = before.filter(|(_, s)| t <= *s) {
            return Err(SceneError::new(
                "every",
                format!(
                    "steps {j} and {k} are both at {s} s in f32, glTF's float for animation \
                     times; keyframe fewer steps with a larger --every"
                ),
            ));
        }
        before = Some((k, t));
    }
    Ok(())
}

/// `x` as f32, glTF's float.
#[allow(clippy::unnecessary_cast)] // a no-op in the f32 build
fn f(x: Real) -> f32 {
    x as f32
}

/// Every recorded pose: times, and per body its translations and rotations (x, y, z, w)
/// one frame after another; a static body's first only (it has no animation).
struct Recording {
    times: Vec<f32>,
    poses: Vec<(Vec<f32>, Vec<f32>)>,
    /// Whether each body is animated (not static).
    moving: Vec<bool>,
    /// The farthest any body's surface came from the origin (m), for the planes' size.
    reach: f32,
    /// Each body's distance from its origin to the farthest point of its shape (m).
    radii: Vec<f32>,
}

impl Recording {
    fn new(world: &World) -> Recording {
        let radii = world
            .bodies()
            .map(|(_, b)| match b.shape() {
                Shape::Plane { .. } => 0.0,
                shape => tumble_render::mesh::radius(&tumble_render::mesh::tessellate(
                    shape,
                    f32::INFINITY,
                )),
            })
            .collect();
        Recording {
            times: Vec::new(),
            poses: world.bodies().map(|_| (Vec::new(), Vec::new())).collect(),
            moving: world
                .bodies()
                .map(|(_, b)| b.kind() != BodyKind::Static)
                .collect(),
            reach: 0.0,
            radii,
        }
    }

    /// The world at `time` (s). A time that does not come after the last one in f32
    /// (only the extra frame of a failed run can) replaces the last frame.
    fn push(&mut self, time: Real, world: &World) {
        let t = f(time);
        if self.times.last().is_some_and(|last| t <= *last) {
            self.times.pop();
            for ((p, q), _) in self.poses.iter_mut().zip(&self.moving).filter(|(_, m)| **m) {
                p.truncate(p.len() - 3);
                q.truncate(q.len() - 4);
            }
        }
        let first = self.times.is_empty();
        self.times.push(t);
        let bodies = world.bodies().zip(&mut self.poses).zip(&self.moving);
        for ((((_, body), (p, q)), moving), radius) in bodies.zip(&self.radii) {
            let (x, o) = (body.position(), body.orientation());
            let x = [f(x.x), f(x.y), f(x.z)];
            if first || *moving {
                p.extend(x);
                q.extend([f(o.x), f(o.y), f(o.z), f(o.w)]);
            }
            let r = x.iter().map(|c| c * c).sum::<f32>().sqrt() + radius;
            if r.is_finite() {
                self.reach = self.reach.max(r);
            }
        }
    }
}

/// Steps `scene` through `plan`, recording step 0, every `every`-th step and the last
/// (as `tumble run`'s `step_all`). A failed step records the last good state if it was
/// not, and its failure is returned.
fn record(
    scene: &mut Scene,
    plan: &RunPlan,
    every: u64,
    recording: &mut Recording,
    progress: &mut Progress,
) -> Option<Failure> {
    recording.push(0.0, &scene.world);
    for k in 1..=plan.steps {
        if let Err(e) = scene.step(plan.step_dt(k)) {
            let good = k - 1;
            if good % every != 0 {
                recording.push(plan.time_after(good), &scene.world);
            }
            return Some(crate::sample::step_failure(k, e));
        }
        if k % every == 0 || k == plan.steps {
            recording.push(plan.time_after(k), &scene.world);
        }
        progress.inc(1);
    }
    None
}

/// The glTF document of a recorded run, and its binary data.
fn document(scene: &Scene, recording: &Recording, z_up: bool) -> (Value, Buffer) {
    let colours: Vec<Option<Rgb>> = scene.body_colors.iter().map(|c| c.map(Rgb)).collect();
    let model = Model::new(&scene.world, &colours, f32::INFINITY);
    let half_side = PLANE_MIN_HALF_SIDE.max(PLANE_REACH * recording.reach);
    let mut buffer = Buffer::default();
    let (mut nodes, mut meshes, mut materials) = (vec![], vec![], vec![]);
    let bodies = scene
        .world
        .bodies()
        .zip(&model.bodies)
        .zip(&scene.body_names);
    for (i, (((_, body), drawn), name)) in bodies.enumerate() {
        let (p, q) = &recording.poses[i];
        let kind = match body.kind() {
            BodyKind::Static => "static",
            BodyKind::Kinematic => "kinematic",
            BodyKind::Dynamic => "dynamic",
        };
        let mut node = json!({
            "name": name,
            "translation": p[..3],
            "rotation": q[..4],
            "extras": {"kind": kind},
        });
        let (positions, indices) = shared(&triangles(&drawn.geometry, half_side));
        if !indices.is_empty() {
            let accessor = buffer.floats(&positions, "VEC3", Some(ARRAY_BUFFER));
            let indices = buffer.indices(&indices);
            materials.push(material(name, drawn.colour, !closed(body.shape())));
            meshes.push(json!({
                "name": name,
                "primitives": [{
                    "attributes": {"POSITION": accessor},
                    "indices": indices,
                    "material": materials.len() - 1,
                    "mode": 4,
                }],
            }));
            node["mesh"] = json!(meshes.len() - 1);
        }
        nodes.push(node);
    }
    let title = scene.name.clone().unwrap_or_else(|| "tumble".into());
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("tumble export-gltf ", env!("CARGO_PKG_VERSION")),
        },
    });
    place(&mut doc, nodes, &title, z_up);
    if !meshes.is_empty() {
        doc["meshes"] = Value::Array(meshes);
        doc["materials"] = Value::Array(materials);
    }
    if let Some(animation) = animation(scene, recording, &title, &mut buffer) {
        doc["animations"] = json!([animation]);
    }
    (doc, buffer)
}

/// The scene of `doc`: the bodies' `nodes`, or, when the scene is `z_up`, one node above
/// them turning it −90° about x, which takes its +z to glTF's +y (and +y to −z). Nothing
/// when there are no bodies (glTF wants no empty list).
fn place(doc: &mut Value, mut nodes: Vec<Value>, title: &str, z_up: bool) {
    if nodes.is_empty() {
        return;
    }
    let bodies: Vec<usize> = (0..nodes.len()).collect();
    let roots = if z_up {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        nodes.push(json!({"name": "z-up", "rotation": [-h, 0.0, 0.0, h], "children": bodies}));
        vec![nodes.len() - 1]
    } else {
        bodies
    };
    doc["scene"] = json!(0);
    doc["scenes"] = json!([{"name": title, "nodes": roots}]);
    doc["nodes"] = Value::Array(nodes);
}

/// One animation with a translation and a rotation channel per body that is not static,
/// all on the one time accessor; `None` when nothing moves.
fn animation(
    scene: &Scene,
    recording: &Recording,
    title: &str,
    buffer: &mut Buffer,
) -> Option<Value> {
    let moving: Vec<usize> = scene
        .world
        .bodies()
        .enumerate()
        .filter(|(_, (_, b))| b.kind() != BodyKind::Static)
        .map(|(i, _)| i)
        .collect();
    if moving.is_empty() {
        return None;
    }
    let input = buffer.floats(&recording.times, "SCALAR", None);
    let (mut samplers, mut channels) = (vec![], vec![]);
    for i in moving {
        let (p, q) = &recording.poses[i];
        for (path, data, kind) in [("translation", p, "VEC3"), ("rotation", q, "VEC4")] {
            let output = buffer.floats(data, kind, None);
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
            channels
                .push(json!({"sampler": samplers.len() - 1, "target": {"node": i, "path": path}}));
        }
    }
    Some(json!({"name": title, "samplers": samplers, "channels": channels}))
}

/// Triangles given by their corners (x, y, z, three per triangle) as distinct vertices
/// and indices into them: corners with the same f32 coordinates become one vertex (−0
/// and +0 alike), so closed shapes come out watertight and files a third the size. The
/// vertices are numbered in order of first use, so the result depends on nothing else.
fn shared(corners: &[f32]) -> (Vec<f32>, Vec<u32>) {
    let mut number: BTreeMap<[u32; 3], u32> = BTreeMap::new();
    let mut vertices = Vec::new();
    let mut indices = Vec::with_capacity(corners.len() / 3);
    for p in corners.chunks_exact(3) {
        // Adding +0 turns −0 into +0 and leaves every other value as it is.
        let p = [p[0] + 0.0, p[1] + 0.0, p[2] + 0.0];
        let next = number.len() as u32;
        let i = *number.entry(p.map(f32::to_bits)).or_insert(next);
        if i == next {
            vertices.extend(p);
        }
        indices.push(i);
    }
    (vertices, indices)
}

/// The corners of `geometry`'s triangles, three per triangle. No normals: glTF viewers
/// shade a mesh without them flat, as `tumble render` does. A plane is a square of
/// half side `half_side` on its surface, centred on the point nearest the body origin,
/// counter-clockwise seen from outside.
fn triangles(geometry: &Geometry, half_side: f32) -> Vec<f32> {
    match geometry {
        Geometry::Solid(tris) => tris.iter().flatten().flat_map(|p| p.to_array()).collect(),
        Geometry::Plane { normal, offset } => {
            let n = *normal;
            let centre = n * *offset;
            // u × v = n: the corners below run counter-clockwise seen from the normal.
            let u = n.any_orthonormal_vector() * half_side;
            let v = n.cross(u);
            let c = [
                centre - u - v,
                centre + u - v,
                centre + u + v,
                centre - u + v,
            ];
            [c[0], c[1], c[2], c[0], c[2], c[3]]
                .iter()
                .flat_map(|p| p.to_array())
                .collect()
        }
    }
}

/// Whether `shape`'s triangles close a solid, so that back faces need not be drawn.
fn closed(shape: &Shape) -> bool {
    match shape {
        Shape::Plane { .. } | Shape::TriMesh(_) | Shape::HeightField(_) => false,
        Shape::Compound(children) => children.iter().all(|c| closed(&c.shape)),
        _ => true,
    }
}

/// A body's material: its colour as `tumble render` paints it, as glTF's base colour
/// (linear, so the sRGB bytes are decoded), not metallic, fairly rough.
fn material(name: &str, colour: Rgb, double_sided: bool) -> Value {
    let linear = colour.0.map(|c| {
        let c = f32::from(c) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    });
    json!({
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [linear[0], linear[1], linear[2], 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 0.8,
        },
        "doubleSided": double_sided,
        "extras": {"color": colour.hex()},
    })
}

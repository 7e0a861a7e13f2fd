//! `World.render`: a picture of the world now as an (H, W, 3) uint8 numpy array, drawn by
//! tumble-render exactly as `tumble render` draws a frame (flat-shaded solids, planes as a
//! ground grid). Gymnasium's `render_mode="rgb_array"` (tumble.envs) is built on it.

use glam::Vec3 as V3;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use tumble_render::{Camera, Model, Overlays, Renderer, Snapshot};

use crate::convert::{invalid, vec3};
use crate::world::PyWorld;

/// The largest side of a picture (pixels): 4096 × 4096 × 4 bytes is 64 MiB.
const MAX_SIDE: u32 = 4096;

#[allow(clippy::unnecessary_cast)] // a no-op in the f32 build
fn narrow(v: tumble::Vec3) -> V3 {
    V3::new(v.x as f32, v.y as f32, v.z as f32)
}

fn side(value: i64, field: &str) -> PyResult<u32> {
    if (1..=i64::from(MAX_SIDE)).contains(&value) {
        Ok(value as u32)
    } else {
        Err(invalid(
            field,
            format!("must be a whole number from 1 to {MAX_SIDE}, got {value}"),
        ))
    }
}

fn point(obj: Option<&Bound<'_, PyAny>>, field: &str) -> PyResult<Option<V3>> {
    let Some(o) = obj else { return Ok(None) };
    let v = narrow(vec3(o, field)?);
    if v.is_finite() {
        Ok(Some(v))
    } else {
        Err(invalid(
            field,
            "must be finite numbers (and within f32's range)",
        ))
    }
}

/// What the caller asked for, checked.
struct View {
    width: u32,
    height: u32,
    eye: Option<V3>,
    target: Option<V3>,
    overlays: Overlays,
}

/// The camera: the one asked for, or one framing the moving bodies now; and the size of
/// what is in view (m), which sets the ground grid and how finely shapes are cut.
fn choose_camera(
    world: &tumble::World,
    snapshot: &Snapshot,
    view: &View,
) -> PyResult<(Camera, f32)> {
    let bounds = Model::new(world, &[], f32::INFINITY).bounds(std::slice::from_ref(snapshot));
    let (min, max) = bounds.unwrap_or((V3::splat(-1.0), V3::splat(1.0)));
    let up = -narrow(world.gravity());
    let auto = Camera::framing_up(min, max, up, view.width, view.height);
    let target = view.target.unwrap_or(auto.target);
    let eye = view.eye.unwrap_or(target + (auto.eye - auto.target));
    let camera = Camera::look_at_up(eye, target, up, view.width, view.height)
        .ok_or_else(|| invalid("camera", "must differ from target"))?;
    let scale = match (view.eye, view.target) {
        (Some(e), Some(t)) => (e - t).length().max(0.5),
        _ => (max - min).length().max(0.5),
    };
    Ok((camera, scale))
}

#[pymethods]
impl PyWorld {
    /// The world now as an (height, width, 3) uint8 RGB array.
    #[pyo3(signature = (width=320, height=240, *, camera=None, target=None, contacts=false, joints=false, time=false))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        width: i64,
        height: i64,
        camera: Option<&Bound<'py, PyAny>>,
        target: Option<&Bound<'py, PyAny>>,
        contacts: bool,
        joints: bool,
        time: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let view = View {
            width: side(width, "width")?,
            height: side(height, "height")?,
            eye: point(camera, "camera")?,
            target: point(target, "target")?,
            overlays: Overlays {
                contacts,
                joints,
                time,
            },
        };
        let rgb = {
            let guard = self.lock()?;
            let world = &guard.world;
            let snapshot = Snapshot::capture(world);
            let (cam, scale) = choose_camera(world, &snapshot, &view)?;
            let model = Model::new(world, &[], scale / 12.0);
            let pixmap = Renderer::new(model, cam, view.overlays, scale).render(&snapshot);
            // Every pixel is opaque (the background is), so premultiplied RGBA is RGB.
            pixmap
                .data()
                .chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
                .collect::<Vec<u8>>()
        };
        let shape = [view.height as usize, view.width as usize, 3];
        PyArray1::from_vec(py, rgb)
            .reshape(shape)
            .map(|a| a.into_any())
    }
}

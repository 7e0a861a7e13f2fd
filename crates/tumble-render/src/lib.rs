//! Headless pictures of Tumble worlds, with no display and no GPU: shapes tessellated
//! ([`mesh`]), seen through a pinhole [`camera`], filled far to near with tiny-skia and
//! shaded flat ([`raster`]), written as PNG, GIF, numbered PNGs or MP4 ([`encode`]); and
//! the plots of `tumble analyze --plot` and `tumble plot` ([`plot`]).
//!
//! ```
//! use tumble_render::{Camera, Model, Overlays, Renderer, Snapshot};
//! let scene = tumble_scene::load("free_fall").unwrap();
//! let model = Model::new(&scene.world, &[], 0.1);
//! let snapshot = Snapshot::capture(&scene.world);
//! let (min, max) = model.bounds(std::slice::from_ref(&snapshot)).unwrap();
//! let camera = Camera::framing(min, max, 64, 48);
//! let picture = Renderer::new(model, camera, Overlays::default(), 1.0).render(&snapshot);
//! assert_eq!(picture.width(), 64);
//! ```
#![warn(missing_docs)]

pub mod camera;
mod convert;
pub mod encode;
pub mod mesh;
pub mod model;
pub mod plot;
pub mod raster;
pub mod text;

pub use camera::Camera;
pub use encode::{Encoder, Output};
pub use model::{palette, Model, Rgb, Snapshot};
pub use raster::{Overlays, Renderer, BACKGROUND};
pub use tiny_skia::Pixmap;

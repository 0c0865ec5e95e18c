//! glint: a Whitted-style ray tracer. This library renders headless; the
//! viewer (feature `gui`) and the command line are layers on top of it.
//!
//! ```no_run
//! let scene = glint::scene::load(std::path::Path::new("scenes/sphere.toml"))?;
//! let settings = scene.render_settings();
//! // What the settings choose ray queries to go through (the octree, a
//! // BVH or none), built once, with the light buffer shadow rays ask.
//! let accel = glint::render::Accelerator::build(&scene, &settings, Default::default())?;
//! let renderer = glint::render::Renderer::new(&scene, &accel, settings)?;
//! let (frame, _counts) = renderer.render(false, None);
//! glint::export::save_png(&frame, std::path::Path::new("sphere.png"), None)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![forbid(unsafe_code)]
// NaN guards are written `!(x > 0.0)` on purpose: the negated comparison is
// true for NaN, which `x <= 0.0` is not.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod camera;
pub mod camera_path;
pub mod color;
pub mod export;
pub mod image;
pub mod limits;
pub mod material;
pub mod math;
pub mod render;
pub mod report;
pub mod scene;
pub mod settings;
pub mod shapes;
pub mod simd;
pub mod stats;
pub mod texture;
#[cfg(feature = "gui")]
pub mod viewer;

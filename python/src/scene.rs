//! `glint.Scene` (native half): a loaded scene, its edits by scene-file
//! key, and what it renders: frames, a pixel's ray tree, an octree's
//! statistics and prediction, a benchmark.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use glint::accel::{Octree, OctreeParams};
use glint::export::SceneEdits;
use glint::render::{
    Accelerator, LightBufferSource, PassInfo, PassOptions, PassWatch, Renderer, Reuse,
};
use glint::report::{RenderStats, RenderTimes, TraceReport};
use glint::scene::{KeyValue, Scene};
use glint::settings::{Accel, RenderSettings};

use crate::errors::{edit_error, octree_error, render_error};
use crate::frame::{FrameHeader, PyFrame};

/// A camera as Python passes it: eye, lookat, up, fov (degrees).
type CameraTuple = ([f64; 3], [f64; 3], [f64; 3], f64);
/// A frame's place in a sequence: index, count, time along the path.
type FrameTuple = (u32, u32, Option<f64>);

fn camera_spec((eye, lookat, up, fov): CameraTuple) -> PyResult<glint::camera::CameraSpec> {
    use glint::math::DVec3;
    let spec = glint::camera::CameraSpec {
        eye: DVec3::from_array(eye),
        lookat: DVec3::from_array(lookat),
        up: DVec3::from_array(up),
        fov,
    };
    spec.check()
        .map_err(|(key, message)| PyValueError::new_err(format!("camera {key}: {message}")))?;
    Ok(spec)
}

fn camera_tuple(c: &glint::camera::CameraSpec) -> CameraTuple {
    (
        c.eye.to_array(),
        c.lookat.to_array(),
        c.up.to_array(),
        c.fov,
    )
}

fn recorded_frame((index, count, time): FrameTuple) -> PyResult<glint::export::RecordedFrame> {
    if index >= count {
        return Err(PyValueError::new_err(format!(
            "frame {index} of {count}: a frame's index is below the sequence's count"
        )));
    }
    Ok(glint::export::RecordedFrame { index, count, time })
}
use crate::interrupt::run_stoppable;
use crate::options::{RenderOptions, count, thread_pool};

/// A built octree kept for the renders after it: lights, materials and
/// the camera change no cell, so only new parameters build another.
#[derive(Clone)]
struct CachedOctree {
    params: OctreeParams,
    tree: Arc<Octree>,
    build_s: f64,
}

#[pyclass(name = "Scene", module = "glint._glint")]
pub struct PyScene {
    scene: Scene,
    /// The path as the caller gave it: statistics name the scene by it.
    name: String,
    load_s: f64,
    /// The scene file's own lights and materials: an export records the
    /// edited ones only when they differ.
    loaded: SceneEdits,
    octree: Option<CachedOctree>,
}

impl PyScene {
    pub fn new(scene: Scene, name: String, load_s: f64) -> Self {
        let loaded = SceneEdits {
            lights: scene.lights.clone(),
            materials: scene.materials.clone(),
        };
        Self {
            scene,
            name,
            load_s,
            loaded,
            octree: None,
        }
    }

    /// The lights and materials as edited, if they are not the file's.
    fn edits(&self) -> Option<SceneEdits> {
        (self.scene.lights != self.loaded.lights || self.scene.materials != self.loaded.materials)
            .then(|| SceneEdits {
                lights: self.scene.lights.clone(),
                materials: self.scene.materials.clone(),
            })
    }
}

/// Abandons a render once `stop` is set (asked before each tile).
struct StopWatch<'a>(&'a AtomicBool);

impl PassWatch for StopWatch<'_> {
    fn start_tile(&self, _pass: &PassInfo) -> bool {
        !self.0.load(Ordering::Relaxed)
    }
}

/// Stops a benchmark between timed passes once `stop` is set.
struct BenchStop<'a>(&'a AtomicBool);

impl glint::report::BenchWatch for BenchStop<'_> {
    fn stop(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// What a render needs from the scene object, taken in one short borrow
/// so the GIL can be released without holding it.
struct Snapshot {
    scene: Scene,
    name: String,
    load_s: f64,
    edits: Option<SceneEdits>,
    cached: Option<CachedOctree>,
}

fn snapshot(slf: &Bound<'_, PyScene>) -> Snapshot {
    let me = slf.borrow();
    Snapshot {
        scene: me.scene.clone(),
        name: me.name.clone(),
        load_s: me.load_s,
        edits: me.edits(),
        cached: me.octree.clone(),
    }
}

/// What a render's ray queries go through, built as `glint render` builds
/// it: the octree kept between renders (when the settings ask for it),
/// and no light buffer for a counted render (it would hide the
/// accelerator's work). Returns it and the seconds its parts took.
fn accelerator(
    slf: &Bound<'_, PyScene>,
    snap: &Snapshot,
    settings: &RenderSettings,
    pool: &rayon::ThreadPool,
    counted: bool,
) -> PyResult<(Accelerator, f64)> {
    let (octree, octree_s) = if settings.accel == Accel::Octree {
        let (tree, seconds) = octree_for(slf, snap, pool)?;
        (Some(tree), seconds)
    } else {
        (None, 0.0)
    };
    let reuse = Reuse {
        octree,
        bvh: None,
        light_buffer: if counted {
            LightBufferSource::Given(None)
        } else {
            LightBufferSource::Build
        },
    };
    let accel = pool
        .install(|| Accelerator::build(&snap.scene, settings, reuse))
        .map_err(|e| octree_error(&e))?;
    let build_s = octree_s + accel.build_seconds().0;
    Ok((accel, build_s))
}

/// The scene's octree, built with the GIL released unless the last one
/// built has the same parameters. Returns it and its build's seconds.
fn octree_for(
    slf: &Bound<'_, PyScene>,
    snap: &Snapshot,
    pool: &rayon::ThreadPool,
) -> PyResult<(Arc<Octree>, f64)> {
    let params = snap.scene.octree_params;
    if let Some(c) = snap.cached.as_ref().filter(|c| c.params == params) {
        return Ok((c.tree.clone(), c.build_s));
    }
    let (tree, build_s) = slf.py().detach(|| {
        let start = Instant::now();
        let tree = pool.install(|| snap.scene.build_octree());
        (tree, start.elapsed().as_secs_f64())
    });
    let tree = Arc::new(tree.map_err(|e| octree_error(&e))?);
    slf.borrow_mut().octree = Some(CachedOctree {
        params,
        tree: tree.clone(),
        build_s,
    });
    Ok((tree, build_s))
}

fn key_value(value: &Bound<'_, PyAny>) -> PyResult<KeyValue> {
    // bool before int: Python's True is an int too.
    if let Ok(b) = value.cast::<pyo3::types::PyBool>() {
        return Ok(KeyValue::Switch(b.is_true()));
    }
    if let Ok(n) = value.cast::<pyo3::types::PyInt>() {
        return Ok(KeyValue::Integer(n.extract()?));
    }
    if let Ok(x) = value.extract::<f64>() {
        return Ok(KeyValue::Number(x));
    }
    value
        .extract::<[f64; 3]>()
        .map(KeyValue::Triple)
        .map_err(|_| {
            PyValueError::new_err(format!(
                "expected a number, three numbers, a whole number or a bool, got {}",
                value.repr().map_or_else(|_| "?".into(), |r| r.to_string())
            ))
        })
}

fn to_python<'py>(py: Python<'py>, value: KeyValue) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        KeyValue::Number(x) => x.into_pyobject(py)?.into_any(),
        KeyValue::Integer(n) => n.into_pyobject(py)?.into_any(),
        KeyValue::Switch(b) => b.into_pyobject(py)?.to_owned().into_any(),
        KeyValue::Triple(t) => PyTuple::new(py, t)?.into_any(),
    })
}

fn json<T: serde::Serialize>(value: &T) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

#[pymethods]
impl PyScene {
    /// The scene's name: its path as given to `load`.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Seconds the scene took to load.
    #[getter]
    fn load_s(&self) -> f64 {
        self.load_s
    }

    /// The value of a scene-file key (`camera.fov`, `lights[0].color`).
    fn get<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        let value = self.scene.get_key(key).map_err(|e| edit_error(py, &e))?;
        to_python(py, value)
    }

    /// Sets a scene-file key, held to the limits scene files are held to.
    fn set(&mut self, py: Python<'_>, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let value = key_value(value)?;
        self.scene
            .set_key(key, value)
            .map_err(|e| edit_error(py, &e))
    }

    /// Every key `get` reads, in scene-file order.
    fn keys(&self) -> Vec<String> {
        self.scene.keys()
    }

    fn light_count(&self) -> usize {
        self.scene.lights.len()
    }

    fn material_names(&self) -> Vec<String> {
        self.scene
            .materials
            .iter()
            .map(|m| m.name.clone())
            .collect()
    }

    /// What loading dropped, skipped or could not read, one sentence each.
    fn notes(&self) -> Vec<String> {
        self.scene.notes()
    }

    /// Shapes by kind, e.g. `[("sphere", 3), ("triangle", 12)]`.
    fn shape_counts(&self) -> Vec<(&'static str, usize)> {
        self.scene.shape_counts()
    }

    /// An independent copy: its edits do not reach this scene.
    fn copy(&self) -> Self {
        Self {
            scene: self.scene.clone(),
            name: self.name.clone(),
            load_s: self.load_s,
            loaded: self.loaded.clone(),
            octree: self.octree.clone(),
        }
    }

    #[pyo3(signature = (width=None, height=None, samples=None, aa=None, octree=None,
        accel=None, max_depth=None, view=None, threads=None, stats=false, protocol=None, colors=None,
        sides=None, cancel=None, camera=None, frame=None, textures=None))]
    #[allow(clippy::too_many_arguments)]
    fn render(
        slf: &Bound<'_, Self>,
        width: Option<i64>,
        height: Option<i64>,
        samples: Option<i64>,
        aa: Option<&str>,
        octree: Option<bool>,
        accel: Option<&str>,
        max_depth: Option<i64>,
        view: Option<&str>,
        threads: Option<usize>,
        stats: bool,
        protocol: Option<&str>,
        colors: Option<&str>,
        sides: Option<&str>,
        cancel: Option<&Bound<'_, PyAny>>,
        camera: Option<CameraTuple>,
        frame: Option<FrameTuple>,
        textures: Option<bool>,
    ) -> PyResult<PyFrame> {
        let py = slf.py();
        let mut snap = snapshot(slf);
        if let Some(c) = camera {
            snap.scene.camera = camera_spec(c)?;
        }
        let sequence = frame.map(recorded_frame).transpose()?;
        let options = RenderOptions {
            width: count("width", width)?,
            height: count("height", height)?,
            samples: count("samples", samples)?,
            aa,
            octree,
            accel,
            max_depth: count("max_depth", max_depth)?,
            view,
            protocol,
            colors,
            sides,
            textures,
        };
        let settings = options.settings(&snap.scene)?;
        let pool = thread_pool(threads)?;
        let (accel, build_s) = accelerator(slf, &snap, &settings, &pool, stats)?;
        let renderer =
            Renderer::new(&snap.scene, &accel, settings).map_err(|e| render_error(&e))?;
        glint::render::memory::check_memory(
            &settings,
            accel.memory_bytes() + snap.scene.texture_bytes(),
        )
        .map_err(|e| render_error(&e))?;
        let stop = AtomicBool::new(false);
        let pass_options = PassOptions {
            count_work: stats,
            progressive: false,
        };
        let (rendered, render_s) = run_stoppable(py, cancel, &stop, || {
            let start = Instant::now();
            let rendered = pool.install(|| renderer.render_frame(pass_options, &StopWatch(&stop)));
            (rendered, start.elapsed().as_secs_f64())
        })?;
        let rendered =
            rendered.ok_or_else(|| PyRuntimeError::new_err("the render was abandoned"))?;
        let stats_json = if stats {
            let times = RenderTimes {
                load_s: snap.load_s,
                build_s,
                render_s,
            };
            let threads = pool.current_num_threads();
            let report = RenderStats::new(
                &snap.name,
                &snap.scene,
                &settings,
                threads,
                &accel,
                &rendered,
                times,
            );
            Some(json(&report)?)
        } else {
            None
        };
        Ok(PyFrame::new(
            rendered.frame,
            settings,
            snap.scene,
            snap.name,
            snap.edits,
            stats_json,
        )
        .in_sequence(sequence))
    }

    /// A frame this scene rendered elsewhere (a Dask worker's), from
    /// `Frame.parts()`, with the settings, camera and sequence place it was
    /// rendered with, so its PNG and record are the ones a local render
    /// writes.
    #[pyo3(signature = (header, pixels, width=None, height=None, samples=None, aa=None,
        octree=None, accel=None, max_depth=None, view=None, protocol=None, colors=None,
        sides=None, camera=None, frame=None, textures=None))]
    #[allow(clippy::too_many_arguments)]
    fn frame_from_parts(
        slf: &Bound<'_, Self>,
        header: &str,
        pixels: &[u8],
        width: Option<i64>,
        height: Option<i64>,
        samples: Option<i64>,
        aa: Option<&str>,
        octree: Option<bool>,
        accel: Option<&str>,
        max_depth: Option<i64>,
        view: Option<&str>,
        protocol: Option<&str>,
        colors: Option<&str>,
        sides: Option<&str>,
        camera: Option<CameraTuple>,
        frame: Option<FrameTuple>,
        textures: Option<bool>,
    ) -> PyResult<PyFrame> {
        let mut snap = snapshot(slf);
        if let Some(c) = camera {
            snap.scene.camera = camera_spec(c)?;
        }
        let options = RenderOptions {
            width: count("width", width)?,
            height: count("height", height)?,
            samples: count("samples", samples)?,
            aa,
            octree,
            accel,
            max_depth: count("max_depth", max_depth)?,
            view,
            protocol,
            colors,
            sides,
            textures,
        };
        let settings = options.settings(&snap.scene)?;
        let header: FrameHeader = serde_json::from_str(header)
            .map_err(|e| PyValueError::new_err(format!("not a frame's header: {e}")))?;
        let rendered = PyFrame::from_parts(&header, pixels)
            .filter(|f| {
                (f.width, f.height, f.view) == (settings.width, settings.height, settings.view)
            })
            .ok_or_else(|| PyValueError::new_err("the pixels are not a frame of these settings"))?;
        Ok(
            PyFrame::new(rendered, settings, snap.scene, snap.name, snap.edits, None)
                .in_sequence(frame.map(recorded_frame).transpose()?),
        )
    }

    /// Sets the camera at once (eye, lookat, up, fov), checked as a scene
    /// file's is.
    fn set_camera(&mut self, camera: CameraTuple) -> PyResult<()> {
        self.scene.camera = camera_spec(camera)?;
        Ok(())
    }

    /// `frames` cameras of a turntable about the lookat point (the
    /// camera's up is the axis), frame 0 the scene's camera.
    fn turntable(&self, frames: i64) -> PyResult<Vec<CameraTuple>> {
        let n = count("n", Some(frames))?.unwrap_or(0);
        if !(1..=glint::camera_path::MAX_FRAMES).contains(&n) {
            return Err(PyValueError::new_err(format!(
                "a turntable has from 1 to 1,000,000 frames, got {frames}"
            )));
        }
        Ok(glint::camera_path::turntable(&self.scene.camera, n)
            .iter()
            .map(camera_tuple)
            .collect())
    }

    /// The scene's camera path at `fps` for `seconds` (or `frames`), as
    /// `glint render --path` renders it: (time, camera) pairs.
    #[pyo3(signature = (fps=None, seconds=None, frames=None))]
    fn camera_path(
        &self,
        fps: Option<f64>,
        seconds: Option<f64>,
        frames: Option<i64>,
    ) -> PyResult<Vec<(f64, CameraTuple)>> {
        let Some(path) = &self.scene.camera_path else {
            return Err(PyValueError::new_err(format!(
                "{} has no camera path: give it [[camera.keyframes]] (time, eye, lookat), \
                 or use turntable(n)",
                self.name
            )));
        };
        let timing = glint::camera_path::FrameTiming {
            fps,
            seconds,
            frames: count("frames", frames)?,
        };
        let frames = path
            .frames(&timing)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(frames.iter().map(|(t, c)| (*t, camera_tuple(c))).collect())
    }

    /// The scene's name and the text it was parsed from, to load it again
    /// in another process (`glint._glint.from_source`).
    fn source(&self) -> (String, String) {
        (self.name.clone(), self.scene.source_text.to_string())
    }

    /// The `--trace-pixel` JSON of pixel (x, y) of the image these
    /// settings make.
    #[pyo3(signature = (x, y, width=None, height=None, octree=None, accel=None, max_depth=None,
        protocol=None, colors=None, sides=None, textures=None))]
    #[allow(clippy::too_many_arguments)]
    fn trace_pixel(
        slf: &Bound<'_, Self>,
        x: u32,
        y: u32,
        width: Option<i64>,
        height: Option<i64>,
        octree: Option<bool>,
        accel: Option<&str>,
        max_depth: Option<i64>,
        protocol: Option<&str>,
        colors: Option<&str>,
        sides: Option<&str>,
        textures: Option<bool>,
    ) -> PyResult<String> {
        let snap = snapshot(slf);
        let options = RenderOptions {
            width: count("width", width)?,
            height: count("height", height)?,
            octree,
            accel,
            max_depth: count("max_depth", max_depth)?,
            protocol,
            colors,
            sides,
            textures,
            ..RenderOptions::default()
        };
        let settings = glint::report::trace_settings(options.settings(&snap.scene)?);
        let pool = thread_pool(None)?;
        let (accel, _) = accelerator(slf, &snap, &settings, &pool, true)?;
        let renderer =
            Renderer::new(&snap.scene, &accel, settings).map_err(|e| render_error(&e))?;
        let report = TraceReport::new(&renderer, &snap.scene, &snap.name, x, y)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        json(&report)
    }

    /// Builds the octree with these parameters (the scene's where not
    /// given; the scene keeps its own) and returns the JSON of its
    /// parameters, statistics, build time and predicted cost per ray.
    #[pyo3(signature = (max_depth=None, leaf_size=None, cost_driven=None, max_duplication=None,
        memory_budget_mib=None, threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn octree(
        &self,
        py: Python<'_>,
        max_depth: Option<i64>,
        leaf_size: Option<i64>,
        cost_driven: Option<bool>,
        max_duplication: Option<i64>,
        memory_budget_mib: Option<i64>,
        threads: Option<usize>,
    ) -> PyResult<String> {
        // Through the scene's own keys, so the limits and messages are a
        // scene file's.
        let mut scene = self.scene.clone();
        let integers = [
            ("octree.max_depth", max_depth),
            ("octree.leaf_size", leaf_size),
            ("octree.max_duplication", max_duplication),
            ("octree.memory_budget_mib", memory_budget_mib),
        ];
        for (key, value) in integers {
            if let Some(n) = value {
                scene
                    .set_key(key, KeyValue::Integer(n))
                    .map_err(|e| edit_error(py, &e))?;
            }
        }
        if let Some(c) = cost_driven {
            scene.octree_params.cost_driven = c;
        }
        let pool = thread_pool(threads)?;
        let (tree, build_s) = py.detach(|| {
            let start = Instant::now();
            let tree = pool.install(|| scene.build_octree());
            (tree, start.elapsed().as_secs_f64())
        });
        let tree = tree.map_err(|e| octree_error(&e))?;
        json(&serde_json::json!({
            "octree_params": scene.octree_params,
            "octree_stats": tree.stats(),
            "build_s": build_s,
            "predicted": tree.predicted_cost(),
        }))
    }

    /// The `glint bench --format json` record of this scene.
    #[pyo3(signature = (width=None, height=None, samples=None, aa=None, max_depth=None,
        view=None, protocol=None, colors=None, sides=None, repeat=3, threads=None,
        octree_only=false, brute_force_budget=4e9, cancel=None))]
    #[allow(clippy::too_many_arguments)]
    fn bench(
        slf: &Bound<'_, Self>,
        width: Option<i64>,
        height: Option<i64>,
        samples: Option<i64>,
        aa: Option<&str>,
        max_depth: Option<i64>,
        view: Option<&str>,
        protocol: Option<&str>,
        colors: Option<&str>,
        sides: Option<&str>,
        repeat: u32,
        threads: Option<usize>,
        octree_only: bool,
        brute_force_budget: f64,
        cancel: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<String> {
        if repeat == 0 {
            return Err(PyValueError::new_err("repeat must be at least 1"));
        }
        let snap = snapshot(slf);
        let options = RenderOptions {
            width: count("width", width)?,
            height: count("height", height)?,
            samples: count("samples", samples)?,
            aa,
            max_depth: count("max_depth", max_depth)?,
            view,
            protocol,
            colors,
            sides,
            ..RenderOptions::default()
        };
        let settings = options.settings(&snap.scene)?;
        let pool = thread_pool(threads)?;
        let bench = glint::report::BenchOptions {
            repeat,
            brute_force_budget,
            octree_only,
            bvh: false,
        };
        let stop = AtomicBool::new(false);
        let result = run_stoppable(slf.py(), cancel, &stop, || {
            glint::report::bench_scene(
                &snap.scene,
                &snap.name,
                snap.load_s,
                settings,
                bench,
                &pool,
                &BenchStop(&stop),
            )
        })?;
        match result {
            Ok(record) => json(&record),
            Err(glint::report::BenchError::Render(e)) => Err(render_error(&e)),
            Err(glint::report::BenchError::Octree(e)) => Err(octree_error(&e)),
            Err(e) => Err(PyRuntimeError::new_err(e.to_string())),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "<glint.Scene {}: {} shapes, {} lights, {} materials>",
            self.name,
            self.scene.shapes.len(),
            self.scene.lights.len(),
            self.scene.materials.len()
        )
    }
}

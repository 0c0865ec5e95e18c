//! The keyword arguments of `render`, `trace_pixel` and `bench` made into
//! render settings, with the command line's vocabulary and refusals.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use glint::limits::MAX_THREADS_PER_CORE;
use glint::scene::Scene;
use glint::settings::{Accel, AntiAliasing, Overrides, Protocol, RenderSettings};

/// What a call asks for instead of the scene's own settings (`None`
/// keeps the scene's), as `glint render`'s flags do.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderOptions<'a> {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub samples: Option<u32>,
    pub aa: Option<&'a str>,
    pub octree: Option<bool>,
    /// `octree`, `bvh` or `none`, as `--accel` names them.
    pub accel: Option<&'a str>,
    pub max_depth: Option<u32>,
    pub view: Option<&'a str>,
    pub protocol: Option<&'a str>,
    pub colors: Option<&'a str>,
    pub sides: Option<&'a str>,
    /// Draw materials' textures (`--textures on|off`).
    pub textures: Option<bool>,
}

/// A whole-number argument (`width`, `samples`, ...) as Python gave it,
/// checked: a negative or too large one is a `ValueError` naming it (as
/// the command line refuses `--width -5`), not the `OverflowError` of a
/// conversion to an unsigned type.
pub fn count(name: &str, value: Option<i64>) -> PyResult<Option<u32>> {
    value
        .map(|v| {
            u32::try_from(v).map_err(|_| {
                PyValueError::new_err(if v < 0 {
                    format!("{name} must be a whole number of at least 0, got {v}")
                } else {
                    format!("{name} {v} is too large")
                })
            })
        })
        .transpose()
}

fn parsed<T: std::str::FromStr<Err = String>>(text: Option<&str>) -> PyResult<Option<T>> {
    text.map(str::parse)
        .transpose()
        .map_err(PyValueError::new_err)
}

impl RenderOptions<'_> {
    /// What ray queries go through: `accel`, or `octree` as `--octree
    /// on|off` reads it; both only when they agree (as on the command line).
    fn accel(&self) -> PyResult<Option<Accel>> {
        let named: Option<Accel> = parsed(self.accel)?;
        let switched = self.octree.map(Accel::from_octree_switch);
        match (named, switched) {
            (Some(a), Some(s)) if a != s => Err(PyValueError::new_err(format!(
                "octree={} and accel='{}' disagree: give one",
                if self.octree == Some(true) {
                    "True"
                } else {
                    "False"
                },
                a.name()
            ))),
            (a, s) => Ok(a.or(s)),
        }
    }

    /// The scene's settings with these applied, checked against the limits.
    pub fn settings(&self, scene: &Scene) -> PyResult<RenderSettings> {
        let anti_aliasing = match (self.samples, self.aa) {
            (Some(_), Some(_)) => {
                return Err(PyValueError::new_err("give samples or aa, not both"));
            }
            (Some(1), None) => Some(AntiAliasing::Off),
            (Some(AntiAliasing::SAMPLES), None) => Some(AntiAliasing::Full),
            (Some(n), None) => {
                return Err(PyValueError::new_err(format!(
                    "samples must be 1 or 16, got {n}"
                )));
            }
            // The viewer's older `on` is full, as on the command line.
            (None, Some("on")) => Some(AntiAliasing::Full),
            (None, aa) => parsed(aa)?,
        };
        let protocol: Option<Protocol> = parsed(self.protocol)?;
        if protocol == Some(Protocol::Spd) {
            if self.max_depth.is_some() {
                return Err(PyValueError::new_err(
                    "protocol='spd' fixes the ray depth at 5: drop max_depth",
                ));
            }
            if self.samples.is_some() || self.aa.is_some() {
                return Err(PyValueError::new_err(
                    "protocol='spd' shoots the pixel corners (each pixel the mean of four): \
                     drop samples and aa",
                ));
            }
        }
        let overrides = Overrides {
            width: self.width,
            height: self.height,
            anti_aliasing,
            max_depth: self.max_depth,
            accel: self.accel()?,
            view: parsed(self.view)?,
            protocol,
            colors: parsed(self.colors)?,
            sides: parsed(self.sides)?,
            textures: self.textures,
            ..Overrides::default()
        };
        let mut settings = scene.render_settings();
        // No octree parameters among these: the scene's own stand.
        let mut params = scene.octree_params;
        overrides.apply(&mut settings, &mut params);
        settings
            .check()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(settings)
    }
}

/// A rayon pool of `threads` workers (`None` or 0: one per core), at most
/// [`MAX_THREADS_PER_CORE`] per core, as `glint render --threads`.
pub fn thread_pool(threads: Option<usize>) -> PyResult<rayon::ThreadPool> {
    let threads = threads.unwrap_or(0);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let limit = MAX_THREADS_PER_CORE * cores;
    if threads > limit {
        return Err(PyValueError::new_err(format!(
            "threads={threads} is more than {MAX_THREADS_PER_CORE} per core: this machine has \
             {cores} cores, so at most {limit} (None, the default, is one per core)"
        )));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| {
            pyo3::exceptions::PyRuntimeError::new_err(format!(
                "cannot start the render threads: {e}"
            ))
        })
}

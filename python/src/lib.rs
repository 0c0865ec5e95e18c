//! The native half of glint's Python module (`glint._glint`): the
//! library's scenes, renders and reports behind PyO3, with the GIL
//! released while it works. The Python half (python/glint/) turns what
//! this returns into NumPy arrays, dicts and attribute access; the
//! library itself knows nothing of Python.

mod errors;
mod frame;
mod interrupt;
mod options;
mod scene;

use std::path::PathBuf;
use std::time::Instant;

use pyo3::prelude::*;

use errors::{Cancelled, SceneError, load_error};
use frame::PyFrame;
use scene::PyScene;

/// Loads a `.toml` or `.nff` scene file, or an `.obj` model in a scene
/// glint writes around it (the GIL released while it reads).
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
    let (scene, load_s) = py.detach(|| {
        let start = Instant::now();
        (glint::scene::load(&path), start.elapsed().as_secs_f64())
    });
    let scene = scene.map_err(|e| load_error(py, &e))?;
    Ok(PyScene::new(scene, path.display().to_string(), load_s))
}

/// A TOML scene from its text; `path` names it in errors and anchors
/// relative mesh paths.
#[pyfunction]
fn from_toml(py: Python<'_>, text: &str, path: PathBuf) -> PyResult<PyScene> {
    if path.extension().is_none_or(|e| e != "toml") {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "path names the TOML text in errors and must end in .toml, got {}",
            path.display()
        )));
    }
    let start = Instant::now();
    let scene = glint::scene::load_str(text, &path, &glint::scene::FileSystem)
        .map_err(|e| load_error(py, &e))?;
    let load_s = start.elapsed().as_secs_f64();
    Ok(PyScene::new(scene, path.display().to_string(), load_s))
}

/// A scene from `Scene.source()`'s name and text, as another process
/// loaded it (a Dask worker's copy): the built-in scene by its name,
/// others parsed as the file `name` (which anchors relative mesh paths).
#[pyfunction]
fn from_source(py: Python<'_>, name: String, text: &str) -> PyResult<PyScene> {
    let start = Instant::now();
    let scene = py.detach(|| {
        if name == glint::scene::builtin::NAME {
            glint::scene::builtin::load_text(text)
        } else {
            glint::scene::load_str(text, std::path::Path::new(&name), &glint::scene::FileSystem)
        }
    });
    let scene = scene.map_err(|e| load_error(py, &e))?;
    Ok(PyScene::new(scene, name, start.elapsed().as_secs_f64()))
}

/// The scene glint opens with no file: the default scene built into it.
#[pyfunction]
fn default_scene(py: Python<'_>) -> PyResult<PyScene> {
    let start = Instant::now();
    let scene = glint::scene::builtin::default_scene().map_err(|e| load_error(py, &e))?;
    let load_s = start.elapsed().as_secs_f64();
    Ok(PyScene::new(
        scene,
        glint::scene::builtin::NAME.to_owned(),
        load_s,
    ))
}

#[pymodule]
fn _glint(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(default_scene, m)?)?;
    m.add_function(wrap_pyfunction!(from_source, m)?)?;
    m.add_class::<PyScene>()?;
    m.add_class::<PyFrame>()?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("Cancelled", py.get_type::<Cancelled>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

//! glint's errors as Python exceptions: a scene that cannot be read or an
//! edit that is refused raise `glint.SceneError` (a `ValueError`) carrying
//! the file, line, column and key the command line names; settings
//! outside the limits raise `ValueError`, files that cannot be written
//! `OSError`.

use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::prelude::*;

use glint::scene::{EditError, SceneError as LoadError};

pyo3::create_exception!(
    glint,
    SceneError,
    PyValueError,
    "A scene file that cannot be read, or an edit the scene refuses. \
     Attributes: path, line, column, key (None where they do not apply) and message."
);

pyo3::create_exception!(
    glint,
    Cancelled,
    pyo3::exceptions::PyException,
    "A render or benchmark stopped by its `cancel` hook."
);

/// An error and its sources, as the command line prints them (`a: b: c`).
pub fn chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

/// Where an error points; `None` for what it does not name.
#[derive(Default)]
struct Place {
    path: Option<String>,
    line: Option<usize>,
    column: Option<usize>,
    key: Option<String>,
}

fn scene_error_with(py: Python<'_>, text: String, message: String, place: Place) -> PyErr {
    let error = SceneError::new_err(text);
    let value = error.value(py);
    // Setting attributes on a fresh exception instance cannot fail short
    // of memory running out; the error keeps its text either way.
    let _ = value.setattr("path", place.path);
    let _ = value.setattr("line", place.line);
    let _ = value.setattr("column", place.column);
    let _ = value.setattr("key", place.key);
    let _ = value.setattr("message", message);
    error
}

/// A scene that could not be loaded.
pub fn load_error(py: Python<'_>, e: &LoadError) -> PyErr {
    let path = |p: &std::path::Path| Some(p.display().to_string());
    let (place, message) = match e {
        LoadError::Invalid { location, message }
        | LoadError::Mesh {
            location, message, ..
        } => (
            Place {
                path: path(&location.path),
                line: Some(location.line),
                column: Some(location.column),
                key: Some(location.key.clone()),
            },
            match e {
                LoadError::Mesh { mesh, .. } => format!("mesh {}: {message}", mesh.display()),
                _ => message.clone(),
            },
        ),
        LoadError::Io { path: p, .. }
        | LoadError::NotUtf8 { path: p, .. }
        | LoadError::Png { path: p }
        | LoadError::Model { path: p, .. }
        | LoadError::UnknownFormat { path: p } => (
            Place {
                path: path(p),
                ..Place::default()
            },
            chain(e),
        ),
    };
    scene_error_with(py, chain(e), message, place)
}

/// An edit the scene refused.
pub fn edit_error(py: Python<'_>, e: &EditError) -> PyErr {
    let place = Place {
        key: Some(e.key.clone()),
        ..Place::default()
    };
    scene_error_with(py, e.to_string(), e.message.clone(), place)
}

/// A render that cannot start: settings outside the limits, a camera
/// that cannot see, or not enough memory.
pub fn render_error(e: &glint::render::RenderError) -> PyErr {
    match e {
        glint::render::RenderError::OutOfMemory { .. } => PyMemoryError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub fn octree_error(e: &glint::accel::OctreeError) -> PyErr {
    match e {
        glint::accel::OctreeError::OutOfMemory { .. } => PyMemoryError::new_err(e.to_string()),
        glint::accel::OctreeError::Limit(_) => PyValueError::new_err(e.to_string()),
    }
}

/// An image that could not be written.
pub fn export_error(e: &glint::export::ExportError) -> PyErr {
    PyOSError::new_err(chain(e))
}

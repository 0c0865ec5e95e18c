//! `glint.Frame` (native half): a rendered frame, its values as 32-bit
//! floats and its 8-bit pixels for NumPy, and the PNG `glint render`
//! writes for it.

use std::path::PathBuf;

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes};

use glint::export::{RecordedFrame, SceneEdits};
use glint::image::frame::Frame;
use glint::scene::Scene;
use glint::settings::RenderSettings;

use crate::errors::export_error;

#[pyclass(name = "Frame", module = "glint._glint", frozen)]
pub struct PyFrame {
    frame: Frame,
    settings: RenderSettings,
    /// The scene as rendered (its geometry shared, not copied), for the
    /// record of a saved PNG.
    scene: Scene,
    scene_name: String,
    edits: Option<SceneEdits>,
    stats: Option<String>,
    /// Where the frame sits in a sequence, for its record.
    sequence: Option<RecordedFrame>,
}

/// What a frame's pixels need besides the numbers to be a frame again in
/// another process ([`PyFrame::parts`]).
#[derive(serde::Serialize, serde::Deserialize)]
pub struct FrameHeader {
    pub width: u32,
    pub height: u32,
    pub view: glint::settings::ViewMode,
    pub colors: glint::color::ColorConvention,
}

impl PyFrame {
    pub fn new(
        frame: Frame,
        settings: RenderSettings,
        scene: Scene,
        scene_name: String,
        edits: Option<SceneEdits>,
        stats: Option<String>,
    ) -> Self {
        Self {
            frame,
            settings,
            scene,
            scene_name,
            edits,
            stats,
            sequence: None,
        }
    }

    /// The same frame, recorded as frame `sequence` of a sequence.
    pub fn in_sequence(mut self, sequence: Option<RecordedFrame>) -> Self {
        self.sequence = sequence;
        self
    }

    /// A frame from [`PyFrame::parts`]' header and pixels.
    pub fn from_parts(header: &FrameHeader, pixels: &[u8]) -> Option<Frame> {
        let count = header.width as usize * header.height as usize;
        if pixels.len() != count * 24 {
            return None;
        }
        let values: Vec<f64> = pixels
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default()))
            .collect();
        Some(Frame {
            width: header.width,
            height: header.height,
            view: header.view,
            colors: header.colors,
            pixels: values
                .chunks_exact(3)
                .map(|c| glint::math::DVec3::new(c[0], c[1], c[2]))
                .collect(),
        })
    }

    /// The image's 8-bit RGB rows and their count: with the legend strip
    /// of diagnostic views under the image when `legend`, as in a PNG.
    fn rgb8(&self, legend: bool) -> (Vec<u8>, u32) {
        if legend {
            self.frame.to_annotated_rgb8()
        } else {
            (self.frame.to_rgb8(), self.frame.height)
        }
    }
}

#[pymethods]
impl PyFrame {
    #[getter]
    fn width(&self) -> u32 {
        self.frame.width
    }

    #[getter]
    fn height(&self) -> u32 {
        self.frame.height
    }

    /// The view the frame shows (`shaded`, `cost`, ...).
    #[getter]
    fn view(&self) -> &'static str {
        self.frame.view.name()
    }

    /// The `--stats` JSON, if the render counted its work.
    #[getter]
    fn stats_json(&self) -> Option<&str> {
        self.stats.as_deref()
    }

    /// The frame exactly, for another process (a Dask worker's result):
    /// a JSON header and the values as little-endian 64-bit floats.
    fn parts<'py>(&self, py: Python<'py>) -> PyResult<(String, Bound<'py, PyBytes>)> {
        let header = FrameHeader {
            width: self.frame.width,
            height: self.frame.height,
            view: self.frame.view,
            colors: self.frame.colors,
        };
        let header = serde_json::to_string(&header)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
        let mut bytes = Vec::with_capacity(self.frame.pixels.len() * 24);
        for p in &self.frame.pixels {
            for c in p.to_array() {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        Ok((header, PyBytes::new(py, &bytes)))
    }

    /// The frame's values, row-major from the top, three per pixel, as
    /// little-endian 32-bit floats.
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyByteArray> {
        let mut bytes = Vec::with_capacity(self.frame.pixels.len() * 12);
        for p in &self.frame.pixels {
            for c in p.to_array() {
                bytes.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        PyByteArray::new(py, &bytes)
    }

    /// 8-bit RGB as the PNG holds it, and the number of rows.
    #[pyo3(signature = (legend=false))]
    fn srgb8<'py>(&self, py: Python<'py>, legend: bool) -> (Bound<'py, PyByteArray>, u32) {
        let (rgb, height) = py.detach(|| self.rgb8(legend));
        (PyByteArray::new(py, &rgb), height)
    }

    /// A PNG of the frame in memory (no record): what a notebook shows.
    #[pyo3(signature = (legend=true))]
    fn png<'py>(&self, py: Python<'py>, legend: bool) -> PyResult<Bound<'py, PyBytes>> {
        let png = py.detach(|| {
            let (rgb, height) = self.rgb8(legend);
            let name = std::path::Path::new("frame.png");
            glint::export::png_bytes(name, self.frame.width, height, &rgb, None)
        });
        let png = png.map_err(|e| export_error(&e))?;
        Ok(PyBytes::new(py, &png))
    }

    /// Writes the PNG and record `glint render` writes for this frame.
    #[pyo3(signature = (path, legend=true))]
    fn save(&self, py: Python<'_>, path: PathBuf, legend: bool) -> PyResult<()> {
        if path.as_os_str() == "-" {
            return Err(PyValueError::new_err(
                "save writes a file: give its name (a .png file)",
            ));
        }
        py.detach(|| {
            let scene_file = std::path::Path::new(&self.scene_name);
            glint::export::check_output(&path, Some(scene_file))?;
            let camera = self.scene.camera;
            let mut record =
                glint::export::render_record(&self.scene, &self.scene_name, &camera, self.settings);
            record.settings.legend = legend;
            record.settings.edits = self.edits.clone();
            record.settings.frame = self.sequence;
            glint::export::save_frame(&self.frame, &path, &mut record, None)
        })
        .map_err(|e| match e {
            // The command line's message offers `-` for standard output,
            // which `save` refuses: `png()` gives the bytes instead.
            glint::export::ExportError::NotPng { path } => PyOSError::new_err(format!(
                "{}: save writes PNG images; name the file .png (png() returns the bytes)",
                path.display()
            )),
            e => export_error(&e),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "<glint.Frame {}x{} {}>",
            self.frame.width,
            self.frame.height,
            self.frame.view.name()
        )
    }
}

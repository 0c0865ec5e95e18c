//! The image side: the rendered frame and its encodings, the legend strip
//! of the diagnostic views, image error figures and the octree overlay.

pub mod frame;
pub mod legend;
pub mod metrics;
pub mod overlay;

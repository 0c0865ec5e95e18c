//! The JSON objects glint reports about a render: `glint render --stats`
//! ([`RenderStats`]), `--trace-pixel` ([`TraceReport`]) and `glint bench
//! --format json` ([`SceneBench`]). Built here once, so the command line
//! prints and the Python module returns the same fields from the same
//! code. Their field names are a public interface (docs/cli.md,
//! docs/inspection.md): add fields, never rename or repurpose them.

mod bench;
mod render_stats;
mod trace;

pub use bench::{
    BenchError, BenchOptions, BenchWatch, BvhBench, SceneBench, Timing, bench_scene, duration_text,
    median,
};
pub use render_stats::{CostJson, RaysJson, RenderStats, RenderTimes};
pub use trace::{LightJson, PixelOutside, TraceReport, trace_settings};

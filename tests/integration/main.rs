//! glint's integration tests, one module per subject, built as one test
//! binary: the library is linked once rather than once per file.
//!
//! `cargo test --release` runs them all; `cargo test --release --test
//! integration octree_identity::` runs one module.

mod common;

mod accelerators;
mod adaptive_aa;
mod cli_output;
mod cli_records;
mod extremes;
mod inspect;
mod module_graph;
mod obj_content;
mod obj_materials;
mod octree_identity;
mod render_scenes;
mod robust_scenes;
mod round_trip;
mod self_intersection;
mod sequences;
mod simd_levels;
mod source_files;
mod spd_protocol;
mod textures;
mod viewer;
mod viewer_files;
mod viewer_panels;
mod viewer_path;
mod viewer_worker;
mod walk;

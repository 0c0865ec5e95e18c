//! The interactive viewer (cargo feature `gui`): a layer over the headless
//! renderer. [`GlintApp`] holds what the user edits ([`state::EditState`])
//! and the runtime that shows it; [`worker::Worker`] renders in the
//! background. Panels and input return [`command::Command`]s that the app
//! applies once per frame.

pub mod app;
mod budget;
pub mod command;
pub mod compare;
mod export;
mod input;
pub mod inspect;
mod octree_panel;
mod orbit;
pub mod orbit_bench;
mod panels;
mod pass_cache;
mod path_panel;
pub mod pixel;
mod preview;
mod save;
pub mod screenshot;
pub mod state;
mod timing;
mod walk_view;
pub mod worker;

pub use app::{GlintApp, ViewerOptions};
pub use export::file_dialog_available;
pub use pixel::WalkTarget;
pub use state::SceneSource;

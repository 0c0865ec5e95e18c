//! The interactive viewer (cargo feature `gui`): a layer over the headless
//! renderer. [`app::GlintApp`] holds what the user edits; [`worker::Worker`]
//! renders in the background.

pub mod app;
pub mod inspect;
mod orbit;
mod panels;
pub mod worker;

pub use app::{GlintApp, SceneSource, ViewerOptions};

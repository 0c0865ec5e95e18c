//! What goes wrong writing and reading exports: one error type for the
//! export files, apart from them so that each depends on it and none on
//! its parent.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("cannot write {path}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{path}: glint writes PNG images; name the output .png (or give - for standard output)"
    )]
    NotPng { path: PathBuf },
    #[error("{path} leads to {target}, which is not a .png file: glint does not write over it")]
    LinkNotPng { path: PathBuf, target: PathBuf },
    #[error("{path} is the scene being rendered; choose another output file")]
    IsInput { path: PathBuf },
    #[error("cannot encode {path} as PNG: {message}")]
    Encode { path: PathBuf, message: String },
    #[error("cannot read {path}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path} is not a readable PNG: {message}")]
    Decode { path: PathBuf, message: String },
    #[error(
        "{path} carries no glint metadata (text chunk `{key}` is missing): it was not written by glint, or was re-saved by a program that dropped it"
    )]
    Missing { path: PathBuf, key: &'static str },
    #[error("{path}: text chunk `{key}` is malformed: {message}")]
    Malformed {
        path: PathBuf,
        key: &'static str,
        message: String,
    },
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error(
        "the scene was too large to embed in the PNG (over 16 MiB): --from-png needs {path} \
         with SHA-256 {sha256}, {}", if *found { "and that file has changed" } else { "which cannot be read" }
    )]
    SceneNotEmbedded {
        path: String,
        sha256: String,
        found: bool,
    },
    #[error(
        "{texture} {} since {png} was made, so its colours would not be the recorded ones: \
         restore that texture to re-render the picture, or render the scene afresh",
        if *found { "has changed (its SHA-256 differs from the recorded one)" } else { "cannot be read" }
    )]
    TextureChanged {
        texture: String,
        png: PathBuf,
        found: bool,
    },
    #[error("the recorded light and material edits do not fit the recorded scene {scene}")]
    EditsMismatch { scene: String },
    #[error(
        "{path}: the embedded scene text does not match its SHA-256 (recorded {recorded}, computed {computed})"
    )]
    Checksum {
        path: PathBuf,
        recorded: String,
        computed: String,
    },
}

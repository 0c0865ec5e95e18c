//! What every part of reading a TOML scene shares: the text being read,
//! its path, and errors placed at a line, column and key.

use std::ops::{Range, RangeInclusive};
use std::path::Path;

use toml::Spanned;

use crate::limits::{check_color, check_finite, check_finite_vec3, check_integer, check_range};
use crate::math::DVec3;
use crate::scene::model::{Location, SceneError, line_column};

pub(super) type Vec3 = Spanned<[f64; 3]>;

pub(super) struct Context<'a> {
    pub(super) text: &'a str,
    pub(super) path: &'a Path,
    /// How many materials the file defines (meshes add theirs behind).
    pub(super) defined_materials: usize,
}

impl Context<'_> {
    pub(super) fn location(&self, span: Range<usize>, key: &str) -> Location {
        let (line, column) = line_column(self.text, span.start);
        Location {
            path: self.path.to_owned(),
            line,
            column,
            key: key.to_owned(),
        }
    }

    pub(super) fn error(
        &self,
        span: Range<usize>,
        key: &str,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError::Invalid {
            location: self.location(span, key),
            message: message.into(),
        }
    }

    pub(super) fn finite(&self, v: &Spanned<f64>, key: &str) -> Result<f64, SceneError> {
        check_finite(*v.get_ref()).map_err(|e| self.error(v.span(), key, e))
    }

    pub(super) fn vec3(&self, v: &Vec3, key: &str) -> Result<DVec3, SceneError> {
        check_finite_vec3(DVec3::from(*v.get_ref())).map_err(|e| self.error(v.span(), key, e))
    }

    /// A colour whose components lie in `range` (surface colours in
    /// [0, 1], intensities in [0, 1000]).
    pub(super) fn color(
        &self,
        v: &Vec3,
        key: &str,
        range: &RangeInclusive<f64>,
    ) -> Result<DVec3, SceneError> {
        let c = self.vec3(v, key)?;
        check_color(c, range).map_err(|e| self.error(v.span(), key, e))
    }

    pub(super) fn in_range(
        &self,
        v: &Spanned<f64>,
        key: &str,
        range: &RangeInclusive<f64>,
    ) -> Result<f64, SceneError> {
        let x = self.finite(v, key)?;
        check_range(x, range).map_err(|e| self.error(v.span(), key, e))
    }

    pub(super) fn integer(
        &self,
        v: &Spanned<i64>,
        key: &str,
        range: Range<i64>,
    ) -> Result<u32, SceneError> {
        check_integer(*v.get_ref(), &(range.start..=range.end - 1))
            .map_err(|e| self.error(v.span(), key, e))
    }
}

/// serde's words for the types it expected, in a scene author's: `f64`
/// is a number, `i64` and the other integers a whole number.
fn plain_types(message: &str) -> String {
    let mut out = message.to_owned();
    for (rust, plain) in [
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("expected i64", "expected a whole number"),
        ("expected u64", "expected a whole number"),
        ("expected u32", "expected a whole number"),
        ("expected i32", "expected a whole number"),
        ("expected usize", "expected a whole number"),
    ] {
        out = out.replace(rust, plain);
    }
    out
}

/// `cx.text` deserialized as `T`, each error placed and keyed.
pub(super) fn deserialize<T: serde::de::DeserializeOwned>(cx: &Context) -> Result<T, SceneError> {
    let text = cx.text;
    // Syntax errors have a place but no key; type errors get their key path
    // (`objects[0].radius`, the style of every other error) from
    // serde_path_to_error and their place from toml's span.
    let de = toml::de::Deserializer::parse(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        // A key written twice is named: its span is the key.
        let message = e.message().trim();
        match text.get(span.clone()).map(str::trim) {
            Some(k) if message == "duplicate key" && !k.is_empty() => {
                cx.error(span, k, "written twice in its table")
            }
            _ => cx.error(span, "(syntax)", message.to_owned()),
        }
    })?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        // `Spanned` values add private segments to the path (before the
        // fields of a spanned table): drop them.
        let path = e
            .path()
            .to_string()
            .split('.')
            .filter(|segment| !segment.starts_with("$__"))
            .collect::<Vec<_>>()
            .join(".");
        let path = if path.is_empty() {
            ".".to_owned()
        } else {
            path
        };
        let inner = e.into_inner();
        let key = if path == "." {
            "(top level)".to_string()
        } else {
            path
        };
        cx.error(
            inner.span().unwrap_or(0..0),
            &key,
            plain_types(inner.message().trim()),
        )
    })
}

//! Wavefront OBJ statements, read by glint itself: positions, normals and
//! texture coordinates in f64, faces of any size with their `usemtl`
//! material, the `mtllib` names, and a count of everything else a file may
//! hold.
//!
//! A general-purpose loader gave no line numbers, read coordinates in f32,
//! refused a whole file over one Latin-1 material name or an empty `usemtl`,
//! and divided by `w`. Here every refusal names its line; names are read
//! lossily; `w` (a weight of rational curves, not a homogeneous coordinate
//! for `v`) is ignored; lines, points and free-form statements are skipped
//! and counted.

use std::collections::BTreeMap;

use crate::math::DVec3;

/// No normal (or texture coordinate) given for a face corner.
pub(super) const NO_NORMAL: u32 = u32::MAX;

/// A texture coordinate index that cannot exist (zero, or counting back
/// past the first `vt`): checked and counted with the others.
const NO_SUCH_UV: u32 = u32::MAX - 1;

/// One corner of a face: zero-based indices of its position, its normal
/// and its texture coordinates (`NO_NORMAL` where not given).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Corner {
    pub position: u32,
    pub normal: u32,
    pub uv: u32,
}

/// One `f` element: `len` corners from `start` in [`ObjData::corners`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Face {
    pub start: u32,
    pub len: u32,
    /// Index into [`ObjData::materials`].
    pub material: u32,
    /// The line the face is written on, for notes.
    pub line: u32,
}

/// What the statements of an OBJ file describe.
#[derive(Debug, Default)]
pub(super) struct ObjData {
    pub positions: Vec<DVec3>,
    /// Vertex colours (`v x y z r g b`), by position index; empty when
    /// the file has none, `None` for a vertex written without one.
    pub colors: Vec<Option<DVec3>>,
    pub normals: Vec<DVec3>,
    /// `vt` texture coordinates (u, v); a `w` is ignored.
    pub uvs: Vec<[f64; 2]>,
    /// Every face's corners, checked against the final vertex counts.
    pub corners: Vec<Corner>,
    pub faces: Vec<Face>,
    /// Material names in order of first `usemtl`; index 0 is the faces
    /// before any `usemtl` (or after an empty one): the default material.
    pub materials: Vec<String>,
    /// `mtllib` arguments, as written.
    pub libraries: Vec<String>,
    /// The first comment before any statement that has words in it: where
    /// exporters name themselves (`# Blender v2.79 (sub 0) OBJ File: ''`).
    pub header: Option<String>,
    pub skipped: SkippedElements,
}

/// Elements an OBJ file holds that glint does not render, by kind.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SkippedElements {
    /// `l` polylines (glint renders surfaces only).
    pub lines: usize,
    /// `p` points.
    pub points: usize,
    /// Faces with fewer than three distinct vertices.
    pub short_faces: usize,
    /// Faces that listed a vertex more than once: the repeats were removed
    /// before triangulation.
    pub faces_with_repeated_vertices: usize,
    /// Faces whose normal indices point past the file's normals: shaded
    /// without them.
    pub faces_with_missing_normals: usize,
    /// Faces whose texture coordinate indices point past the file's `vt`
    /// lines: drawn untextured.
    #[serde(skip_serializing_if = "is_zero")]
    pub faces_with_missing_uvs: usize,
    /// Other statements (free-form curves and surfaces, display attributes),
    /// by keyword.
    pub statements: BTreeMap<String, usize>,
}

impl SkippedElements {
    pub fn add(&mut self, other: &SkippedElements) {
        self.lines += other.lines;
        self.points += other.points;
        self.short_faces += other.short_faces;
        self.faces_with_repeated_vertices += other.faces_with_repeated_vertices;
        self.faces_with_missing_normals += other.faces_with_missing_normals;
        for (k, n) in &other.statements {
            *self.statements.entry(k.clone()).or_default() += n;
        }
    }

    pub fn is_empty(&self) -> bool {
        *self == SkippedElements::default()
    }
}

/// A refusal: the 1-based line and what is wrong there.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct ObjError {
    pub line: usize,
    pub message: String,
}

impl std::fmt::Display for ObjError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Logical lines of `bytes`: `\r\n` or `\n` ends a line, a trailing
/// backslash joins the next one; each with its 1-based number.
fn logical_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, Vec<u8>)> + '_ {
    let mut physical = bytes.split(|&b| b == b'\n').enumerate().peekable();
    std::iter::from_fn(move || {
        let (first, line) = physical.next()?;
        let mut joined = line.strip_suffix(b"\r").unwrap_or(line).to_vec();
        while joined.last() == Some(&b'\\') {
            joined.pop();
            match physical.next() {
                Some((_, next)) => {
                    joined.push(b' ');
                    joined.extend_from_slice(next.strip_suffix(b"\r").unwrap_or(next));
                }
                None => break,
            }
        }
        Some((first + 1, joined))
    })
}

fn is_space(b: &u8) -> bool {
    b.is_ascii_whitespace()
}

/// The bytes after the keyword, trimmed, decoded lossily (names written by
/// exporters in Latin-1 or any other encoding keep their ASCII part).
fn rest_of_line(line: &[u8], keyword_len: usize) -> String {
    String::from_utf8_lossy(line[keyword_len..].trim_ascii()).into_owned()
}

/// Parses OBJ bytes.
pub(super) fn parse(bytes: &[u8]) -> Result<ObjData, ObjError> {
    let mut data = ObjData {
        materials: vec![String::new()],
        ..ObjData::default()
    };
    let mut material_slot: BTreeMap<String, u32> = BTreeMap::new();
    let mut current_material = 0u32;
    // Positive indices may point forward (some exporters write faces
    // first); they are checked once every vertex is known.
    let mut last_line_of_face: Vec<usize> = Vec::new();
    let text = super::text::utf8_text(bytes);
    let mut in_header = true;
    for (number, line) in logical_lines(&text) {
        let err = |message: String| ObjError {
            line: number,
            message,
        };
        let hash = super::text::comment_start(&line).map_err(&err)?;
        let content = match hash {
            Some(hash) => &line[..hash],
            None => &line[..],
        };
        let content = content.trim_ascii();
        if content.is_empty() {
            if let Some(hash) = hash
                && in_header
                && data.header.is_none()
            {
                let comment = String::from_utf8_lossy(line[hash + 1..].trim_ascii());
                if comment.chars().any(|c| c.is_alphabetic()) {
                    data.header = Some(comment.chars().take(120).collect());
                }
            }
            continue;
        }
        in_header = false;
        let keyword_len = content.iter().position(is_space).unwrap_or(content.len());
        let keyword = &content[..keyword_len];
        let mut args = content[keyword_len..]
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        match keyword {
            b"v" | b"vn" => {
                let mut xyz = [0.0; 3];
                for (k, value) in xyz.iter_mut().enumerate() {
                    let token = args.next().ok_or_else(|| {
                        err(format!(
                            "`{}` needs three coordinates, got {k}",
                            String::from_utf8_lossy(keyword)
                        ))
                    })?;
                    *value = number_of(token)
                        .ok_or_else(|| err(format!("`{}` is not a number", lossy(token))))?;
                }
                let p = DVec3::from_array(xyz);
                if !p.is_finite() {
                    return Err(err("coordinates must be finite".into()));
                }
                // `v x y z w`: w weighs rational curves and is ignored;
                // `v x y z r g b` (MeshLab, scanners) gives a colour.
                if keyword == b"v" {
                    let rest: Vec<&[u8]> = args.collect();
                    if rest.len() >= 3 {
                        let mut rgb = [0.0; 3];
                        for (value, token) in rgb.iter_mut().zip(&rest) {
                            *value = number_of(token).ok_or_else(|| {
                                err(format!("vertex colour `{}` is not a number", lossy(token)))
                            })?;
                        }
                        let c = DVec3::from_array(rgb);
                        if !c.is_finite() {
                            return Err(err("vertex colours must be finite".into()));
                        }
                        data.colors.resize(data.positions.len(), None);
                        data.colors.push(Some(c));
                    }
                    data.positions.push(p);
                } else {
                    data.normals.push(p);
                }
            }
            b"vt" => {
                let mut uv = [0.0; 2];
                // `vt u [v [w]]`: v defaults to 0, w (3D textures) is ignored.
                for (k, value) in uv.iter_mut().enumerate() {
                    match args.next() {
                        Some(token) => {
                            *value =
                                number_of(token).filter(|x| x.is_finite()).ok_or_else(|| {
                                    err(format!("`{}` is not a finite number", lossy(token)))
                                })?
                        }
                        None if k == 0 => return Err(err("`vt` needs a coordinate".into())),
                        None => {}
                    }
                }
                data.uvs.push(uv);
            }
            b"f" | b"fo" => {
                let start = data.corners.len();
                for token in args {
                    let corner = corner_of(token, &data).map_err(&err)?;
                    data.corners.push(corner);
                }
                let len = data.corners.len() - start;
                data.faces.push(Face {
                    start: start as u32,
                    len: len as u32,
                    material: current_material,
                    line: number.min(u32::MAX as usize) as u32,
                });
                last_line_of_face.push(number);
            }
            b"usemtl" => {
                let name = rest_of_line(content, keyword_len);
                current_material = if name.is_empty() {
                    0
                } else {
                    let next = data.materials.len() as u32;
                    *material_slot.entry(name.clone()).or_insert_with(|| {
                        data.materials.push(name);
                        next
                    })
                };
            }
            b"mtllib" => data.libraries.push(rest_of_line(content, keyword_len)),
            b"l" => data.skipped.lines += 1,
            b"p" => data.skipped.points += 1,
            // Groups, objects and smoothing groups: nothing glint renders
            // depends on them.
            b"g" | b"o" | b"s" => {}
            other => {
                *data
                    .skipped
                    .statements
                    .entry(String::from_utf8_lossy(other).into_owned())
                    .or_default() += 1;
            }
        }
    }
    // Check the indices now that every vertex is known. A face whose
    // normals do not exist is kept without them (exporters write `i//n`
    // with no `vn`); a missing vertex leaves nothing to draw.
    let (positions, normals, uvs) = (data.positions.len(), data.normals.len(), data.uvs.len());
    for (face, &line) in data.faces.iter().zip(&last_line_of_face) {
        let corners = &mut data.corners[face.start as usize..(face.start + face.len) as usize];
        if let Some(c) = corners.iter().find(|c| c.position as usize >= positions) {
            return Err(ObjError {
                line,
                message: format!(
                    "vertex index {} is out of range (the file has {positions} vertices)",
                    c.position as u64 + 1
                ),
            });
        }
        let missing = |index: u32, count: usize| index != NO_NORMAL && index as usize >= count;
        if corners.iter().any(|c| missing(c.normal, normals)) {
            data.skipped.faces_with_missing_normals += 1;
            for corner in corners.iter_mut() {
                corner.normal = NO_NORMAL;
            }
        }
        if corners.iter().any(|c| missing(c.uv, uvs)) {
            data.skipped.faces_with_missing_uvs += 1;
            for corner in corners.iter_mut() {
                corner.uv = NO_NORMAL;
            }
        }
    }
    if !data.colors.is_empty() {
        data.colors.resize(data.positions.len(), None);
    }
    Ok(data)
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

fn lossy(token: &[u8]) -> String {
    String::from_utf8_lossy(token).into_owned()
}

fn number_of(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// A face corner `i`, `i/t`, `i//n` or `i/t/n`, zero-based; negative
/// indices count back from the vertices read so far.
fn corner_of(token: &[u8], data: &ObjData) -> Result<Corner, String> {
    let mut parts = token.split(|&b| b == b'/');
    let bad = || {
        format!(
            "`{}` is not a face corner (i, i/t, i//n or i/t/n)",
            lossy(token)
        )
    };
    let position = parts.next().ok_or_else(bad)?;
    let texture = parts.next();
    let normal = parts.next();
    if parts.next().is_some() {
        return Err(bad());
    }
    let resolve = |index: &[u8], count: usize, what: &str| -> Result<u32, String> {
        let i: i64 = std::str::from_utf8(index)
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(bad)?;
        let resolved = match i {
            0 => return Err(format!("{what} index 0 (OBJ counts from 1)")),
            i if i > 0 => i - 1,
            i => count as i64 + i,
        };
        if resolved < 0 {
            return Err(format!(
                "{what} index {i} reaches before the first {what} ({count} so far)"
            ));
        }
        u32::try_from(resolved).map_err(|_| format!("{what} index {i} is too large"))
    };
    let p = resolve(position, data.positions.len(), "vertex")?;
    let n = match normal {
        Some(n) if !n.is_empty() => resolve(n, data.normals.len(), "normal")?,
        _ => NO_NORMAL,
    };
    // Texture coordinates that do not exist leave the face untextured
    // (counted) rather than refuse a model that renders without them.
    let t = match texture {
        Some(t) if !t.is_empty() => {
            resolve(t, data.uvs.len(), "texture coordinate").unwrap_or(NO_SUCH_UV)
        }
        _ => NO_NORMAL,
    };
    Ok(Corner {
        position: p,
        normal: n,
        uv: t,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_in_every_form_and_negative_indices() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1 2 3\nf 1/1 2/2 3/3\nf 1//1 2//1 3//1\nf -3/1/1 -2/2/1 -1/3/1\n";
        let data = parse(text.as_bytes()).unwrap();
        assert_eq!(data.faces.len(), 4);
        let pn = |d: &ObjData, r: std::ops::Range<usize>| -> Vec<(u32, u32)> {
            d.corners[r]
                .iter()
                .map(|c| (c.position, c.normal))
                .collect()
        };
        assert_eq!(
            pn(&data, 0..3),
            [(0, NO_NORMAL), (1, NO_NORMAL), (2, NO_NORMAL)]
        );
        assert_eq!(pn(&data, 6..9), [(0, 0), (1, 0), (2, 0)]);
        assert_eq!(pn(&data, 9..12), [(0, 0), (1, 0), (2, 0)]);
    }

    #[test]
    fn coordinates_are_f64_and_w_is_ignored() {
        // 1e6 + 0.001 needs more digits than an f32 holds (its spacing
        // there is 0.0625).
        let data = parse(b"v 1000000.001 2 3 0.5\n").unwrap();
        assert_eq!(data.positions[0], DVec3::new(1000000.001, 2.0, 3.0));
    }

    #[test]
    fn lines_points_and_curves_are_counted_not_filled() {
        let text =
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3 1\np 1\ncstype bspline\ncurv 0 1 1 2\nf 1 2 3\n";
        let data = parse(text.as_bytes()).unwrap();
        assert_eq!(data.faces.len(), 1);
        assert_eq!(data.skipped.lines, 1);
        assert_eq!(data.skipped.points, 1);
        assert_eq!(data.skipped.statements["cstype"], 1);
        assert_eq!(data.skipped.statements["curv"], 1);
    }

    #[test]
    fn material_names_in_any_encoding_and_an_empty_usemtl() {
        let mut text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl caf\xe9\nf 1 2 3\nusemtl\nf 1 2 3\nusemtl red\nf 1 2 3\nusemtl caf\xe9\nf 1 2 3\n".to_vec();
        text.extend_from_slice(b"mtllib a b.mtl\n");
        let data = parse(&text).unwrap();
        let slots: Vec<u32> = data.faces.iter().map(|f| f.material).collect();
        assert_eq!(slots, [1, 0, 2, 1]);
        assert_eq!(data.materials[1], "caf\u{fffd}");
        assert_eq!(data.libraries, ["a b.mtl"]);
    }

    #[test]
    fn refusals_name_the_line() {
        let cases: [(&str, usize, &str); 6] = [
            ("v 0 0 0\nv 1 x 0\n", 2, "`x` is not a number"),
            ("v 0 0\n", 1, "needs three coordinates"),
            ("v 0 0 0\n\nf 1 2 3\n", 3, "vertex index 2 is out of range"),
            (
                "v 0 0 0\nf 1//1 2//1 1//1\n",
                2,
                "vertex index 2 is out of range",
            ),
            ("v 0 0 0\nf 0 1 1\n", 2, "vertex index 0"),
            (
                "v 0 0 0\nv 1 0 0\nf -3 1 2\n",
                3,
                "reaches before the first vertex",
            ),
        ];
        for (text, line, needle) in cases {
            let e = parse(text.as_bytes()).unwrap_err();
            assert_eq!(e.line, line, "{text:?}: {e}");
            assert!(e.message.contains(needle), "{text:?}: {e}");
        }
    }

    #[test]
    fn normals_that_do_not_exist_are_dropped_and_counted() {
        let data =
            parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\nf 1//1 2//1 3//1\n")
                .unwrap();
        assert_eq!(data.skipped.faces_with_missing_normals, 1);
        let normals: Vec<u32> = data.corners.iter().map(|c| c.normal).collect();
        assert_eq!(normals, [NO_NORMAL, NO_NORMAL, NO_NORMAL, 0, 0, 0]);
    }

    #[test]
    fn texture_coordinates_by_index_and_counted_back_and_missing_ones_dropped() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5\nvt 1 0.25 7\nvt 0 1\n\
                    f 1/1 2/2 3/3\nf 1/-1/ 2/-2 3/-3\nf 1/1 2/2 3/9\nf 1/-9 2/1 3/1\n";
        let data = parse(text.as_bytes()).unwrap();
        assert_eq!(data.uvs, [[0.5, 0.0], [1.0, 0.25], [0.0, 1.0]]);
        let uvs: Vec<u32> = data.corners.iter().map(|c| c.uv).collect();
        assert_eq!(uvs[..6], [0, 1, 2, 2, 1, 0]);
        assert!(uvs[6..].iter().all(|&t| t == NO_NORMAL));
        assert_eq!(data.skipped.faces_with_missing_uvs, 2);
        let e = parse(b"vt x\n").unwrap_err();
        assert!(e.message.contains("`x` is not a finite number"), "{e}");
    }

    #[test]
    fn a_backslash_continues_the_line() {
        let data = parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n 2 3\n").unwrap();
        assert_eq!(data.faces[0].len, 3);
    }
}

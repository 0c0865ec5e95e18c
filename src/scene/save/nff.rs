//! Saving an NFF scene: its own text with the numbers the viewer edits
//! rewritten in place.

use crate::settings::Accel;
use std::ops::Range;

use super::{LeftOut, SaveError, SaveRequest, SavedText};
use crate::material::Material;
use crate::settings::Protocol;

/// The NFF text of `request`: the loaded file with the numbers the viewer
/// edits (viewpoint, resolution, lights, `f` materials) rewritten and
/// everything else, comments included, as it was. What NFF cannot say
/// (samples, depth, colours, sides, the octree switch, a reflectivity
/// apart from Ks) is listed in `left_out`.
pub fn scene_nff(request: &SaveRequest) -> Result<SavedText, SaveError> {
    let loaded = request.loaded;
    let path = request.loaded_path;
    let is_nff = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nff"));
    if !is_nff {
        return Err(SaveError::NotNff {
            path: path.to_owned(),
        });
    }
    let text = &*loaded.source_text;
    let layout = crate::scene::nff::layout(text, path).map_err(|e| SaveError::Unreadable {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    if request.lights.len() != loaded.lights.len() {
        return Err(SaveError::LightCount {
            loaded: loaded.lights.len(),
            edited: request.lights.len(),
        });
    }
    let mut edits: Vec<(Range<usize>, String)> = Vec::new();
    let mut left_out = Vec::new();

    let s = request.settings;
    let im = &loaded.image;
    let resize = s.protocol == Protocol::Glint && (s.width, s.height) != (im.width, im.height);
    let rows = if resize { s.height } else { im.height };
    if let Some(view) = &layout.view {
        let (old, new) = (&loaded.camera, request.camera);
        for (ranges, a, b) in [
            (&view.from, old.eye, new.eye),
            (&view.at, old.lookat, new.lookat),
            (&view.up, old.up, new.up),
        ] {
            put(&mut edits, text, ranges, &a.to_array(), &b.to_array());
        }
        // NFF's angle depends on the row count; the field of view is kept.
        // A written angle that gives the field of view at this row count
        // stays as written (45, not 44.92069306851313).
        let written: Option<f64> = text[view.angle.clone()].parse().ok();
        let keeps_fov =
            written.is_some_and(|a| crate::scene::nff::fov_from_nff_angle(a, rows) == new.fov);
        if (old.fov != new.fov || resize) && !keeps_fov {
            let angle = crate::scene::nff::nff_angle_from_fov(new.fov, rows);
            edits.push((
                view.angle.clone(),
                number_like(angle, &text[view.angle.clone()]),
            ));
        }
        if resize {
            edits.push((view.resolution[0].clone(), s.width.to_string()));
            edits.push((view.resolution[1].clone(), s.height.to_string()));
        }
    }
    if s.protocol == Protocol::Glint {
        for (what, differs) in [
            (
                LeftOut::Samples,
                (s.samples, s.adaptive) != (im.samples, im.adaptive),
            ),
            (LeftOut::MaxDepth, s.max_depth != im.max_depth),
            (LeftOut::Colors, s.colors != im.colors),
            (LeftOut::Sides, s.sides != im.sides),
        ] {
            if differs {
                left_out.push(what);
            }
        }
    }
    if (s.accel == Accel::Octree) != loaded.octree_enabled {
        left_out.push(LeftOut::OctreeSwitch);
    }
    if *request.octree != loaded.octree_params {
        left_out.push(LeftOut::OctreeParams);
    }
    if request.camera_path != loaded.camera_path.as_ref() {
        left_out.push(LeftOut::CameraPath);
    }

    for ((place, old), new) in layout.lights.iter().zip(&loaded.lights).zip(request.lights) {
        put(
            &mut edits,
            text,
            &place.position,
            &old.position.to_array(),
            &new.position.to_array(),
        );
        if old.color != new.color {
            match &place.color {
                Some(ranges) => put(
                    &mut edits,
                    text,
                    ranges,
                    &old.color.to_array(),
                    &new.color.to_array(),
                ),
                None => {
                    let end = place.position[2].end;
                    let c = new.color;
                    edits.push((
                        end..end,
                        format!(
                            " {} {} {}",
                            number_like(c.x, ""),
                            number_like(c.y, ""),
                            number_like(c.z, "")
                        ),
                    ));
                }
            }
        }
    }

    for (i, (old, new)) in loaded.materials.iter().zip(request.materials).enumerate() {
        if old == new {
            continue;
        }
        // The default grey of objects before any `f` has no line to edit.
        if layout.materials.get(i).is_none_or(Vec::is_empty) {
            left_out.push(LeftOut::Material {
                name: old.name.clone(),
            });
            continue;
        }
        // NFF has one coefficient for the highlight and the mirror ray, and
        // weights the ambient term by Kd.
        if new.reflectivity != new.ks {
            left_out.push(LeftOut::Reflectivity {
                material: old.name.clone(),
            });
        }
        // The changed numbers of every `f` line of the material, and the
        // index of refraction where the file's own differs from the one
        // used (an opaque material's is often written 0 and loaded as 1; a
        // material made transparent needs one the file can load).
        let (before, after) = (nff_key(old), nff_key(new));
        for entity in layout.materials.get(i).into_iter().flatten() {
            for (k, r) in entity.iter().enumerate().take(after.len()) {
                let token = &text[r.clone()];
                let ior_needed =
                    k == 7 && new.transparency > 0.0 && token.parse::<f64>() != Ok(after[k]);
                if before[k] != after[k] || ior_needed {
                    edits.push((r.clone(), number_like(after[k], token)));
                }
            }
        }
    }
    // NFF gives one material to equal `f` lines: materials edited to be
    // equal are one material when the file is read again.
    for (i, a) in request.materials.iter().enumerate() {
        if let Some(b) = request.materials[..i]
            .iter()
            .find(|b| nff_key(b) == nff_key(a))
        {
            left_out.push(LeftOut::EqualMaterial {
                material: a.name.clone(),
                equal_to: b.name.clone(),
            });
        }
    }

    edits.sort_by_key(|(r, _)| (r.start, r.end));
    let mut out = String::with_capacity(text.len() + 64 * edits.len());
    let mut at = 0;
    for (r, new) in edits {
        out.push_str(&text[at..r.start]);
        out.push_str(&new);
        at = r.end;
    }
    out.push_str(&text[at..]);
    Ok(SavedText {
        text: out,
        left_out,
    })
}

/// Rewrites the numbers at `ranges` whose values changed from `old` to
/// `new`, each in its token's style.
fn put(
    edits: &mut Vec<(Range<usize>, String)>,
    text: &str,
    ranges: &[Range<usize>],
    old: &[f64],
    new: &[f64],
) {
    for ((r, &a), &b) in ranges.iter().zip(old).zip(new) {
        if a != b {
            edits.push((r.clone(), number_like(b, &text[r.clone()])));
        }
    }
}

/// A material's numbers in the order of its `f` line.
fn nff_key(m: &Material) -> [f64; 8] {
    [
        m.color.x,
        m.color.y,
        m.color.z,
        m.kd,
        m.ks,
        m.shininess,
        m.transparency,
        m.ior,
    ]
}

/// `x` written in the style of the number it replaces: a whole number
/// stays whole where the file wrote one without a point (`3`, not `3.0`);
/// otherwise the shortest text that reads back as `x`.
fn number_like(x: f64, token: &str) -> String {
    let plain_integer = !token.is_empty()
        && token
            .bytes()
            .all(|b| b.is_ascii_digit() || b == b'-' || b == b'+');
    if plain_integer && x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{}", x as i64)
    } else {
        format!("{x:?}")
    }
}

//! Saving an NFF scene: its own text with the numbers the viewer edits
//! rewritten in place.

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
    let number = |x: f64| format!("{x:?}");
    let mut edits: Vec<(Range<usize>, String)> = Vec::new();
    let mut put = |ranges: &[Range<usize>], values: &[f64]| {
        for (r, &x) in ranges.iter().zip(values) {
            edits.push((r.clone(), number(x)));
        }
    };
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
            if a != b {
                put(ranges, &b.to_array());
            }
        }
        // NFF's angle depends on the row count; the field of view is kept.
        if old.fov != new.fov || resize {
            put(
                std::slice::from_ref(&view.angle),
                &[crate::scene::nff::nff_angle_from_fov(new.fov, rows)],
            );
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
    if s.use_octree != loaded.octree_enabled {
        left_out.push(LeftOut::OctreeSwitch);
    }

    for ((place, old), new) in layout.lights.iter().zip(&loaded.lights).zip(request.lights) {
        let mut put = |ranges: &[Range<usize>], values: &[f64]| {
            for (r, &x) in ranges.iter().zip(values) {
                edits.push((r.clone(), number(x)));
            }
        };
        if old.position != new.position {
            put(&place.position, &new.position.to_array());
        }
        if old.color != new.color {
            match &place.color {
                Some(ranges) => put(ranges, &new.color.to_array()),
                None => {
                    let end = place.position[2].end;
                    let c = new.color;
                    edits.push((
                        end..end,
                        format!(" {} {} {}", number(c.x), number(c.y), number(c.z)),
                    ));
                }
            }
        }
    }

    for (i, (old, new)) in loaded.materials.iter().zip(request.materials).enumerate() {
        if old == new {
            continue;
        }
        // NFF has one coefficient for the highlight and the mirror ray, and
        // weights the ambient term by Kd.
        if new.reflectivity != new.ks {
            left_out.push(LeftOut::Reflectivity {
                material: old.name.clone(),
            });
        }
        // Every number of the material's `f` lines is written: the file's
        // own may differ from the loaded value (an opaque material's index
        // of refraction is often written 0 and loaded as 1).
        let values = [
            new.color.x,
            new.color.y,
            new.color.z,
            new.kd,
            new.ks,
            new.shininess,
            new.transparency,
            new.ior,
        ];
        for entity in layout.materials.get(i).into_iter().flatten() {
            for (r, &x) in entity.iter().zip(&values) {
                edits.push((r.clone(), number(x)));
            }
        }
    }
    // NFF gives one material to equal `f` lines: materials edited to be
    // equal are one material when the file is read again.
    let nff_key = |m: &Material| {
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
    };
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

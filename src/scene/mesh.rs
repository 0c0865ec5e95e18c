//! Wavefront OBJ meshes, placed by scale, rotation and translation (their
//! MTL materials are `mesh_materials`'s).

use super::obj::{self, Corner, NO_NORMAL, SkippedElements};
use super::polygon::{DroppedPolygons, PolygonDefect, triangulate};
use crate::math::DVec3;

/// Uniform scale, then rotation about x, y and z (degrees, in that order),
/// then translation.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    pub scale: f64,
    pub rotate_degrees: DVec3,
    pub translate: DVec3,
}

impl Placement {
    fn rotation(&self) -> glam::DMat3 {
        let r = self.rotate_degrees * (std::f64::consts::PI / 180.0);
        glam::DMat3::from_rotation_z(r.z)
            * glam::DMat3::from_rotation_y(r.y)
            * glam::DMat3::from_rotation_x(r.x)
    }
}

pub struct LoadedMesh {
    pub triangles: Vec<[DVec3; 3]>,
    /// Per-triangle vertex normals when the mesh is smooth shaded.
    pub normals: Option<Vec<[DVec3; 3]>>,
    /// Each triangle's material: an index into `material_names`.
    pub triangle_materials: Vec<u32>,
    /// The `usemtl` names in order; index 0 (empty) is the faces with none.
    pub material_names: Vec<String>,
    /// The file's `mtllib` arguments.
    pub libraries: Vec<String>,
    /// Faces that were not simple polygons or had no area.
    pub dropped_polygons: DroppedPolygons,
    /// The lines of the first few dropped faces, for the note.
    pub dropped_lines: Vec<u32>,
    /// Self-crossing (folded) quads split into their two triangles.
    pub folded_quads: usize,
    /// Per-triangle vertex colours (`v x y z r g b`), in [0, 1]: empty
    /// when the file has none, `None` for a triangle with a corner
    /// written without one.
    pub colors: Vec<Option<[DVec3; 3]>>,
    /// Per-triangle texture coordinates (`vt`): empty when the file has
    /// none, `None` for a triangle with a corner written without one.
    pub uvs: Vec<Option<[[f64; 2]; 3]>>,
    /// Elements glint does not render, counted.
    pub skipped: SkippedElements,
    /// The file's header comment, where exporters name themselves.
    pub header: Option<String>,
}

/// Parses OBJ bytes (every refusal names its line). `smooth`: `None` uses
/// the file's normals when it has them; `Some(true)` computes area-weighted
/// vertex normals when it has none; `Some(false)` shades flat.
pub fn parse_obj(
    bytes: &[u8],
    smooth: Option<bool>,
    placement: &Placement,
) -> Result<LoadedMesh, String> {
    let data = obj::parse(bytes).map_err(|e| e.to_string())?;
    // Nothing of OBJ's at all (binary or another format): said as such,
    // without quoting the content (a mesh path may name any file).
    if data.positions.is_empty() && data.faces.is_empty() && !data.skipped.statements.is_empty() {
        return Err("not an OBJ file: it has no vertex or face statement".into());
    }
    let rotation = placement.rotation();
    let place = |p: DVec3| rotation * (p * placement.scale) + placement.translate;
    let positions: Vec<DVec3> = data.positions.iter().map(|&p| place(p)).collect();
    if !positions.iter().all(|p| p.is_finite()) {
        return Err(
            "vertex coordinates overflow once placed (scale or translate too large)".into(),
        );
    }
    let normals: Vec<DVec3> = data.normals.iter().map(|&n| rotation * n).collect();
    let mut triangles = Vec::new();
    let mut triangle_normals = Vec::new();
    let mut triangle_materials = Vec::new();
    let mut triangle_colors = Vec::new();
    let mut triangle_uvs = Vec::new();
    // Colours written 0-255 (some scanners) rather than 0-1: scaled.
    let color_scale = if data.colors.iter().flatten().any(|c| c.max_element() > 1.0) {
        1.0 / 255.0
    } else {
        1.0
    };
    let color_of = |p: u32| {
        data.colors
            .get(p as usize)
            .copied()
            .flatten()
            .map(|c| (c * color_scale).clamp(DVec3::ZERO, DVec3::ONE))
    };
    let mut any_normals = false;
    let mut dropped_polygons = DroppedPolygons::default();
    let mut dropped_lines = Vec::new();
    let mut folded_quads = 0;
    let mut skipped = data.skipped.clone();
    let mut face: Vec<Corner> = Vec::new();
    for f in &data.faces {
        // Repeated vertices removed (the first of each kept): a face that
        // lists its four corners 234 times is a quad, not 936 triangles.
        face.clear();
        let listed = &data.corners[f.start as usize..(f.start + f.len) as usize];
        // A face with a hole written as one bridged polygon: triangulated
        // as the ring it describes (removing the repeats cut a wedge out).
        let keyhole = (listed.len() >= 8)
            .then(|| keyhole_face(listed, &positions))
            .flatten();
        // The triangles, as indices into the corners they use.
        let (pieces, used): (Vec<[u32; 3]>, &[Corner]) = match keyhole {
            Some(pieces) => (pieces, listed),
            None => {
                for &corner in listed {
                    if !face.iter().any(|c| c.position == corner.position) {
                        face.push(corner);
                    }
                }
                // Counted once: as short if too few corners are left, else
                // as a face whose repeats were removed.
                if face.len() < 3 {
                    skipped.short_faces += 1;
                    continue;
                }
                if face.len() < listed.len() {
                    skipped.faces_with_repeated_vertices += 1;
                }
                let corners: Vec<DVec3> = face
                    .iter()
                    .map(|c| positions[c.position as usize])
                    .collect();
                let pieces = if face.len() == 3 {
                    vec![[0, 1, 2]]
                } else {
                    // Faces are ear-clipped, not fanned: concave faces exist.
                    let folded = |defect| match defect {
                        PolygonDefect::NotSimple => folded_quad(&corners),
                        PolygonDefect::ZeroArea => None,
                    };
                    match triangulate(&corners).map_err(|defect| (defect, folded(defect))) {
                        Ok(t) => t,
                        // A quad whose outline crosses itself (scanners
                        // write them where the surface folds): its two
                        // triangles.
                        Err((_, Some(t))) => {
                            folded_quads += 1;
                            t
                        }
                        Err((defect, None)) => {
                            dropped_polygons.record(defect);
                            if dropped_lines.len() < 5 {
                                dropped_lines.push(f.line);
                            }
                            continue;
                        }
                    }
                };
                (pieces, &face[..])
            }
        };
        let has_normals = used.iter().all(|c| c.normal != NO_NORMAL);
        any_normals |= has_normals;
        let has_uvs = used.iter().all(|c| c.uv != NO_NORMAL);
        for t in pieces {
            let corners = t.map(|k| used[k as usize]);
            triangles.push(corners.map(|c| positions[c.position as usize]));
            triangle_normals.push(if has_normals {
                corners.map(|c| normals[c.normal as usize])
            } else {
                [DVec3::ZERO; 3]
            });
            triangle_materials.push(f.material);
            if !data.colors.is_empty() {
                let [ca, cb, cc] = corners.map(|c| color_of(c.position));
                triangle_colors.push(ca.zip(cb).zip(cc).map(|((a, b), c)| [a, b, c]));
            }
            if !data.uvs.is_empty() {
                triangle_uvs.push(has_uvs.then(|| corners.map(|c| data.uvs[c.uv as usize])));
            }
        }
    }
    if triangles.is_empty() {
        return Err(if dropped_polygons.total() > 0 {
            "the mesh has no face that is a simple polygon".into()
        } else {
            "the mesh has no faces (lines and points are not rendered)".into()
        });
    }
    // All of them without area is as empty as none: refused alike (the
    // scene would otherwise skip each one and show its background).
    if triangles
        .iter()
        .all(|t| crate::shapes::Triangle::new(*t).is_none())
    {
        return Err(format!(
            "the mesh has no face with an area: all {} of its triangles are degenerate \
             (no area: corners on one line or at one point, or too far apart for \
             their area to be a number)",
            triangles.len()
        ));
    }
    let normals = match smooth {
        Some(false) => None,
        None if !any_normals => None,
        Some(true) if !any_normals => Some(computed_vertex_normals(&triangles)),
        _ => Some(triangle_normals),
    };
    Ok(LoadedMesh {
        triangles,
        normals,
        triangle_materials,
        material_names: data.materials,
        libraries: data.libraries,
        dropped_polygons,
        dropped_lines,
        folded_quads,
        colors: triangle_colors,
        uvs: triangle_uvs,
        skipped,
        header: data.header,
    })
}

/// A keyhole face's triangles (indices into `listed`), if it is one: its
/// corners repeat a vertex, in the `a b … b a` pattern of a bridge.
fn keyhole_face(listed: &[Corner], positions: &[DVec3]) -> Option<Vec<[u32; 3]>> {
    let ids: Vec<u32> = listed.iter().map(|c| c.position).collect();
    let corners: Vec<DVec3> = ids.iter().map(|&p| positions[p as usize]).collect();
    super::keyhole::triangulate_keyhole(&ids, &corners)
}

/// A self-crossing quad as two triangles with area: split along the
/// diagonal whose two halves face the most alike (the fold the scanner
/// saw), `None` for anything else.
fn folded_quad(corners: &[DVec3]) -> Option<Vec<[u32; 3]>> {
    let [a, b, c, d] = corners else {
        return None;
    };
    let normal = |p: DVec3, q: DVec3, r: DVec3| (q - p).cross(r - p).try_normalize();
    [
        ([0, 1, 2], [0, 2, 3], normal(*a, *b, *c), normal(*a, *c, *d)),
        ([0, 1, 3], [1, 2, 3], normal(*a, *b, *d), normal(*b, *c, *d)),
    ]
    .into_iter()
    .filter_map(|(s, t, m, n)| Some((s, t, m?.dot(n?))))
    .max_by(|x, y| x.2.total_cmp(&y.2))
    .map(|(s, t, _)| vec![s, t])
}

/// Area-weighted vertex normals for a triangle soup, vertices matched by
/// exact position.
fn computed_vertex_normals(triangles: &[[DVec3; 3]]) -> Vec<[DVec3; 3]> {
    use std::collections::HashMap;
    let key = |p: DVec3| (p.x.to_bits(), p.y.to_bits(), p.z.to_bits());
    let mut sums: HashMap<(u64, u64, u64), DVec3> = HashMap::new();
    for t in triangles {
        let area_normal = (t[1] - t[0]).cross(t[2] - t[0]);
        for p in t {
            *sums.entry(key(*p)).or_default() += area_normal;
        }
    }
    triangles
        .iter()
        .map(|t| t.map(|p| sums[&key(p)].normalize_or_zero()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

    fn identity() -> Placement {
        Placement {
            scale: 1.0,
            rotate_degrees: DVec3::ZERO,
            translate: DVec3::ZERO,
        }
    }

    #[test]
    fn quad_is_triangulated_and_placed() {
        let placement = Placement {
            scale: 2.0,
            rotate_degrees: DVec3::new(0.0, 0.0, 90.0),
            translate: DVec3::new(0.0, 0.0, 5.0),
        };
        let mesh = parse_obj(QUAD.as_bytes(), None, &placement).unwrap();
        assert_eq!(mesh.triangles.len(), 2);
        assert!(mesh.normals.is_none());
        // (1,0,0) scaled to (2,0,0), rotated 90 degrees about z to (0,2,0).
        let placed = DVec3::new(0.0, 2.0, 5.0);
        assert!(
            mesh.triangles
                .iter()
                .flatten()
                .any(|v| (*v - placed).length() < 1e-12)
        );
    }

    #[test]
    fn concave_faces_are_ear_clipped_not_fanned() {
        // An arrow head given from its reflex vertex: a fixed diagonal
        // (1-3) and a fan from vertex 1 would both fill outside it.
        let arrow = "v 2 1 0\nv 4 0 0\nv 2 3 0\nv 0 0 0\nf 1 2 3 4\n";
        let mesh = parse_obj(arrow.as_bytes(), None, &identity()).unwrap();
        let area: f64 = mesh
            .triangles
            .iter()
            .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).z)
            .sum();
        assert_eq!(mesh.triangles.len(), 2);
        // Shoelace area of the outline: 4.
        assert!((area - 4.0).abs() < 1e-12, "area {area}");
        // A folded quad (its outline crosses itself) is split into its two
        // triangles; a self-crossing five-pointed star is still dropped, its
        // line kept for the note.
        let bow_tie = "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\nf 1 3 2\n";
        let mesh = parse_obj(bow_tie.as_bytes(), None, &identity()).unwrap();
        assert_eq!(mesh.triangles.len(), 3);
        assert_eq!(
            (mesh.folded_quads, mesh.dropped_polygons.not_simple),
            (1, 0)
        );
        let star = "v 0 1 0\nv 0.588 -0.809 0\nv -0.951 0.309 0\nv 0.951 0.309 0\n\
                    v -0.588 -0.809 0\nf 1 2 3\nf 1 2 3 4 5\n";
        let mesh = parse_obj(star.as_bytes(), None, &identity()).unwrap();
        assert_eq!(mesh.dropped_polygons.not_simple, 1);
        assert_eq!(mesh.dropped_lines, [7]);
    }

    #[test]
    fn smooth_without_file_normals_computes_them() {
        let mesh = parse_obj(QUAD.as_bytes(), Some(true), &identity()).unwrap();
        let normals = mesh.normals.unwrap();
        assert!(
            normals
                .iter()
                .flatten()
                .all(|n| (*n - DVec3::Z).length() < 1e-12)
        );
    }

    #[test]
    fn empty_and_broken_meshes_are_errors() {
        assert!(parse_obj(b"# nothing\n", None, &identity()).is_err());
        assert!(parse_obj(b"v 0 0 0\nf 1 2 3\n", None, &identity()).is_err());
    }
}

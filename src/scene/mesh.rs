//! Wavefront OBJ meshes (through `tobj`), placed by scale, rotation and translation.

use std::path::Path;

use super::polygon::{DroppedPolygons, triangulate};
use crate::math::DVec3;

/// Where mesh files come from: the file system, or memory for scenes
/// embedded in the binary.
pub trait MeshSource {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>>;
}

pub struct FileSystem;

impl MeshSource for FileSystem {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

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
    /// Faces that were not simple polygons or had no area.
    pub dropped_polygons: DroppedPolygons,
}

/// Parses OBJ bytes. `smooth`: `None` uses the file's normals when it has
/// them; `Some(true)` computes area-weighted vertex normals when it has none;
/// `Some(false)` shades flat.
pub fn parse_obj(
    bytes: &[u8],
    smooth: Option<bool>,
    placement: &Placement,
) -> Result<LoadedMesh, String> {
    // tobj's own triangulation splits quads on a fixed diagonal and larger
    // faces as a fan, which is wrong for concave faces: faces are read
    // whole and ear-clipped here.
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(bytes);
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| Ok(Default::default()))
        .map_err(|e| format!("not a valid OBJ file: {e}"))?;
    let rotation = placement.rotation();
    let place = |p: DVec3| rotation * (p * placement.scale) + placement.translate;
    let mut triangles = Vec::new();
    let mut normals = Vec::new();
    let mut any_normals = false;
    let mut dropped_polygons = DroppedPolygons::default();
    for model in &models {
        let m = &model.mesh;
        let position = |i: u32| -> Result<DVec3, String> {
            let i = i as usize * 3;
            m.positions
                .get(i..i + 3)
                .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                .ok_or_else(|| format!("vertex index {} out of range", i / 3 + 1))
        };
        let has_normals = m.normals.len() == m.positions.len() && !m.normals.is_empty();
        any_normals |= has_normals;
        let normal = |i: u32| {
            let i = i as usize * 3;
            rotation
                * DVec3::new(
                    m.normals[i] as f64,
                    m.normals[i + 1] as f64,
                    m.normals[i + 2] as f64,
                )
        };
        // Every face is a triangle when the file has no larger ones.
        let arities: Vec<usize> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut start = 0;
        for arity in arities {
            let face = m
                .indices
                .get(start..start + arity)
                .ok_or("face indices out of range")?;
            start += arity;
            let corners = face
                .iter()
                .map(|&i| position(i).map(place))
                .collect::<Result<Vec<DVec3>, String>>()?;
            if !corners.iter().all(|p| p.is_finite()) {
                return Err("vertex coordinates must be finite".into());
            }
            let pieces = if arity == 3 {
                vec![[0, 1, 2]]
            } else {
                match triangulate(&corners) {
                    Ok(t) => t,
                    Err(defect) => {
                        dropped_polygons.record(defect);
                        continue;
                    }
                }
            };
            for [a, b, c] in pieces {
                let (a, b, c) = (a as usize, b as usize, c as usize);
                triangles.push([corners[a], corners[b], corners[c]]);
                normals.push(if has_normals {
                    [normal(face[a]), normal(face[b]), normal(face[c])]
                } else {
                    [DVec3::ZERO; 3]
                });
            }
        }
    }
    if triangles.is_empty() {
        return Err(if dropped_polygons.total() > 0 {
            "the mesh has no face that is a simple polygon".into()
        } else {
            "the mesh has no triangles".into()
        });
    }
    let normals = match smooth {
        Some(false) => None,
        None if !any_normals => None,
        Some(true) if !any_normals => Some(computed_vertex_normals(&triangles)),
        _ => Some(normals),
    };
    Ok(LoadedMesh {
        triangles,
        normals,
        dropped_polygons,
    })
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
        // An arrow head given from its reflex vertex: tobj's fixed diagonal
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
        let bow_tie = "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\nf 1 3 2\n";
        let mesh = parse_obj(bow_tie.as_bytes(), None, &identity()).unwrap();
        assert_eq!(mesh.triangles.len(), 1);
        assert_eq!(mesh.dropped_polygons.not_simple, 1);
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

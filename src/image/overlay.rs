//! Octree overlay: the octree's cells drawn as projected wireframe boxes
//! over a rendered image, coloured by how many primitives each references.

use crate::accel::OctreeCell;
use crate::camera::Camera;
use crate::image::legend::viridis;
use crate::math::{DVec3, Ray};

/// Colour of a cell holding `references` when the fullest holds `most`:
/// viridis on a logarithmic scale (counts span orders of magnitude).
pub fn cell_color(references: u64, most: u64) -> [u8; 3] {
    let t = ((1 + references) as f64).ln() / ((1 + most.max(1)) as f64).ln();
    viridis(t)
}

/// The twelve edges of a box.
fn edges(min: DVec3, max: DVec3) -> [(DVec3, DVec3); 12] {
    let c = |i: usize| {
        DVec3::new(
            if i & 1 == 1 { max.x } else { min.x },
            if i & 2 == 2 { max.y } else { min.y },
            if i & 4 == 4 { max.z } else { min.z },
        )
    };
    let mut out = [(DVec3::ZERO, DVec3::ZERO); 12];
    let mut n = 0;
    for i in 0..8 {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                out[n] = (c(i), c(i | bit));
                n += 1;
            }
        }
    }
    out
}

/// Image-space end points of segment `a`-`b`, cut at a plane just in front
/// of the eye so segments passing behind the camera still draw their
/// visible part.
pub fn project_segment(camera: &Camera, a: DVec3, b: DVec3) -> Option<((f64, f64), (f64, f64))> {
    let near = 1e-6 * (a - camera.eye).length().max((b - camera.eye).length());
    let (za, zb) = (camera.view_depth(a), camera.view_depth(b));
    if za <= near && zb <= near {
        return None;
    }
    let cut = |p: DVec3, zp: f64, q: DVec3, zq: f64| p + (q - p) * ((near - zp) / (zq - zp));
    let a2 = if za <= near { cut(a, za, b, zb) } else { a };
    let b2 = if zb <= near { cut(b, zb, a, za) } else { b };
    Some((camera.project(a2)?, camera.project(b2)?))
}

/// The projected edges of `cell` (image coordinates, not clipped to the image).
pub fn cell_segments(camera: &Camera, cell: &OctreeCell) -> Vec<((f64, f64), (f64, f64))> {
    edges(cell.bounds.min, cell.bounds.max)
        .into_iter()
        .filter_map(|(a, b)| project_segment(camera, a, b))
        .collect()
}

/// Liang–Barsky clipping of a segment to `[0, w] x [0, h]`.
fn clip(p: (f64, f64), q: (f64, f64), w: f64, h: f64) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (den, num) in [(-dx, p.0), (dx, w - p.0), (-dy, p.1), (dy, h - p.1)] {
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1 && t0.is_finite() && t1.is_finite()).then_some((
        (p.0 + t0 * dx, p.1 + t0 * dy),
        (p.0 + t1 * dx, p.1 + t1 * dy),
    ))
}

/// The cells in drawing order with their colours: fuller cells last, so
/// they stay visible where edges overlap. The PNG overlay and the viewer's
/// both draw this list.
pub fn styled_cells(cells: &[OctreeCell]) -> Vec<(&OctreeCell, [u8; 3])> {
    let most = cells.iter().map(|c| c.references).max().unwrap_or(1);
    let mut order: Vec<&OctreeCell> = cells.iter().collect();
    order.sort_by_key(|c| c.references);
    order
        .into_iter()
        .map(|c| (c, cell_color(c.references, most)))
        .collect()
}

/// Draws `cells` as wireframe boxes into an RGB8 image the camera's size.
pub fn draw_cells(rgb: &mut [u8], camera: &Camera, cells: &[OctreeCell]) {
    let (w, h) = (camera.width(), camera.height());
    for (cell, color) in styled_cells(cells) {
        for (p, q) in cell_segments(camera, cell) {
            let Some((p, q)) = clip(p, q, w as f64 - 1e-9, h as f64 - 1e-9) else {
                continue;
            };
            let steps = (q.0 - p.0).abs().max((q.1 - p.1).abs()).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let t = k as f64 / steps as f64;
                let (x, y) = (p.0 + (q.0 - p.0) * t, p.1 + (q.1 - p.1) * t);
                let (x, y) = (x as u32, y as u32);
                if x < w && y < h {
                    let i = ((y * w + x) * 3) as usize;
                    rgb[i..i + 3].copy_from_slice(&color);
                }
            }
        }
    }
}

/// The RGB8 picture of `frame` with the octree's cells down to level
/// `depth` drawn over it, and with `legend` a legend strip (the view's
/// own, or else the overlay's colour scale). Returns the bytes and the
/// height.
pub fn annotate(
    frame: &crate::image::frame::Frame,
    camera: &Camera,
    cells: &[OctreeCell],
    depth: u32,
    legend: bool,
) -> (Vec<u8>, u32) {
    let mut rgb = frame.to_rgb8();
    draw_cells(&mut rgb, camera, cells);
    if !legend {
        return (rgb, frame.height);
    }
    let legend = frame.legend().unwrap_or_else(|| {
        let most = cells.iter().map(|c| c.references).max().unwrap_or(0);
        crate::image::legend::Legend {
            low: "1".into(),
            high: most.to_string(),
            caption: format!("octree to depth {depth}: refs per cell (log)"),
            ramp: crate::image::legend::Ramp::Viridis,
        }
    });
    let height = crate::image::legend::append_legend(&mut rgb, frame.width, frame.height, &legend);
    (rgb, height)
}

/// The cell the ray through pixel `(x, y)` (continuous image coordinates)
/// enters first, for hover read-outs.
pub fn cell_at<'a>(
    camera: &Camera,
    cells: &'a [OctreeCell],
    x: f64,
    y: f64,
) -> Option<&'a OctreeCell> {
    let (i, j) = (x.floor(), y.floor());
    if i < 0.0 || j < 0.0 || i >= camera.width() as f64 || j >= camera.height() as f64 {
        return None;
    }
    let ray: Ray = camera.ray(i as u32, j as u32, x - i, y - j);
    cells
        .iter()
        .filter_map(|c| {
            c.bounds
                .ray_range(&ray, 0.0, f64::INFINITY)
                .map(|(t0, _)| (t0, c))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.depth.cmp(&b.1.depth)))
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraSpec;
    use crate::math::Aabb;

    fn camera() -> Camera {
        let spec = CameraSpec {
            eye: DVec3::new(0.0, 0.0, 5.0),
            lookat: DVec3::ZERO,
            up: DVec3::Y,
            fov: 60.0,
        };
        Camera::new(&spec, 64, 48).unwrap()
    }

    #[test]
    fn projection_inverts_the_camera_ray() {
        let cam = camera();
        for (i, j) in [(0, 0), (10, 40), (63, 47), (32, 24)] {
            let ray = cam.ray(i, j, 0.25, 0.75);
            let (x, y) = cam.project(ray.at(3.7)).unwrap();
            assert!((x - (i as f64 + 0.25)).abs() < 1e-9 && (y - (j as f64 + 0.75)).abs() < 1e-9);
        }
        assert!(
            cam.project(DVec3::new(0.0, 0.0, 6.0)).is_none(),
            "behind the eye"
        );
    }

    #[test]
    fn a_box_in_view_draws_its_outline_and_hover_finds_it() {
        let cam = camera();
        let cell = OctreeCell {
            bounds: Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
            depth: 2,
            references: 7,
        };
        let mut rgb = vec![0u8; 64 * 48 * 3];
        draw_cells(&mut rgb, &cam, &[cell]);
        // Seen head-on from 4 and 6 units, the front face (z = 1) is a
        // square of half-side 1/4 on the image plane at distance 1, the
        // back face one of 1/6; pixels are 2 tan 30° / 48 wide, the centre
        // at (32, 24). Lines ink the pixel each point falls in.
        let pixel = 2.0 * 30f64.to_radians().tan() / 48.0;
        let square = |half: f64| {
            let r = half / pixel;
            let lo = |c: f64| (c - r).floor() as u32;
            let hi = |c: f64| (c + r).floor() as u32;
            (lo(32.0), hi(32.0), lo(24.0), hi(24.0))
        };
        let inked = |x: u32, y: u32| rgb[((y * 64 + x) * 3) as usize..][..3] != [0, 0, 0];
        for (left, right, top, bottom) in [square(0.25), square(1.0 / 6.0)] {
            for y in top + 1..bottom {
                assert!(inked(left, y) && inked(right, y), "sides at row {y}");
            }
            for x in left + 1..right {
                assert!(inked(x, top) && inked(x, bottom), "top and bottom at {x}");
            }
        }
        // Nothing outside the front square; inside, only the edges: the
        // centre and a point between the two squares' sides stay black.
        let (left, right, top, bottom) = square(0.25);
        for y in 0..48 {
            for x in 0..64 {
                let within = (left..=right).contains(&x) && (top..=bottom).contains(&y);
                assert!(within || !inked(x, y), "ink outside the outline at {x},{y}");
            }
        }
        assert!(!inked(32, 24) && !inked(left + 2, 24));
        // The centre of the image looks through the box; the corner does not.
        assert_eq!(cell_at(&cam, &[cell], 32.0, 24.0), Some(&cell));
        assert_eq!(cell_at(&cam, &[cell], 0.5, 0.5), None);
        // A box around the eye still draws (edges cut at the near plane) without panicking.
        let around = OctreeCell {
            bounds: Aabb::new(DVec3::splat(-10.0), DVec3::splat(10.0)),
            ..cell
        };
        draw_cells(&mut rgb, &cam, &[around]);
    }
}

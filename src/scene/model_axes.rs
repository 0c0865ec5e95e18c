//! Which way is up in an OBJ model, which has no up axis of its own: read
//! from how its faces lean, then from the flat base it stands on, weighed
//! against the exporter its header names.

use crate::math::{Aabb, DVec3};
use crate::shapes::Shape;

/// The model's own axes: which way is up, which side is its front, and
/// the one across. OBJ has no up axis of its own; exporters mostly write
/// +y up with the model facing +z (Blender's and 3ds Max's defaults), but
/// scans and CAD or 3D-printing exports are +z up, facing -y (Blender's
/// front view looks along +y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ModelAxes {
    pub side: DVec3,
    pub up: DVec3,
    pub front: DVec3,
}

pub(super) const Y_UP: ModelAxes = ModelAxes {
    side: DVec3::X,
    up: DVec3::Y,
    front: DVec3::Z,
};
pub(super) const Z_UP: ModelAxes = ModelAxes {
    side: DVec3::X,
    up: DVec3::Z,
    front: DVec3::NEG_Y,
};

/// Whether the exporter a header comment names writes +y up by default:
/// Blender's OBJ exporter (up Y, forward -Z unless changed), 3ds Max's
/// (guruware's, which flips to y-up), Maya, Cinema 4D and Wings 3D, whose
/// own axes are y-up. A user can change that default, so the header only
/// raises the bar a flat base must clear (`model_axes`).
fn exporter_writes_y_up(header: &str) -> bool {
    let header = header.to_ascii_lowercase();
    [
        "blender",
        "guruware",
        "3ds max wavefront obj exporter",
        "maya",
        "cinema 4d",
        "wings 3d",
    ]
    .iter()
    .any(|name| header.contains(name))
}

/// The least net lean, as a share of the area, that names an up axis
/// outright: most of the area faces up (a terrain, a street, a floor
/// plan).
const STRONG_LEAN: f64 = 0.6;
/// The least net lean that names an up axis unless the other axis has a
/// floor and a ceiling: a building open underneath, a room without its
/// roof or its front walls.
const WEAK_LEAN: f64 = 0.1;
/// The share of the footprint a flat base must cover, and the larger share
/// it must cover when the header names a y-up exporter.
const BASE: f64 = 0.02;
const BASE_AGAINST_HEADER: f64 = 0.05;

/// What one pass over the faces gathers along one axis (y or z).
#[derive(Clone, Copy, Default)]
struct AlongAxis {
    /// The area-weighted sum of the unit normals' component.
    net: f64,
    /// The area-weighted height of the faces, 0 at the bottom, 1 at the top.
    moment: f64,
    /// The area of faces perpendicular to the axis at its low and high end.
    low: f64,
    high: f64,
}

/// The up axis the model's content suggests, +y (OBJ's convention) unless
/// it says +z. In this order:
///
/// 1. The way the faces lean (`leans_up`). Floors, roofs and the ground
///    face up, so a model open to the sky or underneath has more face area
///    turned up than down, where a closed model's outward faces cancel.
/// 2. A flat base at its lowest z (faces perpendicular to z there covering
///    at least 2 % of its footprint) that has no match at its top (a box
///    or a slab is flat at both ends and says nothing) and no comparable
///    base at its lowest y: a statue's plinth, a 3D-print's bed face, a
///    building's ground slab. The flat butt of a rifle lying along z is no
///    base, its muzzle end being as flat. Where the header names an
///    exporter whose default is y-up (`exporter_writes_y_up`), the base
///    must cover 5 %: the default weighs against a faint base, while a
///    clear one shows the default was changed (a scanned drill standing
///    on its battery).
pub(super) fn model_axes(shapes: &[Shape], bounds: Aabb, header: Option<&str>) -> ModelAxes {
    let extent = bounds.max - bounds.min;
    let largest = extent.max_element();
    if !(largest > 0.0 && largest.is_finite()) {
        return Y_UP;
    }
    let (y, z, area) = survey(shapes, bounds);
    if !(area > 0.0) {
        return Y_UP;
    }
    // The footprint across each axis, in the scaled units of `survey`.
    let across =
        |axis: usize| extent[(axis + 1) % 3] * extent[(axis + 2) % 3] / (largest * largest);
    // A model flat across an axis has no footprint across it: no base.
    let share = |along: AlongAxis, axis: usize| {
        let across = across(axis);
        if across > 0.0 {
            (along.low / across, along.high / across)
        } else {
            (0.0, 0.0)
        }
    };
    let (base_y, top_y) = share(y, 1);
    let (base_z, top_z) = share(z, 2);
    let thick = |axis: usize| extent[axis] >= 0.02 * largest;
    let lean_y = (y.net / area, y.moment / area);
    let lean_z = (z.net / area, z.moment / area);
    // A floor and a ceiling across the axis: a room, closed or open at its
    // front, whose lean along its depth says nothing of up.
    let roofed = |base: f64, top: f64| base >= 0.5 && top >= 0.5;
    if thick(2) && leans_up(lean_z, lean_y.0, roofed(base_y, top_y)) {
        return Z_UP;
    }
    if thick(1) && leans_up(lean_y, lean_z.0, roofed(base_z, top_z)) {
        return Y_UP;
    }
    let least_base = if header.is_some_and(exporter_writes_y_up) {
        BASE_AGAINST_HEADER
    } else {
        BASE
    };
    if base_z >= least_base && base_z > 2.0 * top_z && base_z > 2.0 * base_y {
        Z_UP
    } else {
        Y_UP
    }
}

/// Whether an axis's `(lean, height)` (net lean and where the area sits,
/// as shares of the area) names it up against the other axis's lean: the
/// lean is up, twice the other's, and the area sits in the lower 60 % (a
/// mask open at the back leans the way it faces, but its area sits at its
/// front). A lean of 0.6 names it outright; one of 0.1 unless the other
/// axis has a floor and a ceiling (`other_roofed`): a Cornell box, open at
/// its front, leans forwards as a room without its roof leans up. A floor
/// and a wall of equal size lean as much up as forwards and name neither.
fn leans_up((lean, height): (f64, f64), other: f64, other_roofed: bool) -> bool {
    let clear = lean >= 2.0 * other.abs() && height <= 0.6;
    clear && (lean >= STRONG_LEAN || (lean >= WEAK_LEAN && !other_roofed))
}

/// One pass over the triangles: along y and along z, the net lean, the
/// area-weighted height and the flat ends (faces within 1 % of the extent
/// of an end, their normals within 8 degrees of the axis), and the total
/// area. Coordinates are scaled to the model's size first, so the cross
/// product of a 1e200 model does not overflow.
fn survey(shapes: &[Shape], bounds: Aabb) -> (AlongAxis, AlongAxis, f64) {
    let extent = bounds.max - bounds.min;
    let largest = extent.max_element();
    let scaled = extent / largest;
    let mut along = [AlongAxis::default(); 2];
    let mut area_sum = 0.0;
    for shape in shapes {
        let Shape::Triangle(t) = shape else { continue };
        let [a, b, c] = t.vertices.map(|v| (v - bounds.min) / largest);
        let twice = (b - a).cross(c - a);
        let area = 0.5 * twice.length();
        if !(area > 0.0 && area.is_finite()) {
            continue;
        }
        area_sum += area;
        for (along, axis) in along.iter_mut().zip([1, 2]) {
            along.net += 0.5 * twice[axis];
            if scaled[axis] > 0.0 {
                along.moment += area * (a[axis] + b[axis] + c[axis]) / (3.0 * scaled[axis]);
            }
            if twice[axis].abs() > 0.99 * 2.0 * area {
                let tolerance = 0.01 * scaled[axis];
                let (lo, hi) = (
                    a[axis].min(b[axis]).min(c[axis]),
                    a[axis].max(b[axis]).max(c[axis]),
                );
                if hi <= tolerance {
                    along.low += area;
                }
                if lo >= scaled[axis] - tolerance {
                    along.high += area;
                }
            }
        }
    }
    (along[0], along[1], area_sum)
}

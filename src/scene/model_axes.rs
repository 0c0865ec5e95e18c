//! Which way is up in an OBJ model, which has no up axis of its own: read
//! from how its faces lean, the exporter its header names, and the flat
//! base it stands on, in that order.

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
/// own axes are y-up. Their files are read y-up unless the faces' lean
/// says otherwise: a fence's flat back is no base, but a terrain exported
/// with the axes changed still faces up.
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

/// The up axis the model's content suggests: +z when the model stands on
/// a flat base at its lowest z (faces perpendicular to z there covering at
/// least 2 % of its footprint) that has no match at its top (a box or a
/// slab is flat at both ends and says nothing) and no comparable base at
/// its lowest y; +y, OBJ's convention, otherwise. A statue's plinth, a
/// 3D-print's bed face or a building's ground slab is such a base; the
/// flat butt of a rifle lying along z is not, its muzzle end being as flat.
///
/// Two things come before the base. First the way the faces lean: floors,
/// roofs and the ground face up, so a model open to the sky (a room
/// without its ceiling, a terrain, a street) has more face area turned up
/// than down, where a closed model's outward faces cancel (`upward_lean`).
/// Then the exporter named in the header comment, whose default is y-up
/// (`exporter_writes_y_up`); a user can change that default, which only
/// the content then shows.
pub(super) fn model_axes(shapes: &[Shape], bounds: Aabb, header: Option<&str>) -> ModelAxes {
    if let Some(axes) = upward_lean(shapes, bounds) {
        return axes;
    }
    if header.is_some_and(exporter_writes_y_up) {
        return Y_UP;
    }
    let extent = bounds.max - bounds.min;
    // Area of faces perpendicular to `axis` lying at its low and high end,
    // as fractions of the model's footprint across that axis.
    let flat_ends = |axis: usize| {
        let across = extent[(axis + 1) % 3] * extent[(axis + 2) % 3];
        let tolerance = 0.01 * extent[axis];
        let (mut low, mut high) = (0.0, 0.0);
        if !(across > 0.0 && across.is_finite()) {
            return (0.0, 0.0);
        }
        for shape in shapes {
            let Shape::Triangle(t) = shape else { continue };
            let [a, b, c] = t.vertices;
            let normal = (b - a).cross(c - a);
            let area = 0.5 * normal.length();
            if !(area.is_finite() && normal[axis].abs() > 0.99 * 2.0 * area) {
                continue;
            }
            let (lo, hi) = (
                a[axis].min(b[axis]).min(c[axis]),
                a[axis].max(b[axis]).max(c[axis]),
            );
            // A flat model's faces lie at both ends: no base.
            if hi <= bounds.min[axis] + tolerance {
                low += area;
            }
            if lo >= bounds.max[axis] - tolerance {
                high += area;
            }
        }
        (low / across, high / across)
    };
    let (base_z, top_z) = flat_ends(2);
    let (base_y, _) = flat_ends(1);
    if base_z >= 0.02 && base_z > 2.0 * top_z && base_z > 2.0 * base_y {
        Z_UP
    } else {
        Y_UP
    }
}

/// The up axis the faces' net lean names, if they name one: the
/// area-weighted sum of the unit face normals, as a share of the area,
/// leans up along +y or +z by at least 0.6 and twice as much as along the
/// other (a terrain, a floor plan, a street: most of the area faces up; a
/// floor and a wall of equal size lean as much up as forwards), with the
/// model's area in the lower 60 % along that axis (a mask open at the
/// back leans as much along the way it faces, but its area sits at its
/// front). A smaller lean says nothing: a room without a ceiling leans up
/// as much as a Cornell box, open at its front, leans forwards. A model
/// thinner than 2 % of its size along the axis (a sheet) names none: it
/// may be a floor or a picture.
fn upward_lean(shapes: &[Shape], bounds: Aabb) -> Option<ModelAxes> {
    let extent = bounds.max - bounds.min;
    let largest = extent.max_element();
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    let (mut net, mut area_sum, mut moment) = (DVec3::ZERO, 0.0, DVec3::ZERO);
    for shape in shapes {
        let Shape::Triangle(t) = shape else { continue };
        let [a, b, c] = t.vertices;
        // Scaled by the model's size, so the cross product of a 1e200
        // model does not overflow.
        let (a, b, c) = (
            (a - bounds.min) / largest,
            (b - bounds.min) / largest,
            (c - bounds.min) / largest,
        );
        let twice = (b - a).cross(c - a);
        let area = 0.5 * twice.length();
        if !(area > 0.0 && area.is_finite()) {
            continue;
        }
        net += 0.5 * twice;
        area_sum += area;
        moment += area * (a + b + c) / 3.0;
    }
    if !(area_sum > 0.0) {
        return None;
    }
    let lean = net / area_sum;
    // Where the area sits along each axis, 0 at the bottom, 1 at the top.
    let sits = (moment / area_sum) * largest / extent;
    let names = |axis: usize, other: usize| {
        extent[axis] >= 0.02 * largest
            && lean[axis] >= 0.6
            && lean[axis] >= 2.0 * lean[other].abs()
            && sits[axis] <= 0.6
    };
    if names(2, 1) {
        Some(Z_UP)
    } else if names(1, 2) {
        Some(Y_UP)
    } else {
        None
    }
}

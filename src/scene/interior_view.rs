//! A camera inside an enclosed model: an atrium, a hall, a walled and
//! roofed street. Seen from outside, such a model is its shell, a closed
//! box; what it was made for is inside. The camera stands in its most open
//! place, at eye height above the floor there, looking along the model's
//! longest horizontal extent, with the light in the space it looks into.
//!
//! The model is enclosed when rays cast from its centre in all directions
//! mostly meet it. A place in it is inside when rays cast from it mostly
//! meet the model too, and nearly all of what they meet faces the place:
//! the inner side of walls, floors and ceilings, as an interior is
//! modelled (an atrium, a cathedral, a conference room). From inside a
//! solid part, or inside a closed box whose faces face out (an object, not
//! a room), the faces met face away. A model whose faces are wound at
//! random faces no place and is seen from outside. The caller keeps the
//! outside view unless the inside one shows clearly more of the model.

use crate::accel::WalkStack;
use crate::camera::{Camera, CameraSpec};
use crate::math::{Aabb, DVec3, Ray};

use super::model_probe::{ModelProbe, ProbeHit};

/// Vertical field of view inside, degrees: wider than outside, as a room
/// surrounds the eye.
const FOV: f64 = 60.0;
/// Rays cast from a place: enough that a doorway or an opening to the sky
/// shows as a share of them, few enough to survey a grid of places.
const DIRECTIONS: usize = 96;
/// Least share of those rays that meet the model for the place to be
/// enclosed: an atrium open to the sky still is, a room open at one side
/// is not.
const ENCLOSED: f64 = 0.85;
/// Least share of the surfaces met that face the place: interiors are
/// modelled facing in throughout, and a model with some faces wound the
/// other way (a diorama's buildings) is no interior.
const FACING: f64 = 0.9;
/// Heights of the eye above the floor tried, as shares of the
/// floor-to-ceiling height.
const EYE_HEIGHTS: [f64; 2] = [0.3, 0.45];

/// The camera and light inside the model, or `None` when it is not
/// enclosed. `up` is its up axis, `across` its two horizontal axes.
pub(super) fn interior_view(
    probe: &ModelProbe,
    bounds: Aabb,
    up: DVec3,
    across: [DVec3; 2],
) -> Option<(CameraSpec, DVec3)> {
    let center = 0.5 * bounds.min + 0.5 * bounds.max;
    let extent = bounds.max - bounds.min;
    // Scaled, so the squares of a 1e200 model do not overflow.
    let largest = extent.max_element();
    let radius = 0.5 * largest * (extent / largest).length();
    if !(radius > 0.0 && radius.is_finite()) {
        return None;
    }
    let mut stack = WalkStack::default();
    let directions = sphere_directions(DIRECTIONS);
    // Enclosed: rays cast from the centre mostly meet the model (a room
    // open at one side, a Cornell box, is seen through that side).
    let met = directions
        .iter()
        .filter(|&&dir| {
            probe
                .closest(Ray::new(center, dir), f64::INFINITY, &mut stack)
                .is_some()
        })
        .count();
    if (met as f64) < ENCLOSED * directions.len() as f64 {
        return None;
    }
    // Candidate places on a 3x3x3 grid through the middle of the bounds
    // that are inside: the lowest storey first (the ground floor, not a
    // gallery), there the most open place (the longest mean distance to
    // what its rays meet), on a tie the first surveyed (the centre's).
    let mut candidates = Vec::new();
    for (storey, f_up) in [0.25, 0.5, 0.75].into_iter().enumerate() {
        for f0 in [0.5, 0.3, 0.7] {
            for f1 in [0.5, 0.3, 0.7] {
                let place = bounds.min
                    + up.abs() * extent * f_up
                    + across[0].abs() * extent * f0
                    + across[1].abs() * extent * f1;
                if let Some(found) = survey(probe, place, &directions, &mut stack) {
                    candidates.push((storey, found));
                }
            }
        }
    }
    candidates.sort_by(|(storey_a, a), (storey_b, b)| {
        storey_a
            .cmp(storey_b)
            .then(b.openness.total_cmp(&a.openness))
    });
    let place = candidates.first()?.1.place;

    let height_of = |p: DVec3| p.dot(up);
    let cast = |from: DVec3, dir: DVec3, stack: &mut WalkStack| {
        probe.closest(Ray::new(from, dir), f64::INFINITY, stack)
    };
    // Where a ceiling is open to the sky, the model's top stands for it.
    let top = height_of(bounds.min).max(height_of(bounds.max));
    let at_height = |p: DVec3, height: f64| p + up * (height - height_of(p));

    // Along the longest horizontal extent, towards its farther end, from
    // most of the way back to the nearer one. Of the places beside that
    // line and the two eye heights, the one inside whose view reaches
    // farthest (not into a table or a column). The floor and ceiling are
    // taken again under each place, for stairs, steps and arches.
    let (longest, beside) = if extent.dot(across[0].abs()) >= extent.dot(across[1].abs()) {
        (across[0], across[1])
    } else {
        (across[1], across[0])
    };
    let width = extent.dot(beside.abs());
    let mut best: Option<(f64, CameraSpec, DVec3)> = None;
    for lateral in [0.0, -0.25, 0.25, -0.4, 0.4] {
        let aside = place + beside * (lateral * width);
        let Some(under) = cast(aside, -up, &mut stack) else {
            continue;
        };
        let floor = height_of(under.point);
        let ceiling = cast(aside, up, &mut stack).map_or(top, |h| height_of(h.point));
        let room = ceiling - floor;
        if !(room > 0.0) {
            continue;
        }
        for share in EYE_HEIGHTS {
            let standing = at_height(aside, floor + share * room);
            let reach = |dir: DVec3, stack: &mut WalkStack| {
                cast(standing, dir, stack).map_or(radius, |h| h.t.min(radius))
            };
            let (ahead, behind) = (reach(longest, &mut stack), reach(-longest, &mut stack));
            let (look, ahead, behind) = if ahead >= behind {
                (longest, ahead, behind)
            } else {
                (-longest, behind, ahead)
            };
            // Back only onto a step of the floor (not a gallery's roof or
            // a pit), at the same share of the room's height there.
            let stepped = standing - look * (0.75 * behind);
            let floor_there = cast(stepped, -up, &mut stack).map(|h| height_of(h.point));
            let ceiling_there = cast(stepped, up, &mut stack).map_or(top, |h| height_of(h.point));
            let eye = match floor_there {
                Some(f) if (f - floor).abs() <= 0.1 * room && ceiling_there > f => {
                    at_height(stepped, f + share * (ceiling_there - f))
                }
                _ => standing,
            };
            // The eye itself must be inside, not through a doorway or on
            // a plaza beside the building.
            if survey(probe, eye, &directions, &mut stack).is_none() {
                continue;
            }
            let ahead = ahead + (standing - eye).dot(look);
            let camera = CameraSpec {
                eye,
                lookat: eye + look * (0.5 * ahead).max(1e-6 * radius),
                up,
                fov: FOV,
            };
            let depth = view_depth(probe, &camera, radius, &mut stack);
            // The light in the space the eye looks into, a third of the
            // way ahead and two thirds of the way up to the ceiling there:
            // what the eye sees is mostly lit (not shut off behind an arch
            // over the eye), and the shadows fall away from the eye.
            let eye_height = height_of(eye);
            let ahead_of_eye = eye + look * (ahead / 3.0);
            let ceiling_ahead =
                cast(ahead_of_eye, up, &mut stack).map_or(top, |h| height_of(h.point));
            let light = at_height(
                ahead_of_eye,
                eye_height + (ceiling_ahead - eye_height).max(0.0) * 2.0 / 3.0,
            );
            if best.as_ref().is_none_or(|(most, ..)| depth > *most) {
                best = Some((depth, camera, light));
            }
        }
    }
    let (_, camera, light) = best?;
    (camera.eye.is_finite()
        && camera.lookat.is_finite()
        && light.is_finite()
        && camera.check().is_ok())
    .then_some((camera, light))
}

/// How far a view reaches: the mean distance to what a 12x9 thumbnail's
/// rays meet, a ray that meets nothing (the sky over an atrium) counting
/// as the model's radius.
fn view_depth(probe: &ModelProbe, camera: &CameraSpec, radius: f64, stack: &mut WalkStack) -> f64 {
    const WIDE: u32 = 12;
    const HIGH: u32 = 9;
    let Ok(camera) = Camera::new(camera, WIDE, HIGH) else {
        return 0.0;
    };
    let mut sum = 0.0;
    for j in 0..HIGH {
        for i in 0..WIDE {
            let ray = camera.ray(i, j, 0.5, 0.5);
            sum += probe.closest(ray, radius, stack).map_or(radius, |h| h.t);
        }
    }
    sum / f64::from(WIDE * HIGH)
}

/// What rays cast from a place meet.
struct Survey {
    place: DVec3,
    /// Mean distance to what the rays meet.
    openness: f64,
}

/// The place's survey if it is inside (see the module doc), else `None`.
fn survey(
    probe: &ModelProbe,
    place: DVec3,
    directions: &[DVec3],
    stack: &mut WalkStack,
) -> Option<Survey> {
    let allowed_misses = ((1.0 - ENCLOSED) * directions.len() as f64) as usize;
    let (mut misses, mut met, mut facing, mut distance) = (0, 0, 0, 0.0);
    for &dir in directions {
        match probe.closest(Ray::new(place, dir), f64::INFINITY, stack) {
            Some(ProbeHit { t, front, .. }) => {
                met += 1;
                facing += usize::from(front);
                distance += t;
            }
            None => {
                misses += 1;
                if misses > allowed_misses {
                    return None;
                }
            }
        }
    }
    (met > 0 && facing as f64 >= FACING * met as f64).then(|| Survey {
        place,
        openness: distance / met as f64,
    })
}

/// `n` unit directions spread evenly over the sphere (a Fibonacci
/// lattice: equal areas, no pole clustering).
fn sphere_directions(n: usize) -> Vec<DVec3> {
    let golden_angle = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f64 / n as f64;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (i as f64 * golden_angle).sin_cos();
            DVec3::new(r * c, r * s, z)
        })
        .collect()
}

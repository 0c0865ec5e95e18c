//! Shapes that lie in one plane, grouped, so that a shadow ray leaving
//! that plane skips them all: it cannot meet any of them again. A 144-sided
//! gear face cut into 142 slivers is one group (on SPD gears nearly half
//! of the triangle tests were of such neighbours of the ray's own face,
//! which the exact test rejects only at its edge tests).
//!
//! Skipping is exact: a group is skipped only when the ray's origin lies
//! off the group's plane by more than any member's vertex does, rounding
//! included, and the ray heads away from the plane, so no point of the ray
//! is anywhere the group reaches. A secondary ray's origin is offset by at
//! least 2^-40 of the scene's magnitude (Wächter and Binder 2019, see
//! [`crate::math::offset_ray_origin`]); members may lie 2^-44 of it off
//! the plane, so a shadow ray clears them.

use crate::math::DVec3;
use crate::shapes::Shape;

/// A shape in no group (alone in its plane, or not flat).
const NO_GROUP: u32 = u32::MAX;

/// Relative bound on the rounding of `normal . p - offset` for the
/// magnitudes involved (four roundings, with room).
const EVALUATION_ERROR: f64 = 1.0 / (1u64 << 50) as f64;

/// How far off its group's plane a vertex may lie, relative to the scene's
/// magnitude: a sixteenth of the least offset a secondary ray's origin
/// makes ([`crate::math::offset_ray_origin`], 2^-40), so rays leaving a
/// surface clear every group member's slack.
const SLACK_RELATIVE: f64 = 1.0 / (1u64 << 44) as f64;

/// One group: its shapes, `first..first + len`, and their plane,
/// `normal . p = offset`, with `slack`, the farthest any member's vertex
/// lies from it (an upper bound).
#[derive(Clone, Copy, Debug)]
struct GroupPlane {
    normal: DVec3,
    offset: f64,
    slack: f64,
    shapes: ShapeRange,
}

/// Shapes `first..first + len` (a group's; `len` 0: none), tested by one
/// subtraction and one comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeRange {
    first: u32,
    len: u32,
}

impl ShapeRange {
    pub const EMPTY: Self = Self { first: 0, len: 0 };

    #[inline(always)]
    pub fn contains(self, index: u32) -> bool {
        index.wrapping_sub(self.first) < self.len
    }
}

impl GroupPlane {
    /// A bound on the rounding of `normal . p - offset`.
    #[inline(always)]
    fn rounding(&self, p: DVec3) -> f64 {
        (self.normal.abs().dot(p.abs()) + self.offset.abs()) * EVALUATION_ERROR
    }

    /// The slack once `vertices` are in the group: the farthest any of
    /// them lies from the plane, rounding included, or the slack before.
    fn slack_with(&self, vertices: &[DVec3]) -> f64 {
        vertices
            .iter()
            .map(|&v| (self.normal.dot(v) - self.offset).abs() + self.rounding(v))
            .fold(self.slack, f64::max)
    }
}

/// Consecutive shapes in one plane, grouped (see the module's comment).
#[derive(Clone, Debug, Default)]
pub struct PlaneGroups {
    /// Per shape, its group (`NO_GROUP`: none); empty when there is none.
    of_shape: Vec<u32>,
    planes: Vec<GroupPlane>,
}

impl PlaneGroups {
    /// Groups `shapes`: each triangle joins the one before it if all its
    /// vertices lie within the slack of that one's group's plane. A group
    /// of one triangle is kept as none: skipping a shape's own face saves
    /// less than asking costs (docs/notes/experiments.md, "Shadow rays skip
    /// the triangles of the plane they leave").
    pub fn build(shapes: &[Shape]) -> Self {
        let mut scale: f64 = 0.0;
        for shape in shapes {
            if let Shape::Triangle(t) = shape {
                for v in t.vertices {
                    scale = scale.max(v.abs().max_element());
                }
            }
        }
        let limit = scale * SLACK_RELATIVE;
        let mut groups = Self::default();
        // The group the triangle before began or joined.
        let mut open: Option<GroupPlane> = None;
        for (index, shape) in shapes.iter().enumerate() {
            let Shape::Triangle(t) = shape else {
                groups.close(open.take(), shapes.len());
                continue;
            };
            if let Some(plane) = &mut open {
                let slack = plane.slack_with(&t.vertices);
                if slack <= limit {
                    plane.slack = slack;
                    plane.shapes.len += 1;
                    continue;
                }
            }
            groups.close(open.take(), shapes.len());
            // (A triangle too thin for a finite normal gets a NaN slack
            // and is never skipped.)
            let normal = t.normal();
            let mut plane = GroupPlane {
                normal,
                offset: normal.dot(t.vertices[0]),
                slack: 0.0,
                shapes: ShapeRange {
                    first: index as u32,
                    len: 1,
                },
            };
            plane.slack = plane.slack_with(&t.vertices);
            open = Some(plane);
        }
        groups.close(open, shapes.len());
        groups
    }

    /// Keeps `plane`'s group if it holds two shapes or more (of a scene
    /// of `count`).
    fn close(&mut self, plane: Option<GroupPlane>, count: usize) {
        let Some(plane) = plane.filter(|p| p.shapes.len >= 2) else {
            return;
        };
        if self.of_shape.is_empty() {
            self.of_shape = vec![NO_GROUP; count];
        }
        let ShapeRange { first, len } = plane.shapes;
        let group = self.planes.len() as u32;
        self.of_shape[first as usize..(first + len) as usize].fill(group);
        self.planes.push(plane);
    }

    /// Whether any shapes share a plane.
    pub fn has_groups(&self) -> bool {
        !self.planes.is_empty()
    }

    /// The shapes a ray from `origin` along `dir`, leaving a hit on shape
    /// `shape`, cannot meet: its group, when the origin lies off the
    /// group's plane farther than any member reaches and the ray heads
    /// away from the plane; none otherwise.
    #[inline(always)]
    pub fn left_behind(&self, shape: u32, origin: DVec3, dir: DVec3) -> ShapeRange {
        let Some(&group) = self.of_shape.get(shape as usize) else {
            return ShapeRange::EMPTY;
        };
        let Some(plane) = self.planes.get(group as usize) else {
            return ShapeRange::EMPTY;
        };
        let above = plane.normal.dot(origin) - plane.offset;
        let away = plane.normal.dot(dir);
        let leaving = if above > 0.0 {
            away >= 0.0
        } else {
            away <= 0.0
        };
        if leaving && above.abs() > plane.slack + plane.rounding(origin) {
            plane.shapes
        } else {
            ShapeRange::EMPTY
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Ray, XorShift, offset_ray_origin};
    use crate::shapes::{Plane, PreparedRay, Sphere, Triangle};

    /// An `n`-gon of radius `radius` about `center` in the plane of unit
    /// `normal`, cut into a fan of slivers from its first vertex: its
    /// triangles consecutive, as a scene file's polygon's are.
    fn fan(center: DVec3, normal: DVec3, radius: f64, n: usize) -> Vec<Shape> {
        let (u, w) = crate::math::orthonormal_basis(normal);
        let vertex = |k: usize| {
            let angle = std::f64::consts::TAU * k as f64 / n as f64;
            center + radius * (angle.cos() * u + angle.sin() * w)
        };
        (1..n - 1)
            .filter_map(|k| Triangle::new([vertex(0), vertex(k), vertex(k + 1)]))
            .map(Shape::Triangle)
            .collect()
    }

    fn range(first: u32, len: u32) -> ShapeRange {
        ShapeRange { first, len }
    }

    #[test]
    fn a_polygons_fan_is_one_group_and_shapes_apart_are_not() {
        let up = DVec3::Z;
        let mut shapes = fan(DVec3::new(0.0, 0.0, 1.0), up, 0.75, 144);
        assert_eq!(shapes.len(), 142);
        shapes.push(Shape::Sphere(Sphere::new(DVec3::ZERO, 1.0)));
        shapes.extend(fan(
            DVec3::new(2.0, 0.5, -1.0),
            DVec3::new(1.0, 2.0, 2.0) / 3.0,
            1.0,
            5,
        ));
        // Tilted out of the fan's plane by a millionth of its size.
        let [a, b, c] = [
            DVec3::new(2.0, 0.5, -1.0),
            DVec3::new(2.5, 0.5, -1.25),
            DVec3::new(2.0, 1.0, -1.5),
        ];
        shapes.push(Shape::Triangle(
            Triangle::new([a, b, c + DVec3::splat(1e-6)]).unwrap(),
        ));
        shapes.push(Shape::Plane(Plane::new(DVec3::new(0.0, 0.0, -2.0), up)));
        let groups = PlaneGroups::build(&shapes);
        let ranges: Vec<ShapeRange> = groups.planes.iter().map(|p| p.shapes).collect();
        // The tilted triangle and the plane are alone in theirs: no group.
        assert_eq!(ranges, [range(0, 142), range(143, 3)]);
        assert_eq!(groups.of_shape[142], NO_GROUP);
        assert_eq!(groups.of_shape[146..], [NO_GROUP, NO_GROUP]);
        assert_eq!(groups.of_shape[145], 1);
        assert!(groups.planes.iter().all(|p| p.slack < 1e-13));
    }

    /// Rays from hit points on fans of slivers, offset as the renderer
    /// offsets them, in every direction (grazing ones too): wherever the
    /// group is skipped, no shape of it is met, so skipping changes no
    /// answer. Heading into the plane, nothing is skipped. Near the
    /// origin and a million away, at sizes 1e-4 to 1e4.
    #[test]
    fn rays_leaving_a_group_meet_none_of_it() {
        let mut random = XorShift(0x2545_f491_4f6c_dd1d);
        let (mut skipped, mut toward) = (0, 0);
        for case in 0..400 {
            let scale = 10f64.powi(case % 9 - 4);
            let far = if case % 3 == 0 { 1e6 } else { 0.0 };
            let center = DVec3::new(random.unit(), random.unit(), random.unit()) * scale + far;
            let normal = match case % 4 {
                0 => DVec3::Z,
                _ => (DVec3::new(random.unit(), random.unit(), random.unit()) - 0.5)
                    .normalize_or(DVec3::X),
            };
            let shapes = fan(center, normal, scale, 4 + case as usize % 40);
            let groups = PlaneGroups::build(&shapes);
            let floor_scale = shapes
                .iter()
                .filter_map(Shape::bounds)
                .fold(0.0f64, |m, b| {
                    m.max(b.min.abs().max(b.max.abs()).max_element())
                });
            for _ in 0..50 {
                let index = (random.unit() * shapes.len() as f64) as usize;
                let Shape::Triangle(t) = &shapes[index] else {
                    unreachable!()
                };
                let (b1, b2) = (random.unit(), random.unit());
                let (b1, b2) = if b1 + b2 > 1.0 {
                    (1.0 - b1, 1.0 - b2)
                } else {
                    (b1, b2)
                };
                let [v0, v1, v2] = t.vertices;
                let point = v0 + b1 * (v1 - v0) + b2 * (v2 - v0);
                let side = if random.unit() < 0.5 {
                    t.normal()
                } else {
                    -t.normal()
                };
                // As the renderer offsets it, or barely off the plane.
                let origin = if random.unit() < 0.75 {
                    offset_ray_origin(point, side, floor_scale)
                } else {
                    point + side * floor_scale * 10f64.powf(-13.0 - 4.0 * random.unit())
                };
                // Away from the plane, grazing it or heading into it.
                let along = match (random.unit() * 4.0) as u32 {
                    0 => 10f64.powf(-12.0 * random.unit()),
                    1 => -10f64.powf(-12.0 * random.unit()),
                    _ => random.unit() * 2.0 - 1.0,
                };
                let (u, w) = crate::math::orthonormal_basis(side);
                let angle = std::f64::consts::TAU * random.unit();
                let across = (1.0 - along * along).max(0.0).sqrt();
                let dir = (along * side + across * (angle.cos() * u + angle.sin() * w)).normalize();
                let left = groups.left_behind(index as u32, origin, dir);
                // Into the group's plane (a sliver's own normal may differ
                // from the group's by a millionth of a radian, so a ray
                // grazing into the sliver's plane may leave the group's).
                let plane = &groups.planes[groups.of_shape[index] as usize];
                let above = plane.normal.dot(origin) - plane.offset;
                if plane.normal.dot(dir) * above < 0.0 {
                    toward += 1;
                    assert_eq!(
                        left,
                        ShapeRange::EMPTY,
                        "case {case}: a ray into the plane skips"
                    );
                }
                let ray = PreparedRay::new(Ray::new(origin, dir));
                for (k, shape) in shapes.iter().enumerate() {
                    if left.contains(k as u32) {
                        skipped += 1;
                        assert!(
                            shape.intersect(&ray, f64::INFINITY).is_none()
                                && shape.crossings(&ray, f64::INFINITY).as_slice().is_empty(),
                            "case {case}: a skipped shape is met"
                        );
                    }
                }
            }
        }
        assert!(toward > 1000 && skipped > 100_000, "{toward} {skipped}");
    }

    #[test]
    fn a_ray_from_on_the_plane_skips_nothing() {
        let shapes = fan(DVec3::ZERO, DVec3::Z, 1.0, 8);
        let groups = PlaneGroups::build(&shapes);
        let (on, above) = (DVec3::new(0.1, 0.1, 0.0), DVec3::new(0.1, 0.1, 1e-9));
        assert_eq!(groups.left_behind(2, on, DVec3::Z), ShapeRange::EMPTY);
        assert_eq!(groups.left_behind(2, above, DVec3::Z), range(0, 6));
        assert_eq!(groups.left_behind(2, above, -DVec3::Z), ShapeRange::EMPTY);
        // A shape past the scene's (a stale index) or in no group.
        assert_eq!(
            groups.left_behind(99, DVec3::Z, DVec3::Z),
            ShapeRange::EMPTY
        );
    }
}

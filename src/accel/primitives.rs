//! The shapes a ray query runs over and the tests on them: what the
//! octree's leaves run, and brute force is, over every shape. Apart from
//! `mod.rs` so that the octree depends on it and not on its parent.

// Lane loops index several arrays by the same lane number.
#![allow(clippy::needless_range_loop)]

use crate::shapes::{
    PacketHits, PreparedRay, RayPacket, Shape, ShapeHit, Triangle, TriangleLanes, probe_past, wins,
};
use crate::stats::Counter;

/// The shapes a ray query runs over, and what it must know of each.
#[derive(Clone, Copy, Debug)]
pub struct Primitives<'a> {
    pub shapes: &'a [Shape],
    /// Shapes seen only from outside (`true`); empty when every shape is
    /// two-sided, glint's default.
    pub one_sided: &'a [bool],
    /// Shapes that let light through: shadow rays record their crossings
    /// instead of stopping. Empty when none does.
    pub transparent: &'a [bool],
    /// The shapes in the plane the ray leaves ([`crate::accel::PlaneGroups`]):
    /// it cannot meet them, so uncounted queries skip them.
    pub left_behind: super::planes::ShapeRange,
}

impl<'a> Primitives<'a> {
    /// Every shape two-sided and opaque.
    pub fn opaque(shapes: &'a [Shape]) -> Self {
        Self {
            shapes,
            one_sided: &[],
            transparent: &[],
            left_behind: super::planes::ShapeRange::EMPTY,
        }
    }

    /// Whether at least half of `shapes` are triangles: where single rays
    /// test triangles four at a time ([`crate::shapes::TriangleLanes`];
    /// elsewhere sorting them out costs more than the batches save).
    pub fn mostly_triangles(shapes: &[Shape]) -> bool {
        let triangles = shapes
            .iter()
            .filter(|s| matches!(s, Shape::Triangle(_)))
            .count();
        2 * triangles >= shapes.len()
    }

    /// Shape `index`'s nearest hit in `(0, t_max)`, on its outside only if
    /// it is one-sided.
    #[inline(always)]
    fn intersect(&self, index: u32, ray: &PreparedRay, t_max: f64) -> Option<ShapeHit> {
        let shape = &self.shapes[index as usize];
        if self.one_sided.get(index as usize) == Some(&true) {
            shape.intersect_front(ray, t_max)
        } else {
            shape.intersect(ray, t_max)
        }
    }

    /// Whether shape `index` is opaque and blocks a shadow ray over
    /// `(0, t_max)`: the test an occlusion query makes of it. `false` for
    /// an index this scene lacks (a hint kept from another render).
    #[inline(always)]
    pub fn blocks(&self, index: u32, ray: &PreparedRay, t_max: f64) -> bool {
        (index as usize) < self.shapes.len()
            && !self.is_transparent(index)
            && self.intersect(index, ray, t_max).is_some()
    }

    /// Shape `index` as a triangle a single ray's closest-hit query may
    /// test four at a time ([`TriangleBatch`]): a two-sided one.
    #[inline(always)]
    pub(crate) fn lane_triangle(&self, index: u32) -> Option<&'a Triangle> {
        match self.shapes.get(index as usize) {
            Some(Shape::Triangle(t)) if self.one_sided.get(index as usize) != Some(&true) => {
                Some(t)
            }
            _ => None,
        }
    }

    /// Shape `index` as a triangle a shadow ray may test four at a time
    /// (a transparent one, crossed from either side, or an opaque
    /// two-sided one), with `true` if it is the transparent kind.
    #[inline(always)]
    pub(crate) fn shadow_triangle(&self, index: u32) -> Option<(&'a Triangle, bool)> {
        match self.shapes.get(index as usize) {
            Some(Shape::Triangle(t)) => {
                let transparent = self.is_transparent(index);
                (transparent || self.one_sided.get(index as usize) != Some(&true))
                    .then_some((t, transparent))
            }
            _ => None,
        }
    }

    /// Whether shape `index` lies in the plane group the ray leaves
    /// behind: then the ray cannot meet it.
    #[inline(always)]
    pub(crate) fn left_behind(&self, index: u32) -> bool {
        self.left_behind.contains(index)
    }

    #[inline(always)]
    pub(crate) fn is_transparent(&self, index: u32) -> bool {
        self.transparent.get(index as usize) == Some(&true)
    }

    /// Whether any shape lets light through (shadow rays then record
    /// crossings one by one instead of stopping at the first hit).
    pub fn any_transparent(&self) -> bool {
        self.transparent.contains(&true)
    }

    /// [`test_closest`] for the `lanes` of a packet: two-sided triangles
    /// in lanes, other shapes lane by lane.
    #[inline(always)]
    pub(crate) fn closest_lanes<C: Counter, const N: usize>(
        &self,
        index: u32,
        p: &RayPacket<N>,
        lanes: u32,
        best: &mut PacketHits<N>,
        counter: &mut C,
    ) {
        counter.add_lanes(lanes.count_ones(), 0, 0);
        let probe = best.probe;
        match &self.shapes[index as usize] {
            Shape::Triangle(t) if self.one_sided.get(index as usize) != Some(&true) => {
                let h = t.intersect_lanes(p, &probe);
                best.merge(index, h.hit & lanes, h.t, h.b1, h.b2);
            }
            Shape::Sphere(s) if self.one_sided.get(index as usize) != Some(&true) => {
                let h = s.intersect_lanes(p, &probe);
                best.merge(index, h.hit & lanes, h.t, h.b1, h.b2);
            }
            _ => {
                for i in 0..N {
                    if lanes >> i & 1 == 1
                        && let Some(hit) = self.intersect(index, &p.lane(i), probe[i])
                    {
                        let mut t = best.t;
                        let (mut b1, mut b2) = (best.b1, best.b2);
                        (t[i], b1[i], b2[i]) = (hit.t, hit.b1, hit.b2);
                        best.merge(index, 1 << i, t, b1, b2);
                    }
                }
            }
        }
    }
}

/// The closest hit found so far.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestHit {
    pub shape: u32,
    pub hit: ShapeHit,
}

/// Tests shape `index` and keeps its hit if it is closer than `best`, or as
/// close with a lower index (so the answer never depends on visiting order).
#[inline(always)]
pub(crate) fn test_closest<C: Counter>(
    prims: &Primitives,
    index: u32,
    ray: &PreparedRay,
    best: &mut Option<ClosestHit>,
    t_max: f64,
    counter: &mut C,
) {
    counter.intersection_test();
    let limit = best.map_or(t_max, |b| b.hit.t);
    // `limit` is exclusive in `intersect`; an equal t with a lower index
    // also wins, so look just past it.
    let probe = if best.is_some() {
        probe_past(limit)
    } else {
        limit
    };
    let found = prims.intersect(index, ray, probe);
    counter.tested(index, found.map(|h| h.t));
    if let Some(hit) = found {
        let better = match best {
            None => true,
            Some(b) => wins(hit.t, index, b.hit.t, b.shape),
        };
        if better {
            *best = Some(ClosestHit { shape: index, hit });
        }
    }
}

/// Up to four triangles (from [`Primitives::lane_triangle`] for a closest
/// hit, [`Primitives::shadow_triangle`] for a shadow ray) waiting to be
/// tested against a single ray together ([`TriangleLanes::intersect_four`]),
/// with the answers [`test_closest`] and [`test_occlusion`] give one by
/// one: a closest hit is the lexicographic minimum of `(t, index)` in any
/// order, and a shadow ray is blocked by any of them alike.
pub(crate) struct TriangleBatch<'a> {
    triangles: [&'a Triangle; 4],
    index: [u32; 4],
    /// Lanes whose triangle lets light through (shadow rays only).
    transparent: u32,
    len: usize,
}

/// What a batch's lanes hold before anything is pushed: computed with the
/// rest, then masked out by `live` (as are the stale triangles spare
/// lanes keep from the batch before).
static UNUSED_LANE: Triangle = Triangle {
    vertices: [
        crate::math::DVec3::ZERO,
        crate::math::DVec3::X,
        crate::math::DVec3::Y,
    ],
    vertex_normals: crate::shapes::NO_NORMALS,
};

impl<'a> TriangleBatch<'a> {
    #[inline(always)]
    pub(crate) fn new() -> Self {
        Self {
            triangles: [&UNUSED_LANE; 4],
            index: [0; 4],
            transparent: 0,
            len: 0,
        }
    }

    /// Adds triangle `triangle` (shape `index`, letting light through if
    /// `transparent`); `true` once full.
    #[inline(always)]
    pub(crate) fn push(&mut self, index: u32, triangle: &'a Triangle, transparent: bool) -> bool {
        debug_assert!(self.len < 4, "a full batch is tested before the next push");
        let slot = self.len & 3;
        self.triangles[slot] = triangle;
        self.index[slot] = index;
        let bit = 1 << slot;
        self.transparent = (self.transparent & !bit) | (transparent as u32 * bit);
        self.len = slot + 1;
        self.len == 4
    }

    /// Tests the waiting triangles as [`test_closest`] would, and empties
    /// the batch. One alone is tested as a single ray's test is.
    #[inline(always)]
    pub(crate) fn closest<L: TriangleLanes>(
        &mut self,
        prims: &Primitives,
        ray: &PreparedRay,
        best: &mut Option<ClosestHit>,
        t_max: f64,
        lanes: L,
    ) {
        let len = std::mem::take(&mut self.len);
        if len <= 1 {
            if len == 1 {
                test_closest(
                    prims,
                    self.index[0],
                    ray,
                    best,
                    t_max,
                    &mut crate::stats::NoCounts,
                );
            }
            return;
        }
        // The limit when the batch is tested: a lane hit past a nearer
        // one found beside it loses to it below, as it would have been
        // cut off one by one.
        let limit = best.map_or(t_max, |b| b.hit.t);
        let probe = if best.is_some() {
            probe_past(limit)
        } else {
            limit
        };
        let hits = lanes.intersect_four(self.triangles, (1 << len) - 1, ray, probe);
        let mut hit_lanes = hits.hit;
        while hit_lanes != 0 {
            let j = hit_lanes.trailing_zeros() as usize;
            hit_lanes &= hit_lanes - 1;
            let (index, t) = (self.index[j], hits.t[j]);
            if best.is_none_or(|b| wins(t, index, b.hit.t, b.shape)) {
                let hit = ShapeHit {
                    t,
                    b1: hits.v[j] / hits.det[j],
                    b2: hits.w[j] / hits.det[j],
                };
                *best = Some(ClosestHit { shape: index, hit });
            }
        }
    }

    /// Tests the waiting triangles as [`test_occlusion`] would, and
    /// empties the batch: `true` once an opaque one blocks the ray; the
    /// transparent ones crossed are recorded (which, like the crossings,
    /// does not depend on the order).
    #[inline(always)]
    pub(crate) fn blocks<L: TriangleLanes>(
        &mut self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        found: &mut ShadowCrossings,
        lanes: L,
    ) -> bool {
        let len = std::mem::take(&mut self.len);
        if len <= 1 {
            return len == 1
                && test_occlusion(
                    prims,
                    self.index[0],
                    ray,
                    t_max,
                    found,
                    &mut crate::stats::NoCounts,
                );
        }
        let hits = lanes.intersect_four(self.triangles, (1 << len) - 1, ray, t_max);
        let opaque = hits.hit & !self.transparent;
        if opaque != 0 {
            found.blocked = true;
            found.blocker = self.index[opaque.trailing_zeros() as usize];
            return true;
        }
        let mut crossed = hits.hit;
        while crossed != 0 {
            let j = crossed.trailing_zeros() as usize;
            crossed &= crossed - 1;
            found.add(hits.t[j], self.index[j]);
        }
        false
    }
}

/// Closest hit by testing every shape in index order.
pub fn closest_brute_force<C: Counter>(
    prims: &Primitives,
    ray: &PreparedRay,
    t_max: f64,
    counter: &mut C,
) -> Option<ClosestHit> {
    let mut best = None;
    for i in 0..prims.shapes.len() as u32 {
        test_closest(prims, i, ray, &mut best, t_max, counter);
    }
    best
}

/// How many transparent crossings a shadow ray keeps: the nearest ones.
/// Light through more surfaces than this is attenuated by these alone
/// (even at a transparency of 0.9, 32 surfaces pass 3% of it).
pub const MAX_SHADOW_CROSSINGS: usize = 32;

/// What a shadow ray met between its origin and the light: whether an
/// opaque surface blocks it, and otherwise every crossing of a transparent
/// surface, as (distance, shape) sorted by distance then shape index. The
/// order and the set do not depend on the order shapes were tested in, so
/// the octree and brute force answer alike. Fixed size: no allocation per ray.
#[derive(Clone)]
pub struct ShadowCrossings {
    blocked: bool,
    /// The opaque shape that blocked the ray, when `blocked`. Which one
    /// depends on the order shapes were tested in, so it is not part of
    /// the answer (nor of equality): only a hint for the next ray.
    blocker: u32,
    len: usize,
    hits: [(f64, u32); MAX_SHADOW_CROSSINGS],
}

impl Default for ShadowCrossings {
    fn default() -> Self {
        Self {
            blocked: false,
            blocker: 0,
            len: 0,
            hits: [(0.0, 0); MAX_SHADOW_CROSSINGS],
        }
    }
}

/// Equal when both are blocked (what was crossed before the blocker does
/// not matter), or both hold the same transparent crossings.
impl PartialEq for ShadowCrossings {
    fn eq(&self, other: &Self) -> bool {
        self.blocked == other.blocked && self.transparent() == other.transparent()
    }
}

impl std::fmt::Debug for ShadowCrossings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.blocked {
            f.write_str("Blocked")
        } else {
            f.debug_list().entries(self.transparent()).finish()
        }
    }
}

impl ShadowCrossings {
    /// Empties it for the next shadow ray (without touching the array).
    pub fn clear(&mut self) {
        self.blocked = false;
        self.len = 0;
    }

    pub fn is_blocked(&self) -> bool {
        self.blocked
    }

    /// The opaque shape that blocked the ray (one of them: which depends on
    /// the order of the tests), if it was blocked.
    pub fn blocker(&self) -> Option<u32> {
        self.blocked.then_some(self.blocker)
    }

    /// Transparent crossings, nearest first (empty when blocked).
    pub fn transparent(&self) -> &[(f64, u32)] {
        if self.blocked {
            &[]
        } else {
            &self.hits[..self.len]
        }
    }

    /// Records a crossing of a transparent surface. The same crossing found
    /// twice (a shape referenced from two leaves) is kept once; when full,
    /// the farthest crossing gives way.
    #[inline]
    fn add(&mut self, t: f64, shape: u32) {
        let key = (t, shape);
        let before = |a: &(f64, u32)| a.0 < t || (a.0 == t && a.1 < shape);
        let at = self.hits[..self.len].partition_point(before);
        if at < self.len && self.hits[at] == key {
            return;
        }
        if at == MAX_SHADOW_CROSSINGS {
            return;
        }
        let end = self.len.min(MAX_SHADOW_CROSSINGS - 1);
        self.hits.copy_within(at..end, at + 1);
        self.hits[at] = key;
        self.len = end + 1;
    }
}

/// Tests shape `index` against a shadow ray over `(0, t_max)`, recording
/// what it crosses; `true` once an opaque surface blocks the ray.
#[inline(always)]
pub(crate) fn test_occlusion<C: Counter>(
    prims: &Primitives,
    index: u32,
    ray: &PreparedRay,
    t_max: f64,
    found: &mut ShadowCrossings,
    counter: &mut C,
) -> bool {
    counter.intersection_test();
    if !prims.is_transparent(index) {
        let hit = prims.intersect(index, ray, t_max);
        counter.tested(index, hit.map(|h| h.t));
        if hit.is_some() {
            found.blocked = true;
            found.blocker = index;
        }
        return found.blocked;
    }
    // Transparent shapes are two-sided (light passes in and out).
    let crossings = prims.shapes[index as usize].crossings(ray, t_max);
    counter.tested(index, crossings.as_slice().first().copied());
    for &t in crossings.as_slice() {
        found.add(t, index);
    }
    false
}

/// Everything in `(0, t_max)` into `found` (cleared first), testing every
/// shape; stops at the first opaque one.
pub fn occlusion_brute_force<C: Counter>(
    prims: &Primitives,
    ray: &PreparedRay,
    t_max: f64,
    found: &mut ShadowCrossings,
    counter: &mut C,
) {
    found.clear();
    for i in 0..prims.shapes.len() as u32 {
        if test_occlusion(prims, i, ray, t_max, found, counter) {
            break;
        }
    }
}

/// [`occlusion_brute_force`] over only the shapes in `lists`: brute
/// force's answer when no other shape can meet the ray (a light buffer's
/// cell and the unbounded shapes).
#[inline(always)]
pub fn occlusion_among<C: Counter>(
    prims: &Primitives,
    lists: [&[u32]; 2],
    ray: &PreparedRay,
    t_max: f64,
    found: &mut ShadowCrossings,
    counter: &mut C,
) {
    occlusion_among_skipping(prims, lists, ray, t_max, found, counter, false);
}

/// [`occlusion_among`], skipping the shapes the ray leaves behind if
/// `skipping` (a constant where it is inlined).
#[inline(always)]
fn occlusion_among_skipping<C: Counter>(
    prims: &Primitives,
    lists: [&[u32]; 2],
    ray: &PreparedRay,
    t_max: f64,
    found: &mut ShadowCrossings,
    counter: &mut C,
    skipping: bool,
) {
    found.clear();
    for list in lists {
        for &i in list {
            if skipping && prims.left_behind(i) {
                continue;
            }
            if test_occlusion(prims, i, ray, t_max, found, counter) {
                return;
            }
        }
    }
}

/// [`occlusion_among`] with the listed triangles tested four at a time by
/// `lanes` (one by one where the level cannot), nothing counted.
#[inline(always)]
pub(crate) fn occlusion_among_in_lanes<L: TriangleLanes>(
    prims: &Primitives,
    lists: [&[u32]; 2],
    ray: &PreparedRay,
    t_max: f64,
    found: &mut ShadowCrossings,
    lanes: L,
) {
    // Most lists are short (one or two shapes on the default scene): they
    // go as they went.
    if !(L::FOUR_AT_ONCE && lists[1].len() >= 4) {
        let counter = &mut crate::stats::NoCounts;
        occlusion_among_skipping(prims, lists, ray, t_max, found, counter, L::SKIPS_PLANES);
        return;
    }
    found.clear();
    let mut batch = TriangleBatch::new();
    let counter = &mut crate::stats::NoCounts;
    for list in lists {
        if shadow_tests(
            prims,
            ray,
            t_max,
            found,
            counter,
            &mut batch,
            list,
            |_| false,
            lanes,
        ) {
            return;
        }
    }
    batch.blocks(prims, ray, t_max, found, lanes);
}

/// A shadow ray's tests of the shapes `refs` (a leaf's, or a light
/// buffer's list), stopping at the first that blocks it (`true`): shapes
/// in the plane it leaves ([`TriangleLanes::SKIPS_PLANES`]) and those
/// `tested` says were tested already are passed over; uncounted, where
/// the lanes can, triangles wait in `batch` to be tested four at a time
/// (the caller tests what is left in it at the end).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn shadow_tests<'a, C: Counter, L: TriangleLanes>(
    prims: &'a Primitives,
    ray: &PreparedRay,
    t_max: f64,
    found: &mut ShadowCrossings,
    counter: &mut C,
    batch: &mut TriangleBatch<'a>,
    refs: &[u32],
    mut tested: impl FnMut(u32) -> bool,
    lanes: L,
) -> bool {
    let batching = !C::COUNTS && L::FOUR_AT_ONCE;
    for &i in refs {
        if (L::SKIPS_PLANES && prims.left_behind(i)) || tested(i) {
            continue;
        }
        let blocked = if batching && let Some((triangle, transparent)) = prims.shadow_triangle(i) {
            batch.push(i, triangle, transparent) && batch.blocks(prims, ray, t_max, found, lanes)
        } else {
            test_occlusion(prims, i, ray, t_max, found, counter)
        };
        if blocked {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossings_are_sorted_deduplicated_and_keep_the_nearest() {
        let mut c = ShadowCrossings::default();
        for (t, s) in [(3.0, 1), (1.0, 4), (3.0, 0), (1.0, 4), (2.0, 9)] {
            c.add(t, s);
        }
        assert_eq!(c.transparent(), &[(1.0, 4), (2.0, 9), (3.0, 0), (3.0, 1)]);
        let mut full = ShadowCrossings::default();
        for k in (0..2 * MAX_SHADOW_CROSSINGS).rev() {
            full.add(k as f64, 0);
        }
        let kept: Vec<f64> = full.transparent().iter().map(|h| h.0).collect();
        let nearest: Vec<f64> = (0..MAX_SHADOW_CROSSINGS).map(|k| k as f64).collect();
        assert_eq!(kept, nearest);
        full.blocked = true;
        assert!(full.transparent().is_empty());
    }
}

//! Faces with a hole written as one polygon, as LightWave and 3ds Max
//! export them: the outer loop, a bridge edge to the inner loop, the inner
//! loop, and the bridge back (`… a b i1 … ik b a …`). Removing the
//! repeated vertices would cut a wedge out of the face; instead a second
//! bridge splits the ring into two simple polygons, each ear-clipped by
//! [`triangulate`], which checks that each is simple: a candidate bridge
//! that crosses the face's edges is refused there, and the next is tried.

use super::polygon::triangulate;
use crate::math::DVec3;

/// Second bridges tried before the face is given up.
const CANDIDATES: usize = 16;

/// Triangles (indices into `ids`, the face's corners as written, repeats
/// included) covering the ring a keyhole face describes; `None` if the
/// face is not one (no `a b … b a` bridge) or no bridge splits it.
pub fn triangulate_keyhole(ids: &[u32], points: &[DVec3]) -> Option<Vec<[u32; 3]>> {
    let n = ids.len();
    // The bridge: `a` at i and j, its neighbour `b` after i and before j,
    // read round the face's cycle: the list may start anywhere on it (`1 2
    // 3 4 1 5 6 7 8 5` is the ring 1 2 3 4 with the bridge 1-5 to the hole
    // 5 6 7 8, the closing edge back to the first 1 being the bridge out).
    let at = |k: usize| ids[k % n];
    let (i, j) = (0..n).find_map(|i| {
        let j = (i + 1..i + n).find(|&j| at(j) == ids[i])?;
        (j >= i + 5 && at(i + 1) == at(j - 1) && at(i + 1) != ids[i]).then_some((i, j))
    })?;
    // Positions in `ids` of the inner loop (b first) and the outer (a first).
    let inner: Vec<usize> = (i + 1..j - 1).map(|k| k % n).collect();
    let outer: Vec<usize> = (j..i + n).map(|k| k % n).collect();
    let distinct = |loop_: &[usize]| {
        let mut seen: Vec<u32> = loop_.iter().map(|&k| ids[k]).collect();
        seen.sort_unstable();
        seen.windows(2).all(|w| w[0] != w[1])
    };
    if inner.len() < 3 || outer.len() < 3 || !distinct(&inner) || !distinct(&outer) {
        return None;
    }
    let area = |loop_: &[usize]| {
        let mut v = DVec3::ZERO;
        for (k, &a) in loop_.iter().enumerate() {
            v += points[a].cross(points[loop_[(k + 1) % loop_.len()]]);
        }
        0.5 * v.length()
    };
    let ring_area = area(&outer) - area(&inner);
    if !(ring_area > 0.0) {
        return None;
    }
    // Second bridges from each outer vertex (but `a`) to its nearest inner
    // vertex (but `b`), shortest first.
    let mut bridges: Vec<(f64, usize, usize)> = (1..outer.len())
        .filter_map(|c| {
            let p = points[outer[c]];
            (1..inner.len())
                .map(|d| (points[inner[d]].distance_squared(p), c, d))
                .min_by(|x, y| x.0.total_cmp(&y.0))
        })
        .collect();
    bridges.sort_by(|x, y| x.0.total_cmp(&y.0));
    for &(_, c, d) in bridges.iter().take(CANDIDATES) {
        // The keyhole cycle a, b, i1 … ik, b, a, o1 … cut at inner d and
        // outer c: each half keeps one crossing of the first bridge.
        let first: Vec<usize> = inner[d..]
            .iter()
            .chain([&inner[0], &outer[0]])
            .chain(&outer[1..=c])
            .copied()
            .collect();
        let second: Vec<usize> = outer[c..]
            .iter()
            .chain([&outer[0]])
            .chain(&inner[..=d])
            .copied()
            .collect();
        let piece = |half: &[usize]| -> Option<(Vec<[u32; 3]>, f64)> {
            let corners: Vec<DVec3> = half.iter().map(|&k| points[k]).collect();
            let triangles = triangulate(&corners).ok()?;
            let area = area(half);
            Some((
                triangles
                    .into_iter()
                    .map(|t| t.map(|k| half[k as usize] as u32))
                    .collect(),
                area,
            ))
        };
        if let (Some((mut a, area_a)), Some((b, area_b))) = (piece(&first), piece(&second))
            && ((area_a + area_b) - ring_area).abs() <= 1e-9 * ring_area
        {
            a.extend(b);
            return Some(a);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square ring written as LightWave does: outer loop, bridge in,
    /// inner loop the other way round, bridge out.
    #[test]
    fn a_bridged_ring_is_covered_exactly() {
        let outer = [[-2.0, -2.0], [2.0, -2.0], [2.0, 2.0], [-2.0, 2.0]];
        let inner = [[-1.0, -1.0], [-1.0, 1.0], [1.0, 1.0], [1.0, -1.0]];
        let points: Vec<DVec3> = outer
            .iter()
            .chain(&inner)
            .map(|p| DVec3::new(p[0], p[1], 0.0))
            .collect();
        // The area the triangles of the keyhole face `ids` cover.
        let covered = |ids: &[u32]| -> f64 {
            let corners: Vec<DVec3> = ids.iter().map(|&k| points[k as usize]).collect();
            let triangles = triangulate_keyhole(ids, &corners).expect("a keyhole");
            triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| corners[k as usize]);
                    0.5 * (b - a).cross(c - a).z.abs()
                })
                .sum()
        };
        // The bridge from corner 0 to corner 4 first, round the hole, back
        // and round the outer loop.
        let area = covered(&[0, 4, 5, 6, 7, 4, 0, 1, 2, 3]);
        assert!((area - 12.0).abs() < 1e-12, "covered {area}");
        // The same ring written from the outer loop first, its bridge out
        // being the closing edge.
        let area = covered(&[0, 1, 2, 3, 0, 4, 5, 6, 7, 4]);
        assert!((area - 12.0).abs() < 1e-12, "covered {area}");
        // A face without a bridge is not a keyhole.
        assert!(triangulate_keyhole(&[0, 1, 2, 3], &points[..4]).is_none());
    }
}

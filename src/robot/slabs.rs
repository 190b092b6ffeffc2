//! A tight collision shape for a big link that does not move with an arm (the torso), or
//! for a bent one that does: a few boxes stacked along one of the link's axes, each
//! holding the part of the mesh that lies between its two cutting planes.
//!
//! The part of a triangle between two parallel planes is the convex polygon whose corners
//! are the triangle's corners between the planes and the points where its edges cross
//! them; a box around those points holds that polygon. So the boxes of all slabs hold the
//! whole surface, and since a slab's cross-section of the solid lies within the convex
//! hull of its boundary, the solid too. One box around a whole torso is far fatter: the
//! YuMi's body is a wide foot, a narrow neck and shoulders set back from the foot's front.

use nalgebra::{Point3, Vector3};

/// Thin slabs the mesh is cut into before neighbouring ones are merged.
const FINE_SLABS: usize = 48;
/// Boxes at most for a link that stays still: every one is a shape each arm link is
/// tested against.
pub(super) const MAX_BOXES: usize = 6;
/// Boxes at most for a link an arm moves: every one is tested at every configuration.
pub(super) const MAX_ARM_BOXES: usize = 3;
/// A box more must make the union at least this much smaller (a fraction of the volume of
/// one box around everything) to be worth its collision tests.
const WORTH_A_BOX: f32 = 0.02;

/// An axis-aligned box in the mesh's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Bounds {
    pub mins: Point3<f32>,
    pub maxs: Point3<f32>,
}

impl Bounds {
    fn empty() -> Bounds {
        Bounds {
            mins: Point3::from(Vector3::repeat(f32::INFINITY)),
            maxs: Point3::from(Vector3::repeat(f32::NEG_INFINITY)),
        }
    }

    fn is_empty(&self) -> bool {
        (0..3).any(|k| self.mins[k] > self.maxs[k])
    }

    fn merged(&self, other: &Bounds) -> Bounds {
        Bounds {
            mins: self.mins.inf(&other.mins),
            maxs: self.maxs.sup(&other.maxs),
        }
    }

    pub fn volume(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        (self.maxs - self.mins).iter().product()
    }
}

/// A triangle's corners as plain arrays: the cutting runs for every triangle of every
/// mesh at each start, and nalgebra's generic indexing is slow in an unoptimized build.
type Corners = [[f32; 3]; 3];

/// The least and greatest corner of what a slab holds so far.
type Extent = ([f32; 3], [f32; 3]);

const NO_EXTENT: Extent = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// The boxes (at most `max_boxes`, fewer when one more is hardly smaller) that together
/// hold `triangles`, cut along whichever of the mesh's three axes gives the least volume.
/// Empty when there are no triangles.
pub(super) fn stacked_boxes(triangles: &[[Point3<f32>; 3]], max_boxes: usize) -> Vec<Bounds> {
    let corners: Vec<Corners> = triangles
        .iter()
        .map(|t| [t[0].into(), t[1].into(), t[2].into()])
        .collect();
    let mut best: Option<(f32, Vec<Bounds>)> = None;
    for axis in 0..3 {
        let boxes = merge(&fine_slabs(&corners, axis), max_boxes);
        let volume: f32 = boxes.iter().map(Bounds::volume).sum();
        if best.as_ref().is_none_or(|(v, _)| volume < *v) {
            best = Some((volume, boxes));
        }
    }
    best.map(|(_, b)| b).unwrap_or_default()
}

/// The boxes of `FINE_SLABS` equal slabs along `axis` between the mesh's extremes; none
/// when there are no triangles.
fn fine_slabs(triangles: &[Corners], axis: usize) -> Vec<Bounds> {
    let (lo, hi) = triangles
        .iter()
        .flatten()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[axis]), hi.max(p[axis]))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    let step = (hi - lo) / FINE_SLABS as f32;
    let cuts: Vec<f32> = (0..=FINE_SLABS)
        .map(|i| {
            if i == FINE_SLABS {
                hi
            } else {
                lo + step * i as f32
            }
        })
        .collect();
    // A triangle adds to the slabs its extent along the axis meets and to no other, so
    // each is cut only against those (one more either side for the rounding of `step`).
    let mut fine = vec![NO_EXTENT; FINE_SLABS];
    for t in triangles {
        let (t_lo, t_hi) = t
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), p| {
                (l.min(p[axis]), h.max(p[axis]))
            });
        let (first, last) = if step > 0.0 {
            let index = |x: f32| ((x - lo) / step).floor().max(0.0) as usize;
            (
                index(t_lo).saturating_sub(1),
                (index(t_hi) + 1).min(FINE_SLABS - 1),
            )
        } else {
            (0, FINE_SLABS - 1)
        };
        for (i, extent) in fine.iter_mut().enumerate().take(last + 1).skip(first) {
            take_part(extent, t, axis, cuts[i], cuts[i + 1]);
        }
    }
    fine.into_iter()
        .map(|(mins, maxs)| Bounds {
            mins: Point3::from(mins),
            maxs: Point3::from(maxs),
        })
        .collect()
}

/// Takes into `extent` the part of triangle `t` with `a <= p[axis] <= b`.
fn take_part(extent: &mut Extent, t: &Corners, axis: usize, a: f32, b: f32) {
    let (lo, hi) = extent;
    let mut take = |x: &[f32; 3]| {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    };
    for (i, p) in t.iter().enumerate() {
        if a <= p[axis] && p[axis] <= b {
            take(p);
        }
        let q = &t[(i + 1) % 3];
        for plane in [a, b] {
            let (u, v) = (p[axis] - plane, q[axis] - plane);
            // The edge crosses the plane (strictly: a corner on it is taken above).
            if u * v < 0.0 {
                let s = u / (u - v);
                let mut x = [0.0; 3];
                for k in 0..3 {
                    x[k] = p[k] + (q[k] - p[k]) * s;
                }
                // Exactly on the plane, whatever the rounding of the line above.
                x[axis] = plane;
                take(&x);
            }
        }
    }
}

/// The partition of `fine` into consecutive groups with the least total volume for each
/// number of groups up to `max_boxes`, and of those the fewest groups whose next one would
/// not save `WORTH_A_BOX`.
fn merge(fine: &[Bounds], max_boxes: usize) -> Vec<Bounds> {
    let n = fine.len();
    if n == 0 {
        return Vec::new();
    }
    // span[i][j]: the box around fine slabs i..=j.
    let mut span = vec![vec![Bounds::empty(); n]; n];
    for (i, row) in span.iter_mut().enumerate() {
        let mut b = Bounds::empty();
        for (j, slab) in fine.iter().enumerate().skip(i) {
            b = b.merged(slab);
            row[j] = b;
        }
    }
    // cost[k][j]: least volume of the first j slabs in k groups; from[k][j]: where the
    // last group starts.
    let groups = max_boxes.min(n);
    let mut cost = vec![vec![f32::INFINITY; n + 1]; groups + 1];
    let mut from = vec![vec![0usize; n + 1]; groups + 1];
    cost[0][0] = 0.0;
    for k in 1..=groups {
        for j in 1..=n {
            for i in (k - 1)..j {
                let c = cost[k - 1][i] + span[i][j - 1].volume();
                if c < cost[k][j] {
                    cost[k][j] = c;
                    from[k][j] = i;
                }
            }
        }
    }
    let whole = span[0][n - 1].volume();
    let mut chosen = 1;
    while chosen < groups && cost[chosen][n] - cost[chosen + 1][n] > WORTH_A_BOX * whole {
        chosen += 1;
    }
    let mut boxes = Vec::with_capacity(chosen);
    let (mut k, mut j) = (chosen, n);
    while k > 0 {
        let i = from[k][j];
        let b = span[i][j - 1];
        if !b.is_empty() {
            boxes.push(b);
        }
        (k, j) = (k - 1, i);
    }
    boxes.reverse();
    boxes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The twelve triangles of the box from `lo` to `hi`.
    fn cuboid(lo: [f32; 3], hi: [f32; 3]) -> Vec<[Point3<f32>; 3]> {
        let c = |i: usize| {
            Point3::new(
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            )
        };
        let faces = [
            [0, 1, 3, 2],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 3, 7, 5],
        ];
        faces
            .iter()
            .flat_map(|f| [[c(f[0]), c(f[1]), c(f[2])], [c(f[0]), c(f[2]), c(f[3])]])
            .collect()
    }

    #[test]
    fn a_wide_foot_under_a_thin_column_is_two_boxes_that_hold_every_triangle() {
        // Long triangles across every slab: the column's sides span its whole height.
        let mut mesh = cuboid([-0.3, -0.2, 0.0], [0.3, 0.2, 0.1]);
        mesh.extend(cuboid([-0.05, -0.05, 0.1], [0.05, 0.05, 0.6]));
        let boxes = stacked_boxes(&mesh, MAX_BOXES);
        assert_eq!(boxes.len(), 2, "{boxes:?}");
        // The two solids' own volumes, and one slab's worth of the foot more at most.
        let exact: f32 = 0.6 * 0.4 * 0.1 + 0.1 * 0.1 * 0.5;
        let stacked: f32 = boxes.iter().map(Bounds::volume).sum();
        assert!(
            stacked >= exact - 1e-6 && stacked <= exact + 0.6 * 0.4 * 0.6 / 48.0,
            "{stacked} against {exact}"
        );
        for t in &mesh {
            for (a, b) in [
                (0.0, 0.0),
                (1.0, 0.0),
                (0.0, 1.0),
                (0.3, 0.3),
                (0.5, 0.5),
                (0.1, 0.8),
            ] {
                let p = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
                assert!(
                    boxes
                        .iter()
                        .any(|b| (0..3)
                            .all(|k| b.mins[k] - 1e-6 <= p[k] && p[k] <= b.maxs[k] + 1e-6)),
                    "{p:?} outside {boxes:?}"
                );
            }
        }
    }

    #[test]
    fn each_slab_holds_what_cutting_every_triangle_against_it_gives() {
        // Triangles of every size and slant, some corners exactly on cuts.
        let mut state = 7u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        let mut mesh: Vec<Corners> = cuboid([0.0, 0.0, 0.0], [1.0, 0.5, 0.25])
            .iter()
            .map(|t| [t[0].into(), t[1].into(), t[2].into()])
            .collect();
        for _ in 0..300 {
            let mut corner = || [next(), next() * 0.5, next() * 0.25];
            mesh.push([corner(), corner(), corner()]);
        }
        for axis in 0..3 {
            let (lo, hi) = mesh
                .iter()
                .flatten()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), p| {
                    (l.min(p[axis]), h.max(p[axis]))
                });
            let step = (hi - lo) / FINE_SLABS as f32;
            let cut = |i: usize| {
                if i == FINE_SLABS {
                    hi
                } else {
                    lo + step * i as f32
                }
            };
            let every: Vec<Bounds> = (0..FINE_SLABS)
                .map(|i| {
                    let mut e = NO_EXTENT;
                    for t in &mesh {
                        take_part(&mut e, t, axis, cut(i), cut(i + 1));
                    }
                    Bounds {
                        mins: Point3::from(e.0),
                        maxs: Point3::from(e.1),
                    }
                })
                .collect();
            assert_eq!(fine_slabs(&mesh, axis), every, "axis {axis}");
        }
    }

    #[test]
    fn no_triangles_no_boxes() {
        assert!(stacked_boxes(&[], MAX_BOXES).is_empty());
    }
}

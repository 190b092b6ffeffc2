//! Collision queries: is a straight motion free, is a region empty. Each counts the box
//! tests (whole solids) and exact tests (convex part pairs) it makes, and its time.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use nalgebra::Vector3;
use parry3d::bounding_volume::BoundingVolume;
use parry3d::query::{self, ShapeCastOptions};

use super::{Body, Part, Pose, aabb_of};

/// A solid in the world at its current pose: what a moving thing may hit.
pub struct Obstacle<'a> {
    pub pose: Pose,
    pub body: &'a Body,
}

/// Counts collision tests, shared by every fork of a world (for checks per second):
/// `narrow` are exact tests of two convex parts (a shape cast or an intersection test),
/// `broad` are box-against-box tests of whole solids that decide which pairs get one.
/// `queries` are whole questions (is this path free? is this region empty?) and `nanos`
/// the time spent answering them.
#[derive(Debug, Default)]
pub struct Counter {
    narrow: AtomicU64,
    broad: AtomicU64,
    queries: AtomicU64,
    nanos: AtomicU64,
}

impl Counter {
    pub fn add(&self, narrow: u64, broad: u64, since: Instant) {
        self.narrow.fetch_add(narrow, Ordering::Relaxed);
        self.broad.fetch_add(broad, Ordering::Relaxed);
        self.queries.fetch_add(1, Ordering::Relaxed);
        let nanos = u64::try_from(since.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.nanos.fetch_add(nanos, Ordering::Relaxed);
    }

    /// Questions answered (paths and regions).
    pub fn queries(&self) -> u64 {
        self.queries.load(Ordering::Relaxed)
    }

    /// Seconds spent answering them.
    pub fn seconds(&self) -> f64 {
        self.nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }

    /// Exact tests of part pairs.
    pub fn get(&self) -> u64 {
        self.narrow.load(Ordering::Relaxed)
    }

    /// Box tests of whole solids.
    pub fn broad(&self) -> u64 {
        self.broad.load(Ordering::Relaxed)
    }
}

/// Whether `moving` parts, carried in a frame that travels in a straight line from
/// `start` to `end`, touch any obstacle on the way. The swept box of the motion filters
/// obstacles; each remaining pair of convex parts is tested by casting one against the
/// other over the whole motion (the exact swept volume of the motion, not samples).
pub fn path_collides(
    moving: &[Part],
    start: &Pose,
    end: &Pose,
    obstacles: &[Obstacle],
    counter: &Counter,
) -> bool {
    let since = Instant::now();
    let swept = aabb_of(moving, start).merged(&aabb_of(moving, end));
    let travel = end.translation.vector - start.translation.vector;
    let mut checks = 0;
    let options = ShapeCastOptions {
        max_time_of_impact: 1.0,
        target_distance: 0.0,
        stop_at_penetration: true,
        compute_impact_geometry_on_penetration: false,
    };
    let mut hit = false;
    let mut broad = 0;
    'outer: for o in obstacles {
        broad += 1;
        if !o.body.aabb(&o.pose).intersects(&swept) {
            continue;
        }
        for op in o.body.parts.iter() {
            let op_pose = o.pose * op.local;
            if !op.shape.compute_aabb(&op_pose).intersects(&swept) {
                continue;
            }
            for mp in moving {
                checks += 1;
                let mp_pose = start * mp.local;
                let cast = query::cast_shapes(
                    &mp_pose,
                    &travel,
                    mp.shape.as_ref(),
                    &op_pose,
                    &Vector3::zeros(),
                    op.shape.as_ref(),
                    options,
                );
                // A query parry cannot answer is treated as a collision: never claim a
                // path is free without having shown it.
                if !matches!(cast, Ok(None)) {
                    hit = true;
                    break 'outer;
                }
            }
        }
    }
    counter.add(checks, broad, since);
    hit
}

/// Whether a part (already in world space) overlaps any obstacle.
pub fn overlaps_any(part: &Part, obstacles: &[Obstacle], counter: &Counter) -> bool {
    let since = Instant::now();
    let bound = part.shape.compute_aabb(&part.local);
    let mut checks = 0;
    let mut hit = false;
    let mut broad = 0;
    'outer: for o in obstacles {
        broad += 1;
        if !o.body.aabb(&o.pose).intersects(&bound) {
            continue;
        }
        for op in o.body.parts.iter() {
            checks += 1;
            let touching = query::intersection_test(
                &part.local,
                part.shape.as_ref(),
                &(o.pose * op.local),
                op.shape.as_ref(),
            );
            if !matches!(touching, Ok(false)) {
                hit = true;
                break 'outer;
            }
        }
    }
    counter.add(checks, broad, since);
    hit
}

//! Solids, poses and collision: the one place where nalgebra meets parry3d.
//!
//! Units are metres, z points up, the table top is z = 0. Every body's local frame has
//! its origin at the centre of its footprint (bottom centre), so "resting on a face" is a
//! translation to that face's height. Bodies are lists of convex parts (a cup is a ring of
//! wall slabs plus a bottom disc), which lets a path test run convex-against-convex and
//! count every test it makes.

use std::f32::consts::{FRAC_PI_2, PI};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::query::{self, ShapeCastOptions};
use parry3d::shape::SharedShape;

/// A rigid placement in the world (or relative to another frame).
pub type Pose = Isometry3<f32>;

/// Contacts closer than this count as touching, not colliding (teleported objects rest
/// exactly on faces, so exact contact must not read as a collision).
pub const CONTACT_GAP: f32 = 0.002;
/// How far a resting object's bottom may be from a support's top and still rest on it.
pub const REST_TOLERANCE: f32 = 0.003;
/// Depth of the region just outside a container's opening that must be free for the
/// container to count as open.
pub const OPENING_DEPTH: f32 = 0.04;

/// One convex piece of a body, placed in the body's frame.
#[derive(Clone)]
pub struct Part {
    pub local: Pose,
    pub shape: SharedShape,
}

/// Which side of a container things go in through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Opening {
    /// Through the top face (+z of the body): cups, a centrifuge, a bucket, a crib.
    Top,
    /// Through the front face (-x of the body): a cupboard.
    Front,
}

/// The hollow inside a container, as a box in the body's frame.
#[derive(Debug, Clone, Copy)]
pub struct Cavity {
    pub center: Point3<f32>,
    pub half: Vector3<f32>,
    pub opening: Opening,
}

/// A solid shape made of convex parts, with the box around it in its own frame.
#[derive(Clone)]
pub struct Body {
    pub parts: Arc<Vec<Part>>,
    pub local_aabb: Aabb,
    pub cavity: Option<Cavity>,
}

/// The shapes a scenario can ask for (all sizes in metres).
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeSpec {
    Box {
        size: [f32; 3],
    },
    Cylinder {
        radius: f32,
        height: f32,
    },
    Ball {
        radius: f32,
    },
    /// Lying along x (a banana, a hammer handle).
    Capsule {
        radius: f32,
        length: f32,
    },
    /// A round cup: a bottom disc and a ring of wall slabs, open at the top.
    Cup {
        radius: f32,
        height: f32,
        wall: f32,
        bottom: f32,
    },
    /// A box with one open face (centrifuge body, cupboard, crib).
    OpenBox {
        size: [f32; 3],
        wall: f32,
        opening: Opening,
    },
}

/// Wall slabs around a cup: enough that a cube cannot slip between them.
const CUP_SEGMENTS: usize = 12;

fn cuboid_at(center: Vector3<f32>, half: Vector3<f32>) -> Part {
    Part {
        local: Pose::translation(center.x, center.y, center.z),
        shape: SharedShape::cuboid(half.x, half.y, half.z),
    }
}

impl Body {
    pub fn new(spec: &ShapeSpec) -> Body {
        let mut cavity = None;
        let parts = match *spec {
            ShapeSpec::Box { size } => {
                let h = Vector3::from(size) / 2.0;
                vec![cuboid_at(Vector3::new(0.0, 0.0, h.z), h)]
            }
            ShapeSpec::Cylinder { radius, height } => vec![Part {
                // parry's cylinder stands along y; turn it to stand along z.
                local: Pose::new(
                    Vector3::new(0.0, 0.0, height / 2.0),
                    Vector3::x() * FRAC_PI_2,
                ),
                shape: SharedShape::cylinder(height / 2.0, radius),
            }],
            ShapeSpec::Ball { radius } => vec![Part {
                local: Pose::translation(0.0, 0.0, radius),
                shape: SharedShape::ball(radius),
            }],
            ShapeSpec::Capsule { radius, length } => vec![Part {
                local: Pose::translation(0.0, 0.0, radius),
                shape: SharedShape::capsule_x((length / 2.0 - radius).max(0.0), radius),
            }],
            ShapeSpec::Cup {
                radius,
                height,
                wall,
                bottom,
            } => {
                let mut parts = vec![Part {
                    local: Pose::new(
                        Vector3::new(0.0, 0.0, bottom / 2.0),
                        Vector3::x() * FRAC_PI_2,
                    ),
                    shape: SharedShape::cylinder(bottom / 2.0, radius),
                }];
                let wall_h = (height - bottom) / 2.0;
                let chord = radius * (PI / CUP_SEGMENTS as f32).tan();
                for i in 0..CUP_SEGMENTS {
                    let angle = 2.0 * PI * i as f32 / CUP_SEGMENTS as f32;
                    let r = radius - wall / 2.0;
                    parts.push(Part {
                        local: Pose::new(
                            Vector3::new(r * angle.cos(), r * angle.sin(), bottom + wall_h),
                            Vector3::z() * angle,
                        ),
                        shape: SharedShape::cuboid(wall / 2.0, chord, wall_h),
                    });
                }
                // The largest square inside the inner ring, from the bottom to the rim.
                let inner = (radius - wall) * (PI / CUP_SEGMENTS as f32).cos() / 2f32.sqrt();
                cavity = Some(Cavity {
                    center: Point3::new(0.0, 0.0, bottom + wall_h),
                    half: Vector3::new(inner, inner, wall_h),
                    opening: Opening::Top,
                });
                parts
            }
            ShapeSpec::OpenBox {
                size,
                wall,
                opening,
            } => {
                let [sx, sy, sz] = size;
                let (hx, hy, hz, t) = (sx / 2.0, sy / 2.0, sz / 2.0, wall / 2.0);
                let mut parts = vec![
                    cuboid_at(Vector3::new(0.0, 0.0, t), Vector3::new(hx, hy, t)),
                    cuboid_at(Vector3::new(0.0, hy - t, hz), Vector3::new(hx, t, hz)),
                    cuboid_at(Vector3::new(0.0, -hy + t, hz), Vector3::new(hx, t, hz)),
                    cuboid_at(Vector3::new(hx - t, 0.0, hz), Vector3::new(t, hy, hz)),
                ];
                let top = match opening {
                    Opening::Top => {
                        parts.push(cuboid_at(
                            Vector3::new(-hx + t, 0.0, hz),
                            Vector3::new(t, hy, hz),
                        ));
                        sz
                    }
                    Opening::Front => {
                        parts.push(cuboid_at(
                            Vector3::new(0.0, 0.0, sz - t),
                            Vector3::new(hx, hy, t),
                        ));
                        sz - wall
                    }
                };
                let front = if opening == Opening::Front {
                    -hx
                } else {
                    -hx + wall
                };
                let (x0, x1) = (front, hx - wall);
                cavity = Some(Cavity {
                    center: Point3::new((x0 + x1) / 2.0, 0.0, (wall + top) / 2.0),
                    half: Vector3::new((x1 - x0) / 2.0, hy - wall, (top - wall) / 2.0),
                    opening,
                });
                parts
            }
        };
        Body::from_parts(parts, cavity)
    }

    pub fn from_parts(parts: Vec<Part>, cavity: Option<Cavity>) -> Body {
        let local_aabb = aabb_of(&parts, &Pose::identity());
        Body {
            parts: Arc::new(parts),
            local_aabb,
            cavity,
        }
    }

    /// The box around the body at `pose`.
    pub fn aabb(&self, pose: &Pose) -> Aabb {
        self.local_aabb.transform_by(pose)
    }

    /// The pose that rests the body, turned by `rotation`, on a face at height `top`
    /// with its footprint centred on `(x, y)`.
    pub fn resting(&self, rotation: UnitQuaternion<f32>, x: f32, y: f32, top: f32) -> Pose {
        let turned = self.aabb(&Pose::from_parts(Translation3::identity(), rotation));
        let c = turned.center();
        Pose::from_parts(
            Translation3::new(x - c.x, y - c.y, top - turned.mins.z),
            rotation,
        )
    }

    /// The cavity as a world-space box (pose and half extents), if the body has one.
    pub fn cavity_at(&self, pose: &Pose) -> Option<(Pose, Vector3<f32>, Opening)> {
        let c = self.cavity?;
        Some((
            pose * Pose::translation(c.center.x, c.center.y, c.center.z),
            c.half,
            c.opening,
        ))
    }

    /// Whether a world point lies inside the cavity.
    pub fn cavity_contains(&self, pose: &Pose, point: &Point3<f32>) -> bool {
        let Some(c) = self.cavity else { return false };
        let p = pose.inverse_transform_point(point) - c.center;
        p.x.abs() <= c.half.x && p.y.abs() <= c.half.y && p.z.abs() <= c.half.z
    }

    /// The slab just outside the cavity's opening, as a part in world space: it must be
    /// free of other solids for the container to be open.
    pub fn opening_region(&self, pose: &Pose) -> Option<Part> {
        let c = self.cavity?;
        let shrink = CONTACT_GAP;
        let (center, half) = match c.opening {
            Opening::Top => (
                c.center + Vector3::new(0.0, 0.0, c.half.z + OPENING_DEPTH / 2.0 + shrink),
                Vector3::new(c.half.x, c.half.y, OPENING_DEPTH / 2.0),
            ),
            Opening::Front => (
                c.center - Vector3::new(c.half.x + OPENING_DEPTH / 2.0 + shrink, 0.0, 0.0),
                Vector3::new(OPENING_DEPTH / 2.0, c.half.y, c.half.z),
            ),
        };
        Some(Part {
            local: pose * Pose::translation(center.x, center.y, center.z),
            shape: SharedShape::cuboid(half.x - shrink, half.y - shrink, half.z - shrink),
        })
    }
}

/// The box around some parts placed at `pose`.
pub fn aabb_of(parts: &[Part], pose: &Pose) -> Aabb {
    let mut out: Option<Aabb> = None;
    for p in parts {
        let b = p.shape.compute_aabb(&(pose * p.local));
        out = Some(match out {
            Some(a) => a.merged(&b),
            None => b,
        });
    }
    out.unwrap_or_else(|| Aabb::new(Point3::origin(), Point3::origin()))
}

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

/// Whether a body's local +z still points up (within about 8 degrees).
pub fn is_upright(pose: &Pose) -> bool {
    (pose.rotation * Vector3::z()).z > 0.99
}

/// A half turn about the world x axis, applied to a rotation (flipping a cup over).
pub fn flipped(rotation: UnitQuaternion<f32>) -> UnitQuaternion<f32> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI) * rotation
}

/// Rotation from degrees about x, y, z (applied in that order).
pub fn rotation_deg(r: [f32; 3]) -> UnitQuaternion<f32> {
    UnitQuaternion::from_euler_angles(r[0].to_radians(), r[1].to_radians(), r[2].to_radians())
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn cube(size: f32) -> Body {
        Body::new(&ShapeSpec::Box { size: [size; 3] })
    }

    #[test]
    fn resting_puts_the_bottom_on_the_face() {
        let b = cube(0.04);
        let p = b.resting(UnitQuaternion::identity(), 0.3, 0.1, 0.04);
        let a = b.aabb(&p);
        assert!((a.mins.z - 0.04).abs() < 1e-6);
        assert!((a.center().x - 0.3).abs() < 1e-6);
        let cup = Body::new(&ShapeSpec::Cup {
            radius: 0.04,
            height: 0.09,
            wall: 0.005,
            bottom: 0.008,
        });
        let down = cup.resting(flipped(UnitQuaternion::identity()), 0.0, 0.0, 0.0);
        assert!(!is_upright(&down));
        assert!(cup.aabb(&down).mins.z.abs() < 1e-5);
    }

    #[test]
    fn a_falling_cube_hits_a_cube_below_but_not_beside() {
        let counter = Counter::default();
        let b = cube(0.04);
        let below = Obstacle {
            pose: b.resting(UnitQuaternion::identity(), 0.0, 0.0, 0.0),
            body: &b,
        };
        let start = Pose::translation(0.0, 0.0, 0.3);
        let end = Pose::translation(0.0, 0.0, 0.01);
        let parts = b.parts.as_ref().clone();
        assert!(path_collides(
            &parts,
            &start,
            &end,
            std::slice::from_ref(&below),
            &counter
        ));
        let aside = Pose::translation(0.1, 0.0, 0.0);
        assert!(!path_collides(
            &parts,
            &(aside * start),
            &(aside * end),
            std::slice::from_ref(&below),
            &counter
        ));
        assert!(counter.get() >= 1 && counter.broad() >= 2);
    }

    #[test]
    fn cavity_and_opening_follow_the_pose() {
        let cup = Body::new(&ShapeSpec::Cup {
            radius: 0.045,
            height: 0.09,
            wall: 0.005,
            bottom: 0.008,
        });
        let up = cup.resting(UnitQuaternion::identity(), 0.0, 0.0, 0.0);
        assert!(cup.cavity_contains(&up, &Point3::new(0.0, 0.0, 0.03)));
        assert!(!cup.cavity_contains(&up, &Point3::new(0.0, 0.0, 0.12)));
        let region = cup.opening_region(&up).unwrap();
        assert!(region.local.translation.vector.z > 0.09);
        let down = cup.resting(flipped(UnitQuaternion::identity()), 0.0, 0.0, 0.0);
        let region = cup.opening_region(&down).unwrap();
        assert!(region.local.translation.vector.z < 0.0);
    }
}

//! Solids, poses and collision: the one place where nalgebra meets parry3d.
//!
//! Units are metres, z points up, the table top is z = 0. Every body's local frame has
//! its origin at the centre of its footprint (bottom centre), so "resting on a face" is a
//! translation to that face's height. Bodies are lists of convex parts (a cup is a ring of
//! wall slabs plus a bottom disc), which lets a path test run convex-against-convex and
//! count every test it makes. The collision queries themselves are in `collision`.

mod collision;
mod footprints;

pub use collision::{Counter, Obstacle, overlaps_any, path_collides};
pub use footprints::Footprints;
pub use parry3d::bounding_volume::Aabb;

use std::f32::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d::bounding_volume::BoundingVolume;
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

/// A box part centred at `center` with half extents `half` (gripper fingers, walls).
pub fn cuboid_at(center: Vector3<f32>, half: Vector3<f32>) -> Part {
    Part {
        local: Pose::translation(center.x, center.y, center.z),
        shape: SharedShape::cuboid(half.x, half.y, half.z),
    }
}

/// A cup's parts (a disc for the bottom, a ring of wall segments) and its cavity.
fn cup(radius: f32, height: f32, wall: f32, bottom: f32) -> (Vec<Part>, Cavity) {
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
    let cavity = Cavity {
        center: Point3::new(0.0, 0.0, bottom + wall_h),
        half: Vector3::new(inner, inner, wall_h),
        opening: Opening::Top,
    };
    (parts, cavity)
}

/// An open box's parts (the floor, three walls, and the fourth wall or the lid on the
/// side that is not open) and its cavity.
fn open_box(size: [f32; 3], wall: f32, opening: Opening) -> (Vec<Part>, Cavity) {
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
    let cavity = Cavity {
        center: Point3::new((x0 + x1) / 2.0, 0.0, (wall + top) / 2.0),
        half: Vector3::new((x1 - x0) / 2.0, hy - wall, (top - wall) / 2.0),
        opening,
    };
    (parts, cavity)
}

impl Body {
    pub fn new(spec: &ShapeSpec) -> Body {
        let (parts, cavity) = match *spec {
            ShapeSpec::Box { size } => {
                let h = Vector3::from(size) / 2.0;
                (vec![cuboid_at(Vector3::new(0.0, 0.0, h.z), h)], None)
            }
            ShapeSpec::Cylinder { radius, height } => (
                vec![Part {
                    // parry's cylinder stands along y; turn it to stand along z.
                    local: Pose::new(
                        Vector3::new(0.0, 0.0, height / 2.0),
                        Vector3::x() * FRAC_PI_2,
                    ),
                    shape: SharedShape::cylinder(height / 2.0, radius),
                }],
                None,
            ),
            ShapeSpec::Ball { radius } => (
                vec![Part {
                    local: Pose::translation(0.0, 0.0, radius),
                    shape: SharedShape::ball(radius),
                }],
                None,
            ),
            ShapeSpec::Capsule { radius, length } => (
                vec![Part {
                    local: Pose::translation(0.0, 0.0, radius),
                    shape: SharedShape::capsule_x((length / 2.0 - radius).max(0.0), radius),
                }],
                None,
            ),
            ShapeSpec::Cup {
                radius,
                height,
                wall,
                bottom,
            } => {
                let (parts, cavity) = cup(radius, height, wall, bottom);
                (parts, Some(cavity))
            }
            ShapeSpec::OpenBox {
                size,
                wall,
                opening,
            } => {
                let (parts, cavity) = open_box(size, wall, opening);
                (parts, Some(cavity))
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

    /// The box around the body at `pose`: its own box moved when the pose turns it by
    /// quarter turns (exact then), else the box around its parts (the box around a turned
    /// box is larger than the body: a banana rolled a little about its length would seem
    /// to sink into what it lies on).
    pub fn aabb(&self, pose: &Pose) -> Aabb {
        if quarter_turns(&pose.rotation) {
            self.local_aabb.transform_by(pose)
        } else {
            aabb_of(&self.parts, pose)
        }
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

/// Whether `rotation` maps each axis onto an axis (every matrix entry 0 or ±1).
fn quarter_turns(rotation: &UnitQuaternion<f32>) -> bool {
    rotation
        .to_rotation_matrix()
        .matrix()
        .iter()
        .all(|v| v.abs() < 1e-4 || (v.abs() - 1.0).abs() < 1e-4)
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
mod tests;

//! The robot: an ABB YuMi (IRB 14000) — two 7-axis arms on one torso, each reaching
//! `reach` (559 mm) from its shoulder and carrying `payload` (0.5 kg) — with a parallel
//! gripper modelled as a solid (two fingers below a palm). All numbers come from the
//! scenario's `[world.robot]` table, so another robot is a data change.
//!
//! Reach is a sphere around each shoulder: a point is reachable when one shoulder is
//! within `reach` of it. That is the arm's outer envelope (joint limits inside it are not
//! modelled). A mobile base, when a scenario gives the robot one, moves the torso in the
//! floor plane.

use super::geometry::{Part, cuboid_at};
use nalgebra::{Point3, Vector2, Vector3};

/// The gripper's solid dimensions (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct Gripper {
    /// Finger size: thickness (across the grip), width, length (down from the palm).
    pub finger: [f32; 3],
    /// Palm size: along x, height.
    pub palm: [f32; 2],
    /// Gap left between each finger and the object when the gripper opens around it.
    pub clearance: f32,
    /// How far below an object's top the finger tips close.
    pub grip_depth: f32,
    /// Length of the straight approach (and retreat) path next to the target.
    pub approach: f32,
}

/// The robot's published description, whose arms the execution world moves.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmsSpec {
    pub description: &'static crate::model::DescriptionSpec,
    /// Each arm's joint values (radians) before its first motion.
    pub rest: Vec<Vec<f64>>,
    /// The tool centre point along the flange's z axis (metres).
    pub tool: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    /// The arms from a published description, when the scenario names one.
    pub arms: Option<ArmsSpec>,
    /// Shoulder positions relative to the base (x forward, y left, z up).
    pub shoulders: Vec<Point3<f32>>,
    pub reach: f32,
    /// Payload per arm (kg).
    pub payload: f32,
    /// When driving to an object, end this fraction of `reach` away from it.
    pub drive_margin: f32,
    pub gripper: Gripper,
}

impl Robot {
    fn shoulders_at(&self, base: Vector2<f32>) -> impl Iterator<Item = Point3<f32>> + '_ {
        self.shoulders
            .iter()
            .map(move |s| s + Vector3::new(base.x, base.y, 0.0))
    }

    /// Distance from the nearest shoulder to `point`, and that shoulder.
    pub fn nearest_shoulder(&self, base: Vector2<f32>, point: &Point3<f32>) -> (f32, Point3<f32>) {
        self.shoulders_at(base)
            .map(|s| ((point - s).norm(), s))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((f32::INFINITY, Point3::origin()))
    }

    pub fn reaches(&self, base: Vector2<f32>, point: &Point3<f32>) -> bool {
        self.nearest_shoulder(base, point).0 <= self.reach
    }

    /// Where the base must drive, along its y axis (the table's edge), so that the
    /// nearest shoulder ends `drive_margin * reach` from `point`; `None` when the point is
    /// too far from the edge, too high or too low to reach from anywhere along it.
    pub fn base_to_reach(&self, base: Vector2<f32>, point: &Point3<f32>) -> Option<Vector2<f32>> {
        if self.reaches(base, point) {
            return Some(base);
        }
        let want = self.reach * self.drive_margin;
        self.shoulders_at(base)
            .filter_map(|s| {
                let d = point - s;
                let across = want * want - d.x * d.x - d.z * d.z;
                (across >= 0.0).then(|| {
                    let dy = d.y - d.y.signum() * across.sqrt();
                    Vector2::new(base.x, base.y + dy)
                })
            })
            .min_by(|a, b| (a.y - base.y).abs().total_cmp(&(b.y - base.y).abs()))
    }

    /// The gripper's parts in the frame of its tool centre point (between the finger
    /// tips), opened to hold an object `half_width` wide across y.
    pub fn gripper_parts(&self, half_width: f32) -> Vec<Part> {
        let g = &self.gripper;
        let [t, w, len] = g.finger;
        let y = half_width + g.clearance + t / 2.0;
        let finger = |side: f32| {
            cuboid_at(
                Vector3::new(0.0, side * y, len / 2.0),
                Vector3::new(w / 2.0, t / 2.0, len / 2.0),
            )
        };
        let [px, ph] = g.palm;
        vec![
            finger(1.0),
            finger(-1.0),
            cuboid_at(
                Vector3::new(0.0, 0.0, len + ph / 2.0),
                Vector3::new(px / 2.0, y + t / 2.0, ph / 2.0),
            ),
        ]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn yumi() -> Robot {
        Robot {
            arms: None,
            shoulders: vec![
                Point3::new(0.05, 0.18, 0.28),
                Point3::new(0.05, -0.18, 0.28),
            ],
            reach: 0.559,
            payload: 0.5,
            drive_margin: 0.8,
            gripper: Gripper {
                finger: [0.01, 0.02, 0.04],
                palm: [0.03, 0.02],
                clearance: 0.005,
                grip_depth: 0.02,
                approach: 0.15,
            },
        }
    }

    #[test]
    fn reach_is_a_sphere_around_a_shoulder() {
        let r = yumi();
        let base = Vector2::zeros();
        assert!(r.reaches(base, &Point3::new(0.4, 0.1, 0.04)));
        assert!(!r.reaches(base, &Point3::new(0.9, 0.6, 0.04)));
        // Right at the edge of the left arm's sphere.
        let edge = Point3::new(0.05 + 0.558, 0.18, 0.28);
        assert!(r.reaches(base, &edge));
    }

    #[test]
    fn driving_brings_a_far_point_into_reach() {
        let r = yumi();
        let far = Point3::new(0.4, 1.2, 0.02);
        let base = r.base_to_reach(Vector2::zeros(), &far).unwrap();
        assert!(r.reaches(base, &far));
        assert!(base.y > 0.5 && base.x == 0.0);
        // Too far from the edge to reach by driving along it.
        assert_eq!(
            r.base_to_reach(Vector2::zeros(), &Point3::new(1.5, 0.0, 0.02)),
            None
        );
        // Nothing to do when it is already close.
        let near = Point3::new(0.3, 0.1, 0.02);
        assert_eq!(
            r.base_to_reach(Vector2::zeros(), &near),
            Some(Vector2::zeros())
        );
    }

    #[test]
    fn gripper_opens_around_the_object() {
        let parts = yumi().gripper_parts(0.02);
        assert_eq!(parts.len(), 3);
        // Fingers clear a 4 cm cube.
        assert!(parts[0].local.translation.vector.y - 0.005 >= 0.02);
    }
}

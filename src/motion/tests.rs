//! The YuMi's arms in poses the collision test finds free, and in poses it does not.

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use parry3d::shape::SharedShape;

use super::*;
use crate::robot::tests::yumi;
use crate::robot::{Robot, RobotShapes};

/// Degrees to radians.
fn radians(degrees: [f64; 7]) -> Vec<f64> {
    degrees.iter().map(|d| d.to_radians()).collect()
}

/// Both arms' flanges 35 cm (right) and 25 cm (left) above the table in front of the
/// body, pointing down (found by the arms' inverse kinematics), per arm.
fn home(robot: &Robot) -> Vec<Vec<f64>> {
    let right = radians([42.2, -14.9, -103.7, 41.8, -4.9, -16.0, -35.3]);
    let left = radians([-75.9, -40.3, 127.8, 21.9, -21.3, -23.0, 73.1]);
    robot
        .arms
        .iter()
        .map(|arm| {
            if arm.tip.ends_with("_l") {
                left.clone()
            } else {
                right.clone()
            }
        })
        .collect()
}

/// The right arm's flange lower and further out to the right.
fn forward() -> Vec<f64> {
    radians([75.7, -40.3, -127.8, 21.9, 21.3, -23.0, -73.1])
}

fn cuboid(name: &str, at: [f32; 3], half: [f32; 3]) -> Solid {
    Solid {
        name: name.to_string(),
        pose: Isometry3::from_parts(
            Translation3::new(at[0], at[1], at[2]),
            UnitQuaternion::identity(),
        ),
        shape: SharedShape::cuboid(half[0], half[1], half[2]),
    }
}

fn shapes(robot: &Robot) -> RobotShapes {
    RobotShapes::new(&robot.model, &robot.arms).unwrap()
}

#[test]
fn the_home_and_forward_poses_are_free() {
    let robot = yumi();
    let shapes = shapes(robot);
    let q = home(robot);
    for arm in 0..2 {
        let check = ArmCheck::new(robot, &shapes, Isometry3::identity(), arm, &q, &[]).unwrap();
        assert_eq!(check.blocker(&q[arm]), None, "arm {arm}");
    }
    let check = ArmCheck::new(robot, &shapes, Isometry3::identity(), 0, &q, &[]).unwrap();
    assert_eq!(check.blocker(&forward()), None);
}

#[test]
fn a_solid_at_the_hand_and_the_other_arm_are_named() {
    let robot = yumi();
    let shapes = shapes(robot);
    let q = home(robot);
    let hand = robot.arms[0].fk(&q[0]).translation.vector.cast::<f32>();
    let cube = cuboid("red cube", [hand.x, hand.y, hand.z], [0.02, 0.02, 0.02]);
    let check = ArmCheck::new(robot, &shapes, Isometry3::identity(), 0, &q, &[cube]).unwrap();
    assert_eq!(check.blocker(&q[0]).as_deref(), Some("red cube"));
    assert!(!check.is_free(&q[0]));
    // The right hand sent where the left hand is meets the left arm.
    let left_hand = robot.arms[1].fk(&q[1]);
    let (reaching, _, _) = crate::robot::solve(
        &robot.arms[0],
        &left_hand,
        &q[0],
        &crate::robot::IkOptions::default(),
    )
    .expect("the right arm reaches the left hand's place");
    let check = ArmCheck::new(robot, &shapes, Isometry3::identity(), 0, &q, &[]).unwrap();
    let blocker = check.blocker(&reaching);
    assert!(
        blocker
            .as_deref()
            .is_some_and(|b| b.ends_with("_l") || b.contains("_l_")),
        "{blocker:?}"
    );
}

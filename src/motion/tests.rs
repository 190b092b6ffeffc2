//! The YuMi's arms in poses the collision test finds free and in poses it does not, and
//! the right arm's paths among solids: found in free space and around a post in the way,
//! the same for the same seed, refused when the target is enclosed.

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

/// Every point along the path, at the planner's resolution, is free.
fn assert_free(check: &ArmCheck<'_>, path: &JointPath, resolution: f64) {
    for w in path.waypoints.windows(2) {
        let d: f64 = w[0]
            .iter()
            .zip(&w[1])
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        let steps = (d / resolution).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let q: Vec<f64> = w[0]
                .iter()
                .zip(&w[1])
                .map(|(a, b)| a + (b - a) * t)
                .collect();
            assert!(check.is_free(&q), "{q:?} hits {:?}", check.blocker(&q));
        }
    }
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

#[test]
fn a_path_is_found_in_free_space() {
    let robot = yumi();
    let shapes = shapes(robot);
    let q = home(robot);
    let options = PlanOptions::default();
    let free = ArmCheck::new(robot, &shapes, Isometry3::identity(), 0, &q, &[]).unwrap();
    let path = plan(&free, &q[0], &forward(), &options).unwrap();
    assert_eq!(path.waypoints.first(), Some(&q[0]));
    assert_eq!(path.waypoints.last(), Some(&forward()));
    assert_free(&free, &path, options.resolution);
    // The same seed finds the same path.
    assert_eq!(plan(&free, &q[0], &forward(), &options).unwrap(), path);
}

#[test]
fn a_target_inside_a_closed_box_is_refused_naming_the_box() {
    let robot = yumi();
    let shapes = shapes(robot);
    let q = home(robot);
    let tool = robot.arms[0]
        .fk(&forward())
        .translation
        .vector
        .cast::<f32>();
    // A closed box around the flange: four walls, a floor and a lid 8 cm from it.
    let (x, y, z) = (tool.x, tool.y, tool.z);
    let (h, t) = (0.08, 0.005);
    let solids = vec![
        cuboid("box lid", [x, y, z + h], [h, h, t]),
        cuboid("box floor", [x, y, z - h], [h, h, t]),
        cuboid("box front", [x + h, y, z], [t, h, h]),
        cuboid("box back", [x - h, y, z], [t, h, h]),
        cuboid("box left", [x, y + h, z], [h, t, h]),
        cuboid("box right", [x, y - h, z], [h, t, h]),
    ];
    let check = ArmCheck::new(robot, &shapes, Isometry3::identity(), 0, &q, &solids).unwrap();
    let err = plan(&check, &q[0], &forward(), &PlanOptions::default()).unwrap_err();
    let text = err.to_string();
    assert!(
        text.starts_with("No collision free path found for yumi_link_7_r"),
        "{text}"
    );
    let MotionError::NoPath {
        blocker: Some(blocker),
        ..
    } = err
    else {
        panic!("{text}");
    };
    assert!(blocker.starts_with("box "), "{text}");
}

#[test]
fn a_path_goes_around_a_post_on_the_straight_way() {
    let robot = yumi();
    let shapes = shapes(robot);
    let q = home(robot);
    let options = PlanOptions::default();
    // The whole right arm swung outwards about its first joint, and a small post where
    // the hand passes halfway.
    let straight = |to: &[f64], t: f64| -> Vec<f64> {
        q[0].iter().zip(to).map(|(a, b)| a + (b - a) * t).collect()
    };
    let mut swung = q[0].clone();
    swung[0] += 1.2;
    let hand = robot.arms[0]
        .fk(&straight(&swung, 0.5))
        .translation
        .vector
        .cast::<f32>();
    let post = vec![cuboid("post", [hand.x, hand.y, hand.z], [0.02, 0.02, 0.02])];
    let check = ArmCheck::new(robot, &shapes, Isometry3::identity(), 0, &q, &post).unwrap();
    assert!(check.is_free(&q[0]) && check.is_free(&swung));
    assert_eq!(
        check.blocker(&straight(&swung, 0.5)).as_deref(),
        Some("post")
    );
    let around = plan(&check, &q[0], &swung, &options).unwrap();
    assert!(
        around.samples > 0 && around.waypoints.len() > 2,
        "{around:?}"
    );
    assert_eq!(around.waypoints.first(), Some(&q[0]));
    assert_eq!(around.waypoints.last(), Some(&swung));
    assert_free(&check, &around, options.resolution);
    assert_eq!(plan(&check, &q[0], &swung, &options).unwrap(), around);
    // With too small a budget the search gives up and names what stopped it.
    let hurried = PlanOptions {
        samples: 2,
        ..options
    };
    let err = plan(&check, &q[0], &swung, &hurried).unwrap_err();
    assert_eq!(
        err.to_string(),
        "No collision free path found for yumi_link_7_r: 2 samples tried, most often blocked by post"
    );
}

//! The queries extracted from a scenario are the motions its tree makes with the arms.

use std::path::Path;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d::shape::SharedShape;

use super::*;

fn scenario(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/cell")
        .join(name)
}

#[test]
fn scenario_one_poses_the_paths_of_its_repaired_run_each_planned_again_the_same_way() {
    crate::robot::tests::yumi_dir();
    let found = scenario_queries(&scenario("red_on_blue.toml"))
        .unwrap()
        .expect("scenario 1 moves the real arms");
    let rest = &found.arms.rest;
    let queries = &found.queries;
    // Repaired: the red cube grasped and put down (there, and back to rest), then the
    // blue cube grasped and placed on the green cube (there, and back to rest).
    assert!(queries.len() >= 6, "{}", queries.len());
    // Each run starts with the arms at rest, and the first path of an arm starts there.
    assert_eq!(queries[0].start, rest[queries[0].arm]);
    assert!(queries.iter().all(|q| q.start != q.goal));
    // Every path carrying something ends with a path back to rest, empty-handed.
    for pair in queries.windows(2) {
        if !pair[0].carried.is_empty() {
            assert_eq!(pair[1].start, pair[0].goal);
            assert_eq!(pair[1].goal, rest[pair[1].arm]);
            assert!(pair[1].carried.is_empty());
        }
    }
    assert!(
        queries.iter().any(|q| !q.carried.is_empty()),
        "a place carries the cube"
    );
    // The grasped cube is never an obstacle of the path to it, and what is carried is
    // left out of the solids.
    for q in queries {
        for c in &q.carried {
            assert!(q.solids.iter().all(|s| s.name != c.name), "{}", c.name);
        }
    }
    // The same query planned again gives a path: the world's planner found one.
    let times = betr_plan(&found.arms, queries).unwrap();
    assert_eq!(times.solved, queries.len());
}

#[test]
fn the_solids_turn_into_pybullet_shapes_with_their_axes() {
    let at = Isometry3::from_parts(Translation3::new(0.1, 0.2, 0.3), UnitQuaternion::identity());
    let solid = |shape: SharedShape| Solid {
        name: "s".into(),
        pose: at,
        shape,
    };
    let cuboid = pybullet_solid(&solid(SharedShape::cuboid(0.1, 0.2, 0.3))).unwrap();
    assert_eq!(cuboid["kind"], "box");
    assert_eq!(cuboid["sizes"]["half"][1].as_f64().unwrap() as f32, 0.2);
    // parry's cylinder stands along y, PyBullet's along z: turned so that z goes to y.
    let cylinder = pybullet_solid(&solid(SharedShape::cylinder(0.05, 0.02))).unwrap();
    assert_eq!(cylinder["kind"], "cylinder");
    assert!((cylinder["sizes"]["height"].as_f64().unwrap() - 0.1).abs() < 1e-6);
    let q: Vec<f32> = (0..4)
        .map(|i| cylinder["orientation"][i].as_f64().unwrap() as f32)
        .collect();
    let turn = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
    assert!((turn * Vector3::z() - Vector3::y()).norm() < 1e-5);
    // A capsule along x: its middle at the pose, z turned onto x, the height between the
    // hemispheres' centres.
    let capsule = pybullet_solid(&solid(SharedShape::capsule_x(0.1, 0.02))).unwrap();
    assert_eq!(capsule["kind"], "capsule");
    assert!((capsule["sizes"]["height"].as_f64().unwrap() - 0.2).abs() < 1e-6);
    assert!((capsule["position"][0].as_f64().unwrap() - 0.1).abs() < 1e-6);
    // A shape PyBullet has no primitive for is named, not guessed.
    let halfspace = solid(SharedShape::halfspace(Vector3::z_axis()));
    assert!(pybullet_solid(&halfspace).is_none());
}

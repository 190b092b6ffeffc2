//! The YuMi read from its fetched description (the one test path that reaches the package
//! index: the description is installed into the model cache once), checked against
//! Pinocchio's forward kinematics; bad descriptions refused with the file and element.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use super::*;
use crate::model::{Pip, Progress, YUMI_DESCRIPTION, cache_dir, ensure_description};
use nalgebra::Vector3;

struct Quiet;
impl Progress for Quiet {
    fn stage(&mut self, _: &str) {}
    fn bytes(&mut self, _: u64, _: u64) {}
}

/// The YuMi's description in the cache, fetched on first use.
pub(crate) fn yumi_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        ensure_description(&YUMI_DESCRIPTION, &cache_dir(), Pip::DEFAULT, &mut Quiet)
            .unwrap_or_else(|e| panic!("fetching the YuMi's description: {e}"))
    })
}

pub(crate) fn yumi() -> &'static Robot {
    static ROBOT: OnceLock<Robot> = OnceLock::new();
    ROBOT.get_or_init(|| Robot::read(&YUMI_DESCRIPTION, yumi_dir()).unwrap())
}

#[test]
fn the_yumi_has_two_seven_axis_arms_with_their_limits() {
    let robot = yumi();
    // 14 arm joints, 4 gripper fingers, and the fixed ones from the world to the body
    // and from each flange to its gripper.
    assert_eq!(robot.model.joints.len(), 22);
    assert_eq!(robot.model.links[robot.model.root].name, "world");
    let tips: Vec<&str> = robot.arms.iter().map(|a| a.tip.as_str()).collect();
    assert_eq!(tips, ["yumi_link_7_r", "yumi_link_7_l"]);
    for arm in &robot.arms {
        assert_eq!(arm.dof(), 7, "{}", arm.tip);
        assert!(arm.joints.iter().all(|j| j.rotates && j.lower < j.upper));
        // Joint 2's range is not symmetric: its limits are read, not assumed.
        assert!((arm.joints[1].lower + 2.50454747661).abs() < 1e-12);
        assert!((arm.joints[1].upper - 0.759218224618).abs() < 1e-12);
        // The gripper (base and two fingers) rides on the last joint.
        let last = arm.dof() - 1;
        let on_last: Vec<&str> = arm
            .carried
            .iter()
            .filter(|c| c.joint == Some(last))
            .map(|c| robot.model.links[c.link].name.as_str())
            .collect();
        assert_eq!(on_last.len(), 4, "{on_last:?}");
    }
    // Every mesh was found beside the URDF.
    for link in &robot.model.links {
        for e in link.visuals.iter().chain(&link.collisions) {
            if let Geometry::Mesh { path, .. } = &e.geometry {
                assert!(path.starts_with(yumi_dir()) && path.is_file(), "{path:?}");
            }
        }
    }
}

/// What a viewer composes from the joints' transforms (each joint's `transform_at` from
/// its parent link's frame to its child's, root first) is where forward kinematics puts
/// the flange.
#[test]
fn joint_transforms_compose_to_the_flange() {
    let robot = yumi();
    let model = &robot.model;
    for arm in &robot.arms {
        let q: Vec<f64> = arm
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| j.lower + (j.upper - j.lower) * (0.2 + 0.08 * i as f64))
            .collect();
        let tip = model.link(&arm.tip).unwrap();
        let mut at = nalgebra::Isometry3::identity();
        for joint in model.path_to(tip) {
            let value = arm
                .joints
                .iter()
                .position(|j| j.name == joint.name)
                .map_or(joint.resting_value(), |i| q[i]);
            at *= joint.transform_at(value);
        }
        let fk = arm.fk(&q);
        assert!(
            (at.translation.vector - fk.translation.vector).norm() < 1e-9,
            "{}: {at} vs {fk}",
            arm.tip
        );
        assert!(at.rotation.angle_to(&fk.rotation) < 1e-9, "{}", arm.tip);
    }
}

#[derive(serde::Deserialize)]
struct Fixture {
    arms: Vec<FixtureArm>,
}

#[derive(serde::Deserialize)]
struct FixtureArm {
    tip: String,
    joints: Vec<String>,
    cases: Vec<FixtureCase>,
}

#[derive(serde::Deserialize)]
struct FixtureCase {
    q: Vec<f64>,
    translation: [f64; 3],
    rotation: [[f64; 3]; 3],
}

#[test]
fn forward_kinematics_matches_pinocchio() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/motion/yumi_fk.json"),
    )
    .unwrap();
    let fixture: Fixture = serde_json::from_str(&text).unwrap();
    assert_eq!(fixture.arms.len(), 2);
    let mut frames = Vec::new();
    for arm in &fixture.arms {
        let chain = yumi().arm(&arm.tip).unwrap();
        let names: Vec<&str> = chain.joints.iter().map(|j| j.name.as_str()).collect();
        assert_eq!(names, arm.joints);
        assert_eq!(arm.cases.len(), 20);
        for case in &arm.cases {
            assert!(chain.within_limits(&case.q));
            let pose = chain.fk(&case.q);
            let t = pose.translation.vector;
            for i in 0..3 {
                assert!(
                    (t[i] - case.translation[i]).abs() < 1e-6,
                    "{} {:?}: {t}",
                    arm.tip,
                    case.q
                );
            }
            let r = pose.rotation.to_rotation_matrix();
            for (i, row) in case.rotation.iter().enumerate() {
                for (k, v) in row.iter().enumerate() {
                    assert!(
                        (r[(i, k)] - v).abs() < 1e-6,
                        "{} {:?}: {r}",
                        arm.tip,
                        case.q
                    );
                }
            }
            // The last frame is the flange's link.
            chain.frames(&case.q, &mut frames);
            assert!(
                (frames[6] * chain.flange)
                    .translation
                    .vector
                    .relative_eq(&t, 1e-12, 1e-12)
            );
        }
    }
}

/// A two-link arm whose one joint and one mesh can be spoiled.
fn tiny_urdf(dir: &Path, lower: &str, mesh: &str) -> PathBuf {
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(dir.join("meshes/link.stl"), b"").unwrap();
    let urdf = format!(
        r#"<robot name="tiny">
  <link name="base"/>
  <link name="arm">
    <visual><geometry><mesh filename="{mesh}"/></geometry></visual>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="{lower}" upper="1.0" effort="1" velocity="1"/>
  </joint>
</robot>
"#
    );
    let path = dir.join("tiny.urdf");
    std::fs::write(&path, urdf).unwrap();
    path
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("betr-robot-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn bad_descriptions_name_the_file_and_the_element() {
    let dir = scratch("bad");
    let packages = [Package {
        name: "tiny_description",
        dir: &dir,
    }];
    let ok = tiny_urdf(&dir, "-1.0", "package://tiny_description/meshes/link.stl");
    let robot = Robot::from_model(Model::read(&ok, &packages).unwrap()).unwrap();
    assert_eq!(robot.arms[0].tip, "arm");
    assert!((robot.arms[0].fk(&[0.3]).translation.z - 0.1).abs() < 1e-12);

    let inverted = tiny_urdf(&dir, "2.0", "meshes/link.stl");
    let err = Model::read(&inverted, &packages).unwrap_err().to_string();
    assert!(
        err.contains("tiny.urdf")
            && err.contains("joint \"shoulder\"")
            && err.contains("lower limit 2"),
        "{err}"
    );

    let missing = tiny_urdf(&dir, "-1.0", "package://tiny_description/meshes/gone.stl");
    let err = Model::read(&missing, &packages).unwrap_err().to_string();
    assert!(
        err.contains("tiny.urdf")
            && err.contains("link \"arm\"")
            && err.contains("meshes/gone.stl"),
        "{err}"
    );

    let elsewhere = tiny_urdf(&dir, "-1.0", "package://other/meshes/link.stl");
    let err = Model::read(&elsewhere, &packages).unwrap_err().to_string();
    assert!(err.contains("package \"other\""), "{err}");

    let broken = dir.join("broken.urdf");
    std::fs::write(&broken, "<robot name=\"x\"><link name=\"a\"></robot>").unwrap();
    let err = Model::read(&broken, &packages).unwrap_err().to_string();
    assert!(
        err.contains("broken.urdf") && err.contains("not a readable URDF"),
        "{err}"
    );

    let err = Model::read(&dir.join("absent.urdf"), &packages)
        .unwrap_err()
        .to_string();
    assert!(err.contains("absent.urdf"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A pose where the flange points straight down (tool z along world -z).
fn from_above(x: f64, y: f64, z: f64) -> nalgebra::Isometry3<f64> {
    nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(x, y, z),
        nalgebra::UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0),
    )
}

fn middle(chain: &Chain) -> Vec<f64> {
    chain
        .joints
        .iter()
        .map(|j| (j.lower + j.upper) / 2.0)
        .collect()
}

fn assert_reaches(chain: &Chain, q: &[f64], target: &nalgebra::Isometry3<f64>) {
    assert!(chain.within_limits(q), "{q:?}");
    let got = chain.fk(q);
    let dp = (got.translation.vector - target.translation.vector).norm();
    let da = got.rotation.angle_to(&target.rotation);
    assert!(
        dp < 1e-4 && da < 1e-3,
        "{} off by {dp} m, {da} rad",
        chain.tip
    );
}

#[test]
fn inverse_kinematics_reaches_poses_forward_kinematics_gives() {
    let robot = yumi();
    let options = IkOptions::default();
    for (a, arm) in robot.arms.iter().enumerate() {
        let mut rng = SplitMix::new(a as u64);
        for _ in 0..8 {
            let q: Vec<f64> = arm
                .joints
                .iter()
                .map(|j| j.lower + (0.1 + 0.8 * rng.unit()) * (j.upper - j.lower))
                .collect();
            let target = arm.fk(&q);
            let (solution, _, _) = solve(arm, &target, &middle(arm), &options)
                .unwrap_or_else(|| panic!("{}: no solution for {q:?}", arm.tip));
            assert_reaches(arm, &solution, &target);
        }
    }
}

#[test]
fn a_grasp_from_above_goes_to_the_nearer_arm() {
    let robot = yumi();
    let starts: Vec<Vec<f64>> = robot.arms.iter().map(middle).collect();
    let options = IkOptions::default();
    for (y, tip) in [(0.2, "yumi_link_7_l"), (-0.2, "yumi_link_7_r")] {
        let target = from_above(0.4, y, 0.15);
        let found = nearest_arm_solution(&robot.arms, &target, &starts, &options).unwrap();
        let arm = &robot.arms[found.arm];
        assert_eq!(arm.tip, tip);
        assert_reaches(arm, &found.q, &target);
        // Same query, same answer.
        assert_eq!(
            nearest_arm_solution(&robot.arms, &target, &starts, &options).unwrap(),
            found
        );
    }
}

#[test]
fn the_spare_axis_keeps_the_arm_near_where_it_starts() {
    let arm = &yumi().arms[0];
    let options = IkOptions::default();
    let start = vec![0.3, -1.2, -1.0, 0.4, 0.2, 0.8, 0.1];
    let target = arm.fk(&start);
    // Already there: nothing moves.
    let (same, _, _) = solve(arm, &target, &start, &options).unwrap();
    assert_eq!(same, start);
    // The elbow turned away by 0.3 rad: the flange is elsewhere, and the solution from
    // there stays near that elbow rather than jumping to another branch.
    let mut turned = start.clone();
    turned[2] += 0.3;
    let (q, _, _) = solve(arm, &target, &turned, &options).unwrap();
    assert_reaches(arm, &q, &target);
    let moved: f64 = q
        .iter()
        .zip(&turned)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(moved < 0.6, "{q:?} from {turned:?}");
}

#[test]
fn an_unreachable_pose_is_named() {
    let robot = yumi();
    let starts: Vec<Vec<f64>> = robot.arms.iter().map(middle).collect();
    let options = IkOptions {
        starts: 4,
        ..IkOptions::default()
    };
    let err = nearest_arm_solution(&robot.arms, &from_above(2.0, 0.0, 0.3), &starts, &options)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("(2.000, 0.000, 0.300) m") && err.contains("yumi_link_7_r and yumi_link_7_l"),
        "{err}"
    );
}

#[test]
fn each_link_shape_contains_its_mesh() {
    let robot = yumi();
    let shapes = RobotShapes::new(&robot.model, &robot.arms).unwrap();
    // The torso: a few boxes, each a part of the body, together far tighter than one box.
    assert!((2..=6).contains(&shapes.torso.len()), "{:?}", shapes.torso);
    assert!(shapes.torso.iter().all(|s| s.name == "yumi_body"));
    let body = &robot.model.links[shapes.torso[0].link];
    let Geometry::Mesh { path, .. } = &body.collisions[0].geometry else {
        panic!("the body is a mesh");
    };
    let vertices = read_stl(path).unwrap();
    let (lo, hi) = vertices.iter().fold(
        (
            Vector3::repeat(f32::INFINITY),
            Vector3::repeat(f32::NEG_INFINITY),
        ),
        |(lo, hi), v| (lo.inf(&v.coords), hi.sup(&v.coords)),
    );
    let one_box: f32 = (hi - lo).iter().product();
    let stacked: f32 = shapes
        .torso
        .iter()
        .map(|s| {
            let h = s
                .shape
                .as_cuboid()
                .expect("the torso's shapes are boxes")
                .half_extents;
            8.0 * h.x * h.y * h.z
        })
        .sum();
    assert!(stacked < 0.6 * one_box, "{stacked} m³ against {one_box} m³");
    let arms: Vec<&LinkShape> = shapes.arms.iter().flatten().flatten().collect();
    // Every one of the ten links each arm carries has a shape; bent ones a few boxes.
    assert!(
        shapes
            .arms
            .iter()
            .all(|arm| arm.len() == 10 && arm.iter().all(|link| !link.is_empty()))
    );
    assert!(arms.len() > 2 * 10, "no link is stacked boxes");
    // Every link's mesh — its corners and points spread over every triangle — lies in
    // one of the link's shapes.
    let mut links: Vec<usize> = shapes
        .torso
        .iter()
        .chain(arms.iter().copied())
        .map(|s| s.link)
        .collect();
    links.dedup();
    for link in links {
        let own: Vec<&LinkShape> = shapes
            .torso
            .iter()
            .chain(arms.iter().copied())
            .filter(|s| s.link == link)
            .collect();
        let link = &robot.model.links[link];
        for element in &link.collisions {
            let Geometry::Mesh { path, .. } = &element.geometry else {
                panic!("{}: the YuMi's links are meshes", link.name);
            };
            let origin = element.origin.cast::<f32>();
            for t in read_stl_triangles(path).unwrap() {
                for (a, b) in [
                    (0.0, 0.0),
                    (1.0, 0.0),
                    (0.0, 1.0),
                    (0.5, 0.5),
                    (0.5, 0.0),
                    (0.0, 0.5),
                    (0.25, 0.25),
                    (1.0 / 3.0, 1.0 / 3.0),
                ] {
                    let p = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
                    let inside = origin * p;
                    let (d, local, holder) = own
                        .iter()
                        .map(|s| {
                            let local = s.local.inverse() * inside;
                            (s.shape.distance_to_local_point(&local, true), local, s)
                        })
                        .min_by(|a, b| a.0.total_cmp(&b.0))
                        .unwrap();
                    // The shapes hold the coarse mesh exactly (to rounding), and the ball
                    // of the quick first test holds its shape's part.
                    assert!(
                        d < 1e-5,
                        "{}: {} is {d} m outside",
                        link.name,
                        path.display()
                    );
                    assert!((local - holder.center).norm() <= holder.radius + 1e-4);
                }
            }
        }
    }
}

//! The view of the YuMi's real arms: drawn from the robot's description, moving between
//! ticks, holding what they grasp, and marking what blocked them.

use super::*;

/// Scenario 1 before and after its repair in the execution world with the YuMi's real
/// arms, streamed to memory: the robot is its meshes and joints (no boxes), every motion's
/// way is drawn between the ticks on the `motion` timeline, the failing grasp names the
/// red cube as what blocked it, and the way ends where the arm now is.
#[test]
fn real_arms_are_drawn_from_the_description_and_move_between_ticks() {
    crate::robot::tests::yumi_dir();
    let scenario = scenario1();
    let planning = crate::world::load(&scenario).unwrap();
    let execution = crate::world::load_execution(&scenario, None).unwrap();
    assert_eq!(execution.notice, None, "the arms are available");
    let planner = Planner::new(&scenario.domain);
    let goal = scenario.goal.clone().unwrap();
    let plan = planner.plan(&goal.to_dnf(), planning.as_ref()).unwrap();
    let Outcome::ActionFailed { node, .. } = plan.outcome else {
        panic!("scenario 1 should fail before repair: {:?}", plan.outcome);
    };
    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    let mut viz = Viz::with_stream(rec);
    let mut exec = execution.world.fork();
    let before = run_streamed(&plan.tree, exec.as_mut(), &scenario.domain, &mut viz);
    assert!(matches!(before.end, RunEnd::Failure { action: Some(_) }));
    let motion = CellWorld::motion_of(exec.as_ref()).expect("the refused grasp");
    assert_eq!(motion.length, None);
    assert_eq!(motion.blocker.as_deref(), Some("red cube"));
    assert!(motion.attempts >= 1 && motion.seconds > 0.0, "{motion:?}");

    let fix = scenario.parse_goal(&scenario.expected_fix[0]).unwrap();
    let conditions = fix.to_dnf().0[0].clone();
    let repaired = planner
        .repair(plan.tree, node, &conditions, planning.as_ref())
        .unwrap();
    let mut exec = execution.world.fork();
    let after = run_streamed(&repaired.tree, exec.as_mut(), &scenario.domain, &mut viz);
    assert_eq!(after.end, RunEnd::Success);
    let scene = CellWorld::scene_of(exec.as_ref()).unwrap();
    let motion = scene.motion.clone().expect("the last motion");
    assert!(motion.length.is_some_and(|l| l > 0.0), "{motion:?}");
    assert_eq!(motion.blocker, None);
    let arms = scene.arms.clone().expect("real arms");
    let path = arms.path.clone().expect("the last motion's way");
    assert_eq!(path.joints.len(), path.tool.len());
    assert_eq!(
        path.joints.last(),
        Some(&robot::values_now(&arms)[path.arm]),
        "the way ends where the arm is"
    );
    for pair in path.joints.windows(2) {
        let widest = pair[0]
            .iter()
            .zip(&pair[1])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(widest <= 0.05 + 1e-9, "a jump of {widest} rad");
    }
    viz.stream().flush_blocking().unwrap();

    let logged = decode(storage.take());
    let has = |path: &str, component: &str| {
        logged
            .components
            .get(path)
            .is_some_and(|c| c.contains(component))
    };
    assert!(!logged.components.contains_key(scene::ROBOT_TORSO));
    assert!(!logged.components.contains_key(scene::ROBOT_ARMS));
    // The importer's output: the robot's root frame, each link's mesh in its frame (the
    // coarse ones by default, as visual geometry), and every joint at value 0 in
    // `tf_static`.
    assert!(has(
        "world/robot/yumi/visual_geometries/yumi_link_3_l/visual_0",
        "Asset3D:blob"
    ));
    assert!(has(
        "world/robot/yumi/visual_geometries/yumi_link_3_l/visual_0",
        "CoordinateFrame:frame"
    ));
    assert!(has("world/robot/yumi", "CoordinateFrame:frame"));
    assert!(has("tf_static", "Transform3D:child_frame"));
    assert!(!logged.steps.contains_key("tf_static"), "static");
    assert!(has(robot::ROBOT_DESCRIPTION, "TextDocument:text"));
    assert!(has("world/robot/yumi/base", "Transform3D:parent_frame"));
    assert!(has(robot::GRIPPER_PATH, "LineStrips3D:strips"));
    // Each left-arm joint at every step of the scene, and many more values of `motion`
    // (the way between the ticks the arm moved in).
    let joint = "world/robot/yumi/joints/yumi_joint_2_l";
    assert!(has(joint, "Transform3D:child_frame"));
    let steps = logged.steps[joint].len();
    let motions = logged.motions[joint].len();
    assert_eq!(steps as i64, viz.steps() + 1, "step 0 and every tick");
    assert!(
        motions > 5 * steps,
        "{motions} motion values for {steps} steps"
    );
    // The red cube the arm picks up and puts on the table is drawn along the way too.
    let cube = "world/solids/red_cube";
    assert!(
        logged.motions[cube].len() > 2 * logged.steps[cube].len(),
        "{} motion values, {} steps",
        logged.motions[cube].len(),
        logged.steps[cube].len()
    );
    // The fingers and fixed joints are left at the importer's static transforms.
    assert!(
        !logged
            .components
            .contains_key("world/robot/yumi/joints/gripper_l_joint")
    );
}

/// The YuMi's description drawn once into a memory recording with `meshes`: what was
/// logged, and the bytes of the recording's messages.
fn description_logged(meshes: RobotMeshes) -> (Logged, usize) {
    crate::robot::tests::yumi_dir();
    let scenario = scenario1();
    let world = crate::world::load_execution(&scenario, None).unwrap().world;
    let arms = CellWorld::scene_of(world.as_ref()).unwrap().arms.unwrap();
    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    robot::log_description(&rec, &arms, meshes).unwrap();
    rec.flush_blocking().unwrap();
    let msgs = storage.take();
    let bytes = msgs
        .iter()
        .map(|m| match m {
            LogMsg::ArrowMsg(_, arrow) => arrow.batch.get_array_memory_size(),
            _ => 0,
        })
        .sum();
    (decode(msgs), bytes)
}

/// The importer is given the URDF with its `package://` paths made relative to the URDF's
/// folder: every mesh the URDF names is found from there, and the cached file is left as
/// it was fetched.
#[test]
fn the_importer_finds_the_meshes_from_the_urdf_folder() {
    crate::robot::tests::yumi_dir();
    let scenario = scenario1();
    let world = crate::world::load_execution(&scenario, None).unwrap().world;
    let arms = CellWorld::scene_of(world.as_ref()).unwrap().arms.unwrap();
    let model = arms.model.as_ref();
    let text = std::fs::read_to_string(&model.file).unwrap();
    let urdf_dir = model.file.parent().unwrap();
    assert!(text.contains("package://yumi_description/meshes/coarse/body.stl"));
    let local = robot::with_local_packages(&text, urdf_dir, &model.packages);
    assert!(!local.contains("package://"), "every package path replaced");
    let meshes: Vec<&str> = local
        .split("<mesh filename=\"")
        .skip(1)
        .filter_map(|rest| rest.split('"').next())
        .collect();
    assert!(meshes.len() >= 40, "{meshes:?}");
    for mesh in &meshes {
        assert!(mesh.starts_with("../meshes/"), "{mesh}");
        assert!(urdf_dir.join(mesh).is_file(), "{mesh} from {urdf_dir:?}");
    }
    let (rec, _storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    robot::log_description(&rec, &arms, RobotMeshes::Coarse).unwrap();
    rec.flush_blocking().unwrap();
    assert_eq!(std::fs::read_to_string(&model.file).unwrap(), text);
}

/// The coarse drawing gives the importer each link's collision mesh as its visual one
/// (in the visual material's colour), the detailed one the URDF's visual meshes; neither
/// has collision elements, so each link is drawn once, and the detailed recording is many
/// times bigger.
#[test]
fn coarse_and_detailed_meshes_are_both_drawn_by_the_importer() {
    let (coarse, coarse_bytes) = description_logged(RobotMeshes::Coarse);
    let (detailed, detailed_bytes) = description_logged(RobotMeshes::Detailed);
    let mut links = vec!["yumi_body".to_string()];
    for side in ["l", "r"] {
        links.extend((1..=7).map(|n| format!("yumi_link_{n}_{side}")));
        for part in ["base", "finger_r", "finger_l"] {
            links.push(format!("gripper_{side}_{part}"));
        }
    }
    let robot = "world/robot/yumi";
    for link in &links {
        let visual = format!("{robot}/visual_geometries/{link}/visual_0");
        for (logged, kind) in [(&coarse, "coarse"), (&detailed, "detailed")] {
            let comps = logged.components.get(&visual);
            assert!(
                comps.is_some_and(|c| c.contains("Asset3D:blob")
                    && c.contains("Asset3D:albedo_factor")
                    && c.contains("CoordinateFrame:frame")),
                "{kind}: {visual}: {comps:?}"
            );
        }
    }
    for logged in [&coarse, &detailed] {
        assert!(
            !logged
                .components
                .keys()
                .any(|p| p.contains("collision_geometries")),
            "each link drawn once"
        );
    }
    assert!(
        detailed_bytes > 8 * coarse_bytes,
        "detailed {detailed_bytes} B, coarse {coarse_bytes} B"
    );
}

/// Both kinds keep the robot's links, joints and materials and leave no collision
/// element; the coarse one draws the collision mesh in the visual material, the detailed
/// one keeps the visual mesh; a text that is no URDF is refused.
#[test]
fn the_importer_is_given_one_kind_of_mesh_per_link() {
    let text = r#"<robot name="tiny">
  <material name="Grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="base">
    <visual><geometry><mesh filename="meshes/base.stl"/></geometry><material name="Grey"/></visual>
    <collision><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><mesh filename="meshes/coarse/base.stl"/></geometry></collision>
  </link>
  <link name="tip">
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>
  </link>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>"#;
    let mesh_of = |visual: &urdf_rs::Visual| match &visual.geometry {
        urdf_rs::Geometry::Mesh { filename, .. } => filename.clone(),
        other => panic!("{other:?}"),
    };
    for (meshes, file, z) in [
        (RobotMeshes::Coarse, "meshes/coarse/base.stl", 0.1),
        (RobotMeshes::Detailed, "meshes/base.stl", 0.0),
    ] {
        let given = robot::one_kind_of_mesh(text, meshes).unwrap();
        let robot = urdf_rs::read_from_string(&given).unwrap();
        assert_eq!(robot.joints.len(), 1);
        assert_eq!(robot.materials.len(), 1);
        let base = &robot.links[0];
        assert!(base.collision.is_empty(), "{meshes:?}");
        assert_eq!(base.visual.len(), 1);
        assert_eq!(mesh_of(&base.visual[0]), file);
        assert_eq!(base.visual[0].origin.xyz.0, [0.0, 0.0, z]);
        assert_eq!(
            base.visual[0].material.as_ref().map(|m| m.name.as_str()),
            Some("Grey")
        );
        let tip = &robot.links[1];
        assert!(matches!(
            tip.visual[0].geometry,
            urdf_rs::Geometry::Box { .. }
        ));
    }
    assert!(robot::one_kind_of_mesh("<robot", RobotMeshes::Coarse).is_err());
}

/// With real arms a grasped solid is drawn in the hand: at the tool of the arm's joint
/// values once the grasp completes (the arm back above where it grasped), not where it
/// lay on the table.
#[test]
fn a_solid_grasped_by_a_real_arm_is_drawn_in_its_hand() {
    use crate::domain::ActionCall;
    use crate::world::Step;
    crate::robot::tests::yumi_dir();
    let scenario = scenario1();
    let mut world = crate::world::load_execution(&scenario, None).unwrap().world;
    let centre = |scene: &crate::world::cell::snapshot::SceneSnapshot| {
        let red = scene.solids.iter().find(|s| s.name == "red cube").unwrap();
        red.parts[0].pose.translation.vector
    };
    let lying = centre(&CellWorld::scene_of(world.as_ref()).unwrap());
    let grasp = ActionCall::parse("grasp \"red cube\"").unwrap();
    let mut started = true;
    loop {
        match world.step(&grasp, started) {
            Step::Running => started = false,
            Step::Success => break,
            Step::Failure(e) => panic!("the grasp failed: {e}"),
        }
    }
    let scene = CellWorld::scene_of(world.as_ref()).unwrap();
    let held = centre(&scene);
    let path = scene.arms.unwrap().path.unwrap();
    let tool = nalgebra::Vector3::from(*path.tool.last().unwrap());
    assert!(
        (held - tool).norm() < 0.05,
        "in the hand: {held:?}, tool at {tool:?}"
    );
    assert!(held.z > lying.z + 0.03, "lifted: {held:?} from {lying:?}");
}

/// A link of the robot that blocked a motion (the torso here) is marked in its own
/// frame; a solid's name is not a link, and no blocker clears the mark.
#[test]
fn a_blocking_link_is_marked_in_its_frame() {
    crate::robot::tests::yumi_dir();
    let scenario = scenario1();
    let world = crate::world::load_execution(&scenario, None).unwrap().world;
    let mut scene = CellWorld::scene_of(world.as_ref()).unwrap();
    let arms = scene.arms.clone().expect("real arms");
    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    robot::log_blocking_link(&rec, &arms, Some("yumi_body")).unwrap();
    rec.flush_blocking().unwrap();
    let logged = decode(storage.take());
    let mark = &logged.components["world/robot/yumi/blocked_by"];
    assert!(mark.contains("Points3D:labels"), "{mark:?}");
    assert!(mark.contains("CoordinateFrame:frame"), "{mark:?}");

    scene.motion = Some(crate::world::cell::snapshot::MotionView {
        arm: "yumi_link_7_l".into(),
        length: None,
        seconds: 0.1,
        attempts: 2,
        blocker: Some("red cube".into()),
    });
    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    let mut viz = Viz::with_stream(rec);
    viz.scene(&scene);
    viz.stream().flush_blocking().unwrap();
    let logged = decode(storage.take());
    let mark = &logged.components["world/robot/yumi/blocked_by"];
    assert!(
        !mark.contains("Points3D:labels"),
        "a solid is no link: {mark:?}"
    );
    assert!(
        logged.components["world/solids/red_cube"].contains("Boxes3D:labels"),
        "the solid is marked instead"
    );
}

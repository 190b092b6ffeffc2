//! The robot drawn by rerun's own URDF importer, given the description's URDF once per
//! recording (static): an entity named after the robot in its root link's frame, each
//! link's meshes in the link's frame, and every joint's transform at value 0 from its
//! parent link's frame to its child's (the importer's `tf_static`). The arms' joints are
//! logged here, with the importer's frame names (the link names), at every tick, and
//! between two ticks in which an arm moved, along the way it went on the `motion` timeline;
//! a transform logged on the timelines overrides the importer's static one for that frame.
//!
//! The importer finds `package://` meshes only through ROS's environment variables, but
//! reads a relative mesh path from the folder of the URDF it is told it reads, so it is
//! given the URDF's text with the packages' paths made relative to that folder, in memory
//! (the cached description stays as it was fetched).

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Isometry3, UnitQuaternion};
use rerun::{
    Clear, Color, CoordinateFrame, EntityPath, EntityPathPart, LineStrips3D, Points3D, Quaternion,
    RecordingStream, RecordingStreamResult, TextDocument, Transform3D,
};

use crate::robot::{JointKind, Model};
use crate::world::cell::snapshot::ArmsView;

/// Where the robot's entities hang (the robot's name below it).
pub const ROBOT_ROOT: &str = "world/robot";
/// The tool's way through the last motion.
pub const GRIPPER_PATH: &str = "world/robot/gripper_path";
/// The URDF the robot was drawn from, as text (where ROS keeps it too); outside `world`,
/// so the 3D view does not try to draw it.
pub const ROBOT_DESCRIPTION: &str = "robot_description";
/// The frame of the 3D view's origin entity (`world`), which the robot's root link
/// hangs from.
pub const WORLD_FRAME: &str = "tf#/world";

/// Largest number of configurations drawn between two ticks: a longer way is drawn at
/// every n-th so a motion stays a few seconds of scrubbing.
const MOST_SUB_STEPS: usize = 120;

/// The robot's entity, as the importer names it: its URDF name below [`ROBOT_ROOT`].
fn robot_path(model: &Model) -> EntityPath {
    EntityPath::from(ROBOT_ROOT) / EntityPathPart::new(model.name.as_str())
}

fn joint_path(model: &Model, joint: &str) -> EntityPath {
    robot_path(model) / EntityPathPart::new("joints") / EntityPathPart::new(joint)
}

fn transform(pose: &Isometry3<f64>, parent: &str, child: &str) -> Transform3D {
    let t = pose.translation.vector;
    let q: UnitQuaternion<f32> = pose.rotation.cast();
    Transform3D::from_translation_rotation(
        [t.x as f32, t.y as f32, t.z as f32],
        Quaternion::from_xyzw([q.i, q.j, q.k, q.w]),
    )
    .with_parent_frame(parent)
    .with_child_frame(child)
}

/// `text` with every `package://NAME/` of a package in `packages` turned into the path of
/// that package's folder relative to `urdf_dir` (or its absolute path when the package
/// is not a folder above the URDF).
pub(super) fn with_local_packages(
    text: &str,
    urdf_dir: &Path,
    packages: &[(String, std::path::PathBuf)],
) -> String {
    let mut out = text.to_string();
    for (name, dir) in packages {
        let local = match urdf_dir.strip_prefix(dir) {
            Ok(below) => "../".repeat(below.components().count()),
            Err(_) => format!("{}/", dir.display()),
        };
        out = out.replace(&format!("package://{name}/"), &local);
    }
    out
}

/// Which of a link's meshes the 3D view draws: one kind, so each link is drawn once (the
/// importer would otherwise draw both, one around the other).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum RobotMeshes {
    /// Its collision meshes (the coarse ones of a description that has both) in the colour
    /// of its visual material: the YuMi's take 2.7 MB of a recording.
    #[default]
    Coarse,
    /// Its visual meshes (the detailed ones): the YuMi's take 29 MB of a recording.
    Detailed,
}

impl std::str::FromStr for RobotMeshes {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "coarse" => Ok(RobotMeshes::Coarse),
            "detailed" => Ok(RobotMeshes::Detailed),
            _ => Err(format!("{s:?}: expected `coarse` or `detailed`")),
        }
    }
}

/// The URDF `text` as the importer is given it for `meshes`: no collision elements left,
/// and for [`RobotMeshes::Coarse`] each link's collision elements drawn in place of its
/// visual ones, in the colour of its first visual material.
pub(super) fn one_kind_of_mesh(
    text: &str,
    meshes: RobotMeshes,
) -> Result<String, urdf_rs::UrdfError> {
    let mut robot = urdf_rs::read_from_string(text)?;
    for link in &mut robot.links {
        let collisions = std::mem::take(&mut link.collision);
        if meshes == RobotMeshes::Detailed || collisions.is_empty() {
            continue;
        }
        let material = link.visual.iter().find_map(|v| v.material.clone());
        link.visual = collisions
            .into_iter()
            .map(|c| urdf_rs::Visual {
                name: c.name,
                origin: c.origin,
                geometry: c.geometry,
                material: material.clone(),
            })
            .collect();
    }
    urdf_rs::write_to_string(&robot)
}

/// The static part: the URDF's text at [`ROBOT_DESCRIPTION`], and the robot drawn by
/// rerun's URDF importer below [`ROBOT_ROOT`] with the meshes `meshes` says.
pub fn log_description(
    rec: &RecordingStream,
    view: &ArmsView,
    meshes: RobotMeshes,
) -> RecordingStreamResult<()> {
    let model = view.model.as_ref();
    let urdf = match std::fs::read_to_string(&model.file) {
        Ok(urdf) => urdf,
        Err(e) => {
            tracing::warn!(urdf = %model.file.display(), error = %e, "cannot read the robot's URDF");
            return Ok(());
        }
    };
    rec.log_static(ROBOT_DESCRIPTION, &TextDocument::new(urdf.as_str()))?;
    let urdf_dir = model.file.parent().unwrap_or(Path::new("."));
    let local = with_local_packages(&urdf, urdf_dir, &model.packages);
    let given = match one_kind_of_mesh(&local, meshes) {
        Ok(text) => text,
        Err(e) => {
            tracing::warn!(urdf = %model.file.display(), error = %e, "cannot read the robot's URDF");
            return Ok(());
        }
    };
    rec.log_file_from_contents(
        &model.file,
        Cow::Owned(given.into_bytes()),
        Some(EntityPath::from(ROBOT_ROOT)),
        true,
    )
}

/// The robot's root link in the world (hung from the frame of the view's origin).
pub fn log_base(rec: &RecordingStream, view: &ArmsView) -> RecordingStreamResult<()> {
    let model = view.model.as_ref();
    let root = &model.links[model.root].name;
    rec.log(
        robot_path(model) / EntityPathPart::new("base"),
        &transform(&view.base.cast(), WORLD_FRAME, root),
    )
}

/// The arms' joints at `values` (per arm, in the order of [`ArmsView::joints`]).
pub fn log_joints(
    rec: &RecordingStream,
    view: &ArmsView,
    values: &[Vec<f64>],
) -> RecordingStreamResult<()> {
    let model = view.model.as_ref();
    let by_name: HashMap<&str, &crate::robot::Joint> =
        model.joints.iter().map(|j| (j.name.as_str(), j)).collect();
    for (arm, q) in view.joints.iter().zip(values) {
        for ((name, _), v) in arm.iter().zip(q) {
            let Some(joint) = by_name.get(name.as_str()) else {
                continue;
            };
            if joint.kind == JointKind::Fixed {
                continue;
            }
            rec.log(
                joint_path(model, name),
                &transform(
                    &joint.transform_at(*v),
                    &model.links[joint.parent].name,
                    &model.links[joint.child].name,
                ),
            )?;
        }
    }
    Ok(())
}

/// The arms' joint values now, per arm.
pub fn values_now(view: &ArmsView) -> Vec<Vec<f64>> {
    view.joints
        .iter()
        .map(|arm| arm.iter().map(|(_, v)| *v).collect())
        .collect()
}

/// The configurations to draw between `before` (the arms' values last drawn) and now,
/// each with its index on the last motion's way: that way when it starts where the arm
/// was and ends where it is now (the motion happened since), else none.
pub fn sub_steps(view: &ArmsView, before: &[Vec<f64>]) -> Vec<(usize, Vec<Vec<f64>>)> {
    let Some(path) = &view.path else {
        return Vec::new();
    };
    let now = values_now(view);
    let close = |a: &[f64], b: &[f64]| {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
    };
    let (Some(was), Some(is), Some(first), Some(last)) = (
        before.get(path.arm),
        now.get(path.arm),
        path.joints.first(),
        path.joints.last(),
    ) else {
        return Vec::new();
    };
    if close(was, is) || !close(was, first) || !close(is, last) {
        return Vec::new();
    }
    let every = path.joints.len().div_ceil(MOST_SUB_STEPS).max(1);
    path.joints
        .iter()
        .enumerate()
        .step_by(every)
        .skip(1)
        .map(|(index, q)| {
            let mut values = now.clone();
            values[path.arm].clone_from(q);
            (index, values)
        })
        .collect()
}

/// The tool's way through the last motion, or nothing.
pub fn log_gripper_path(rec: &RecordingStream, view: &ArmsView) -> RecordingStreamResult<()> {
    match view.path.as_ref().filter(|p| p.tool.len() > 1) {
        Some(p) => rec.log(
            GRIPPER_PATH,
            &LineStrips3D::new([p.tool.clone()])
                .with_colors([Color::from_unmultiplied_rgba(255, 170, 0, 255)])
                .with_radii([0.004]),
        ),
        None => rec.log(GRIPPER_PATH, &Clear::flat()),
    }
}

/// A link of the robot that blocked the last motion (the arm met the torso or the other
/// arm): a red mark with a label in the link's frame; nothing otherwise.
pub fn log_blocking_link(
    rec: &RecordingStream,
    view: &ArmsView,
    blocker: Option<&str>,
) -> RecordingStreamResult<()> {
    let model = view.model.as_ref();
    let entity = robot_path(model) / EntityPathPart::new("blocked_by");
    match blocker.filter(|b| model.link(b).is_some()) {
        Some(link) => {
            rec.log(entity.clone(), &CoordinateFrame::new(link))?;
            rec.log(
                entity,
                &Points3D::new([[0.0, 0.0, 0.0]])
                    .with_radii([0.04])
                    .with_colors([Color::from_unmultiplied_rgba(230, 40, 40, 255)])
                    .with_labels([format!("{link} blocks the arm")]),
            )
        }
        None => rec.log(entity, &Clear::flat()),
    }
}

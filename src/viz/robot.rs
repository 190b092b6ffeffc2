//! The robot drawn from its description, laid out the way rerun's own URDF importer lays
//! a robot out, so the viewer's frame tools read it the same: an entity named after the
//! robot in its root link's frame, each link's meshes under
//! `collision_geometries/mesh/LINK/collision_N` in the link's frame (an `InstancePoses3D`
//! for the element's origin, an `Asset3D` with the STL), and every joint as a
//! `Transform3D` from its parent link's frame to its child's. Meshes and fixed joints are
//! logged once (static); the arms' joints at every tick, and between two ticks in which an
//! arm moved, along the way it went on the `motion` timeline.
//!
//! The coarse collision meshes are drawn, in the colour of the link's visual material: the
//! detailed visual meshes of the YuMi weigh 58 MB, which every recording would carry.

use std::collections::HashMap;

use nalgebra::{Isometry3, UnitQuaternion};
use rerun::{
    Asset3D, Clear, Color, CoordinateFrame, InstancePoses3D, LineStrips3D, Points3D, Quaternion,
    RecordingStream, RecordingStreamResult, Rgba32, TextDocument, Transform3D,
};

use crate::robot::{Geometry, JointKind, Model};
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

fn robot_path(model: &Model) -> String {
    format!("{ROBOT_ROOT}/{}", super::scene::slug(&model.name))
}

fn joint_path(model: &Model, joint: &str) -> String {
    format!("{}/joints/{}", robot_path(model), super::scene::slug(joint))
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

/// The static part: the URDF's text, the root's frame, every link's meshes in its frame,
/// and the joints no arm moves (fixed ones, and the fingers at their resting value).
pub fn log_description(rec: &RecordingStream, view: &ArmsView) -> RecordingStreamResult<()> {
    let model = view.model.as_ref();
    match std::fs::read_to_string(&model.file) {
        Ok(urdf) => rec.log_static(ROBOT_DESCRIPTION, &TextDocument::new(urdf))?,
        Err(e) => {
            tracing::warn!(urdf = %model.file.display(), error = %e, "cannot read the robot's URDF");
        }
    }
    let root = &model.links[model.root].name;
    rec.log_static(robot_path(model), &CoordinateFrame::new(root.as_str()))?;
    for link in &model.links {
        let colour = link
            .visuals
            .iter()
            .find_map(|v| v.colour)
            .unwrap_or([0.7, 0.7, 0.72, 1.0]);
        for (i, element) in link.collisions.iter().enumerate() {
            let Geometry::Mesh { path, scale } = &element.geometry else {
                continue;
            };
            let asset = match Asset3D::from_file_path(path) {
                Ok(a) => a.with_albedo_factor(Rgba32::from_linear_unmultiplied_rgba_f32(
                    colour[0], colour[1], colour[2], colour[3],
                )),
                Err(e) => {
                    tracing::warn!(mesh = %path.display(), error = %e, "cannot read a link's mesh");
                    continue;
                }
            };
            let entity = format!(
                "{}/collision_geometries/mesh/{}/collision_{i}",
                robot_path(model),
                super::scene::slug(&link.name)
            );
            let t = element.origin.translation.vector;
            let q: UnitQuaternion<f32> = element.origin.rotation.cast();
            rec.log_static(
                entity.as_str(),
                &InstancePoses3D::new()
                    .with_translations([[t.x as f32, t.y as f32, t.z as f32]])
                    .with_quaternions([Quaternion::from_xyzw([q.i, q.j, q.k, q.w])])
                    .with_scales([[scale.x as f32, scale.y as f32, scale.z as f32]]),
            )?;
            rec.log_static(entity.as_str(), &CoordinateFrame::new(link.name.as_str()))?;
            rec.log_static(entity.as_str(), &asset)?;
        }
    }
    let driven: Vec<&str> = view
        .joints
        .iter()
        .flatten()
        .map(|(name, _)| name.as_str())
        .collect();
    for joint in &model.joints {
        if driven.contains(&joint.name.as_str()) {
            continue;
        }
        let value = match &joint.mimic {
            Some((other, multiplier, offset)) => model
                .joints
                .iter()
                .find(|j| j.name == *other)
                .map_or(0.0, |j| multiplier * j.resting_value() + offset),
            None => joint.resting_value(),
        };
        rec.log_static(
            joint_path(model, &joint.name),
            &transform(
                &joint.transform_at(value),
                &model.links[joint.parent].name,
                &model.links[joint.child].name,
            ),
        )?;
    }
    Ok(())
}

/// The robot's root link in the world (hung from the frame of the view's origin).
pub fn log_base(rec: &RecordingStream, view: &ArmsView) -> RecordingStreamResult<()> {
    let model = view.model.as_ref();
    let root = &model.links[model.root].name;
    rec.log(
        format!("{}/base", robot_path(model)),
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
    let entity = format!("{}/blocked_by", robot_path(model));
    match blocker.filter(|b| model.link(b).is_some()) {
        Some(link) => {
            rec.log(entity.as_str(), &CoordinateFrame::new(link))?;
            rec.log(
                entity.as_str(),
                &Points3D::new([[0.0, 0.0, 0.0]])
                    .with_radii([0.04])
                    .with_colors([Color::from_unmultiplied_rgba(230, 40, 40, 255)])
                    .with_labels([format!("{link} blocks the arm")]),
            )
        }
        None => rec.log(entity.as_str(), &Clear::flat()),
    }
}

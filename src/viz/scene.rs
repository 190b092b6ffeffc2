//! Logging the cell's scene: solids by shape, the robot, the approach path, the reach.

use nalgebra::{UnitQuaternion, Vector3};
use rerun::{
    Boxes3D, Capsules3D, Clear, Color, Cylinders3D, Ellipsoids3D, FillMode, LineStrips3D, Points3D,
    Quaternion, RecordingStream, RecordingStreamResult,
};

use crate::world::cell::snapshot::{
    ArmPathView, PartShape, PartView, RobotView, SceneSnapshot, SolidView,
};

/// Entity paths of the scene (also used by the tests).
pub const SOLIDS: &str = "world/solids";
/// Where the twin's prediction of an action reality did otherwise is drawn, faint.
pub const TWIN: &str = "world/twin";
pub const ROBOT_TORSO: &str = "world/robot/torso";
pub const ROBOT_ARMS: &str = "world/robot/arms";
pub const ROBOT_JOINTS: &str = "world/robot/joints";
pub const ROBOT_GRIPPER: &str = "world/robot/gripper";
pub const APPROACH: &str = "world/approach";
pub const REACH: &str = "world/reach";

const FREE: [u8; 3] = [40, 200, 80];
const COLLIDES: [u8; 3] = [230, 40, 40];

/// A name as one entity path part: lower case, words joined by `_`.
pub fn slug(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_string()
}

fn quat(q: &UnitQuaternion<f32>) -> Quaternion {
    Quaternion::from_xyzw([q.i, q.j, q.k, q.w])
}

fn xyz(v: &Vector3<f32>) -> [f32; 3] {
    [v.x, v.y, v.z]
}

fn colour(rgb: [u8; 3], alpha: u8) -> Color {
    Color::from_unmultiplied_rgba(rgb[0], rgb[1], rgb[2], alpha)
}

/// Parts sorted by kind, in the arrays rerun logs each kind from (in the parts' order).
#[derive(Default)]
struct ByKind {
    /// Boxes: centres, half sizes, rotations.
    box_centres: Vec<[f32; 3]>,
    box_halves: Vec<[f32; 3]>,
    box_turns: Vec<Quaternion>,
    /// Cylinders: centres, lengths, radii, rotations (standing along local z).
    cylinder_centres: Vec<[f32; 3]>,
    cylinder_lengths: Vec<f32>,
    cylinder_radii: Vec<f32>,
    cylinder_turns: Vec<Quaternion>,
    /// Balls: centres, radii.
    ball_centres: Vec<[f32; 3]>,
    ball_radii: Vec<f32>,
    /// Capsules: one end, lengths, radii, rotations (from local z to the other end).
    capsule_starts: Vec<[f32; 3]>,
    capsule_lengths: Vec<f32>,
    capsule_radii: Vec<f32>,
    capsule_turns: Vec<Quaternion>,
}

impl ByKind {
    fn of(parts: &[PartView]) -> ByKind {
        let mut k = ByKind::default();
        for p in parts {
            let centre = xyz(&p.pose.translation.vector);
            match &p.shape {
                PartShape::Box { half } => {
                    k.box_centres.push(centre);
                    k.box_halves.push(*half);
                    k.box_turns.push(quat(&p.pose.rotation));
                }
                PartShape::Cylinder {
                    radius,
                    half_height,
                } => {
                    // parry's cylinders stand along local y, rerun's along local z.
                    let turn = UnitQuaternion::from_axis_angle(
                        &Vector3::x_axis(),
                        -std::f32::consts::FRAC_PI_2,
                    );
                    k.cylinder_centres.push(centre);
                    k.cylinder_lengths.push(2.0 * half_height);
                    k.cylinder_radii.push(*radius);
                    k.cylinder_turns.push(quat(&(p.pose.rotation * turn)));
                }
                PartShape::Ball { radius } => {
                    k.ball_centres.push(centre);
                    k.ball_radii.push(*radius);
                }
                PartShape::Capsule { a, b, radius } => {
                    let d = Vector3::from(*b) - Vector3::from(*a);
                    let turn = UnitQuaternion::rotation_between(&Vector3::z(), &d)
                        .unwrap_or_else(UnitQuaternion::identity);
                    k.capsule_starts.push(*a);
                    k.capsule_lengths.push(d.norm());
                    k.capsule_radii.push(*radius);
                    k.capsule_turns.push(quat(&turn));
                }
            }
        }
        k
    }
}

/// Log `parts` at `path` (boxes there, cleared when there are none; cylinders, balls and
/// capsules below it).
fn log_parts(
    rec: &RecordingStream,
    path: &str,
    parts: &[PartView],
    rgb: [u8; 3],
    label: Option<&str>,
) -> RecordingStreamResult<()> {
    log_parts_drawn(rec, path, parts, (colour(rgb, 255), FillMode::Solid), label)
}

/// [`log_parts`] in a colour and fill of its own (the twin's prediction: faint wires).
fn log_parts_drawn(
    rec: &RecordingStream,
    path: &str,
    parts: &[PartView],
    (c, fill): (Color, FillMode),
    label: Option<&str>,
) -> RecordingStreamResult<()> {
    let k = ByKind::of(parts);
    let labels = |n: usize| {
        label
            .map(|l| {
                let mut v = vec![String::new(); n];
                if let Some(first) = v.first_mut() {
                    *first = l.to_string();
                }
                v
            })
            .unwrap_or_default()
    };
    if k.box_centres.is_empty() {
        rec.log(path, &Clear::flat())?;
    } else {
        let n = k.box_centres.len();
        rec.log(
            path,
            &Boxes3D::from_centers_and_half_sizes(k.box_centres, k.box_halves)
                .with_quaternions(k.box_turns)
                .with_colors([c])
                .with_fill_mode(fill)
                .with_labels(labels(n)),
        )?;
    }
    let sub = |kind: &str| format!("{path}/{kind}");
    // A solid's parts never change kind, so only kinds it has are logged.
    if !k.cylinder_centres.is_empty() {
        let n = k.cylinder_centres.len();
        rec.log(
            sub("cylinders"),
            &Cylinders3D::from_lengths_and_radii(k.cylinder_lengths, k.cylinder_radii)
                .with_centers(k.cylinder_centres)
                .with_quaternions(k.cylinder_turns)
                .with_colors([c])
                .with_fill_mode(fill)
                .with_labels(labels(n)),
        )?;
    }
    if !k.ball_centres.is_empty() {
        rec.log(
            sub("balls"),
            &Ellipsoids3D::from_centers_and_radii(k.ball_centres, k.ball_radii)
                .with_colors([c])
                .with_fill_mode(fill),
        )?;
    }
    if !k.capsule_starts.is_empty() {
        rec.log(
            sub("capsules"),
            &Capsules3D::from_lengths_and_radii(k.capsule_lengths, k.capsule_radii)
                .with_translations(k.capsule_starts)
                .with_quaternions(k.capsule_turns)
                .with_colors([c]),
        )?;
    }
    Ok(())
}

/// The twin's prediction of the action reality did otherwise: every solid that moves, as
/// faint wires where the twin expected it, beside reality's solids.
pub fn log_prediction(
    rec: &RecordingStream,
    predicted: &SceneSnapshot,
) -> RecordingStreamResult<()> {
    for s in predicted.solids.iter().filter(|s| !s.fixed) {
        let path = format!("{TWIN}/{}", slug(&s.name));
        let label = format!("{} (the twin's prediction)", s.name);
        let faint = (colour(s.colour, 90), FillMode::MajorWireframe);
        log_parts_drawn(rec, &path, &s.parts, faint, Some(&label))?;
    }
    Ok(())
}

/// Whether a solid is what blocked the last motion (a lid blocks as "NAME lid").
fn blocks(solid: &str, blocker: Option<&str>) -> bool {
    blocker.is_some_and(|b| b == solid || b.strip_suffix(" lid") == Some(solid))
}

/// Log the whole scene at the current time. With real arms the robot is drawn from its
/// description (`robot.rs`, by the caller) and the boxes stand aside; the solid that
/// blocked a refused motion is drawn red and labelled so.
pub fn log_scene(rec: &RecordingStream, scene: &SceneSnapshot) -> RecordingStreamResult<()> {
    let blocker = scene.motion.as_ref().and_then(|m| m.blocker.as_deref());
    for s in &scene.solids {
        let path = format!("{SOLIDS}/{}", slug(&s.name));
        if blocks(&s.name, blocker) {
            let label = format!("{} blocks the arm", s.name);
            log_parts(rec, &path, &s.parts, COLLIDES, Some(&label))?;
        } else {
            log_parts(rec, &path, &s.parts, s.colour, Some(&s.name))?;
        }
    }
    let r = &scene.robot;
    if scene.arms.is_none() {
        log_robot_boxes(rec, r)?;
    }
    match &scene.approach {
        Some(a) => {
            let strips: Vec<Vec<[f32; 3]>> =
                a.points.windows(2).map(<[[f32; 3]]>::to_vec).collect();
            let colours: Vec<Color> = a
                .collided
                .iter()
                .map(|c| colour(if *c { COLLIDES } else { FREE }, 255))
                .collect();
            rec.log(
                APPROACH,
                &LineStrips3D::new(strips)
                    .with_colors(colours)
                    .with_radii([0.006]),
            )?;
        }
        None => rec.log(APPROACH, &Clear::flat())?,
    }
    if scene.out_of_reach.is_empty() {
        rec.log(REACH, &Clear::flat())?;
    } else {
        let centres: Vec<[f32; 3]> = r.arms.iter().map(|a| a.shoulder).collect();
        let radii = vec![r.reach; centres.len()];
        rec.log(
            REACH,
            &Ellipsoids3D::from_centers_and_radii(centres, radii)
                .with_colors([colour([120, 160, 255], 60)])
                .with_fill_mode(FillMode::MajorWireframe),
        )?;
    }
    Ok(())
}

/// The robot as boxes and segments, for cells without real arms.
fn log_robot_boxes(rec: &RecordingStream, r: &RobotView) -> RecordingStreamResult<()> {
    rec.log(
        ROBOT_TORSO,
        &Boxes3D::from_centers_and_half_sizes([r.torso_center], [r.torso_half])
            .with_colors([colour([200, 200, 205], 255)])
            .with_fill_mode(FillMode::Solid)
            .with_labels(["YuMi"]),
    )?;
    let strips: Vec<Vec<[f32; 3]>> = r
        .arms
        .iter()
        .map(|a| vec![a.shoulder, a.elbow, a.hand])
        .collect();
    rec.log(
        ROBOT_ARMS,
        &LineStrips3D::new(strips)
            .with_colors([colour([90, 90, 100], 255)])
            .with_radii([0.02]),
    )?;
    let joints: Vec<[f32; 3]> = r
        .arms
        .iter()
        .flat_map(|a| [a.shoulder, a.elbow, a.hand])
        .collect();
    rec.log(
        ROBOT_JOINTS,
        &Points3D::new(joints)
            .with_colors([colour([60, 60, 70], 255)])
            .with_radii([0.025]),
    )?;
    log_parts(rec, ROBOT_GRIPPER, &r.gripper, [70, 70, 80], None)?;
    Ok(())
}

/// A solid the last motion picked up or let go: as it was before the motion and as it is
/// after it.
pub struct Carried {
    pub before: SolidView,
    pub after: SolidView,
    /// Picked up (held after the motion), else let go (held before it).
    pub grasped: bool,
}

impl Carried {
    /// The solid whose holding changed from `before` to `after`, if one did.
    pub fn between(before: &[SolidView], after: &[SolidView]) -> Option<Carried> {
        before
            .iter()
            .zip(after)
            .find(|(b, a)| b.name == a.name && b.held != a.held)
            .map(|(b, a)| Carried {
                before: b.clone(),
                after: a.clone(),
                grasped: a.held,
            })
    }
}

/// `parts` moved by `by` (world).
fn shifted(parts: &[PartView], by: &Vector3<f32>) -> Vec<PartView> {
    parts
        .iter()
        .map(|p| {
            let mut moved = p.clone();
            moved.pose.translation.vector += by;
            if let PartShape::Capsule { a, b, .. } = &mut moved.shape {
                *a = (Vector3::from(*a) + by).into();
                *b = (Vector3::from(*b) + by).into();
            }
            moved
        })
        .collect()
}

/// The carried solid at configuration `index` of the way the arm went: in the hand
/// after the fingers close (at `path.acts_at`) for a grasp, up to where they open for a
/// release, else where it lies.
pub fn log_carried(
    rec: &RecordingStream,
    carried: &Carried,
    path: &ArmPathView,
    index: usize,
) -> RecordingStreamResult<()> {
    let tool = &path.tool;
    let (Some(at), Some(first), Some(last)) = (tool.get(index), tool.first(), tool.last()) else {
        return Ok(());
    };
    let at = Vector3::from(*at);
    let parts = match (carried.grasped, index > path.acts_at) {
        (true, true) => shifted(&carried.after.parts, &(at - Vector3::from(*last))),
        (true, false) => carried.before.parts.clone(),
        (false, false) => shifted(&carried.before.parts, &(at - Vector3::from(*first))),
        (false, true) => carried.after.parts.clone(),
    };
    let s = &carried.after;
    log_parts(
        rec,
        &format!("{SOLIDS}/{}", slug(&s.name)),
        &parts,
        s.colour,
        Some(&s.name),
    )
}

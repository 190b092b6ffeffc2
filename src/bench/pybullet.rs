//! What the anchor's PyBullet is given so that its validity check is betr's: the solids
//! as PyBullet primitives, the robot's links with betr's own collision shapes in place of
//! the URDF's meshes, the gripper fingers at the values betr holds them, and, per query,
//! the pairs of parts betr's check tests (`ArmCheck::tested_pairs`). The anchor counts a
//! contact only between such a pair and only when the two overlap (negative distance;
//! PyBullet also reports parts merely near each other), as parry's intersection test does.

use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use parry3d::shape::TypedShape;

use crate::motion::{ArmCheck, Part, Solid};
use crate::robot::{JointKind, Robot, RobotShapes};

/// A solid as PyBullet makes it: its kind and sizes, and its pose (position, quaternion
/// x y z w) with the shape's axis turned to PyBullet's (z for cylinders and capsules);
/// `None` when PyBullet has no such primitive.
pub fn pybullet_solid(solid: &Solid) -> Option<serde_json::Value> {
    let z_to_y = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -std::f32::consts::FRAC_PI_2);
    let (kind, sizes, local) = match solid.shape.as_typed_shape() {
        TypedShape::Cuboid(c) => (
            "box",
            serde_json::json!({"half": [c.half_extents.x, c.half_extents.y, c.half_extents.z]}),
            Isometry3::identity(),
        ),
        TypedShape::Ball(b) => (
            "sphere",
            serde_json::json!({"radius": b.radius}),
            Isometry3::identity(),
        ),
        // parry's cylinder stands along y.
        TypedShape::Cylinder(c) => (
            "cylinder",
            serde_json::json!({"radius": c.radius, "height": 2.0 * c.half_height}),
            Isometry3::from_parts(Default::default(), z_to_y),
        ),
        TypedShape::Capsule(c) => {
            let axis = c.segment.b - c.segment.a;
            let turn = UnitQuaternion::rotation_between(&Vector3::z(), &axis)
                .unwrap_or_else(UnitQuaternion::identity);
            let mid = nalgebra::center(&c.segment.a, &c.segment.b);
            (
                "capsule",
                serde_json::json!({"radius": c.radius, "height": axis.norm()}),
                Isometry3::from_parts(mid.coords.into(), turn),
            )
        }
        TypedShape::ConvexPolyhedron(p) => (
            "mesh",
            serde_json::json!({"vertices": p.points().iter().map(|v| [v.x, v.y, v.z]).collect::<Vec<_>>()}),
            Isometry3::identity(),
        ),
        _ => return None,
    };
    let pose = solid.pose * local;
    let t = pose.translation.vector;
    let r = pose.rotation.coords;
    Some(serde_json::json!({
        "name": solid.name,
        "kind": kind,
        "sizes": sizes,
        "position": [t.x, t.y, t.z],
        "orientation": [r.x, r.y, r.z, r.w],
    }))
}

/// Why the robot cannot be handed to PyBullet as betr checks it.
#[derive(Debug, thiserror::Error)]
#[error("link \"{link}\": a collision shape PyBullet has no primitive for ({kind})")]
pub struct UnconvertedShape {
    pub link: String,
    pub kind: String,
}

/// The robot as betr checks it: per link (by URDF name), its collision shapes in the
/// link's frame — the torso's in the root link's, where betr places them — and the
/// values of the joints no arm moves (the fingers), as betr's chains hold them.
pub fn collision_model(
    robot: &Robot,
    shapes: &RobotShapes,
) -> Result<serde_json::Value, UnconvertedShape> {
    let model = &robot.model;
    let mut links = serde_json::Map::new();
    let mut add = |link: &str, shape: &crate::robot::LinkShape| {
        let solid = Solid {
            name: shape.name.clone(),
            pose: shape.local,
            shape: shape.shape.clone(),
        };
        let converted = pybullet_solid(&solid).ok_or_else(|| UnconvertedShape {
            link: shape.name.clone(),
            kind: format!("{:?}", shape.shape.shape_type()),
        })?;
        if let Some(list) = links
            .entry(link.to_string())
            .or_insert_with(|| serde_json::Value::Array(Vec::new()))
            .as_array_mut()
        {
            list.push(converted);
        }
        Ok(())
    };
    // betr places the torso's shapes at the robot's root (ArmCheck::new).
    let root = &model.links[model.root].name;
    for shape in &shapes.torso {
        add(root, shape)?;
    }
    for arm in &shapes.arms {
        for link_shapes in arm {
            for shape in link_shapes {
                add(&model.links[shape.link].name, shape)?;
            }
        }
    }
    let arm_joints: Vec<&str> = robot
        .arms
        .iter()
        .flat_map(|a| a.joints.iter().map(|j| j.name.as_str()))
        .collect();
    let held: serde_json::Map<String, serde_json::Value> = model
        .joints
        .iter()
        .filter(|j| j.kind != JointKind::Fixed && !arm_joints.contains(&j.name.as_str()))
        .map(|j| (j.name.clone(), j.resting_value().into()))
        .collect();
    Ok(serde_json::json!({
        "root": root,
        "links": links,
        "held_joints": held,
    }))
}

/// The pairs `check` tests, by the names the anchor's script gives its parts: `link:`
/// and the URDF link's name (the torso's shapes are on the root link), `solid:` and the
/// scene solid's name, `carried:` and the index of what the hand carries.
pub fn tested_pairs_json(
    check: &ArmCheck<'_>,
    robot: &Robot,
    shapes: &RobotShapes,
) -> serde_json::Value {
    let model = &robot.model;
    let root = model.root;
    let torso: Vec<usize> = shapes.torso.iter().map(|s| s.link).collect();
    let name = |part: &Part| match part {
        Part::Link(l) => {
            let l = if torso.contains(l) { root } else { *l };
            format!("link:{}", model.links[l].name)
        }
        Part::Solid(s) => format!("solid:{s}"),
        Part::Carried(i) => format!("carried:{i}"),
    };
    let mut pairs: Vec<(String, String)> = check
        .tested_pairs()
        .iter()
        .map(|(a, b)| (name(a), name(b)))
        .collect();
    pairs.sort();
    pairs.dedup();
    pairs
        .into_iter()
        .map(|(a, b)| serde_json::json!([a, b]))
        .collect()
}

//! The cell as another simulator builds it: every solid's convex parts as primitives
//! (parry's shapes turned into the box, cylinder, ball and capsule every physics engine
//! has, cylinders and capsules standing along z), the lids, and the robot's description
//! with its arms' joints and rest values.

use std::f32::consts::FRAC_PI_2;

use nalgebra::{UnitQuaternion, Vector3};

use super::CellWorld;
use super::geometry::{Part, Pose};
use crate::world::description::{
    ArmDescription, DEFAULT_FRICTION, DescriptionError, LidDescription, ObjectDescription,
    PartDescription, Placement, PrimitiveShape, RobotDescription, SceneDescription,
};

/// Why a part cannot be described as a primitive.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{object:?} has a part that is not a box, cylinder, ball or capsule")]
pub struct NotPrimitive {
    pub object: String,
}

impl CellWorld {
    /// The scene as it stands now, for an executor to build its own copy of.
    pub fn describe(&self) -> Result<SceneDescription, NotPrimitive> {
        let mut objects = Vec::with_capacity(self.scene.solids.len());
        for (i, solid) in self.scene.solids.iter().enumerate() {
            let parts = primitives(&solid.name, &solid.body.parts)?;
            let lid = match &solid.lid {
                None => None,
                Some(lid) => Some(LidDescription {
                    parts: primitives(&solid.name, &lid.body.parts)?,
                    closed: placement(&lid.closed),
                    open: placement(&lid.open),
                    is_open: self.state.lid_open[i],
                }),
            };
            let at = placement(&self.state.poses[i]);
            let b = solid.body.local_aabb;
            let half = b.half_extents();
            objects.push(ObjectDescription {
                name: solid.name.clone(),
                position: at.position,
                rotation: at.rotation,
                fixed: solid.fixed,
                mass: solid.mass,
                friction: DEFAULT_FRICTION,
                half_extent: [half.x, half.y, half.z],
                parts,
                lid,
            });
        }
        Ok(SceneDescription {
            robot: self.describe_robot(),
            objects,
        })
    }

    /// The scene the executor's world is: this one as `[world.reality]` perturbs it.
    pub fn reality_description(&self) -> Result<SceneDescription, DescriptionError> {
        self.describe()
            .map_err(|e| DescriptionError::NotPrimitive(e.object))?
            .perturbed(&self.scene.reality)
    }

    fn describe_robot(&self) -> Option<RobotDescription> {
        let arms = self.arms.as_ref()?;
        let model = &arms.model;
        Some(RobotDescription {
            urdf: model.file.display().to_string(),
            packages: model
                .packages
                .iter()
                .map(|(name, dir)| (name.clone(), dir.display().to_string()))
                .collect(),
            base: [self.state.base.x, self.state.base.y, 0.0],
            arms: arms
                .robot
                .arms
                .iter()
                .zip(&self.state.arms)
                .map(|(chain, q)| ArmDescription {
                    joints: chain.joints.iter().map(|j| j.name.clone()).collect(),
                    flange: chain.tip.clone(),
                    rest: q.clone(),
                })
                .collect(),
        })
    }
}

fn placement(pose: &Pose) -> Placement {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion().coords;
    Placement {
        position: [t.x, t.y, t.z],
        rotation: [q.x, q.y, q.z, q.w],
    }
}

fn primitives(object: &str, parts: &[Part]) -> Result<Vec<PartDescription>, NotPrimitive> {
    parts
        .iter()
        .map(|part| {
            primitive(part).ok_or_else(|| NotPrimitive {
                object: object.to_string(),
            })
        })
        .collect()
}

/// One part as a primitive standing along z: parry's cylinders stand along y, its
/// capsules along their segment.
fn primitive(part: &Part) -> Option<PartDescription> {
    let s = &part.shape;
    let (shape, local) = if let Some(b) = s.as_cuboid() {
        let h = b.half_extents;
        (
            PrimitiveShape::Box {
                half: [h.x, h.y, h.z],
            },
            part.local,
        )
    } else if let Some(c) = s.as_cylinder() {
        let upright = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -FRAC_PI_2);
        (
            PrimitiveShape::Cylinder {
                radius: c.radius,
                half_height: c.half_height,
            },
            part.local * Pose::from_parts(Default::default(), upright),
        )
    } else if let Some(b) = s.as_ball() {
        (PrimitiveShape::Ball { radius: b.radius }, part.local)
    } else if let Some(c) = s.as_capsule() {
        let (a, b) = (c.segment.a.coords, c.segment.b.coords);
        let along = b - a;
        let turn = UnitQuaternion::rotation_between(&Vector3::z(), &along).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f32::consts::PI)
        });
        let centre =
            Pose::new((a + b) / 2.0, Vector3::zeros()) * Pose::from_parts(Default::default(), turn);
        (
            PrimitiveShape::Capsule {
                radius: c.radius,
                half_length: along.norm() / 2.0,
            },
            part.local * centre,
        )
    } else {
        return None;
    };
    let at = placement(&local);
    Some(PartDescription {
        shape,
        position: at.position,
        rotation: at.rotation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use crate::world::description::PrimitiveShape;

    fn cell(file: &str) -> CellWorld {
        let scenario = Scenario::load(std::path::Path::new(file)).unwrap();
        CellWorld::from_scenario(&scenario, None).unwrap()
    }

    #[test]
    fn every_solid_of_the_cup_scenario_is_described_in_primitives() {
        let scene = cell("scenarios/cell/flip_cup.toml").describe().unwrap();
        let cup = scene.objects.iter().find(|o| o.name == "red cup").unwrap();
        assert_eq!(cup.parts.len(), 13, "a bottom disc and 12 wall slabs");
        assert!(matches!(
            cup.parts[0].shape,
            PrimitiveShape::Cylinder { .. }
        ));
        let table = scene.objects.iter().find(|o| o.name == "table").unwrap();
        assert!(table.fixed);
    }

    #[test]
    fn a_cylinder_stands_along_z_with_its_height_as_given() {
        let part =
            super::super::geometry::Body::new(&super::super::geometry::ShapeSpec::Cylinder {
                radius: 0.03,
                height: 0.1,
            })
            .parts[0]
                .clone();
        let d = primitive(&part).unwrap();
        let PrimitiveShape::Cylinder {
            radius,
            half_height,
        } = d.shape
        else {
            panic!("{d:?}");
        };
        assert!((radius - 0.03).abs() < 1e-6 && (half_height - 0.05).abs() < 1e-6);
        // The axis z of the described part is the body's z.
        let [x, y, z, w] = d.rotation;
        let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
        assert!((q * Vector3::z() - Vector3::z()).norm() < 1e-5);
        assert!((d.position[2] - 0.05).abs() < 1e-6);
    }
}

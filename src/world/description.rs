//! A scene as another simulator needs it to build its own copy: the robot's published
//! description and where it stands, and every object as rigid primitive parts with a
//! pose, a mass and a friction. An executor gets it once, before the first action
//! (`docs/EXECUTORS.md`); it is how betr tells a world it does not own what to simulate.
//!
//! The description is the scene as betr knows it; `Perturbations` make the world the
//! executor simulates differ from it by declared, seeded amounts (the twin's scene is off
//! by where the camera put things, by what a mass or a friction really is), so that a run
//! with the same seed reproduces.

use indexmap::IndexMap;
use serde::{Deserialize, Serialize};

use crate::robot::SplitMix;

/// Friction coefficient of every surface when the scene gives none (wood, plastic).
pub const DEFAULT_FRICTION: f32 = 0.8;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneDescription {
    /// The robot whose arms follow the twin's paths; none when the twin has no arms.
    pub robot: Option<RobotDescription>,
    pub objects: Vec<ObjectDescription>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotDescription {
    /// The URDF file, and the folder each of its `package://NAME/` paths points into.
    pub urdf: String,
    pub packages: IndexMap<String, String>,
    /// Where the robot's root stands (metres).
    pub base: [f32; 3],
    pub arms: Vec<ArmDescription>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArmDescription {
    /// The moving joints from the root to the flange, in the order a path gives values.
    pub joints: Vec<String>,
    /// The link the tool (gripper) hangs from.
    pub flange: String,
    /// The joint values (radians) the arm starts at.
    pub rest: Vec<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectDescription {
    pub name: String,
    /// The footprint's centre (z up, the table top at 0) and a unit quaternion [x, y, z, w].
    pub position: [f32; 3],
    pub rotation: [f32; 4],
    /// Fixtures (the table, a cupboard) do not move.
    pub fixed: bool,
    pub mass: f32,
    pub friction: f32,
    /// Half the extent of the parts' box, centred above the footprint (for inertia).
    pub half_extent: [f32; 3],
    pub parts: Vec<PartDescription>,
    pub lid: Option<LidDescription>,
}

/// One convex primitive in its object's frame; cylinders and capsules stand along z.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartDescription {
    #[serde(flatten)]
    pub shape: PrimitiveShape,
    pub position: [f32; 3],
    pub rotation: [f32; 4],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum PrimitiveShape {
    Box { half: [f32; 3] },
    Cylinder { radius: f32, half_height: f32 },
    Ball { radius: f32 },
    Capsule { radius: f32, half_length: f32 },
}

/// A moving part (a lid, a door): its parts, and its poses closed and open relative to
/// the object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LidDescription {
    pub parts: Vec<PartDescription>,
    pub closed: Placement,
    pub open: Placement,
    pub is_open: bool,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    pub position: [f32; 3],
    pub rotation: [f32; 4],
}

/// How the world an executor simulates differs from betr's scene: declared per object,
/// and drawn within declared ranges from `seed`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Perturbations {
    pub seed: u64,
    /// Each named object's true position, relative to where the scene has it (metres).
    pub offsets: IndexMap<String, [f32; 3]>,
    /// Every movable object's position off by up to this along x and y (metres).
    pub jitter: f32,
    /// Friction of movable objects drawn from this range (none: as described).
    pub friction: Option<[f32; 2]>,
    /// Mass of movable objects scaled by a factor drawn from this range.
    pub mass_scale: Option<[f32; 2]>,
}

impl Perturbations {
    pub fn is_empty(&self) -> bool {
        self.offsets.is_empty()
            && self.jitter == 0.0
            && self.friction.is_none()
            && self.mass_scale.is_none()
    }
}

/// Why the scene cannot be described to an executor.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DescriptionError {
    #[error("an offset for {0:?}, which is not an object of the scene")]
    UnknownOffset(String),
    #[error("{0:?} has a part that is not a box, cylinder, ball or capsule")]
    NotPrimitive(String),
}

impl SceneDescription {
    /// The scene as the executor's world has it: `perturbations` applied, the same
    /// numbers for the same seed. An offset naming no object of the scene is refused.
    pub fn perturbed(
        &self,
        perturbations: &Perturbations,
    ) -> Result<SceneDescription, DescriptionError> {
        if let Some(name) = perturbations
            .offsets
            .keys()
            .find(|n| !self.objects.iter().any(|o| &o.name == *n))
        {
            return Err(DescriptionError::UnknownOffset(name.clone()));
        }
        let mut rng = SplitMix::new(perturbations.seed);
        let mut draw = |[low, high]: [f32; 2]| low + (high - low) * rng.unit() as f32;
        let mut scene = self.clone();
        for object in scene.objects.iter_mut().filter(|o| !o.fixed) {
            if perturbations.jitter > 0.0 {
                let j = perturbations.jitter;
                object.position[0] += draw([-j, j]);
                object.position[1] += draw([-j, j]);
            }
            if let Some(range) = perturbations.friction {
                object.friction = draw(range);
            }
            if let Some(range) = perturbations.mass_scale {
                object.mass *= draw(range);
            }
            if let Some(offset) = perturbations.offsets.get(&object.name) {
                for (p, o) in object.position.iter_mut().zip(offset) {
                    *p += o;
                }
            }
        }
        Ok(scene)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(name: &str, x: f32) -> ObjectDescription {
        ObjectDescription {
            name: name.into(),
            position: [x, 0.0, 0.0],
            rotation: [0.0, 0.0, 0.0, 1.0],
            fixed: false,
            mass: 0.05,
            friction: DEFAULT_FRICTION,
            half_extent: [0.02; 3],
            parts: vec![PartDescription {
                shape: PrimitiveShape::Box { half: [0.02; 3] },
                position: [0.0, 0.0, 0.02],
                rotation: [0.0, 0.0, 0.0, 1.0],
            }],
            lid: None,
        }
    }

    fn scene() -> SceneDescription {
        SceneDescription {
            robot: None,
            objects: vec![cube("blue cube", 0.3), cube("red cube", 0.4)],
        }
    }

    #[test]
    fn the_same_seed_perturbs_the_same_way_and_another_seed_otherwise() {
        let p = |seed| Perturbations {
            seed,
            jitter: 0.01,
            friction: Some([0.4, 0.9]),
            mass_scale: Some([0.5, 2.0]),
            ..Perturbations::default()
        };
        let a = scene().perturbed(&p(7)).unwrap();
        assert_eq!(a, scene().perturbed(&p(7)).unwrap());
        assert_ne!(a, scene().perturbed(&p(8)).unwrap());
        for (o, before) in a.objects.iter().zip(scene().objects) {
            assert!((o.position[0] - before.position[0]).abs() <= 0.01);
            assert!((0.4..=0.9).contains(&o.friction));
            assert!((0.025..=0.1).contains(&o.mass));
        }
    }

    #[test]
    fn an_offset_moves_its_object_and_an_unknown_name_is_refused() {
        let mut p = Perturbations::default();
        p.offsets.insert("red cube".into(), [0.015, 0.0, 0.0]);
        let moved = scene().perturbed(&p).unwrap();
        assert!((moved.objects[1].position[0] - 0.415).abs() < 1e-6);
        assert_eq!(moved.objects[0], scene().objects[0]);
        p.offsets.insert("banana".into(), [0.0; 3]);
        let error = scene().perturbed(&p).unwrap_err().to_string();
        assert!(error.contains("\"banana\""), "{error}");
    }

    #[test]
    fn parts_are_written_with_their_shape_named() {
        let json = serde_json::to_value(&cube("c", 0.0).parts[0]).unwrap();
        assert_eq!(json["shape"], "box");
        let half = json["half"][0].as_f64().unwrap();
        assert!((half - 0.02).abs() < 1e-6, "{half}");
    }
}

//! What an executor sees of the world it acts in: each object's pose and what the gripper
//! holds, in plain numbers any transport carries. A geometric world takes an observation
//! in (`World::take_observation`) and computes its facts from it with its own geometry, so
//! a simulator or a robot reports poses, never conditions.

use serde::{Deserialize, Serialize};

/// What an executor observed after acting.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Observation {
    /// The objects it sees; an object it does not report keeps the pose the world had.
    pub objects: Vec<ObservedObject>,
    /// The object the gripper holds, or none when it holds nothing.
    pub held: Option<String>,
}

/// One object's pose: the centre of its footprint (metres, z up, the table top at z = 0)
/// and its orientation as a unit quaternion `[x, y, z, w]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObservedObject {
    pub name: String,
    pub position: [f32; 3],
    pub rotation: [f32; 4],
}

/// Why an observation could not be taken in; the world is left as it was.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObservationError {
    #[error("the {0} world has no geometry to take observed poses into")]
    NoGeometry(&'static str),
    #[error("the observation names {name:?}, which is not an object of this scene")]
    UnknownObject { name: String },
    #[error("the observed pose of {name:?} is not finite")]
    NotFinite { name: String },
    #[error("the observed rotation of {name:?} is not a unit quaternion (its length is {length})")]
    NotUnit { name: String, length: f32 },
    #[error("the observation names {name:?} twice")]
    Repeated { name: String },
}

/// A quaternion this far from unit length is refused rather than normalised: it is a
/// reading error, not rounding.
const UNIT_TOLERANCE: f32 = 1e-3;

impl ObservedObject {
    /// Refuse a pose that is not a place: NaN or infinite numbers, a rotation that is
    /// not a unit quaternion.
    pub fn check(&self) -> Result<(), ObservationError> {
        let numbers = self.position.iter().chain(&self.rotation);
        if numbers.clone().any(|x| !x.is_finite()) {
            return Err(ObservationError::NotFinite {
                name: self.name.clone(),
            });
        }
        let length = self.rotation.iter().map(|x| x * x).sum::<f32>().sqrt();
        if (length - 1.0).abs() > UNIT_TOLERANCE {
            return Err(ObservationError::NotUnit {
                name: self.name.clone(),
                length,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn object(position: [f32; 3], rotation: [f32; 4]) -> ObservedObject {
        ObservedObject {
            name: "blue cube".into(),
            position,
            rotation,
        }
    }

    #[test]
    fn a_pose_that_is_not_a_place_is_refused_by_name() {
        assert_eq!(
            object([0.3, 0.1, 0.0], [0.0, 0.0, 0.0, 1.0]).check(),
            Ok(())
        );
        assert!(matches!(
            object([f32::NAN, 0.1, 0.0], [0.0, 0.0, 0.0, 1.0]).check(),
            Err(ObservationError::NotFinite { name }) if name == "blue cube"
        ));
        let err = object([0.3, 0.1, 0.0], [0.0, 0.0, 0.0, 2.0])
            .check()
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "the observed rotation of \"blue cube\" is not a unit quaternion (its length is 2)"
        );
    }

    #[test]
    fn an_observation_reads_from_json_as_a_transport_carries_it() {
        let text = r#"{"objects":[{"name":"red cube","position":[0.45,0.0,0.0],"rotation":[0,0,0,1]}],"held":null}"#;
        let read: Observation = serde_json::from_str(text).unwrap();
        assert_eq!(read.objects[0].name, "red cube");
        assert_eq!(read.held, None);
    }
}

//! The cell as an executor sees it: its objects' poses and what the gripper holds, out as
//! an observation and back in. Taking one in moves the solids to the observed poses; every
//! condition is then computed from them as always, so reality's poses become the cell's
//! facts through the cell's own geometry.

use nalgebra::{Quaternion, Translation3, UnitQuaternion};

use super::geometry::Pose;
use super::{CellWorld, Held};
use crate::world::Observation;
use crate::world::observation::{ObservationError, ObservedObject};

impl CellWorld {
    /// Every solid's pose now, and the object the gripper holds.
    pub fn observation(&self) -> Observation {
        let objects = self
            .scene
            .solids
            .iter()
            .zip(&self.state.poses)
            .map(|(solid, pose)| {
                let t = pose.translation.vector;
                let q = pose.rotation.quaternion().coords;
                ObservedObject {
                    name: solid.name.clone(),
                    position: [t.x, t.y, t.z],
                    rotation: [q.x, q.y, q.z, q.w],
                }
            })
            .collect();
        Observation {
            objects,
            held: self
                .state
                .held
                .as_ref()
                .map(|h| self.name(h.id).to_string()),
        }
    }

    /// Move the solids to the observed poses and hold what the gripper is seen to hold,
    /// all or nothing: an observation naming an object the scene lacks, or a pose that is
    /// not a place, changes nothing. A grasp the cell did not make itself is taken as a
    /// grip from above at the object's observed pose (where a grasp from this cell's
    /// gripper would hold it).
    pub(super) fn take(&mut self, observation: &Observation) -> Result<(), ObservationError> {
        let mut seen = Vec::with_capacity(observation.objects.len());
        for object in &observation.objects {
            object.check()?;
            let id = self.known_object(&object.name)?;
            if seen.iter().any(|(s, _)| *s == id) {
                return Err(ObservationError::Repeated {
                    name: object.name.clone(),
                });
            }
            let [x, y, z] = object.position;
            let [qx, qy, qz, qw] = object.rotation;
            let rotation = UnitQuaternion::from_quaternion(Quaternion::new(qw, qx, qy, qz));
            seen.push((id, Pose::from_parts(Translation3::new(x, y, z), rotation)));
        }
        let held = match &observation.held {
            Some(name) => Some(self.known_object(name)?),
            None => None,
        };
        for (id, pose) in seen {
            self.state.poses[id] = pose;
        }
        let already = self.state.held.as_ref().map(|h| h.id);
        match held {
            None => self.state.held = None,
            Some(id) if already == Some(id) => {}
            Some(id) => {
                let (tool, half_width) = self.grip_pose(id);
                self.state.held = Some(Held {
                    id,
                    grip: tool.inverse() * self.state.poses[id],
                    half_width,
                    from: self.aabb(id).center(),
                    arm: None,
                });
            }
        }
        Ok(())
    }

    fn known_object(&self, name: &str) -> Result<usize, ObservationError> {
        self.id(name)
            .ok_or_else(|| ObservationError::UnknownObject {
                name: name.to_string(),
            })
    }
}

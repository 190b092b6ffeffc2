//! A robot from its published description: the URDF read into links and joints
//! (`urdf.rs`), a serial chain from the root to each arm's tool flange with forward
//! kinematics (`chain.rs`), inverse kinematics for tool poses (`ik.rs`), and the links'
//! collision shapes (`shapes.rs`).
//!
//! Lengths are metres and angles radians, in the robot's root frame (the cell places the
//! root). Kinematics is in f64; collision shapes are f32 like the rest of the cell.

mod chain;
mod ik;
mod rng;
mod shapes;
mod slabs;
mod urdf;

use std::path::{Path, PathBuf};

pub use chain::{Carried, Chain, ChainJoint, arm_tips};
pub use ik::{IkOptions, IkSolution, Unreachable, describe_pose, nearest_arm_solution, solve};
pub use rng::SplitMix;
pub use shapes::{LinkShape, RobotShapes, read_stl, read_stl_triangles};
pub use urdf::{Element, Geometry, Joint, JointKind, Link, Model, Package};

use crate::model::DescriptionSpec;

#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: {message}")]
    Urdf { file: PathBuf, message: String },
    #[error("{file}: link \"{link}\": mesh {mesh} not found")]
    MissingMesh {
        file: PathBuf,
        link: String,
        mesh: PathBuf,
    },
    #[error("{file}: not a readable STL mesh: {message}")]
    Mesh { file: PathBuf, message: String },
    #[error(transparent)]
    Unreachable(#[from] Unreachable),
    #[error("{0}")]
    Fetch(#[from] crate::model::FetchError),
}

/// A robot read from its description: the model and its arms.
#[derive(Debug, Clone)]
pub struct Robot {
    pub model: Model,
    /// One chain per arm, in the order their flanges appear in the URDF.
    pub arms: Vec<Chain>,
}

impl Robot {
    /// Read the URDF of `spec` installed in `dir` (its `package://` paths point into
    /// `dir`), with an arm ending at every tool flange.
    pub fn read(spec: &DescriptionSpec, dir: &Path) -> Result<Robot, RobotError> {
        let packages = [Package {
            name: spec.package,
            dir,
        }];
        Robot::from_model(Model::read(&spec.urdf_in(dir), &packages)?)
    }

    pub fn from_model(model: Model) -> Result<Robot, RobotError> {
        let tips = arm_tips(&model);
        if tips.is_empty() {
            return Err(RobotError::Urdf {
                file: model.file.clone(),
                message: "no arm: no link is moved by revolute joints".into(),
            });
        }
        let arms = tips
            .iter()
            .map(|t| Chain::new(&model, t))
            .collect::<Result<_, _>>()?;
        Ok(Robot { model, arms })
    }

    /// The arm ending at the flange link `tip`.
    pub fn arm(&self, tip: &str) -> Option<&Chain> {
        self.arms.iter().find(|a| a.tip == tip)
    }
}

#[cfg(test)]
pub(crate) mod tests;

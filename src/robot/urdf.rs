//! A URDF file read (with `urdf-rs`) into the robot's tree of links and joints: poses as
//! nalgebra isometries, limits checked, mesh paths resolved to files that exist.

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::RobotError;

/// What a link looks like or collides as, in the link's frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// A mesh file (STL for the robots betr ships) scaled per axis.
    Mesh {
        path: PathBuf,
        scale: Vector3<f64>,
    },
    Box {
        size: Vector3<f64>,
    },
    Cylinder {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
    Capsule {
        radius: f64,
        length: f64,
    },
}

/// One visual or collision element of a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    pub origin: Isometry3<f64>,
    pub geometry: Geometry,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    pub name: String,
    pub visuals: Vec<Element>,
    pub collisions: Vec<Element>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    Fixed,
    /// Rotation about the axis, within limits.
    Revolute,
    /// Rotation about the axis without limits.
    Continuous,
    /// Translation along the axis, within limits.
    Prismatic,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// Indices into [`Model::links`].
    pub parent: usize,
    pub child: usize,
    /// The child's frame in the parent's at joint value 0.
    pub origin: Isometry3<f64>,
    pub axis: Unit<Vector3<f64>>,
    /// Limits (radians or metres); infinite for a continuous joint.
    pub lower: f64,
    pub upper: f64,
    /// The joint this one copies (`value = multiplier * other + offset`).
    pub mimic: Option<(String, f64, f64)>,
}

/// A robot's links and joints as its URDF gives them.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub name: String,
    /// The URDF file it was read from (named in errors).
    pub file: PathBuf,
    pub links: Vec<Link>,
    pub joints: Vec<Joint>,
    /// The link no joint moves.
    pub root: usize,
    /// The folders its `package://NAME/` mesh paths were resolved into, by package name.
    pub packages: Vec<(String, PathBuf)>,
}

/// Where the `package://NAME/` paths of a URDF point.
#[derive(Debug, Clone, Copy)]
pub struct Package<'a> {
    pub name: &'a str,
    pub dir: &'a Path,
}

impl Model {
    /// Read `file`, resolving `package://` mesh paths through `packages` and relative ones
    /// from the file's folder.
    pub fn read(file: &Path, packages: &[Package<'_>]) -> Result<Model, RobotError> {
        let text = std::fs::read_to_string(file).map_err(|source| RobotError::Io {
            path: file.to_path_buf(),
            source,
        })?;
        let robot = urdf_rs::read_from_string(&text).map_err(|e| RobotError::Urdf {
            file: file.to_path_buf(),
            message: format!("not a readable URDF: {e}"),
        })?;
        Model::from_urdf(&robot, file, packages)
    }

    fn from_urdf(
        robot: &urdf_rs::Robot,
        file: &Path,
        packages: &[Package<'_>],
    ) -> Result<Model, RobotError> {
        let links = read_links(robot, file, packages)?;
        let joints = robot
            .joints
            .iter()
            .map(|j| read_joint(j, &links, file))
            .collect::<Result<Vec<_>, _>>()?;
        let root = root_of(&links, &joints, file)?;
        Ok(Model {
            name: robot.name.clone(),
            file: file.to_path_buf(),
            links,
            joints,
            root,
            packages: packages
                .iter()
                .map(|p| (p.name.to_string(), p.dir.to_path_buf()))
                .collect(),
        })
    }

    /// A link's index by name.
    pub fn link(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// The joint whose child is `link` (none for the root).
    pub fn parent_joint(&self, link: usize) -> Option<&Joint> {
        self.joints.iter().find(|j| j.child == link)
    }

    /// The joints from the root down to `link`, root first.
    pub fn path_to(&self, link: usize) -> Vec<&Joint> {
        let mut path = Vec::new();
        let mut at = link;
        while let Some(j) = self.parent_joint(at) {
            path.push(j);
            at = j.parent;
        }
        path.reverse();
        path
    }

    /// The joints whose parent is `link`.
    pub fn child_joints(&self, link: usize) -> impl Iterator<Item = &Joint> {
        self.joints.iter().filter(move |j| j.parent == link)
    }
}

impl Joint {
    /// The value a joint takes when nothing moves it: 0, or the nearest limit when 0 is
    /// outside them.
    pub fn resting_value(&self) -> f64 {
        match self.kind {
            JointKind::Fixed => 0.0,
            _ => self.lower.max(0.0).min(self.upper),
        }
    }

    /// The child link's frame in the parent's at joint value `value`.
    pub fn transform_at(&self, value: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Fixed => self.origin,
            JointKind::Revolute | JointKind::Continuous => {
                self.origin * super::chain::joint_motion(&self.axis, true, value)
            }
            JointKind::Prismatic => {
                self.origin * super::chain::joint_motion(&self.axis, false, value)
            }
        }
    }
}

/// The description in `file` refused, with why.
fn bad(file: &Path, message: String) -> RobotError {
    RobotError::Urdf {
        file: file.to_path_buf(),
        message,
    }
}

/// The description's links with their visual and collision geometry, each name once.
fn read_links(
    robot: &urdf_rs::Robot,
    file: &Path,
    packages: &[Package<'_>],
) -> Result<Vec<Link>, RobotError> {
    let mut links = Vec::with_capacity(robot.links.len());
    for link in &robot.links {
        if links.iter().any(|l: &Link| l.name == link.name) {
            return Err(bad(
                file,
                format!("link \"{}\" is defined twice", link.name),
            ));
        }
        let element = |origin: &urdf_rs::Pose, geometry: &urdf_rs::Geometry| {
            Ok::<_, RobotError>(Element {
                origin: pose(origin),
                geometry: geometry_of(geometry, file, &link.name, packages)?,
            })
        };
        links.push(Link {
            name: link.name.clone(),
            visuals: link
                .visual
                .iter()
                .map(|v| element(&v.origin, &v.geometry))
                .collect::<Result<_, _>>()?,
            collisions: link
                .collision
                .iter()
                .map(|c| element(&c.origin, &c.geometry))
                .collect::<Result<_, _>>()?,
        });
    }
    Ok(links)
}

/// One joint of the description: a kind betr moves, ordered limits, a non-zero axis, and
/// links that are defined.
fn read_joint(j: &urdf_rs::Joint, links: &[Link], file: &Path) -> Result<Joint, RobotError> {
    let index = |joint: &str, name: &str| {
        links.iter().position(|l| l.name == name).ok_or_else(|| {
            bad(
                file,
                format!("joint \"{joint}\" names link \"{name}\", which is not defined"),
            )
        })
    };
    let kind = match j.joint_type {
        urdf_rs::JointType::Fixed => JointKind::Fixed,
        urdf_rs::JointType::Revolute => JointKind::Revolute,
        urdf_rs::JointType::Continuous => JointKind::Continuous,
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        ref other => {
            return Err(bad(
                file,
                format!(
                    "joint \"{}\" is {other:?}; betr moves fixed, revolute, continuous and prismatic joints",
                    j.name
                ),
            ));
        }
    };
    let (lower, upper) = match kind {
        JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
        _ => (j.limit.lower, j.limit.upper),
    };
    let ordered = lower.partial_cmp(&upper).is_some_and(|o| o.is_le());
    if matches!(kind, JointKind::Revolute | JointKind::Prismatic) && !ordered {
        return Err(bad(
            file,
            format!(
                "joint \"{}\": lower limit {lower} is above upper limit {upper}",
                j.name
            ),
        ));
    }
    let axis = Vector3::from(*j.axis.xyz);
    let axis = Unit::try_new(axis, 1e-9)
        .ok_or_else(|| bad(file, format!("joint \"{}\" has a zero axis", j.name)))?;
    Ok(Joint {
        name: j.name.clone(),
        kind,
        parent: index(&j.name, &j.parent.link)?,
        child: index(&j.name, &j.child.link)?,
        origin: pose(&j.origin),
        axis,
        lower,
        upper,
        mimic: j.mimic.as_ref().map(|m| {
            (
                m.joint.clone(),
                m.multiplier.unwrap_or(1.0),
                m.offset.unwrap_or(0.0),
            )
        }),
    })
}

/// The one link no joint moves, when the joints make a tree (no link the child of two).
fn root_of(links: &[Link], joints: &[Joint], file: &Path) -> Result<usize, RobotError> {
    let mut parents = vec![None; links.len()];
    for j in joints {
        if let Some(other) = parents[j.child] {
            let other: &Joint = &joints[other];
            return Err(bad(
                file,
                format!(
                    "link \"{}\" is the child of both \"{}\" and \"{}\"",
                    links[j.child].name, other.name, j.name
                ),
            ));
        }
        parents[j.child] = joints.iter().position(|k| k.name == j.name);
    }
    let roots: Vec<usize> = (0..links.len()).filter(|&l| parents[l].is_none()).collect();
    let [root] = roots[..] else {
        let names: Vec<&str> = roots.iter().map(|&r| links[r].name.as_str()).collect();
        return Err(bad(
            file,
            format!(
                "expected one root link (one no joint moves), found {}: {names:?}",
                roots.len()
            ),
        ));
    };
    Ok(root)
}

/// A URDF `<origin xyz rpy>` (roll about x, then pitch about y, then yaw about z, all
/// about fixed axes).
fn pose(origin: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = *origin.xyz;
    let [roll, pitch, yaw] = *origin.rpy;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}

fn geometry_of(
    geometry: &urdf_rs::Geometry,
    file: &Path,
    link: &str,
    packages: &[Package<'_>],
) -> Result<Geometry, RobotError> {
    Ok(match geometry {
        urdf_rs::Geometry::Box { size } => Geometry::Box {
            size: Vector3::from(**size),
        },
        urdf_rs::Geometry::Cylinder { radius, length } => Geometry::Cylinder {
            radius: *radius,
            length: *length,
        },
        urdf_rs::Geometry::Capsule { radius, length } => Geometry::Capsule {
            radius: *radius,
            length: *length,
        },
        urdf_rs::Geometry::Sphere { radius } => Geometry::Sphere { radius: *radius },
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let path = resolve(filename, file, link, packages)?;
            if !path.is_file() {
                return Err(RobotError::MissingMesh {
                    file: file.to_path_buf(),
                    link: link.to_string(),
                    mesh: path,
                });
            }
            Geometry::Mesh {
                path,
                scale: scale.map_or(Vector3::repeat(1.0), |s| Vector3::from(*s)),
            }
        }
    })
}

/// The file a mesh name points to: `package://NAME/rest` in a known package, `file://`
/// paths as they are, anything else relative to the URDF's folder.
fn resolve(
    name: &str,
    urdf: &Path,
    link: &str,
    packages: &[Package<'_>],
) -> Result<PathBuf, RobotError> {
    if let Some(rest) = name.strip_prefix("package://") {
        let (package, inside) = rest.split_once('/').unwrap_or((rest, ""));
        let Some(p) = packages.iter().find(|p| p.name == package) else {
            let known: Vec<&str> = packages.iter().map(|p| p.name).collect();
            return Err(RobotError::Urdf {
                file: urdf.to_path_buf(),
                message: format!(
                    "link \"{link}\": mesh \"{name}\" is in package \"{package}\", which is not one of {known:?}"
                ),
            });
        };
        return Ok(p.dir.join(inside));
    }
    if let Some(path) = name.strip_prefix("file://") {
        return Ok(PathBuf::from(path));
    }
    Ok(urdf.parent().unwrap_or(Path::new(".")).join(name))
}

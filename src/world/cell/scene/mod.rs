//! Reading a cell from a scenario's `[world]` tables (base file first; a child file's
//! entry for a solid patches the base's entry field by field).
//!
//! ```toml
//! [world]
//! kind = "cell"
//! unknown = ["banana"]                  # objects whose location the robot does not know
//!
//! [world.robot]                         # the YuMi: see robot.rs (usually in cell.toml)
//! shoulders = [[0.05, 0.18, 0.28], [0.05, -0.18, 0.28]]
//! reach = 0.559
//! payload = 0.5
//! base = [0.0, 0.0]
//! drive_margin = 0.8
//! gripper = { finger = [0.01, 0.02, 0.04], palm = [0.03, 0.02], clearance = 0.005, grip_depth = 0.02, approach = 0.15 }
//! description = "yumi"                  # the published description whose arms move
//! rest = [[42.2, -14.9, ...], [...]]    # each arm's joint values (degrees) to start from
//! tool = 0.143                          # the finger tips along the flange's z (metres)
//!
//! [world.solids."red cup"]
//! shape = "cup"                         # box | cylinder | ball | capsule | cup | open box
//! radius = 0.045
//! height = 0.09
//! on = "table"                          # or in = "bucket", or at = [x, y, z]
//! xy = [0.35, -0.1]
//! upside_down = true                    # or rotation = [rx, ry, rz] in degrees
//! mass = 0.1
//!
//! [world.solids."centrifuge".lid]       # a moving part: a box at a closed and an open pose
//! size = [0.2, 0.2, 0.01]
//! closed = [0.0, 0.0, 0.15]
//! open = [0.12, 0.0, 0.15]
//! open_rotation = [0.0, -90.0, 0.0]
//!
//! [[world.values]]                      # how the world judges a value parameter
//! skill = "grasp"
//! object = "egg"
//! value = "force"
//! max = 6.0
//! above = "The egg broke: {value} {unit} is more force than it can bear ({max} {unit} at most)"
//!
//! [world.reality]                      # how the world an executor runs differs (seeded)
//! seed = 1
//! offset."red cube" = [0.015, 0.0, 0.0] # its true position, relative to the scene's
//! jitter = 0.005                        # every movable object off by up to this in x, y
//! friction = [0.5, 1.0]                 # drawn for each movable object
//! mass_scale = [0.8, 1.2]               # times the scene's mass
//!
//! [world.variants.clear]                # the same cell without the obstacle (`--variant clear`)
//! description = "nothing lies on the blue cube"
//! solids."red cube" = { on = "table", xy = [0.3, -0.2] }
//! ```

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

use super::geometry::{Body, Pose};
use super::robot::{ArmsSpec, Gripper, Robot};
use super::values::Judge;
use crate::scenario::{Scenario, ScenarioError, SourceFile};
use crate::world::Perturbations;

mod build;
mod finite;
use build::build;
use finite::modest;

/// The skills the cell can perform, by name.
pub const SKILLS: &[&str] = &[
    "grasp",
    "place",
    "put_in",
    "flip",
    "open",
    "unlock",
    "look_for",
    "move_base",
    "scoop",
    "wipe",
    "slide",
];

#[derive(Deserialize)]
struct FileTables {
    world: Option<RawWorld>,
    #[serde(default)]
    skills: Vec<SkillName>,
}

#[derive(Deserialize)]
struct SkillName {
    name: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorld {
    #[allow(dead_code)]
    kind: Option<String>,
    robot: Option<RawRobot>,
    #[serde(default)]
    solids: IndexMap<String, RawSolid>,
    unknown: Option<Vec<Spanned<String>>>,
    #[serde(default)]
    values: Vec<RawJudge>,
    #[serde(default)]
    variants: IndexMap<String, RawVariant>,
    reality: Option<RawReality>,
}

/// `[world.reality]`: see `Perturbations`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawReality {
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    offset: IndexMap<String, Spanned<Offset>>,
    #[serde(default, deserialize_with = "modest")]
    jitter: Option<f32>,
    #[serde(default, deserialize_with = "modest")]
    friction: Option<[f32; 2]>,
    #[serde(default, deserialize_with = "modest")]
    mass_scale: Option<[f32; 2]>,
}

#[derive(Deserialize)]
#[serde(transparent)]
struct Offset(#[serde(deserialize_with = "modest")] [f32; 3]);

#[derive(Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
struct RawRobot {
    #[serde(default, deserialize_with = "modest")]
    shoulders: Option<Vec<[f32; 3]>>,
    #[serde(default, deserialize_with = "modest")]
    reach: Option<f32>,
    #[serde(default, deserialize_with = "modest")]
    payload: Option<f32>,
    #[serde(default, deserialize_with = "modest")]
    base: Option<[f32; 2]>,
    #[serde(default, deserialize_with = "modest")]
    drive_margin: Option<f32>,
    gripper: Option<RawGripper>,
    /// The robot's published description by name (`"yumi"`): the execution world moves
    /// its arms.
    description: Option<Spanned<String>>,
    /// Each arm's joint values (degrees) before its first motion, in the description's
    /// order of arms.
    #[serde(default, deserialize_with = "modest")]
    rest: Option<Vec<Vec<f32>>>,
    /// The tool centre point (between the finger tips) along the flange's z axis (metres).
    #[serde(default, deserialize_with = "modest")]
    tool: Option<f32>,
}

#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawGripper {
    #[serde(deserialize_with = "modest")]
    finger: [f32; 3],
    #[serde(deserialize_with = "modest")]
    palm: [f32; 2],
    #[serde(deserialize_with = "modest")]
    clearance: f32,
    #[serde(deserialize_with = "modest")]
    grip_depth: f32,
    #[serde(deserialize_with = "modest")]
    approach: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVariant {
    #[allow(dead_code)]
    description: Option<String>,
    #[serde(default)]
    solids: IndexMap<String, RawSolid>,
    unknown: Option<Vec<Spanned<String>>>,
    #[serde(default, deserialize_with = "modest")]
    base: Option<[f32; 2]>,
}

#[derive(Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
struct RawSolid {
    shape: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "modest")]
    size: Option<[f32; 3]>,
    #[serde(default, deserialize_with = "modest")]
    radius: Option<f32>,
    #[serde(default, deserialize_with = "modest")]
    height: Option<f32>,
    #[serde(default, deserialize_with = "modest")]
    length: Option<f32>,
    #[serde(default, deserialize_with = "modest")]
    wall: Option<f32>,
    #[serde(default, deserialize_with = "modest")]
    bottom: Option<f32>,
    opening: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "modest")]
    mass: Option<f32>,
    fixed: Option<bool>,
    on: Option<Spanned<String>>,
    #[serde(rename = "in")]
    inside: Option<Spanned<String>>,
    #[serde(default, deserialize_with = "modest")]
    xy: Option<[f32; 2]>,
    #[serde(default, deserialize_with = "modest")]
    at: Option<[f32; 3]>,
    #[serde(default, deserialize_with = "modest")]
    rotation: Option<[f32; 3]>,
    upside_down: Option<bool>,
    lid: Option<RawLid>,
    locked: Option<bool>,
    open: Option<bool>,
    dirty: Option<bool>,
}

#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawLid {
    #[serde(deserialize_with = "modest")]
    size: [f32; 3],
    #[serde(deserialize_with = "modest")]
    closed: [f32; 3],
    #[serde(deserialize_with = "modest")]
    open: [f32; 3],
    #[serde(default, deserialize_with = "modest")]
    open_rotation: [f32; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJudge {
    skill: Spanned<String>,
    object: Option<Spanned<String>>,
    value: Spanned<String>,
    min: Option<f64>,
    below: Option<String>,
    max: Option<f64>,
    above: Option<String>,
    allowed: Option<Vec<String>>,
    otherwise: Option<String>,
}

/// A moving part of a solid (a lid, a door), at one of two poses relative to the solid.
#[derive(Clone)]
pub struct Lid {
    pub body: Body,
    pub closed: Pose,
    pub open: Pose,
}

/// What does not change while the world runs: names, shapes, masses.
#[derive(Clone)]
pub struct Solid {
    pub name: String,
    pub body: Body,
    pub mass: f32,
    /// Fixtures (the table, a cupboard) cannot be grasped.
    pub fixed: bool,
    pub lid: Option<Lid>,
    pub lockable: bool,
}

/// The state the scene starts in.
#[derive(Debug, Clone)]
pub struct Initial {
    pub poses: Vec<Pose>,
    pub lid_open: Vec<bool>,
    pub locked: Vec<bool>,
    pub known: Vec<bool>,
    pub dirty: Vec<bool>,
    pub base: [f32; 2],
}

pub struct Scene {
    pub solids: Vec<Solid>,
    pub robot: Robot,
    pub judges: Vec<Judge>,
    pub initial: Initial,
    /// How the world an executor simulates differs from this scene.
    pub reality: Perturbations,
}

/// A solid's merged entry and the file (index) that last touched it, for errors.
struct Entry {
    raw: RawSolid,
    file: usize,
}

fn patch(base: &mut RawSolid, p: RawSolid) {
    macro_rules! take {
        ($($f:ident),*) => { $( if p.$f.is_some() { base.$f = p.$f; } )* };
    }
    if p.on.is_some() || p.inside.is_some() || p.at.is_some() {
        base.on = None;
        base.inside = None;
        base.at = None;
        base.xy = None;
    }
    take!(
        shape, size, radius, height, length, wall, bottom, opening, mass, fixed, on, inside, xy, at
    );
    take!(rotation, upside_down, lid, locked, open, dirty);
}

/// The error at the first mention of `needle` in `file` (or its start).
fn near(file: &SourceFile, needle: &str, message: impl std::fmt::Display) -> ScenarioError {
    file.error_at(file.text.find(needle).unwrap_or(0), message)
}

pub fn read(scenario: &Scenario, variant: Option<&str>) -> Result<Scene, ScenarioError> {
    let files = &scenario.files;
    let last = files.len().saturating_sub(1);
    let mut merged = Merged::default();
    for (index, file) in files.iter().enumerate() {
        let tables: FileTables = file.parse()?;
        check_skills(file, &tables.skills)?;
        let Some(world) = tables.world else { continue };
        merged.add_world(scenario, index, world, variant)?;
    }
    if let Some(wanted) = variant {
        merged.apply_variant(files, wanted)?;
    }
    let Merged {
        entries,
        robot,
        unknown,
        judges,
        reality,
        ..
    } = merged;
    let base = robot.base.unwrap_or([0.0, 0.0]);
    let robot = build_robot(&files[last], robot)?;
    let mut scene = build(scenario, entries, unknown, judges, robot)?;
    scene.initial.base = base;
    if let Some((index, raw)) = reality {
        scene.reality = perturbations(&files[index], &scene, raw)?;
    }
    Ok(scene)
}

/// Every skill a file declares is one the cell world performs.
fn check_skills(file: &SourceFile, skills: &[SkillName]) -> Result<(), ScenarioError> {
    for s in skills {
        if !SKILLS.contains(&s.name.get_ref().as_str()) {
            return Err(file.error_in_string(
                &s.name.span(),
                0,
                format!(
                    "the cell world cannot perform a skill named {:?} (it performs: {})",
                    s.name.get_ref(),
                    SKILLS.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The `[world]` tables of a scenario's files merged base first, and the variant asked
/// for (from the last file that has it).
#[derive(Default)]
struct Merged {
    entries: IndexMap<String, Entry>,
    robot: RawRobot,
    unknown: Vec<(usize, Spanned<String>)>,
    judges: Vec<Judge>,
    chosen: Option<(usize, RawVariant)>,
    variant_names: Vec<String>,
    /// The last file's `[world.reality]`.
    reality: Option<(usize, RawReality)>,
}

impl Merged {
    /// Merge file `index`'s `[world]` table: robot values and solids patch those before,
    /// a list of unknown solids replaces the one before, values add up.
    fn add_world(
        &mut self,
        scenario: &Scenario,
        index: usize,
        world: RawWorld,
        variant: Option<&str>,
    ) -> Result<(), ScenarioError> {
        let file = &scenario.files[index];
        if let Some(r) = world.robot {
            let robot = std::mem::take(&mut self.robot);
            self.robot = RawRobot {
                shoulders: r.shoulders.or(robot.shoulders),
                reach: r.reach.or(robot.reach),
                payload: r.payload.or(robot.payload),
                base: r.base.or(robot.base),
                drive_margin: r.drive_margin.or(robot.drive_margin),
                gripper: r.gripper.or(robot.gripper),
                description: r.description.or(robot.description),
                rest: r.rest.or(robot.rest),
                tool: r.tool.or(robot.tool),
            };
        }
        for (name, raw) in world.solids {
            match self.entries.get_mut(&name) {
                Some(e) => {
                    patch(&mut e.raw, raw);
                    e.file = index;
                }
                None => {
                    self.entries.insert(name, Entry { raw, file: index });
                }
            }
        }
        if let Some(u) = world.unknown {
            self.unknown = u.into_iter().map(|s| (index, s)).collect();
        }
        for j in world.values {
            self.judges.push(judge(scenario, file, j)?);
        }
        if let Some(r) = world.reality {
            self.reality = Some((index, r));
        }
        for (name, v) in world.variants {
            self.variant_names.push(name.clone());
            if Some(name.as_str()) == variant {
                self.chosen = Some((index, v));
            }
        }
        Ok(())
    }

    /// Patch the merged world with variant `wanted`, which some file must have.
    fn apply_variant(&mut self, files: &[SourceFile], wanted: &str) -> Result<(), ScenarioError> {
        let last = files.len().saturating_sub(1);
        let Some((index, v)) = self.chosen.take() else {
            return Err(files[last].error_at(
                0,
                format!(
                    "no world variant {wanted:?} in this scenario (variants: {})",
                    if self.variant_names.is_empty() {
                        "none".to_string()
                    } else {
                        self.variant_names.join(", ")
                    }
                ),
            ));
        };
        for (name, raw) in v.solids {
            let Some(e) = self.entries.get_mut(&name) else {
                return Err(near(
                    &files[index],
                    &format!("\"{name}\""),
                    format!("variant {wanted:?} patches {name:?}, which is not a solid"),
                ));
            };
            patch(&mut e.raw, raw);
            e.file = index;
        }
        if let Some(u) = v.unknown {
            self.unknown = u.into_iter().map(|s| (index, s)).collect();
        }
        if v.base.is_some() {
            self.robot.base = v.base;
        }
        Ok(())
    }
}

/// The declared perturbations, each offset naming a solid that moves and each range
/// written low to high.
fn perturbations(
    file: &SourceFile,
    scene: &Scene,
    raw: RawReality,
) -> Result<Perturbations, ScenarioError> {
    let mut offsets = IndexMap::new();
    for (name, offset) in raw.offset {
        let movable = scene.solids.iter().any(|s| s.name == name && !s.fixed);
        if !movable {
            return Err(file.error_at(
                offset.span().start,
                format!("[world.reality] offset: {name:?} is not a solid that moves"),
            ));
        }
        offsets.insert(name, offset.into_inner().0);
    }
    for (what, range) in [("friction", raw.friction), ("mass_scale", raw.mass_scale)] {
        if let Some([low, high]) = range
            && !(0.0 < low && low <= high)
        {
            return Err(near(
                file,
                what,
                format!(
                    "[world.reality] {what} = [{low}, {high}]: a range from low to high, above 0"
                ),
            ));
        }
    }
    Ok(Perturbations {
        seed: raw.seed,
        offsets,
        jitter: raw.jitter.unwrap_or(0.0).abs(),
        friction: raw.friction,
        mass_scale: raw.mass_scale,
    })
}

fn build_robot(file: &SourceFile, r: RawRobot) -> Result<Robot, ScenarioError> {
    let missing = |what: &str| {
        near(
            file,
            "[world",
            format!("[world.robot] needs `{what}` (usually in the base cell.toml)"),
        )
    };
    let g = r.gripper.ok_or_else(|| missing("gripper"))?;
    let arms = match r.description {
        None => None,
        Some(name) => {
            let Some(spec) = crate::model::find_description(name.get_ref()) else {
                let known: Vec<&str> = crate::model::DESCRIPTIONS.iter().map(|d| d.name).collect();
                return Err(file.error_in_string(
                    &name.span(),
                    0,
                    format!(
                        "no robot description named {:?} (known: {})",
                        name.get_ref(),
                        known.join(", ")
                    ),
                ));
            };
            let rest = r.rest.ok_or_else(|| missing("rest"))?;
            Some(ArmsSpec {
                description: spec,
                rest: rest
                    .iter()
                    .map(|arm| arm.iter().map(|d| f64::from(*d).to_radians()).collect())
                    .collect(),
                tool: f64::from(r.tool.ok_or_else(|| missing("tool"))?),
            })
        }
    };
    let robot = Robot {
        arms,
        shoulders: r
            .shoulders
            .ok_or_else(|| missing("shoulders"))?
            .into_iter()
            .map(nalgebra::Point3::from)
            .collect(),
        reach: r.reach.ok_or_else(|| missing("reach"))?,
        payload: r.payload.ok_or_else(|| missing("payload"))?,
        drive_margin: r.drive_margin.unwrap_or(0.8),
        gripper: Gripper {
            finger: g.finger,
            palm: g.palm,
            clearance: g.clearance,
            grip_depth: g.grip_depth,
            approach: g.approach,
        },
    };
    if robot.shoulders.is_empty() || robot.reach <= 0.0 || robot.payload <= 0.0 {
        return Err(near(
            file,
            "[world",
            "the robot needs at least one shoulder, and a positive reach and payload",
        ));
    }
    Ok(robot)
}

fn judge(scenario: &Scenario, file: &SourceFile, j: RawJudge) -> Result<Judge, ScenarioError> {
    let skill = scenario
        .domain
        .skills
        .iter()
        .find(|s| s.name == *j.skill.get_ref());
    let Some(skill) = skill else {
        return Err(file.error_in_string(
            &j.skill.span(),
            0,
            format!("no skill named {:?} in this scenario", j.skill.get_ref()),
        ));
    };
    if !skill.values.iter().any(|v| v.name == *j.value.get_ref()) {
        return Err(file.error_in_string(
            &j.value.span(),
            0,
            format!(
                "skill {:?} declares no value {:?}",
                skill.name,
                j.value.get_ref()
            ),
        ));
    }
    if let Some(o) = &j.object
        && scenario.domain.vocabulary.object(o.get_ref()).is_none()
    {
        return Err(file.error_in_string(
            &o.span(),
            0,
            format!("unknown object {:?}", o.get_ref()),
        ));
    }
    let text = |t: Option<String>, key: &str| {
        t.ok_or_else(|| {
            file.error_in_string(
                &j.value.span(),
                0,
                format!("a judge with `{key}` also needs its error text"),
            )
        })
    };
    let min = j
        .min
        .map(|m| text(j.below.clone(), "min").map(|t| (m, t)))
        .transpose()?;
    let max = j
        .max
        .map(|m| text(j.above.clone(), "max").map(|t| (m, t)))
        .transpose()?;
    let allowed = match j.allowed {
        Some(a) => Some((a, text(j.otherwise.clone(), "allowed")?)),
        None => None,
    };
    if min.is_none() && max.is_none() && allowed.is_none() {
        return Err(file.error_in_string(
            &j.value.span(),
            0,
            "a judge needs `min`, `max` or `allowed`",
        ));
    }
    Ok(Judge {
        skill: skill.name.clone(),
        object: j.object.map(|o| o.into_inner()),
        value: j.value.into_inner(),
        min,
        max,
        allowed,
    })
}

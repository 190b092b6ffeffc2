//! Turning the merged scene entries into solids and initial poses: shapes are checked,
//! and a solid `on` another rests on that one's top face (supports are placed first).

use std::collections::HashSet;

use indexmap::IndexMap;
use toml::Spanned;

use super::super::geometry::{Body, Opening, Pose, ShapeSpec, flipped, rotation_deg};
use super::super::robot::Robot;
use super::super::values::Judge;
use super::{Entry, Initial, Lid, RawSolid, Scene, Solid, near};
use crate::scenario::{Scenario, ScenarioError, SourceFile};

fn shape_of(file: &SourceFile, name: &str, raw: &RawSolid) -> Result<ShapeSpec, ScenarioError> {
    let err = |m: String| near(file, &format!("\"{name}\""), format!("solid {name:?}: {m}"));
    let Some(shape) = &raw.shape else {
        return Err(err(
            "needs a `shape` (box, cylinder, ball, capsule, cup, open box)".into(),
        ));
    };
    let need = |v: Option<f32>, key: &str| match v {
        Some(x) if x > 0.0 => Ok(x),
        _ => Err(err(format!(
            "a {} needs a positive `{key}`",
            shape.get_ref()
        ))),
    };
    let size = || match raw.size {
        Some(s) if s.iter().all(|x| *x > 0.0) => Ok(s),
        _ => Err(err("needs `size = [x, y, z]`, all positive".into())),
    };
    Ok(match shape.get_ref().as_str() {
        "box" => ShapeSpec::Box { size: size()? },
        "cylinder" => ShapeSpec::Cylinder {
            radius: need(raw.radius, "radius")?,
            height: need(raw.height, "height")?,
        },
        "ball" => ShapeSpec::Ball {
            radius: need(raw.radius, "radius")?,
        },
        "capsule" => ShapeSpec::Capsule {
            radius: need(raw.radius, "radius")?,
            length: need(raw.length, "length")?,
        },
        "cup" => ShapeSpec::Cup {
            radius: need(raw.radius, "radius")?,
            height: need(raw.height, "height")?,
            wall: need(raw.wall, "wall")?,
            bottom: need(raw.bottom, "bottom")?,
        },
        "open box" => {
            let opening = match raw.opening.as_ref().map(|o| o.get_ref().as_str()) {
                None | Some("top") => Opening::Top,
                Some("front") => Opening::Front,
                Some(other) => {
                    let span = raw.opening.as_ref().map(Spanned::span).unwrap_or_default();
                    return Err(file.error_in_string(
                        &span,
                        0,
                        format!("expected \"top\" or \"front\", found {other:?}"),
                    ));
                }
            };
            ShapeSpec::OpenBox {
                size: size()?,
                wall: need(raw.wall, "wall")?,
                opening,
            }
        }
        other => {
            return Err(file.error_in_string(
                &shape.span(),
                0,
                format!("unknown shape {other:?} (box, cylinder, ball, capsule, cup, open box)"),
            ));
        }
    })
}

pub(super) fn build(
    scenario: &Scenario,
    entries: IndexMap<String, Entry>,
    unknown: Vec<(usize, Spanned<String>)>,
    judges: Vec<Judge>,
    robot: Robot,
) -> Result<Scene, ScenarioError> {
    let files = &scenario.files;
    every_object_has_a_solid(scenario, &entries)?;
    let solids = solids_of(scenario, &entries)?;
    // Poses, supports first: a solid `on` another rests on that one's top face.
    let raws: Vec<&Entry> = entries.values().collect();
    let mut poses: Vec<Option<Pose>> = vec![None; raws.len()];
    for i in 0..raws.len() {
        place(
            i,
            &raws,
            (&solids, &entries),
            files,
            &mut poses,
            &mut Vec::new(),
        )?;
    }
    let known = known_of(&entries, &unknown, files, solids.len())?;
    let flag = |f: fn(&RawSolid) -> Option<bool>| {
        raws.iter().map(|e| f(&e.raw).unwrap_or(false)).collect()
    };
    Ok(Scene {
        initial: Initial {
            poses: poses
                .into_iter()
                .map(|p| p.unwrap_or_else(Pose::identity))
                .collect(),
            lid_open: flag(|r| r.open),
            locked: flag(|r| r.locked),
            dirty: flag(|r| r.dirty),
            known,
            base: [0.0, 0.0],
        },
        solids,
        robot,
        judges,
        reality: Default::default(),
    })
}

/// Every object of the scenario has a solid; else the error points at the last file
/// that names the object (or the last file).
fn every_object_has_a_solid(
    scenario: &Scenario,
    entries: &IndexMap<String, Entry>,
) -> Result<(), ScenarioError> {
    let files = &scenario.files;
    for o in &scenario.domain.vocabulary.objects {
        if !entries.contains_key(&o.name) {
            let needle = format!("\"{}\"", o.name);
            let file = files
                .iter()
                .rev()
                .find(|f| f.text.contains(&needle))
                .unwrap_or(&files[files.len() - 1]);
            return Err(near(
                file,
                &needle,
                format!(
                    "object {:?} has no solid: add [world.solids.{:?}]",
                    o.name, o.name
                ),
            ));
        }
    }
    Ok(())
}

/// The solids of the entries, in their order, each an object of the scenario with a
/// shape that checks.
fn solids_of(
    scenario: &Scenario,
    entries: &IndexMap<String, Entry>,
) -> Result<Vec<Solid>, ScenarioError> {
    let files = &scenario.files;
    let objects: HashSet<&str> = scenario
        .domain
        .vocabulary
        .objects
        .iter()
        .map(|o| o.name.as_str())
        .collect();
    let mut solids = Vec::new();
    for (name, e) in entries {
        let file = &files[e.file];
        if !objects.contains(name.as_str()) {
            return Err(near(
                file,
                &format!("\"{name}\""),
                format!("solid {name:?} is not an object of this scenario: add it to [objects]"),
            ));
        }
        let lid = e.raw.lid.as_ref().map(|l| Lid {
            body: Body::new(&ShapeSpec::Box { size: l.size }),
            closed: Pose::translation(l.closed[0], l.closed[1], l.closed[2]),
            open: Pose::from_parts(l.open.into(), rotation_deg(l.open_rotation)),
        });
        solids.push(Solid {
            name: name.clone(),
            body: Body::new(&shape_of(file, name, &e.raw)?),
            mass: e.raw.mass.unwrap_or(0.1),
            fixed: e.raw.fixed.unwrap_or(false),
            lid,
            lockable: e.raw.locked.is_some(),
        });
    }
    Ok(solids)
}

/// Which of the `count` solids the robot knows at the start: all but those listed
/// `unknown` (each must name a solid).
fn known_of(
    entries: &IndexMap<String, Entry>,
    unknown: &[(usize, Spanned<String>)],
    files: &[SourceFile],
    count: usize,
) -> Result<Vec<bool>, ScenarioError> {
    let mut known = vec![true; count];
    for (file, u) in unknown {
        match entries.get_index_of(u.get_ref()) {
            Some(i) => known[i] = false,
            None => {
                return Err(files[*file].error_in_string(
                    &u.span(),
                    0,
                    format!("unknown solid {:?}", u.get_ref()),
                ));
            }
        }
    }
    Ok(known)
}

/// The pose of solid `i`, placing its supports first. `entries` index the solids by name
/// (same order).
fn place(
    i: usize,
    raws: &[&Entry],
    (solids, entries): (&[Solid], &IndexMap<String, Entry>),
    files: &[SourceFile],
    poses: &mut Vec<Option<Pose>>,
    visiting: &mut Vec<usize>,
) -> Result<Pose, ScenarioError> {
    if let Some(p) = poses[i] {
        return Ok(p);
    }
    let e = raws[i];
    let name = &solids[i].name;
    let file = &files[e.file];
    if visiting.contains(&i) {
        return Err(near(
            file,
            &format!("\"{name}\""),
            format!("solid {name:?} rests on itself through `on`/`in`"),
        ));
    }
    visiting.push(i);
    let mut rotation = rotation_deg(e.raw.rotation.unwrap_or([0.0; 3]));
    if e.raw.upside_down == Some(true) {
        rotation = flipped(rotation);
    }
    let body = &solids[i].body;
    let support = |s: &Spanned<String>| {
        entries.get_index_of(s.get_ref()).ok_or_else(|| {
            file.error_in_string(&s.span(), 0, format!("no solid named {:?}", s.get_ref()))
        })
    };
    let pose = if let Some(at) = e.raw.at {
        Pose::from_parts(at.into(), rotation)
    } else if let Some(s) = &e.raw.on {
        let j = support(s)?;
        let sp = place(j, raws, (solids, entries), files, poses, visiting)?;
        let top = solids[j].body.aabb(&sp);
        let [x, y] = e.raw.xy.unwrap_or([top.center().x, top.center().y]);
        body.resting(rotation, x, y, top.maxs.z)
    } else if let Some(s) = &e.raw.inside {
        let j = support(s)?;
        let sp = place(j, raws, (solids, entries), files, poses, visiting)?;
        let Some((cavity, half, _)) = solids[j].body.cavity_at(&sp) else {
            return Err(file.error_in_string(
                &s.span(),
                0,
                format!("{:?} has no cavity to be in", s.get_ref()),
            ));
        };
        let floor = cavity * nalgebra::Point3::new(0.0, 0.0, -half.z);
        body.resting(rotation, floor.x, floor.y, floor.z)
    } else {
        return Err(near(
            file,
            &format!("\"{name}\""),
            format!("solid {name:?} needs `at`, `on` (with `xy`) or `in`"),
        ));
    };
    visiting.pop();
    poses[i] = Some(pose);
    Ok(pose)
}

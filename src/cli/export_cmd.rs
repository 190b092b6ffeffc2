//! `betr export`: a planned or saved tree as BehaviorTree.CPP v4 XML or Graphviz DOT, and
//! the one reader of tree files the commands share.

use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Context, Result, bail};

use betr::bt::{NodeId, Tree};
use betr::interop::{self, TreeFormat};
use betr::scenario::Scenario;
use betr::session::policy;

use super::engine_driver::{Driver, Start};

/// What `betr export` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// BehaviorTree.CPP v4 XML (opens in Groot2).
    Btcpp,
    /// Graphviz DOT, coloured by the statuses of the last tick of a run.
    Dot,
}

/// Read a tree file (betr text, a policy, or BT.CPP XML) checked against the scenario;
/// what was read differently from how it was written is said on stderr.
pub fn load_tree(scenario: &Scenario, path: &Path) -> Result<(Tree, TreeFormat)> {
    let loaded = interop::load_tree_file(path, &scenario.domain)?;
    for note in &loaded.notes {
        errln!("note: {}: {note}", path.display());
    }
    Ok((loaded.tree, loaded.format))
}

pub fn export(
    source: &Path,
    scenario_arg: Option<&Path>,
    format: Format,
    out: Option<&Path>,
    knowledge: &super::knowledge_cmd::KnowledgeFlags,
) -> Result<ExitCode> {
    let load = |path: &Path| -> Result<Scenario> {
        let mut scenario = Scenario::load(path)?;
        knowledge.apply(&mut scenario)?;
        Ok(scenario)
    };
    // A scenario file, or a scenario's name (`cell/red_on_blue`) where no tree file is.
    let is_scenario = source
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
        || (!source.exists() && super::find_scenario(source).is_ok());
    let drawn_as_written = !is_scenario
        && format == Format::Dot
        && scenario_arg.is_none()
        && source
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
    if drawn_as_written {
        return draw_as_written(source, out);
    }
    let (scenario_path, tree, new_nodes) = if is_scenario {
        let path = super::find_scenario(source)?;
        let scenario = load(&path)?;
        super::goal_of(&scenario, None)?;
        // Planned only: the run that colours a DOT export starts its own session below.
        let mut session = Driver::start(Start {
            runs_tree: false,
            ..Start::new(&scenario)
        })?;
        session.plan(None)?;
        let tree = Arc::unwrap_or_clone(session.tree()?);
        (path, tree, Vec::new())
    } else {
        let text = betr::store::read_text(source, betr::store::TREE_FILE_BYTES)
            .with_context(|| format!("reading tree file {}", source.display()))?;
        let scenario_path = match (scenario_arg, policy::scenario_of(&text)) {
            (Some(s), _) => super::find_scenario(s)?,
            (None, Some(named)) => super::find_scenario(&named).with_context(|| {
                format!(
                    "the scenario {} named in {}",
                    named.display(),
                    source.display()
                )
            })?,
            (None, None) => bail!(
                "{} does not say which scenario it belongs to: pass --scenario FILE",
                source.display()
            ),
        };
        let scenario = load(&scenario_path)?;
        let (tree, format) = load_tree(&scenario, source)?;
        let new_nodes = match format {
            TreeFormat::Text => last_fix_nodes(&text, &scenario, &tree),
            TreeFormat::BtCpp => Vec::new(),
        };
        (scenario_path, tree, new_nodes)
    };
    let scenario = load(&scenario_path)?;
    let name = scenario_path
        .file_stem()
        .map_or_else(|| "tree".to_string(), |s| s.to_string_lossy().into_owned());
    let text = match format {
        Format::Btcpp => interop::to_btcpp(&tree, &scenario.domain, &name)?,
        Format::Dot => {
            // Coloured by a run of the tree in the scenario's world.
            let mut session = Driver::start(Start::new(&scenario))?;
            if is_scenario {
                session.plan(None)?;
            } else {
                session.load(source.to_path_buf(), false)?;
            }
            let run = session.run(|_| {})?;
            interop::to_dot(&tree, run.last.as_deref(), &new_nodes, &name)
        }
    };
    write_out(&text, out)
}

/// A BehaviorTree.CPP file drawn as written, whatever its node kinds (nothing runs it, so
/// nothing colours it).
fn draw_as_written(source: &Path, out: Option<&Path>) -> Result<ExitCode> {
    let tree = super::monitor_cmd::read_tree_file(source)?;
    write_out(&tree.to_dot(&tree.main), out)
}

/// `text` into `out` (whole or not at all), or on standard output.
fn write_out(text: &str, out: Option<&Path>) -> Result<ExitCode> {
    match out {
        Some(path) => {
            betr::store::write_atomic(path, text.as_bytes())
                .with_context(|| format!("writing {}", path.display()))?;
            errln!("Wrote {}", path.display());
        }
        None => out!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}

/// The nodes the policy's last fix added, by the paths its header records.
fn last_fix_nodes(text: &str, scenario: &Scenario, tree: &Tree) -> Vec<NodeId> {
    let Ok(saved) = policy::parse(text, &scenario.domain) else {
        return Vec::new();
    };
    saved.fixes.last().map_or_else(Vec::new, |fix| {
        fix.nodes
            .iter()
            .filter_map(|p| policy::parse_node_path(p))
            .filter_map(|p| tree.node_at_path(&p).ok())
            .collect()
    })
}

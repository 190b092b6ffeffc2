//! `betr verify`: structural checks and model checking of the planned (or a saved) tree,
//! with the shortest counterexample of each violated property, and Promela export.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};

use betr::bt::Tree;
use betr::interop::TreeFormat;
use betr::scenario::Scenario;
use betr::session::Prediction;
use betr::session::policy;
use betr::session::types::{VerifyRequest, VerifyScope};
use betr::verify::{NamedProperty, Property, Report, Rule, Verdict};

use super::engine_driver::{Driver, Start};

/// What `betr verify` is asked.
#[derive(clap::Args)]
pub struct VerifyArgs {
    pub scenario: PathBuf,
    /// A tree file to verify instead of planning one (betr text, a saved policy, or
    /// BehaviorTree.CPP v4 XML).
    #[arg(long)]
    pub tree: Option<PathBuf>,
    /// A property to check besides the scenario's: 'always F', 'never F', 'eventually F'.
    #[arg(long = "property")]
    pub properties: Vec<String>,
    /// Write the model for the SPIN model checker: --export promela FILE.
    #[arg(long, num_args = 2, value_names = ["FORMAT", "FILE"])]
    pub export: Option<Vec<String>>,
    /// Let every action also fail (leaving the state unchanged).
    #[arg(long)]
    pub failures: bool,
    /// Ignore the disturbances the scenario declares.
    #[arg(long)]
    pub no_disturbances: bool,
    /// Stop exploring after this many states (the result is then "unknown").
    #[arg(value_parser = super::ranged(1, 1_000_000_000), long, default_value_t = 200_000)]
    pub max_states: usize,
    /// Ticks within which the tree must succeed from every reachable state.
    #[arg(value_parser = clap::value_parser!(u64).range(1..=1_000_000_000), long, default_value_t = betr::session::RunLimits::DEFAULT.run_ticks)]
    pub max_ticks: u64,
    #[command(flatten)]
    pub knowledge: super::knowledge_cmd::KnowledgeFlags,
}

/// `betr verify`.
pub fn command(args: &VerifyArgs, ascii: bool) -> Result<ExitCode> {
    let scenario = super::load_with(&args.scenario, &args.knowledge)?;
    verify(&scenario, args, ascii)
}

fn verify(scenario: &Scenario, args: &VerifyArgs, ascii: bool) -> Result<ExitCode> {
    let properties = properties_of(scenario, &args.properties)?;
    let promela = promela_file(args.export.as_deref())?;
    let mut session = Driver::start(Start::new(scenario))?;
    let origin = load_or_plan(&mut session, scenario, args.tree.as_ref())?;
    let (scope, report) = session.verify(VerifyRequest {
        properties,
        no_disturbances: args.no_disturbances,
        action_failures: args.failures,
        max_states: Some(args.max_states),
        max_ticks: Some(args.max_ticks),
        promela,
    })?;
    let tree = session.tree()?;
    print_scope(scenario, &origin, &scope, &tree);
    write_report(&mut super::out::Stdout, &report, ascii)?;
    Ok(if report.holds() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The `--property` texts, each parsed and checked against the scenario's vocabulary.
fn properties_of(scenario: &Scenario, texts: &[String]) -> Result<Vec<NamedProperty>> {
    let mut properties = Vec::new();
    for text in texts {
        let property = Property::parse_checked(text, &scenario.domain.vocabulary)
            .map_err(|e| anyhow::anyhow!("--property {text:?}: {e}"))?;
        properties.push(NamedProperty {
            text: text.trim().to_string(),
            property,
        });
    }
    Ok(properties)
}

/// The file `--export promela FILE` names, if given (promela is the only format).
fn promela_file(export: Option<&[String]>) -> Result<Option<PathBuf>> {
    Ok(match export {
        Some(export) => {
            let [format, file] = export else {
                bail!("--export takes a format and a file: --export promela model.pml");
            };
            if format != "promela" {
                bail!("--export {format:?}: the only format is promela");
            }
            Some(PathBuf::from(file))
        }
        None => None,
    })
}

/// Load the tree file into the session, or plan the scenario's goal when there is none;
/// where the tree came from, for the report.
fn load_or_plan(
    session: &mut Driver,
    scenario: &Scenario,
    tree: Option<&PathBuf>,
) -> Result<String> {
    Ok(match tree {
        Some(path) => {
            let text = betr::store::read_text(path, betr::store::TREE_FILE_BYTES)
                .with_context(|| format!("reading tree file {}", path.display()))?;
            session.load(path.clone(), false)?;
            origin_of_file(path, TreeFormat::of(path, &text), &text, scenario)
        }
        None => {
            let goal = super::goal_of(scenario, None)?;
            session.plan(None)?;
            format!("planned in the planner's model for {goal} (no simulation)")
        }
    })
}

/// What was checked, before the report: the scenario, the tree and where it came from,
/// the conditions added and learned, the planner's note, the failures and disturbances
/// explored, and the Promela model written.
fn print_scope(scenario: &Scenario, origin: &str, scope: &VerifyScope, tree: &Tree) {
    outln!("Scenario: {}", scenario.name);
    outln!("Tree:     {origin} ({} nodes)", scope.nodes);
    for c in &scope.added {
        outln!(
            "Added:    {}? before {}! (property: {})",
            c.condition,
            c.action,
            c.property
        );
    }
    match &scope.planned {
        None | Some(Prediction::Success) => {}
        Some(Prediction::Unreachable { condition, .. }) => {
            outln!("Note:     {condition} cannot be achieved");
        }
        Some(Prediction::ActionFails { action, error, .. }) => {
            outln!("Note:     {action}! failed in the model ({error})");
        }
        Some(Prediction::Exhausted { reason }) => {
            outln!("Note:     planning stopped: {reason}");
        }
    }
    for learned in betr::session::knowledge::learned_in_tree(&scenario.domain, tree) {
        outln!(
            "Learned:  {}? before {}! (rule {})",
            learned.condition,
            learned.action,
            learned.rules.join(", ")
        );
    }
    outln!(
        "Checking: action failures {}, {} disturbance(s){}\n",
        if scope.action_failures { "on" } else { "off" },
        scope.disturbances,
        if scope.disturbances_left_out {
            " (--no-disturbances)"
        } else {
            ""
        }
    );
    if let Some((file, claims)) = &scope.promela {
        outln!(
            "Promela model written to {} (ltl claims: {})\n",
            file.display(),
            claims.join(", ")
        );
    }
}

/// How a tree file came to be, for the report: a policy with its fixes is a repaired
/// tree; anything else was loaded as written.
fn origin_of_file(path: &Path, format: TreeFormat, text: &str, scenario: &Scenario) -> String {
    let fixes = Some(text)
        .filter(|_| format == TreeFormat::Text)
        .and_then(|text| policy::parse(text, &scenario.domain).ok())
        .map_or(0, |p| p.fixes.len());
    if fixes > 0 {
        format!(
            "repaired: loaded from the policy {} with {fixes} fix(es)",
            path.display()
        )
    } else {
        format!("loaded from {} ({})", path.display(), format.name())
    }
}

/// The report as `betr verify` prints it, to any writer (`betr resolve` writes a failed
/// change's report to stderr).
pub(super) fn write_report(
    out: &mut dyn std::io::Write,
    report: &Report,
    ascii: bool,
) -> std::io::Result<()> {
    let (ok, bad, unknown, warn) = if ascii {
        ("ok ", "FAIL", "??", "warn")
    } else {
        ("✓", "✕", "?", "⚠")
    };
    writeln!(out, "Structural checks")?;
    if report.findings.is_empty() {
        writeln!(out, "  {ok} no findings")?;
    }
    for f in &report.findings {
        writeln!(out, "  {bad} {f}")?;
        writeln!(out, "      fix: {}", f.hint)?;
    }
    for f in &report.notes {
        writeln!(out, "  {warn} {f}")?;
        let shown = match f.rule {
            Rule::Oscillation => {
                "model checking shows the tree reaches success from every reachable state, so the oscillation cannot start from a state it reaches"
            }
            _ => {
                "model checking shows it holds whenever the action starts (guarded by what is reachable, not by the tree's shape)"
            }
        };
        writeln!(out, "      {shown}; to make the shape guard it: {}", f.hint)?;
    }
    writeln!(out, "\nModel checking")?;
    match &report.model {
        Err(e) => writeln!(out, "  {bad} not possible: {e}")?,
        Ok(m) => {
            for p in &m.properties {
                match &p.verdict {
                    Verdict::Holds if p.detail.is_empty() => writeln!(out, "  {ok} {}", p.name)?,
                    Verdict::Holds => writeln!(out, "  {ok} {} ({})", p.name, p.detail)?,
                    Verdict::Unknown { states } => writeln!(
                        out,
                        "  {unknown} {}: bound reached: stopped after {states} states (raise --max-states)",
                        p.name
                    )?,
                    Verdict::Violated(cx) => {
                        writeln!(out, "  {bad} {}", p.name)?;
                        writeln!(out, "    counterexample:")?;
                        for line in cx.to_string().lines() {
                            writeln!(out, "      {line}")?;
                        }
                    }
                }
            }
            writeln!(
                out,
                "\n{} states, {} transitions, {} atoms, {:.1} ms{}",
                m.states,
                m.transitions,
                m.atoms,
                m.elapsed.as_secs_f64() * 1e3,
                if m.complete {
                    ""
                } else {
                    " (state bound reached)"
                }
            )?;
        }
    }
    writeln!(
        out,
        "\n{}",
        if report.holds() {
            "VERIFIED: every check and property holds"
        } else {
            "NOT VERIFIED"
        }
    )?;
    Ok(())
}

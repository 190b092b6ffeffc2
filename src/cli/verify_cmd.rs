//! `betr verify`: structural checks and model checking of the planned (or a saved) tree,
//! with the shortest counterexample of each violated property, and Promela export.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};

use betr::interop::TreeFormat;
use betr::planner::Outcome;
use betr::scenario::Scenario;
use betr::session::policy;
use betr::verify::{
    self, Limits, NamedProperty, Property, Report, Rule, Verdict, VerifyConfig, VerifyInput,
    plan_in_model,
};
use betr::world;

/// What `betr verify` was asked.
pub struct Args {
    pub tree: Option<PathBuf>,
    pub properties: Vec<String>,
    pub export: Option<Vec<String>>,
    pub failures: bool,
    pub no_disturbances: bool,
    pub max_states: usize,
    pub max_ticks: u64,
    pub ascii: bool,
}

pub fn verify(scenario: &Scenario, args: &Args) -> Result<ExitCode> {
    let config = VerifyConfig::from_scenario(scenario)?;
    let world = world::load(scenario)?;
    let mut properties = config.properties.clone();
    for text in &args.properties {
        let property = Property::parse_checked(text, &scenario.domain.vocabulary)
            .map_err(|e| anyhow::anyhow!("--property {text:?}: {e}"))?;
        properties.push(NamedProperty {
            text: text.trim().to_string(),
            property,
        });
    }
    let disturbances = if args.no_disturbances {
        Vec::new()
    } else {
        config.disturbances.clone()
    };
    let initial = world.facts();
    let (tree, origin, note) = match &args.tree {
        Some(path) => {
            let (tree, format) = super::export_cmd::load_tree(scenario, path)?;
            (tree, origin_of_file(path, format, scenario), String::new())
        }
        None => {
            let goal = super::goal_of(scenario, None)?;
            let planned = plan_in_model(
                &scenario.domain,
                &initial,
                &goal.to_dnf(),
                &properties,
                &disturbances,
            )?;
            let mut note = String::new();
            for c in &planned.constraints {
                note.push_str(&format!(
                    "Added:    {}? before {}! (property: {})\n",
                    c.condition, c.action, c.property
                ));
            }
            match &planned.plan.outcome {
                Outcome::Success => {}
                Outcome::Unreachable { condition, .. } => {
                    note.push_str(&format!("Note:     {condition} cannot be achieved\n"));
                }
                Outcome::ActionFailed { action, error, .. } => {
                    note.push_str(&format!(
                        "Note:     {action}! failed in the model ({error})\n"
                    ));
                }
                Outcome::Exhausted { reason } => {
                    note.push_str(&format!("Note:     planning stopped: {reason}\n"));
                }
            }
            (
                planned.plan.tree,
                format!("planned in the planner's model for {goal} (no simulation)"),
                note,
            )
        }
    };
    let input = VerifyInput {
        domain: &scenario.domain,
        tree: &tree,
        initial: &initial,
        disturbances: &disturbances,
        properties: &properties,
        limits: Limits {
            max_states: args.max_states,
            max_ticks: args.max_ticks,
            action_failures: args.failures || config.action_failures,
        },
    };

    println!("Scenario: {}", scenario.name);
    println!("Tree:     {origin} ({} nodes)", tree.len());
    print!("{note}");
    for learned in betr::session::knowledge::learned_in_tree(&scenario.domain, &tree) {
        println!(
            "Learned:  {}? before {}! (rule {})",
            learned.condition,
            learned.action,
            learned.rules.join(", ")
        );
    }
    println!(
        "Checking: action failures {}, {} disturbance(s){}\n",
        if input.limits.action_failures {
            "on"
        } else {
            "off"
        },
        disturbances.len(),
        if args.no_disturbances && !config.disturbances.is_empty() {
            " (--no-disturbances)"
        } else {
            ""
        }
    );

    if let Some(export) = &args.export {
        let [format, file] = export.as_slice() else {
            bail!("--export takes a format and a file: --export promela model.pml");
        };
        if format != "promela" {
            bail!("--export {format:?}: the only format is promela");
        }
        let model = verify::export_promela(&input)?;
        betr::store::write_atomic(Path::new(file), model.text.as_bytes())
            .with_context(|| format!("writing the Promela model to {file}"))?;
        let claims: Vec<&str> = model.claims.iter().map(|(n, _)| n.as_str()).collect();
        println!(
            "Promela model written to {file} (ltl claims: {})\n",
            claims.join(", ")
        );
    }

    let report = verify::verify(&input);
    write_report(&mut std::io::stdout(), &report, args.ascii)?;
    Ok(if report.holds() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// How a tree file came to be, for the report: a policy with its fixes is a repaired
/// tree; anything else was loaded as written.
fn origin_of_file(path: &Path, format: TreeFormat, scenario: &Scenario) -> String {
    let fixes = std::fs::read_to_string(path)
        .ok()
        .filter(|_| format == TreeFormat::Text)
        .and_then(|text| policy::parse(&text, &scenario.domain).ok())
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

//! Learned knowledge on the command line: the flags every planning command shares, the
//! offer to keep an approved fix as a rule (`betr resolve --learn`), and
//! `betr knowledge list|show|revoke`.

use std::io::BufRead;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};

use betr::scenario::Scenario;
use betr::session::knowledge::{
    KeptRule, Knowledge, Provenance, check_rule, kept_conditions, offered_rule, rule_for_fix,
};
use betr::session::{PolicyStore, Proposal};

#[derive(Args, Debug, Clone, Default)]
pub struct PolicyDir {
    /// Where policies and the learned knowledge (knowledge.toml) live (default:
    /// $XDG_DATA_HOME/betr/policies).
    #[arg(long, value_name = "DIR")]
    pub policy_dir: Option<PathBuf>,
}

impl PolicyDir {
    /// The directory given, else the default one (the workbench's), if there is one.
    pub fn dir(&self) -> Option<PathBuf> {
        self.policy_dir
            .clone()
            .or_else(|| PolicyStore::default_dir(&|k| std::env::var(k).ok()))
    }

    /// The knowledge file, when a directory is given or a default one exists.
    pub fn knowledge_path(&self) -> Option<PathBuf> {
        self.dir().map(|d| Knowledge::path_in(&d))
    }

    fn open(&self) -> Result<Knowledge> {
        let path = self.knowledge_path().context(
            "no policy directory: pass --policy-dir (neither XDG_DATA_HOME nor HOME is set)",
        )?;
        Ok(Knowledge::open(&path)?)
    }
}

#[derive(Args, Debug, Clone, Default)]
pub struct KnowledgeFlags {
    #[command(flatten)]
    pub dir: PolicyDir,
    /// Plan without the learned rules.
    #[arg(long)]
    pub no_knowledge: bool,
}

impl KnowledgeFlags {
    /// The knowledge file, unless `--no-knowledge` or there is no policy directory.
    pub fn load(&self) -> Result<Option<Knowledge>> {
        match self.dir.knowledge_path() {
            Some(path) if !self.no_knowledge => Ok(Some(Knowledge::open(&path)?)),
            _ => Ok(None),
        }
    }

    /// Add the learned rules of the scenario's domain to its skills and say so on stderr
    /// (nothing is said when there are none); the knowledge read, for a session that may
    /// keep more.
    pub fn apply(&self, scenario: &mut Scenario) -> Result<Option<Knowledge>> {
        let Some(knowledge) = self.load()? else {
            return Ok(None);
        };
        let (applied, notes) = knowledge.apply(scenario);
        let (examples, example_notes) = knowledge.apply_examples(scenario);
        for note in notes.iter().chain(&example_notes) {
            errln!("Knowledge: {note}");
        }
        if !applied.is_empty() {
            errln!(
                "Knowledge: {} learned rule(s) from {} ({}); --no-knowledge plans without them",
                applied.len(),
                knowledge.path.display(),
                applied.join(", ")
            );
        }
        if !examples.is_empty() {
            errln!(
                "Knowledge: {} kept example(s) of corrected readings from {} ({}); --no-knowledge reads without them",
                examples.len(),
                knowledge.examples.path.display(),
                examples.join(", ")
            );
        }
        Ok(Some(knowledge))
    }
}

#[derive(Subcommand, Debug)]
pub enum KnowledgeAction {
    /// Everything kept, one per line: the rules (id r…, domain, the rule in words), then
    /// the corrected readings kept as examples (id e…, domain, instruction → goal).
    List {
        #[command(flatten)]
        dir: PolicyDir,
    },
    /// One rule or kept example with where it came from.
    Show {
        id: String,
        #[command(flatten)]
        dir: PolicyDir,
    },
    /// Take a rule or a kept example out: planning no longer adds the rule, reading no
    /// longer shows the example.
    Revoke {
        id: String,
        #[command(flatten)]
        dir: PolicyDir,
    },
}

pub fn run(action: KnowledgeAction) -> Result<ExitCode> {
    match action {
        KnowledgeAction::List { dir } => {
            let knowledge = dir.open()?;
            if knowledge.rules.is_empty() {
                outln!("No learned rules in {}", knowledge.path.display());
            }
            for r in &knowledge.rules {
                outln!("{:<4} {:<6} {}", r.id, r.domain, words(r));
            }
            let examples = &knowledge.examples;
            if examples.examples.is_empty() {
                outln!("No kept examples in {}", examples.path.display());
            }
            for e in &examples.examples {
                outln!(
                    "{:<4} {:<6} \u{ab}{}\u{bb} \u{2192} {}",
                    e.id,
                    e.domain,
                    e.instruction,
                    e.goal
                );
            }
            for problem in &examples.problems {
                errln!("warning: {problem}");
            }
        }
        KnowledgeAction::Show { id, dir } => {
            let knowledge = dir.open()?;
            if let Some(e) = knowledge.examples.examples.iter().find(|e| e.id == id) {
                outln!("Example:     {}", e.id);
                outln!("Domain:      {}", e.domain);
                outln!("Instruction: {}", e.instruction);
                outln!("Goal:        {}", e.goal);
                if let Some(replaced) = &e.replaced {
                    outln!("Replaced:    {replaced}");
                }
                outln!("From:        {} in {}", e.scenario, e.kept_at);
                outln!("Kept by:     {}", e.kept_by);
                return Ok(ExitCode::SUCCESS);
            }
            let r = knowledge.get(&id)?;
            outln!("Rule:        {} ({})", r.id, words(r));
            outln!("Domain:      {}", r.domain);
            outln!("Skill:       {}", r.skill);
            outln!("Requires:    {}", r.requires);
            if let Some(only) = &r.only {
                outln!("Only for:    {}", quoted(only));
            }
            outln!("From:        {} in {}", r.scenario, r.kept_at);
            outln!("Fix:         {} before {}!", r.condition, r.action);
            outln!("Proposed by: {}", r.proposed_by);
            outln!("Kept by:     {}", r.kept_by);
        }
        KnowledgeAction::Revoke { id, dir } if id.starts_with('e') => {
            let mut knowledge = dir.open()?;
            let e = knowledge.examples.revoke(&id)?;
            outln!(
                "Revoked {} (\u{ab}{}\u{bb} \u{2192} {}) from {}",
                e.id,
                e.instruction,
                e.goal,
                knowledge.examples.path.display()
            );
        }
        KnowledgeAction::Revoke { id, dir } => {
            let mut knowledge = dir.open()?;
            let r = knowledge.revoke(&id)?;
            outln!(
                "Revoked {} ({}) from {}",
                r.id,
                words(&r),
                knowledge.path.display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn quoted(objects: &[String]) -> String {
    objects
        .iter()
        .map(|o| format!("\"{o}\""))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A kept rule in words, with positional objects shown as `{1}` or the objects it is for.
fn words(r: &KeptRule) -> String {
    let mut requires = r.requires.clone();
    let subject = match &r.only {
        Some(only) => {
            for (i, o) in only.iter().enumerate().rev() {
                requires = requires.replace(&format!("{{{}}}", i + 1), o);
            }
            format!("{} {}", r.skill, quoted(only))
        }
        None => {
            let n = (1..=9)
                .filter(|i| r.requires.contains(&format!("{{{i}}}")))
                .max()
                .unwrap_or(0);
            let objects: Vec<String> = (1..=n).map(|i| format!("{{{i}}}")).collect();
            format!("{} {}", r.skill, objects.join(" "))
        }
    };
    format!("{} needs {requires}", subject.trim_end())
}

/// The person chose reading `index` (from 0) of `readings` for `instruction`: when it was
/// not the one offered first, keep it as a correction in the policy directory's examples
/// and say so (or why not).
pub fn keep_choice(
    dir: &PolicyDir,
    (scenario, scenario_path): (&Scenario, &std::path::Path),
    instruction: &str,
    readings: &[betr::session::Reading],
    index: usize,
) -> Result<()> {
    let (Some(first), Some(chosen)) = (readings.first(), readings.get(index)) else {
        return Ok(());
    };
    if index == 0 {
        return Ok(());
    }
    let mut knowledge = dir.open()?;
    match knowledge.examples.keep_correction(
        (scenario, scenario_path),
        (instruction, &chosen.goal),
        Some(&first.goal),
        "a person, choosing a reading not offered first (terminal)",
    ) {
        Ok((kept, _)) => outln!(
            "Correction kept as example {} of the {} domain (in {}; betr knowledge revoke {} takes it out)",
            kept.id,
            kept.domain,
            knowledge.examples.path.display(),
            kept.id
        ),
        Err(e) => outln!("{e}"),
    }
    Ok(())
}

/// After a resolved session: offer each kept fix as a rule (asking unless `yes`), check
/// it, and keep it in the knowledge file. Returns how many were kept.
pub fn offer(
    scenario: &Scenario,
    scenario_path: &std::path::Path,
    kept: &[(Proposal, String)],
    dir: &PolicyDir,
    yes: bool,
) -> Result<usize> {
    let mut knowledge = dir.open()?;
    let mut count = 0;
    for (action, condition, author) in kept_conditions(kept) {
        let rule = if yes {
            let (rule, refused) = rule_for_fix(action, condition, scenario, &knowledge);
            for (rule, why) in refused {
                outln!("Not kept: {} — {why}", rule.describe(&scenario.domain));
            }
            let Some(rule) = rule else {
                continue;
            };
            outln!(
                "Keep as a rule: {}? yes (--yes --learn)",
                rule.describe(&scenario.domain)
            );
            rule
        } else {
            let lifted = offered_rule(action, condition, false);
            let only = offered_rule(action, condition, true);
            let Some(rule) = ask(&lifted, &only, scenario) else {
                outln!("Not kept.");
                continue;
            };
            if let Err(refusal) = check_rule(&rule, scenario, &knowledge) {
                outln!("Not kept: {} — {refusal}", rule.describe(&scenario.domain));
                continue;
            }
            rule
        };
        let (kept, new) = knowledge.keep(KeptRule::new(
            &rule,
            scenario,
            Provenance {
                scenario_file: scenario_path.display().to_string(),
                action,
                condition,
                proposed_by: author.to_string(),
                kept_by: if yes { "--yes --learn" } else { "a person" }.into(),
            },
        ))?;
        if !new {
            outln!(
                "Already kept as rule {}: {} (in {})",
                kept.id,
                rule.describe(&scenario.domain),
                knowledge.path.display()
            );
            continue;
        }
        outln!(
            "Kept rule {}: {} (in {})",
            kept.id,
            rule.describe(&scenario.domain),
            knowledge.path.display()
        );
        count += 1;
    }
    Ok(count)
}

fn ask(
    lifted: &betr::domain::LearnedRule,
    only: &betr::domain::LearnedRule,
    scenario: &Scenario,
) -> Option<betr::domain::LearnedRule> {
    let general = lifted.only.is_none();
    if general {
        out!(
            "Keep as a rule: {}? [y]es / [o]nly {} / [N]o ",
            lifted.describe(&scenario.domain),
            only.describe(&scenario.domain)
        );
    } else {
        out!(
            "Keep as a rule: {}? [y/N] ",
            only.describe(&scenario.domain)
        );
    }
    super::out::flush();
    let mut line = String::new();
    match std::io::stdin().lock().read_line(&mut line) {
        Ok(0) | Err(_) => None,
        Ok(_) => match line.trim().to_ascii_lowercase().as_str() {
            "y" | "yes" => Some(if general {
                lifted.clone()
            } else {
                only.clone()
            }),
            "o" | "only" if general => Some(only.clone()),
            _ => None,
        },
    }
}

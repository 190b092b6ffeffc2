//! Policies that last: the improved tree of a task, saved with a header that says which
//! nodes came from which approved proposal, when, and from which model, so that loading
//! the same task again starts from it and a failure already resolved costs no LLM call.
//!
//! A policy is a tree in the text format (`bt::to_text`) preceded by `#` comment lines,
//! which the tree parser ignores:
//!
//! ```text
//! # betr policy
//! # scenario: scenarios/cell/red_on_blue.toml (Red cube on the blue cube)
//! # instruction: Put the blue cube on the green cube
//! # goal: "blue cube" on "green cube"
//! # saved at: 2026-05-01T09:30:00Z
//! # fix 1: insert ~"any object" on "blue cube" as the first precondition(s) of grasp "blue cube"!
//! #   nodes: 0.1.0, 0.1.0.1
//! #   model: fake-model; approved by a person; at 2026-05-01T09:29:41Z
//! fallback
//!   ...
//! ```
//!
//! Files are keyed by the scenario file's stem and a short hash of the goal, and written
//! atomically (`store::write_atomic`): a reader never sees half of one.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::bt::{self, Tree};
use crate::domain::Domain;
use crate::goal::Formula;
use crate::planner;

pub use super::types::{PolicyError, PolicyTreeError};

/// How a fix got into the tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Approval {
    /// A person approved the model's proposal.
    Person,
    /// `--auto-approve` accepted it without asking.
    Auto,
    /// A person wrote or edited it.
    Edited,
}

impl Approval {
    fn text(self) -> &'static str {
        match self {
            Approval::Person => "approved by a person",
            Approval::Auto => "auto-approved",
            Approval::Edited => "written by a person",
        }
    }

    fn parse(text: &str) -> Option<Approval> {
        [Approval::Person, Approval::Auto, Approval::Edited]
            .into_iter()
            .find(|a| a.text() == text)
    }
}

/// One applied change: what it was, which nodes it added (paths), who proposed it.
#[derive(Debug, Clone, PartialEq)]
pub struct Fix {
    /// The proposal as a sentence (`insert ... as the first precondition(s) of ...`).
    pub change: String,
    /// Paths (`0.1.2`) of the nodes the change added, in the tree as saved.
    pub nodes: Vec<String>,
    /// Who proposed it: a model's name, or `a person`.
    pub model: String,
    pub approval: Approval,
    /// When it was applied (RFC 3339, UTC).
    pub at: String,
}

/// A saved policy.
#[derive(Debug, Clone)]
pub struct Policy {
    pub scenario: String,
    pub instruction: Option<String>,
    pub goal: String,
    pub saved_at: String,
    pub fixes: Vec<Fix>,
    pub tree: Tree,
}

/// Where policies live.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyStore {
    pub dir: PathBuf,
}

impl PolicyStore {
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        PolicyStore { dir: dir.into() }
    }

    /// `$XDG_DATA_HOME/betr/policies`, else `~/.local/share/betr/policies`.
    pub fn default_dir(var: &dyn Fn(&str) -> Option<String>) -> Option<PathBuf> {
        let data = var("XDG_DATA_HOME")
            .filter(|d| !d.is_empty())
            .map(PathBuf::from)
            .or_else(|| var("HOME").map(|h| Path::new(&h).join(".local/share")))?;
        Some(data.join("betr").join("policies"))
    }

    /// The file of a task: `<scenario stem>-<8 hex digits of the goal's hash>.bt`.
    pub fn path_for(&self, scenario: &Path, goal: &Formula) -> PathBuf {
        let stem = stem(scenario);
        let digest = Sha256::digest(goal.to_string().as_bytes());
        let hash: String = digest.iter().take(4).map(|b| format!("{b:02x}")).collect();
        self.dir.join(format!("{stem}-{hash}.bt"))
    }

    /// A saved policy of this scenario made for the same instruction, if any (so the
    /// instruction needs no LLM call to be read again).
    pub fn find_by_instruction(&self, scenario: &Path, instruction: &str) -> Option<PathBuf> {
        let prefix = format!("{}-", stem(scenario));
        let mut files: Vec<PathBuf> = std::fs::read_dir(&self.dir)
            .ok()?
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| {
                p.extension().is_some_and(|x| x == "bt")
                    && p.file_name()
                        .is_some_and(|n| n.to_string_lossy().starts_with(&prefix))
            })
            .collect();
        files.sort();
        files.into_iter().find(|p| {
            std::fs::read_to_string(p).is_ok_and(|text| {
                header_value(&text, "instruction").is_some_and(|i| i == instruction.trim())
            })
        })
    }

    /// Write `policy` to `path` atomically.
    pub fn save(&self, path: &Path, policy: &Policy) -> Result<(), PolicyError> {
        save(path, policy)
    }
}

/// Write `policy` to `path` atomically (never half-written).
pub fn save(path: &Path, policy: &Policy) -> Result<(), PolicyError> {
    crate::store::write_atomic(path, render(policy).as_bytes()).map_err(|e| PolicyError::Write {
        path: path.display().to_string(),
        detail: e.to_string(),
    })
}

fn stem(scenario: &Path) -> String {
    scenario
        .file_stem()
        .map_or_else(|| "task".into(), |s| s.to_string_lossy().into_owned())
}

/// The text of a policy file.
pub fn render(policy: &Policy) -> String {
    let mut out = String::from("# betr policy\n");
    out.push_str(&format!("# scenario: {}\n", one_line(&policy.scenario)));
    if let Some(i) = &policy.instruction {
        out.push_str(&format!("# instruction: {}\n", one_line(i)));
    }
    out.push_str(&format!("# goal: {}\n", one_line(&policy.goal)));
    out.push_str(&format!("# saved at: {}\n", policy.saved_at));
    for (i, fix) in policy.fixes.iter().enumerate() {
        out.push_str(&format!("# fix {}: {}\n", i + 1, one_line(&fix.change)));
        out.push_str(&format!("#   nodes: {}\n", fix.nodes.join(", ")));
        out.push_str(&format!(
            "#   model: {}; {}; at {}\n",
            one_line(&fix.model),
            fix.approval.text(),
            fix.at
        ));
    }
    out.push_str(&bt::to_text(&policy.tree));
    out
}

fn one_line(text: &str) -> String {
    text.replace(['\n', '\r'], " ")
}

fn header_value<'t>(text: &'t str, key: &str) -> Option<&'t str> {
    let prefix = format!("# {key}: ");
    text.lines()
        .take_while(|l| l.starts_with('#'))
        .find_map(|l| l.strip_prefix(&prefix))
        .map(str::trim)
}

/// Read a policy and check its tree against `domain`.
pub fn load(path: &Path, domain: &Domain) -> Result<Policy, PolicyError> {
    let text = crate::store::read_text(path, crate::store::TREE_FILE_BYTES).map_err(|e| {
        PolicyError::Read {
            path: path.display().to_string(),
            detail: e.to_string(),
        }
    })?;
    parse(&text, domain).map_err(|error| PolicyError::Invalid {
        path: path.display().to_string(),
        error: Box::new(error),
    })
}

/// The scenario file a policy's header names (`# scenario: PATH (name)`), if it has one.
pub fn scenario_of(text: &str) -> Option<PathBuf> {
    let value = header_value(text, "scenario")?;
    let path = match value.split_once(" (") {
        Some((path, name)) if name.ends_with(')') => path,
        _ => value,
    };
    (!path.is_empty()).then(|| PathBuf::from(path))
}

/// A node path as the header writes it (`0.1.2`, `root`).
pub fn parse_node_path(text: &str) -> Option<Vec<usize>> {
    if text == "root" {
        return Some(Vec::new());
    }
    text.split('.').map(|p| p.parse().ok()).collect()
}

/// Read a policy's text.
pub fn parse(text: &str, domain: &Domain) -> Result<Policy, PolicyTreeError> {
    let tree = bt::parse(text)?;
    planner::check_tree(domain, &tree)?;
    let header: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
    let mut fixes: Vec<Fix> = Vec::new();
    for line in &header {
        if let Some(rest) = line.strip_prefix("# fix ") {
            let change = rest.split_once(": ").map_or(rest, |(_, c)| c);
            fixes.push(Fix {
                change: change.to_string(),
                nodes: Vec::new(),
                model: String::new(),
                approval: Approval::Person,
                at: String::new(),
            });
        } else if let (Some(fix), Some(nodes)) =
            (fixes.last_mut(), line.strip_prefix("#   nodes: "))
        {
            // Values are read trimmed, as `header_value` reads them: a blank (a carriage
            // return before the line's end) is not part of a node path or a time.
            fix.nodes = nodes
                .split(", ")
                .map(str::trim)
                .filter(|n| !n.is_empty())
                .map(str::to_string)
                .collect();
        } else if let (Some(fix), Some(who)) = (fixes.last_mut(), line.strip_prefix("#   model: "))
        {
            let parts: Vec<&str> = who.split("; ").collect();
            if let [model, approval, at] = parts.as_slice() {
                fix.model = (*model).to_string();
                fix.approval = Approval::parse(approval).unwrap_or(Approval::Person);
                fix.at = at.strip_prefix("at ").unwrap_or(at).trim().to_string();
            }
        }
    }
    Ok(Policy {
        scenario: header_value(text, "scenario").unwrap_or_default().into(),
        instruction: header_value(text, "instruction").map(str::to_string),
        goal: header_value(text, "goal").unwrap_or_default().into(),
        saved_at: header_value(text, "saved at").unwrap_or_default().into(),
        fixes,
        tree,
    })
}

/// Now as RFC 3339 in UTC, to the second.
pub fn now_rfc3339() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    rfc3339(secs)
}

/// `secs` since the Unix epoch as `YYYY-MM-DDTHH:MM:SSZ` (proleptic Gregorian calendar).
pub fn rfc3339(secs: u64) -> String {
    let days = i64::try_from(secs / 86_400).unwrap_or(0);
    let rem = secs % 86_400;
    // Howard Hinnant's civil_from_days.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    fn scenario() -> Scenario {
        Scenario::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml"),
        )
        .unwrap()
    }

    #[test]
    fn the_scenario_is_read_from_the_header() {
        let named =
            "# betr policy\n# scenario: scenarios/cell/red_on_blue.toml (Red cube (1))\nsequence\n";
        assert_eq!(
            scenario_of(named),
            Some(PathBuf::from("scenarios/cell/red_on_blue.toml"))
        );
        let bare = "# scenario: cafe/no_coffee.toml\n";
        assert_eq!(
            scenario_of(bare),
            Some(PathBuf::from("cafe/no_coffee.toml"))
        );
        assert_eq!(scenario_of("sequence\n  A?\n"), None);
    }

    #[test]
    fn timestamps_are_rfc3339_utc() {
        assert_eq!(rfc3339(0), "1970-01-01T00:00:00Z");
        assert_eq!(rfc3339(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(rfc3339(1_700_000_000), "2023-11-14T22:13:20Z");
    }

    #[test]
    fn a_policy_round_trips_with_its_header() {
        let s = scenario();
        let tree = bt::parse("fallback\n  \"blue cube\" on \"green cube\"?\n").unwrap();
        let policy = Policy {
            scenario: "scenarios/cell/red_on_blue.toml".into(),
            instruction: Some("Put the blue cube\non the green cube".into()),
            goal: "\"blue cube\" on \"green cube\"".into(),
            saved_at: rfc3339(1_700_000_000),
            fixes: vec![Fix {
                change: "insert X".into(),
                nodes: vec!["0.1".into(), "0.1.0".into()],
                model: "fake-model".into(),
                approval: Approval::Auto,
                at: rfc3339(1_700_000_000),
            }],
            tree,
        };
        let text = render(&policy);
        assert!(text.starts_with("# betr policy\n"), "{text}");
        let back = parse(&text, &s.domain).unwrap();
        assert_eq!(
            back.instruction.as_deref(),
            Some("Put the blue cube on the green cube")
        );
        assert_eq!(back.fixes, policy.fixes);
        assert_eq!(bt::to_text(&back.tree), bt::to_text(&policy.tree));
        assert!(parse("fallback\n  Nonsense_Thing?\n", &s.domain).is_err());
    }

    #[test]
    fn header_values_are_read_trimmed_so_a_rendered_policy_reads_back_the_same() {
        let s = scenario();
        let text = "# fix 1: x\n#   nodes: \r0.1, x, \r\r\n#   model: m; auto-approved; at t\r\r\nfallback\n  \"blue cube\" on \"green cube\"?\n";
        let policy = parse(text, &s.domain).unwrap();
        assert_eq!(policy.fixes[0].nodes, ["0.1", "x"]);
        assert_eq!(policy.fixes[0].at, "t");
        let back = parse(&render(&policy), &s.domain).unwrap();
        assert_eq!(back.fixes, policy.fixes);
        assert_eq!(render(&back), render(&policy));
        // Only the `at ` the header writes is taken off the time.
        let spaced = text.replace("auto-approved; at t\r\r", "auto-approved;   at at t");
        let policy = parse(&spaced, &s.domain).unwrap();
        assert_eq!(policy.fixes[0].at, "at at t");
        let back = parse(&render(&policy), &s.domain).unwrap();
        assert_eq!(back.fixes, policy.fixes);
    }

    #[test]
    fn files_are_keyed_by_scenario_and_goal() {
        let store = PolicyStore::new("/p");
        let s = scenario();
        let goal = s.goal.clone().unwrap();
        let a = store.path_for(Path::new("scenarios/cell/red_on_blue.toml"), &goal);
        let name = a.file_name().unwrap().to_string_lossy().to_string();
        assert!(
            name.starts_with("red_on_blue-") && name.ends_with(".bt"),
            "{name}"
        );
        assert_eq!(name.len(), "red_on_blue-".len() + 8 + 3);
        let other = s.parse_goal("\"red cube\" on \"green cube\"").unwrap();
        assert_ne!(a, store.path_for(Path::new("x/red_on_blue.toml"), &other));
        let dir = |k: &str| match k {
            "HOME" => Some("/home/u".to_string()),
            _ => None,
        };
        assert_eq!(
            PolicyStore::default_dir(&dir),
            Some(PathBuf::from("/home/u/.local/share/betr/policies"))
        );
    }
}

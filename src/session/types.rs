//! The vocabulary of sessions: options, proposals, events, endings and errors.

use std::path::PathBuf;
use std::sync::Arc;

use crate::bt::{Forced, NodeId, TickRecord, Tree};
use crate::domain::{ActionCall, Atom, Condition, Value};
use crate::goal::Formula;
use crate::llm::LlmError;
use crate::llm::prompt::{PromptError, Templates, Variant};
use crate::llm::reply::{self, ReplyError};
use crate::llm::usage::UsageTotals;
use crate::planner::RepairError;
use crate::scenario::ScenarioError;
use crate::verify::Report;
use crate::world::cell::snapshot::{MotionView, SceneSnapshot};

/// Why a session has no language model (it still plans, ticks and takes the conditions a
/// person types).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoModel {
    /// The front end works without one: its failures are reported, not asked about.
    #[error("{0} runs without a language model")]
    NotUsed(&'static str),
    /// The configured model could not be fetched or built.
    #[error("{0}")]
    Unavailable(String),
}

/// The evidence shown with a proposal, before the model's reasoning.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Evidence {
    /// What betr found, one finding a line, the failure first.
    pub findings: Vec<String>,
    /// The objects the failure involves: the action's, those its error names, those
    /// whose facts stood in the way, and those the change names.
    pub objects: Vec<String>,
    /// Why the model's reasoning is not to be taken as the reason, when it is not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub doubt: Option<String>,
}

/// What trying the conditions related to a failed action found in simulation, before
/// the model is asked: the model chooses among `fixes`.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Shortlist {
    /// Conditions that fix the failure alone: those after which the whole tree succeeds,
    /// or when there are none, those after which it gets further (to an action it had
    /// before); conditions about any object first, then positive ones, then negations.
    pub fixes: Vec<Condition>,
    /// How many conditions were tried.
    pub tried: usize,
    /// The objects the conditions were about.
    pub objects: Vec<String>,
    /// Fixes left out because they were proposed for this failure before and refused.
    #[serde(default)]
    pub refused: usize,
    /// Fixes left out because the tree with them breaks a property the scenario declares,
    /// each with that property.
    #[serde(default)]
    pub breaking: Vec<(Condition, String)>,
}

impl Shortlist {
    /// Leaves out the fixes that break a declared property, keeping each with the
    /// property it breaks.
    pub fn leave_out_breaking(&mut self, breaking: Vec<(Condition, String)>) {
        self.fixes.retain(|c| !breaking.iter().any(|(b, _)| b == c));
        self.breaking = breaking;
    }

    /// What was tried and what fixes the failure, as one finding of the evidence.
    pub fn finding(&self) -> String {
        let about: Vec<String> = self.objects.iter().map(|o| format!("\"{o}\"")).collect();
        let tried = format!(
            "tried {} condition(s) about {} in simulation",
            self.tried,
            about.join(", ")
        );
        let mut left_out = String::new();
        if self.refused > 0 {
            left_out.push_str(&format!(" ({} refused before, left out)", self.refused));
        }
        for (condition, property) in &self.breaking {
            left_out.push_str(&format!(" ({condition} left out: it breaks {property})"));
        }
        if self.fixes.is_empty() {
            return format!("{tried}: none fixes the failure alone{left_out}");
        }
        let fixes: Vec<String> = self.fixes.iter().map(ToString::to_string).collect();
        format!(
            "{tried}: {} fix the failure ({}){left_out}",
            self.fixes.len(),
            fixes.join(", ")
        )
    }
}

impl std::fmt::Display for Shortlist {
    /// The finding, with what the model is asked to do with it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let asked = if self.fixes.is_empty() {
            "the model names the condition itself"
        } else {
            "the model chooses among them"
        };
        write!(f, "{}; {asked}", self.finding())
    }
}

/// One reading of an instruction, as a person chooses it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reading {
    pub goal: Formula,
    /// The goal in words, from the predicates' descriptions.
    pub words: String,
    /// The first actions the robot would take, in order.
    pub first_actions: Vec<String>,
    /// Every action of the plan's run in simulation (what makes two readings one).
    pub(crate) actions: Vec<String>,
}

/// Why a policy cannot be read, used or written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PolicyError {
    #[error("cannot read policy {path}: {detail}")]
    Read { path: String, detail: String },
    #[error("policy {path}: {error}")]
    Invalid {
        path: String,
        error: Box<PolicyTreeError>,
    },
    #[error("cannot write policy {path}: {detail}")]
    Write { path: String, detail: String },
}

/// Why a policy's tree cannot be used: its text (with the position), or a leaf the domain
/// does not know (with the node's path).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PolicyTreeError {
    #[error(transparent)]
    Text(#[from] crate::bt::ParseError),
    #[error(transparent)]
    Check(#[from] crate::planner::TreeCheckError),
}

/// How the loop asks and how long it keeps trying.
#[derive(Debug, Clone)]
pub struct Options {
    /// Questions about failures (each reply, valid or not, is one round).
    pub max_rounds: usize,
    /// Proposals a person may reject for one failure, each followed by the model asked
    /// again with the rejected fix left out; past it, the person types the fix.
    pub max_rejections: usize,
    /// Candidates drawn per question when the first answer fails its checks (goals), or
    /// always (proposals for a failure, each tried in simulation before it is offered).
    pub candidates: usize,
    /// Times the model is told why its candidate goals were refused and asked again.
    pub goal_feedback_rounds: usize,
    /// `resolve`: work on the scenario's stated goal instead of reading the instruction
    /// (so the failure under study is reached whatever a model would read); the
    /// instruction still reaches the questions about failures.
    pub use_scenario_goal: bool,
    /// The resolve loop saves the tree that succeeds as a policy in this directory, with
    /// its provenance, where the workbench finds it (keyed by scenario and goal).
    pub policy_dir: Option<std::path::PathBuf>,
    pub temperature: f32,
    pub max_tokens: u32,
    /// How alike a listed name must be to be offered ("did you mean …?") for a name of a
    /// reply that the scene does not have; nothing is ever replaced by it.
    pub min_similarity: f64,
    pub templates: Templates,
    /// Constrain replies with a JSON schema when the model supports it.
    pub structured: bool,
    /// Constrain replies with a grammar when the model supports it (the local model).
    pub grammar: bool,
    /// The first answer to a goal question is the most likely whole answer of this many
    /// beams searched under the grammar (the embedded model), and the runners-up are
    /// candidates too, with no more calls; 1: one greedy answer.
    pub beams: u32,
    /// When an instruction has more than one reading that would make the robot do
    /// different things, offer them for the person to choose (`Event::Readings`); off:
    /// the best one is taken.
    pub choose_reading: bool,
    /// How the instruction is read and the failure asked about: the product's are the
    /// defaults; only the lab builds others.
    pub steps: Steps,
}

/// How an instruction is read and a failure asked about: the prompt's shape and the steps
/// around each question. The workbench and the one-shot commands always run the default,
/// which is what the measurements of docs/EVAL.md chose; only the lab (`betr eval`, which
/// builds these from its own flags) runs others, to measure what each step earns.
#[derive(Debug, Clone)]
pub struct Steps {
    /// The shape of the prompts (parts left out, chain of thought, which examples).
    pub prompt: Variant,
    /// Check every goal read from an instruction (parses, not contradictory, not true
    /// already, plannable) and draw more candidates when the first fails; off: the
    /// first usable answer is taken, as the paper's single call.
    pub check_goals: bool,
    /// With checks on, read a request of several wishes one wish at a time and join the
    /// goals as the request joins them; off: the request is read whole.
    pub read_by_parts: bool,
    /// Ask the first value of a numeric parameter as a level of the robot's declared
    /// range (very low … very high), turned into a number by betr; off: as a number.
    pub value_levels: bool,
    /// Before asking about a failure, try the conditions over the failing action's objects
    /// in simulation and let the model choose among those that fix it; off: the model
    /// names the condition out of the whole vocabulary.
    pub shortlist: bool,
    /// Try each of the model's candidates for a failure in simulation and propose the
    /// first that fixes it; off: the model's first usable answer is proposed as it is (the
    /// paper's single call), and only the change's own check shows whether it helps.
    pub screen_proposals: bool,
    /// Plan and screen in the scenario's model only: a symbolic world's hidden rules (the
    /// requirements its failures come from) are left out of the planning world, as a
    /// robot's planner has only its model of the world; off: the planning world is the
    /// world as the scenario writes it.
    pub planning_without_hidden_rules: bool,
    /// Detectors of plain misreadings left out, by name (`reading::MISREADINGS`): empty
    /// but in the lab, which measures what each earns.
    pub without_misreadings: Vec<String>,
}

impl Default for Steps {
    fn default() -> Self {
        Steps {
            prompt: Variant::default(),
            check_goals: true,
            read_by_parts: true,
            value_levels: true,
            shortlist: true,
            screen_proposals: true,
            planning_without_hidden_rules: false,
            without_misreadings: Vec::new(),
        }
    }
}

/// Candidates per question: the first answer and three sampled ones.
pub const DEFAULT_CANDIDATES: usize = 4;

/// Beams searched for a goal's first answer.
pub const DEFAULT_BEAMS: u32 = 4;

impl Default for Options {
    fn default() -> Self {
        Options {
            max_rounds: 5,
            max_rejections: 3,
            candidates: DEFAULT_CANDIDATES,
            goal_feedback_rounds: 2,
            use_scenario_goal: false,
            policy_dir: None,
            temperature: 0.0,
            max_tokens: 800,
            min_similarity: reply::MIN_SIMILARITY,
            templates: Templates::builtin(),
            structured: false,
            grammar: true,
            beams: DEFAULT_BEAMS,
            choose_reading: false,
            steps: Steps::default(),
        }
    }
}

/// What `Verify` checks besides the scenario's `[verify]` table, and how far.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VerifyRequest {
    /// Properties checked besides the scenario's.
    pub properties: Vec<crate::verify::NamedProperty>,
    /// Leave the scenario's disturbances out.
    pub no_disturbances: bool,
    /// Let every action fail as well (the scenario may ask for it too).
    pub action_failures: bool,
    /// Bounds of the exploration (none: the defaults).
    pub max_states: Option<usize>,
    pub max_ticks: Option<u64>,
    /// Also write the model that is checked as Promela to this file.
    pub promela: Option<PathBuf>,
}

/// What a verification checks, told before its report.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VerifyScope {
    pub nodes: usize,
    /// Preconditions the safety properties added when the tree was planned in the model.
    pub added: Vec<crate::verify::model_plan::Constraint>,
    /// How planning in the model ended, when it did not reach success there.
    pub planned: Option<super::planned::Prediction>,
    pub action_failures: bool,
    pub disturbances: usize,
    /// The scenario has disturbances and the request left them out.
    pub disturbances_left_out: bool,
    /// The Promela model written, with its LTL claims' names.
    pub promela: Option<(PathBuf, Vec<String>)>,
}

/// What a model proposes for a failure.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Proposal {
    /// Insert these as the first preconditions of the failing action.
    Conditions {
        action: ActionCall,
        node: NodeId,
        conditions: Vec<Condition>,
    },
    /// Set a value parameter on every node of `skill` acting on `object`.
    Value {
        skill: String,
        object: String,
        param: String,
        value: Value,
    },
}

impl std::fmt::Display for Proposal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Proposal::Conditions {
                action, conditions, ..
            } => {
                let c: Vec<String> = conditions.iter().map(ToString::to_string).collect();
                write!(
                    f,
                    "insert {} as the first precondition(s) of {action}!",
                    c.join(" & ")
                )
            }
            Proposal::Value {
                skill,
                object,
                param,
                value,
            } => {
                write!(f, "set {param} = {value} on every {skill} \"{object}\"")
            }
        }
    }
}

/// What a question to the model asks for.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "question", rename_all = "snake_case")]
pub enum Question {
    /// The goal of the instruction: its first answer (`draw` 0) or another candidate
    /// (`draw` counts from 0 among `draws`).
    Goal { draw: usize, draws: usize },
    /// The objects and places the instruction names.
    NamedObjects,
    /// The preconditions the failed `action` misses.
    Preconditions { action: ActionCall },
    /// A value for the parameter `param` of `action`.
    Value { param: String, action: ActionCall },
    /// Whether the instruction asks for `atom`.
    Confirm { atom: Atom },
}

impl std::fmt::Display for Question {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Question::Goal { draw: 0, .. } => f.write_str("the goal of the instruction"),
            Question::Goal { draw, draws } => {
                write!(f, "another candidate goal ({} of {draws})", draw + 1)
            }
            Question::NamedObjects => f.write_str("the objects and places the instruction names"),
            Question::Preconditions { action } => write!(f, "missing preconditions of {action}!"),
            Question::Value { param, action } => write!(f, "a value for {param} of {action}!"),
            Question::Confirm { atom } => write!(f, "whether the instruction asks for {atom}"),
        }
    }
}

/// What a session reports, in order: the steps of the resolve loop (asking, replies,
/// goal, failure, proposal, approval, repair, success) and, for front ends that show a
/// session live, the tree, the statuses of each tick, the world, usage and errors. A
/// recording is these events written as they are (`record`), one JSON object each, tagged
/// by `event`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// A question goes to the model.
    Asking {
        what: Question,
    },
    /// The person stopped the model call under way; no answer comes.
    CallCancelled,
    /// A reply came back: who answered, its tokens and latency.
    Replied {
        attribution: String,
        prompt_tokens: u64,
        completion_tokens: u64,
        latency_ms: u64,
        /// The reply's text as received.
        text: String,
    },
    /// A reply that could not be used; the loop asks again while rounds remain.
    InvalidReply {
        error: String,
    },
    /// A candidate answer that was checked and set aside, and why (a goal that holds
    /// already, a proposal that did not fix the failure in simulation, ...).
    CandidateRejected {
        candidate: String,
        /// The candidate, when it was a proposal for a failure.
        proposal: Option<Proposal>,
        reason: String,
        /// Who wrote the candidate when it was not the model.
        author: Option<String>,
    },
    /// The instruction read as a goal; `matches_expected` compares with the scenario's goal.
    Goal {
        goal: Formula,
        reasoning: Option<String>,
        matches_expected: Option<bool>,
        /// Where the goal came from: `model` (the reply's attribution says which), a
        /// person, a policy file, the scenario file.
        author: String,
        /// The model's first answer when the goal kept is another one (a relation it had
        /// the other way round turned back, a part no word asks for taken out, another
        /// candidate voted for): said, so that no change to what the model wrote is silent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        first_answer: Option<Formula>,
        /// A model's reading: its doubt level and what it rests on, in one line.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        doubt: Option<String>,
    },
    /// The instruction has more than one reading that would make the robot do different
    /// things, or one the checks doubt (`doubt`, why): the person chooses one
    /// (`Command::ChooseReading`), best first, before anything runs.
    Readings {
        instruction: String,
        readings: Vec<Reading>,
        doubt: Option<String>,
    },
    /// An action failed in simulation; `node_path` is the node's path (child indices
    /// from the root), which a person reads as `1.0.1.1`.
    ActionFailed {
        action: ActionCall,
        node: NodeId,
        node_path: Vec<usize>,
        error: String,
        /// The executor it failed in (reality), or none: in betr's world.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        executor: Option<String>,
    },
    /// A proposal, before approval, with who wrote it (the model, the simulation that
    /// narrowed it, a person, betr's midway value).
    Proposal {
        proposal: Proposal,
        /// The author's own reasoning (a model's is checked against the evidence).
        reasoning: Option<String>,
        author: String,
        /// What betr itself found about the failure and the change, shown first; `None`
        /// when the change was not asked of a model (a person's edit).
        evidence: Option<Box<Evidence>>,
    },
    Approved,
    Rejected,
    /// The planner planned or grew the tree: what it did and what its simulation predicts
    /// (emitted before the `TreeChanged` that shows the tree).
    Planned {
        summary: super::planned::PlanSummary,
    },
    /// The tree was changed: how many nodes were added, and on how many actions a value
    /// was set.
    Repaired {
        added_nodes: usize,
        valued_nodes: usize,
    },
    /// The approved proposal did not change the failure; it was undone.
    DidNotHelp {
        reason: String,
    },
    /// The tree succeeded: in betr's world, or performed by `executor` (its name).
    Success {
        ticks: u64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        executor: Option<String>,
    },
    /// The loop stopped without success.
    GaveUp {
        reason: String,
    },
    /// Nothing more is asked about the failure of `action` (`why`): a person decides what
    /// comes next. `rounds_left`: stepping asks the model again; `undoable`: a change to
    /// the tree can be undone.
    PersonDecides {
        action: String,
        why: String,
        rounds_left: bool,
        undoable: bool,
    },
    /// How many fixes are refused and unsaved; told whenever either changes.
    FixCounts(FixCounts),
    /// The tree changed: all of it, the nodes the change added, the conditions learned
    /// rules put there (with the rules' ids), and why.
    TreeChanged {
        tree: Arc<Tree>,
        new_nodes: Vec<NodeId>,
        learned: Vec<(NodeId, Vec<String>)>,
        why: String,
    },
    /// An applied fix may be kept as a rule for later tasks: the rule in words, the
    /// narrower choice (only for the fix's objects) when the rule generalises, and how
    /// many fixes are offered with this one.
    RuleOffered {
        rule: String,
        only: Option<String>,
        remaining: usize,
    },
    /// A rule was kept in the knowledge file.
    RuleKept {
        id: String,
        rule: String,
        path: PathBuf,
    },
    /// A rule was not kept, and why.
    RuleRefused {
        rule: String,
        reason: String,
    },
    /// The kept rules of the scenario's domain, one line each.
    Knowledge {
        path: PathBuf,
        rules: Vec<String>,
    },
    /// One tick in the execution world: every node's status.
    Ticked {
        record: Arc<TickRecord>,
    },
    /// The execution cell's scene after a tick or a reset, for a 3D view (only with
    /// `Setup::scenes`, and only for cell worlds). Not written to recordings: a replay
    /// re-simulates the cell from the recorded trees and ticks (`record::Resimulation`),
    /// and the geometry would outweigh everything else in the file.
    #[serde(skip)]
    Scene {
        scene: Arc<SceneSnapshot>,
    },
    /// A real arm of the execution cell moved, or found no way to: the last motion, after
    /// the tick that asked for it.
    ArmMotion {
        motion: MotionView,
    },
    /// The execution world changed (a tick moved something, or it was reset).
    WorldChanged {
        facts: Vec<Condition>,
        reset: bool,
    },
    /// Model calls so far.
    Usage {
        totals: UsageTotals,
    },
    /// Running (ticking on its own) or paused.
    RunState {
        running: bool,
    },
    /// What the engine does or waits for now; told whenever that changes.
    Phase(PhaseKind),
    /// The conditions related to the failed `action` were tried in simulation before the
    /// model is asked; it chooses among the shortlist's fixes.
    Screened {
        action: ActionCall,
        shortlist: Shortlist,
    },
    /// The nodes whose status is forced in every tick of the execution world (all of
    /// them, after every change of the set; empty when cleared).
    Forced {
        forced: Vec<(NodeId, Forced)>,
    },
    /// The nodes with a breakpoint, and whether running stops after a node fails (all of
    /// them, after every change).
    Breakpoints {
        nodes: Vec<NodeId>,
        on_failure: bool,
    },
    /// Running stopped at a breakpoint: before tick `tick`, which would enter `node`
    /// (`Breakpoint`), or after tick `tick`, in which `node` failed (`Failure`).
    BreakpointHit {
        node: NodeId,
        node_path: Vec<usize>,
        tick: u64,
        reason: BreakReason,
    },
    /// A verification asked for started: what it checks.
    Verifying {
        scope: Arc<VerifyScope>,
    },
    /// `verify` finished; `origin` says where the verified tree came from.
    Verified {
        report: Arc<Report>,
        origin: String,
    },
    /// An applied change made the tree fail verification in the model: it does not run
    /// until a person approves the change again with the counterexample in view, or
    /// undoes it.
    ChangeViolates {
        report: Arc<Report>,
        /// The report's failures the tree before the change has too: the tree's (or the
        /// property's), not the change's.
        #[serde(default)]
        inherited: Vec<String>,
    },
    PolicySaved {
        path: PathBuf,
        fixes: usize,
    },
    /// The tree was written in other tools' formats (BT.CPP XML, Graphviz DOT).
    Exported {
        paths: Vec<PathBuf>,
    },
    /// A saved policy became the tree; `fixes` approved changes came with it.
    PolicyLoaded {
        path: PathBuf,
        fixes: usize,
    },
    /// A command could not be carried out; nothing changed.
    Error {
        message: String,
    },
    /// A step of the pipeline failed (a model call, planning); nothing changed.
    Failed {
        #[serde(with = "failure_text")]
        error: SessionError,
    },
    /// Something worth a line in the log.
    Notice {
        message: String,
    },
    /// An executor performs the actions and the execution world is its twin; told once,
    /// when the engine starts.
    Executor {
        name: String,
    },
    /// An action the twin predicted to succeed that the executor reported otherwise: its
    /// error, or the effect it did not have.
    Diverged {
        executor: String,
        action: ActionCall,
        reality: String,
        /// The twin's scene as it predicted the action would leave it (a cell twin, when
        /// the engine emits scenes); not written to recordings, like `Scene`.
        #[serde(skip)]
        predicted: Option<Arc<SceneSnapshot>>,
    },
}

/// A failure as a recording keeps it: its message (the errors it wraps, from the model
/// client to the planner, are not data), read back as `SessionError::Recorded`.
mod failure_text {
    use super::SessionError;

    pub fn serialize<S: serde::Serializer>(error: &SessionError, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(error)
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<SessionError, D::Error> {
        <String as serde::Deserialize>::deserialize(d).map(SessionError::Recorded)
    }
}

/// Why running stopped at a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum BreakReason {
    /// The next tick would enter a node with a breakpoint; it was not performed.
    Breakpoint,
    /// With break-on-failure, the tick just performed made a node fail that succeeded or
    /// ran in the tick before, or made an action fail.
    Failure,
}

/// What the engine does or waits for, as front ends are told it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PhaseKind {
    /// No tree yet.
    #[default]
    Idle,
    /// The model reads an instruction.
    Reading,
    /// The readings of an instruction wait for the person's choice.
    Choosing,
    /// A tree, stepped by hand.
    Ready,
    /// The tree ticks on its own.
    Running,
    /// An action failed and nothing is asked about it: a person decides.
    Failed,
    /// The model is asked what a failure misses.
    Asking,
    /// A proposal waits for approval.
    Proposed,
    /// An applied change is verified before the changed tree may run.
    Checking,
    /// The changed tree fails verification: the change waits to be approved again,
    /// rejected or undone.
    Violated,
}

/// How the loop ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    Success { ticks: u64 },
    Rejected,
    GaveUp { reason: String },
}

/// Fixes the session holds for its goal, counted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FixCounts {
    /// Refused for the goal's failures (by a person, the simulation or verification).
    pub refused: usize,
    /// Applied to the tree and held by no saved policy.
    pub unsaved: usize,
}

/// The loop's result: the final tree (with every change that helped) and how it ended.
#[derive(Debug, Clone)]
pub struct Resolved {
    pub goal: Formula,
    pub tree: Tree,
    pub ending: Ending,
    /// Failure questions asked.
    pub rounds: usize,
    /// Approved changes kept in the tree.
    pub repairs: usize,
    /// The approved proposals kept in the tree, in order, with who wrote each.
    pub kept: Vec<(Proposal, String)>,
    /// The policy file the tree was saved to (`Options::policy_dir`).
    pub saved: Option<std::path::PathBuf>,
}

#[derive(Debug, Clone, thiserror::Error)]
pub enum SessionError {
    #[error(transparent)]
    Llm(#[from] LlmError),
    #[error(transparent)]
    Prompt(#[from] PromptError),
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Plan(#[from] RepairError),
    #[error(transparent)]
    Executor(#[from] crate::executor::ExecutorError),
    #[error(transparent)]
    Misreading(#[from] crate::reading::UnknownMisreading),
    #[error("scenario {0:?} has no instruction; give one")]
    NoInstruction(String),
    #[error("scenario {0:?} states no goal to work on instead of reading its instruction")]
    NoStatedGoal(String),
    #[error("no usable goal after {attempts} call(s); last reply: {last}")]
    NoGoal { attempts: usize, last: ReplyError },
    #[error("{0}")]
    Policy(#[from] PolicyError),
    #[error(transparent)]
    TreeFile(Box<crate::interop::TreeFileError>),
    #[error("the session stopped before the loop ended")]
    Stopped,
    #[error("{}", not_chosen(*count, doubt.as_deref()))]
    ReadingNotChosen { count: usize, doubt: Option<String> },
    /// A failure read back from a recording, which keeps only its message.
    #[error("{0}")]
    Recorded(String),
}

/// Why no reading was worked on: several to choose among, or one the checks doubt.
fn not_chosen(count: usize, doubt: Option<&str>) -> String {
    match doubt {
        Some(why) => format!(
            "the goal read from the instruction is doubtful ({why}) and was not approved: run without --yes to approve it, or say the instruction otherwise"
        ),
        None => format!(
            "the instruction has {count} readings that make the robot do different things, and none was chosen: choose one with --reading N"
        ),
    }
}

impl From<crate::interop::TreeFileError> for SessionError {
    fn from(e: crate::interop::TreeFileError) -> Self {
        SessionError::TreeFile(Box::new(e))
    }
}

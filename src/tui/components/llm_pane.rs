//! The LLM pane: the call under way; for a pending proposal, what betr itself found about
//! the failure first (the failure, what stood in the way, the conditions tried in
//! simulation and which fixed it, what the change did there), then the proposal with who
//! wrote it and its keys, then the author's own reasoning labelled as theirs (marked
//! doubtful when the findings do not bear it out); then the goal with where it came from,
//! and a log of what happened below them.
//!
//! The log follows its newest line unless the person scrolled it up (then a marker says
//! how many rows are below); a line said again right after itself is counted, not
//! repeated.

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};

use crate::session::{Evidence, Proposal};

use super::super::strings;
use super::super::theme::Theme;

const LOG_LINES: usize = 200;
const SPINNER: [&str; 4] = ["|", "/", "-", "\\"];

/// The keys the pane names, as they are bound.
pub struct PaneHints<'a> {
    /// Under a proposal: approve, reject, edit, whole.
    pub proposal: &'a str,
    /// Beside a question under way: the key that cancels it (none in a replay, where
    /// nothing is under way and no time passes).
    pub cancel: Option<&'a str>,
}

/// What a person can do when nothing more is asked about a failure.
#[derive(Debug, Clone, PartialEq)]
pub struct Guidance {
    /// What ended, and "What now:".
    pub head: String,
    /// Each way on: its key as bound, and what it does.
    pub ways: Vec<(String, String)>,
}

/// A proposal as the pane shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct ProposalView {
    /// The action it is for (`grasp "blue cube"`), or the skill and object of a value.
    pub target: String,
    /// One line per condition, or the value.
    pub lines: Vec<String>,
    /// The text the edit line starts with.
    pub edit_text: String,
    /// Who wrote it (a model, a person, the simulation that narrowed it, betr's midway).
    pub author: String,
    /// What betr found, one finding a line (empty when nothing was looked into).
    pub findings: Vec<String>,
    /// The author's own reasoning.
    pub reasoning: Option<String>,
    /// Why that reasoning is doubtful, when it is.
    pub doubt: Option<String>,
}

impl ProposalView {
    /// `proposal` by `author`, with their `reasoning` and what betr found.
    pub fn of(
        proposal: &Proposal,
        author: &str,
        reasoning: Option<String>,
        evidence: Option<Box<Evidence>>,
    ) -> ProposalView {
        let (findings, doubt) = evidence.map(|e| (e.findings, e.doubt)).unwrap_or_default();
        let (target, lines, edit_text) = ProposalView::parts(proposal);
        ProposalView {
            target,
            lines,
            edit_text,
            author: author.to_string(),
            findings,
            reasoning,
            doubt,
        }
    }

    /// The proposal whole, as lines: betr's findings, the proposal, the reasoning.
    pub fn details(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if !self.findings.is_empty() {
            lines.push(strings::FOUND_BY_BETR.to_string());
            lines.extend(self.findings.iter().map(|f| format!("  {f}")));
        }
        lines.push(strings::proposal_by(&self.target, &self.author));
        lines.extend(self.lines.iter().map(|l| format!("  {l}")));
        if let Some(r) = &self.reasoning {
            lines.push(strings::reasoning_of(&self.author, self.doubt.as_deref()));
            lines.push(format!("  {r}"));
        }
        lines
    }

    /// What the proposal is for, its lines, and the edit line's text.
    fn parts(proposal: &Proposal) -> (String, Vec<String>, String) {
        match proposal {
            Proposal::Conditions {
                action, conditions, ..
            } => {
                let lines: Vec<String> = conditions.iter().map(ToString::to_string).collect();
                (format!("{action}!"), lines.clone(), lines.join(" & "))
            }
            Proposal::Value {
                skill,
                object,
                param,
                value,
            } => (
                format!("{skill} \"{object}\""),
                vec![format!("{param} = {value}")],
                value.to_string(),
            ),
        }
    }
}

#[derive(Default)]
pub struct LlmPane {
    pub asking: Option<String>,
    /// When the question under way was asked.
    pub asking_since: Option<std::time::Instant>,
    /// The model's replies to the question under way so far (a reply the checks refuse
    /// is followed by another call).
    pub replies_to_question: usize,
    /// What trying conditions in simulation found for the failed action (named), shown
    /// while its failure waits without a proposal.
    pub screened: Option<(String, crate::session::Shortlist)>,
    /// Who answered the last model call (`model qwen…`, a fixture).
    pub replied_by: Option<String>,
    pub goal: Option<String>,
    /// Where the goal came from (a model, a person, a policy file, the scenario file).
    pub goal_by: Option<String>,
    /// The model's reasoning for the goal, when a model read it.
    pub goal_reasoning: Option<String>,
    /// The doubt level of a model's reading and what it rests on.
    pub goal_doubt: Option<String>,
    pub proposal: Option<ProposalView>,
    /// An approved fix offered as a rule, with the keys that answer it.
    pub offer: Option<String>,
    /// Nothing more is asked about a failure: the ways on, each with its key.
    pub guidance: Option<Guidance>,
    pub error: Option<String>,
    /// Each line with how many times in a row it was said.
    log: Vec<(String, usize)>,
    /// Rows the log is scrolled up from its newest line (0: following it).
    log_scroll: usize,
    /// Rows of the log above the view when it last followed its newest line: how far it
    /// can be scrolled.
    log_hidden: std::cell::Cell<usize>,
    /// Rows of the proposal (and goal) above the log scrolled past, when they do not fit.
    head_scroll: usize,
    /// How far they can be scrolled at the last draw.
    head_hidden: std::cell::Cell<usize>,
    /// Where the log was drawn last (for the mouse).
    log_area: std::cell::Cell<Rect>,
    /// Whether keys go to this pane, and to its log.
    pub focused: bool,
    pub log_focused: bool,
    spin: usize,
}

/// Rows one log scroll key moves.
const SCROLL_ROWS: usize = 5;

impl LlmPane {
    pub fn log(&mut self, line: impl Into<String>) {
        let line = line.into();
        if let Some((last, count)) = self.log.last_mut()
            && *last == line
        {
            *count += 1;
            return;
        }
        self.log.push((line, 1));
        if self.log.len() > LOG_LINES {
            self.log.remove(0);
        }
        // A person reading older lines keeps them in view while new ones arrive.
        if self.log_scroll > 0 {
            self.log_scroll += 1;
        }
    }

    /// The log as shown: each line once, with its count when said more than once.
    pub fn log_lines(&self) -> Vec<String> {
        self.log
            .iter()
            .map(|(line, count)| match count {
                1 => line.clone(),
                n => strings::repeated(line, *n),
            })
            .collect()
    }

    /// Scroll the log towards older lines.
    pub fn scroll_log_up(&mut self) {
        self.log_scroll = (self.log_scroll + SCROLL_ROWS).min(self.log_hidden.get());
    }

    /// Scroll the log towards the newest line (following it again at the bottom).
    pub fn scroll_log_down(&mut self) {
        self.log_scroll = self.log_scroll.saturating_sub(SCROLL_ROWS);
    }

    /// Scroll the log `rows` towards older lines (negative: towards the newest).
    pub fn scroll_log(&mut self, rows: isize) {
        self.log_scroll = self
            .log_scroll
            .saturating_add_signed(rows)
            .min(self.log_hidden.get());
    }

    /// Scroll the proposal above the log `rows` down (negative: up), when it does not fit.
    pub fn scroll_head(&mut self, rows: isize) {
        self.head_scroll = self
            .head_scroll
            .saturating_add_signed(rows)
            .min(self.head_hidden.get());
    }

    /// Where the log was drawn last.
    pub fn log_area(&self) -> Rect {
        self.log_area.get()
    }

    /// Scroll the log as far up as `previous` was.
    pub fn adopt_scroll(&mut self, previous: &LlmPane) {
        self.log_scroll = previous.log_scroll;
        self.log_hidden.set(previous.log_hidden.get());
    }

    pub fn animate(&mut self) {
        self.spin = (self.spin + 1) % SPINNER.len();
    }

    /// The question under way is over (answered, cancelled, or left).
    pub fn stop_asking(&mut self) {
        self.asking = None;
        self.asking_since = None;
    }

    pub fn draw(&self, frame: &mut Frame, area: Rect, theme: &Theme, hints: &PaneHints) {
        let block = self.block(theme, hints);
        let inner = block.inner(area);
        frame.render_widget(block, area);
        // The parts above the log take the rows they wrap to; the log gets the rest. A
        // proposal whose findings would push it out of view comes first, with its keys.
        let mut head =
            Paragraph::new(self.head_lines(theme, hints, false)).wrap(Wrap { trim: false });
        let mut head_rows = head.line_count(inner.width);
        if self.proposal.is_some() && head_rows > usize::from(inner.height) {
            head = Paragraph::new(self.head_lines(theme, hints, true)).wrap(Wrap { trim: false });
            head_rows = head.line_count(inner.width);
        }
        let [head_area, log_area] = Layout::vertical([
            Constraint::Length(u16::try_from(head_rows).unwrap_or(u16::MAX)),
            Constraint::Fill(1),
        ])
        .areas(inner);
        self.draw_head(frame, head, head_rows, head_area, theme);
        self.log_area.set(log_area);
        self.draw_log(frame, log_area, theme);
    }

    /// What stands above the log: a question under way, the proposal (`proposal_first`:
    /// before betr's findings), the guidance or the offer of a rule, the goal, who replied
    /// last, an error, and the log's heading.
    fn head_lines(&self, theme: &Theme, hints: &PaneHints, proposal_first: bool) -> Vec<Line<'_>> {
        let mut lines: Vec<Line> = Vec::new();
        if let Some(what) = &self.asking {
            let live = match (hints.cancel, self.asking_since) {
                (Some(key), Some(since)) => format!(
                    " {} s · call {} · {key} cancels",
                    since.elapsed().as_secs(),
                    self.replies_to_question + 1
                ),
                _ => String::new(),
            };
            lines.push(Line::from(Span::styled(
                format!("{} {} {what} …{live}", SPINNER[self.spin], strings::ASKING),
                theme.running,
            )));
        }
        // What screening found: above while the model chooses from it, below the ways on
        // once the person does.
        let screened = self.screened.as_ref().filter(|_| self.proposal.is_none());
        let asking = self.asking.is_some();
        if let Some((action, shortlist)) = screened.filter(|_| asking) {
            screened_lines(action, shortlist, true, theme, &mut lines);
        }
        match (&self.proposal, &self.guidance) {
            (Some(p), _) => proposal_lines(p, theme, hints.proposal, proposal_first, &mut lines),
            (None, Some(guidance)) => {
                lines.push(Line::from(Span::styled(
                    guidance.head.clone(),
                    theme.proposal,
                )));
                for (key, what) in &guidance.ways {
                    lines.push(Line::from(vec![
                        Span::styled(format!("  {key:>5}  "), theme.key),
                        Span::raw(what.clone()),
                    ]));
                }
            }
            (None, None) => match &self.offer {
                Some(offer) => lines.push(Line::from(Span::styled(offer.clone(), theme.proposal))),
                None => lines.push(Line::from(Span::styled(strings::NO_PROPOSAL, theme.dim))),
            },
        }
        if let Some((action, shortlist)) = screened.filter(|_| !asking) {
            screened_lines(action, shortlist, false, theme, &mut lines);
        }
        if let Some(goal) = &self.goal {
            let by = self.goal_by.as_deref().unwrap_or("the scenario file");
            lines.push(Line::from(vec![
                Span::styled(format!("{}: ", strings::GOAL), theme.title),
                Span::raw(goal.clone()),
            ]));
            lines.push(Line::from(Span::styled(strings::goal_by(by), theme.dim)));
            if let Some(doubt) = &self.goal_doubt {
                let style = if doubt.starts_with("doubtful") {
                    theme.failing
                } else {
                    theme.dim
                };
                lines.push(Line::from(Span::styled(format!("  {doubt}"), style)));
            }
            // The goal's reasoning only while no proposal's is shown: one reasoning at a
            // time, each under what it is about.
            if let (Some(r), None) = (&self.goal_reasoning, &self.proposal) {
                lines.push(Line::from(Span::styled(
                    format!(
                        "  {} {}",
                        strings::reasoning_of(by, None),
                        r.replace('\n', " ")
                    ),
                    theme.dim,
                )));
            }
        }
        // The last model reply, when no pane above says who wrote it already.
        if let Some(who) = &self.replied_by
            && self.proposal.is_none()
            && self.goal_by.as_ref() != Some(who)
        {
            lines.push(Line::from(Span::styled(
                strings::last_reply(who),
                theme.dim,
            )));
        }
        if let Some(e) = &self.error {
            lines.push(Line::from(Span::styled(e.clone(), theme.error)));
        }
        lines.push(Line::from(Span::styled(
            format!("── {} ──", strings::LOG),
            if self.log_focused {
                theme.focused
            } else {
                theme.dim
            },
        )));
        lines
    }

    /// The pane's frame: its title, and a proposal's conditions and keys on the border.
    fn block(&self, theme: &Theme, hints: &PaneHints) -> Block<'_> {
        let mut block = Block::default()
            .borders(Borders::ALL)
            .border_style(if self.focused {
                theme.focused
            } else {
                theme.border
            })
            .title(Span::styled(strings::LLM_TITLE, theme.title));
        // What is proposed and the keys that answer it stay on the border, so a pane too
        // small for the findings still shows them (D shows the whole proposal).
        if let Some(p) = &self.proposal {
            block = block
                .title(Span::styled(
                    strings::proposed_title(&p.lines.join(" & ")),
                    theme.proposal,
                ))
                .title_bottom(Span::styled(format!(" {} ", hints.proposal), theme.key));
        }
        block
    }

    /// The proposal and the goal: whole when they fit, else the rows scrolled to with a
    /// last row saying which rows these are.
    fn draw_head(
        &self,
        frame: &mut Frame,
        head: Paragraph,
        rows: usize,
        area: Rect,
        theme: &Theme,
    ) {
        let height = usize::from(area.height);
        if rows <= height || height < 2 {
            self.head_hidden.set(0);
            frame.render_widget(head, area);
            return;
        }
        let shown = height - 1;
        let hidden = rows - shown;
        self.head_hidden.set(hidden);
        let top = self.head_scroll.min(hidden);
        let [text_area, marker_area] =
            Layout::vertical([Constraint::Fill(1), Constraint::Length(1)]).areas(area);
        frame.render_widget(
            head.scroll((u16::try_from(top).unwrap_or(u16::MAX), 0)),
            text_area,
        );
        frame.render_widget(
            Paragraph::new(Span::styled(
                strings::rows_of(top + 1, top + shown, rows),
                theme.key,
            )),
            marker_area,
        );
    }
}

/// What screening found for the failed `action`, before a proposal: the fixes betr's
/// simulation confirmed, and what is done with them (the model chooses among them, or the
/// person does).
fn screened_lines(
    action: &str,
    shortlist: &crate::session::Shortlist,
    asking: bool,
    theme: &Theme,
    lines: &mut Vec<Line<'_>>,
) {
    lines.push(Line::from(vec![
        Span::styled(strings::FOUND_BY_BETR, theme.title),
        Span::styled(format!(" {action}"), theme.dim),
    ]));
    lines.push(Line::from(format!("  {}", shortlist.finding())));
    let n = shortlist.fixes.len();
    let next = match (asking, n) {
        (_, 0) => return,
        (true, _) => strings::model_chooses_among(n),
        (false, _) => strings::SHORTLIST_IS_YOURS.to_string(),
    };
    lines.push(Line::from(Span::styled(next, theme.dim)));
}

/// A pending proposal: betr's findings, the proposal with its author and keys, then the
/// author's reasoning labelled as theirs. `proposal_first` (a pane too small for it all):
/// the proposal and its keys, then the findings.
fn proposal_lines<'a>(
    p: &'a ProposalView,
    theme: &Theme,
    keys_hint: &str,
    proposal_first: bool,
    lines: &mut Vec<Line<'a>>,
) {
    let findings = |lines: &mut Vec<Line<'a>>| {
        if !p.findings.is_empty() {
            lines.push(Line::from(Span::styled(
                strings::FOUND_BY_BETR,
                theme.title,
            )));
            for f in &p.findings {
                lines.push(Line::from(format!("  {f}")));
            }
        }
    };
    if !proposal_first {
        findings(lines);
    }
    lines.push(Line::from(Span::styled(
        strings::proposal_by(&p.target, &p.author),
        theme.proposal,
    )));
    for l in &p.lines {
        lines.push(Line::from(Span::styled(format!("  {l}"), theme.proposal)));
    }
    lines.push(Line::from(Span::styled(keys_hint.to_string(), theme.key)));
    if proposal_first {
        findings(lines);
    }
    if let Some(r) = &p.reasoning {
        let style = if p.doubt.is_some() {
            theme.error
        } else {
            theme.dim
        };
        lines.push(Line::from(Span::styled(
            strings::reasoning_of(&p.author, p.doubt.as_deref()),
            style,
        )));
        lines.push(Line::from(Span::styled(
            format!("  {}", r.replace('\n', " ")),
            theme.dim,
        )));
    }
}

impl LlmPane {
    /// The log's rows that fit in `area`: the newest, or those the person scrolled to,
    /// with a marker of the rows below them.
    fn draw_log(&self, frame: &mut Frame, area: Rect, theme: &Theme) {
        if area.height == 0 {
            return;
        }
        let log = Paragraph::new(
            self.log_lines()
                .into_iter()
                .map(Line::from)
                .collect::<Vec<_>>(),
        )
        .wrap(Wrap { trim: false });
        let total = log.line_count(area.width);
        let height = usize::from(area.height);
        let hidden = total.saturating_sub(height);
        self.log_hidden.set(hidden);
        let below = self.log_scroll.min(hidden);
        let (log_area, marker_area) = if below > 0 {
            let [log_area, marker_area] =
                Layout::vertical([Constraint::Fill(1), Constraint::Length(1)]).areas(area);
            (log_area, Some(marker_area))
        } else {
            (area, None)
        };
        // Rows above the view: everything but what fits and what is scrolled below.
        let top = total.saturating_sub(usize::from(log_area.height) + below);
        let top = u16::try_from(top).unwrap_or(u16::MAX);
        frame.render_widget(log.scroll((top, 0)), log_area);
        if let Some(marker_area) = marker_area {
            frame.render_widget(
                Paragraph::new(Span::styled(strings::log_below(below), theme.key)),
                marker_area,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    fn screen(pane: &LlmPane) -> String {
        screen_with(pane, 40, 12, None)
    }

    fn screen_with(pane: &LlmPane, width: u16, height: u16, cancel: Option<&str>) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
        let hints = PaneHints {
            proposal: "a approve",
            cancel,
        };
        terminal
            .draw(|f| pane.draw(f, f.area(), &Theme::default(), &hints))
            .unwrap();
        terminal.backend().to_string()
    }

    /// A question under way says how long it has waited and the key that cancels it;
    /// a replayed one neither (nothing is under way there).
    #[test]
    fn a_question_under_way_shows_its_wait_and_its_cancel_key() {
        let pane = LlmPane {
            asking: Some("the missing precondition".into()),
            asking_since: std::time::Instant::now().checked_sub(std::time::Duration::from_secs(7)),
            ..LlmPane::default()
        };
        let live = screen_with(&pane, 80, 6, Some("esc"));
        assert!(
            live.contains("the missing precondition … 7 s · call 1 · esc cancels"),
            "{live}"
        );
        let replayed = screen_with(&pane, 80, 6, None);
        assert!(
            replayed.contains("the missing precondition …") && !replayed.contains("cancels"),
            "{replayed}"
        );
    }

    /// Scenario 1's proposal with the reasoning a small model gave for it, which blames
    /// the green cube while the simulation found the red cube in the way.
    fn scenario_1_pane(reasoning: &str) -> LlmPane {
        use crate::domain::{ActionCall, Condition, Object};
        let object = |name: &str| Object {
            name: name.into(),
            types: vec!["cube".into()],
            called: Vec::new(),
        };
        let scene: Vec<Object> = ["table", "blue cube", "green cube", "red cube"]
            .into_iter()
            .map(object)
            .collect();
        let objects = vec!["blue cube".to_string(), "red cube".to_string()];
        let evidence = Evidence {
            findings: vec![
                "grasp \"blue cube\"! failed: No collision free path found".into(),
                "in the way: \"red cube\" on \"blue cube\" (true now)".into(),
            ],
            doubt: crate::session::repair::evidence::doubt(
                reasoning,
                &objects,
                &["red cube".to_string()],
                &scene,
            ),
            objects,
        };
        let proposal = Proposal::Conditions {
            action: ActionCall::parse("grasp \"blue cube\"").unwrap(),
            node: crate::bt::NodeId(7),
            conditions: vec![Condition::parse("~\"any object\" on \"blue cube\"").unwrap()],
        };
        LlmPane {
            proposal: Some(ProposalView::of(
                &proposal,
                "model qwen",
                Some(reasoning.to_string()),
                Some(Box::new(evidence)),
            )),
            ..LlmPane::default()
        }
    }

    fn screen_of(pane: &LlmPane, width: u16, height: u16) -> String {
        screen_with(pane, width, height, None)
    }

    #[test]
    fn the_first_lines_are_betrs_evidence_and_a_misplaced_reasoning_is_doubtful() {
        let pane = scenario_1_pane(
            "The blue cube was resting on the table, and the green cube was also resting on the table, which blocked the path.",
        );
        let screen = screen_of(&pane, 70, 16);
        let rows: Vec<&str> = screen.lines().collect();
        assert!(rows[1].contains("Found by betr:"), "{screen}");
        assert!(rows[2].contains("grasp \"blue cube\"! failed"), "{screen}");
        let reasoning_at = rows
            .iter()
            .position(|r| r.contains("Reasoning of model qwen"));
        let proposal_at = rows.iter().position(|r| r.contains("Proposal for"));
        assert!(
            proposal_at > Some(2) && reasoning_at > proposal_at,
            "{screen}"
        );
        assert!(screen.contains("DOUBTFUL"), "{screen}");
        insta::assert_snapshot!("doubtful_reasoning_after_the_evidence", screen);

        // A reasoning that names none of the failure's objects is doubtful too.
        let pane = scenario_1_pane("The gripper needs more room.");
        let p = pane.proposal.as_ref().unwrap();
        assert_eq!(
            p.doubt.as_deref(),
            Some("it names none of the failure's objects (\"blue cube\", \"red cube\")")
        );
        // One naming what was in the way is shown as the model's, not doubted.
        let pane = scenario_1_pane("The red cube sits on the blue cube.");
        let screen = screen_of(&pane, 70, 16);
        assert!(!screen.contains("DOUBTFUL"), "{screen}");
        assert!(
            screen.contains("Reasoning of model qwen (its words"),
            "{screen}"
        );
    }

    #[test]
    fn no_reasoning_is_left_under_no_proposal_pending() {
        let mut pane = scenario_1_pane("The red cube sits on the blue cube.");
        pane.proposal = None;
        let screen = screen_of(&pane, 70, 16);
        assert!(screen.contains("No proposal pending."), "{screen}");
        assert!(!screen.contains("red cube"), "{screen}");
    }

    #[test]
    fn a_repeated_line_is_counted_not_repeated() {
        let mut pane = LlmPane::default();
        pane.log("ticked");
        for _ in 0..15 {
            pane.log("grasp failed");
        }
        pane.log("ticked");
        assert_eq!(pane.log_lines(), ["ticked", "grasp failed (×15)", "ticked"]);
    }

    #[test]
    fn the_log_follows_its_newest_line_unless_scrolled_up() {
        let mut pane = LlmPane::default();
        for n in 1..=30 {
            pane.log(format!("line {n}"));
        }
        let s = screen(&pane);
        assert!(s.contains("line 30"), "{s}");
        assert!(!s.contains("line 20 "), "{s}");
        assert!(!s.contains("below"), "{s}");

        pane.scroll_log_up();
        let s = screen(&pane);
        assert!(!s.contains("line 30"), "{s}");
        assert!(s.contains("↓ 5 more row(s) below"), "{s}");
        // New lines keep the view where the person scrolled to.
        pane.log("line 31");
        let s = screen(&pane);
        assert!(s.contains("↓ 6 more row(s) below"), "{s}");

        pane.scroll_log_down();
        pane.scroll_log_down();
        let s = screen(&pane);
        assert!(s.contains("line 31"), "{s}");
        assert!(!s.contains("below"), "{s}");
    }
}

//! The world pane as a blackboard: the last error, the values parameters set on the tree's
//! actions, the last motion of a real arm (its arm, joint path length, planning time and
//! attempts, or what blocked it), and a table of the facts true now in the execution world, each marked when
//! the last tick made it true, with the facts it made false listed (struck) above the
//! rest. The table scrolls and can be narrowed to the facts holding a text; the objects
//! are named when they fit on one line, else counted (D shows a node whole). A short pane
//! shows the last error and the last motion in one row each, so the facts keep rows to
//! scroll in.

use std::collections::HashSet;

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};

use super::super::strings;
use super::super::theme::Theme;
use crate::world::cell::snapshot::MotionView;

#[derive(Default)]
pub struct WorldPane {
    /// The facts true now, in the order shown.
    pub facts: Vec<String>,
    /// Facts the last change of the world made true.
    pub became_true: HashSet<String>,
    /// Facts the last change of the world made false.
    pub became_false: Vec<String>,
    pub objects: Vec<String>,
    pub last_error: Option<String>,
    /// The tree has succeeded since the last error.
    pub error_resolved: bool,
    /// Values parameters set on the tree's actions (`grasp "egg": force = 5 N`).
    pub values: Vec<String>,
    /// The last motion of a real arm, when the cell moves them.
    pub motion: Option<MotionView>,
    /// The executor that performs the actions, when this world is its twin.
    pub executor: Option<String>,
    /// What the executor last reported that the twin did not predict.
    pub diverged: Option<String>,
    /// Only facts holding this text (any case) are listed.
    pub filter: Option<String>,
    /// Rows of the fact table scrolled past.
    scroll: usize,
    /// Do not mark what changed: a replay seeks past the worlds in between, so the
    /// world before the last one is not known there.
    pub unmarked: bool,
    /// Whether keys go to this pane (its border says so).
    pub focused: bool,
}

/// Rows one scroll key moves the fact table.
const SCROLL_ROWS: usize = 5;

impl WorldPane {
    /// The pane of a scene with these objects.
    pub fn of(objects: Vec<String>) -> WorldPane {
        WorldPane {
            objects,
            ..WorldPane::default()
        }
    }

    /// The world after a tick (`reset`: afresh): what changed is marked, unless it was
    /// reset.
    pub fn set_facts(&mut self, facts: Vec<String>, reset: bool) {
        if reset || self.unmarked {
            self.became_true.clear();
            self.became_false.clear();
        } else {
            let now: HashSet<&String> = facts.iter().collect();
            let before: HashSet<&String> = self.facts.iter().collect();
            self.became_true = facts
                .iter()
                .filter(|f| !before.contains(f))
                .cloned()
                .collect();
            self.became_false = self
                .facts
                .iter()
                .filter(|f| !now.contains(f))
                .cloned()
                .collect();
        }
        self.facts = facts;
    }

    pub fn scroll_down(&mut self) {
        self.scroll(SCROLL_ROWS.cast_signed());
    }

    pub fn scroll_up(&mut self) {
        self.scroll(-SCROLL_ROWS.cast_signed());
    }

    /// Scroll the fact table by `rows` (negative: up), keeping its last row in view.
    pub fn scroll(&mut self, rows: isize) {
        let last = self.rows().len().saturating_sub(1);
        self.scroll = self.scroll.saturating_add_signed(rows).min(last);
    }

    pub fn set_filter(&mut self, filter: Option<String>) {
        self.filter = filter.filter(|f| !f.is_empty());
        self.scroll = 0;
    }

    /// The fact table's rows: those the last tick made false, then those it made true,
    /// then the rest; each with its mark, narrowed by the filter.
    fn rows(&self) -> Vec<(&'static str, &String, Mark)> {
        let keep = |f: &String| {
            self.filter
                .as_ref()
                .is_none_or(|q| f.to_lowercase().contains(&q.to_lowercase()))
        };
        let mut rows: Vec<(&'static str, &String, Mark)> = Vec::new();
        for f in self.became_false.iter().filter(|f| keep(f)) {
            rows.push((strings::MADE_FALSE, f, Mark::False));
        }
        for f in self.facts.iter().filter(|f| keep(f)) {
            if self.became_true.contains(f) {
                rows.push((strings::MADE_TRUE, f, Mark::True));
            }
        }
        for f in self.facts.iter().filter(|f| keep(f)) {
            if !self.became_true.contains(f) {
                rows.push(("  ", f, Mark::Same));
            }
        }
        rows
    }

    pub fn draw(&self, frame: &mut Frame, area: Rect, theme: &Theme) {
        let mut lines: Vec<Line> = Vec::new();
        let width = usize::from(area.width.saturating_sub(2));
        // In a short pane the error takes one row, so the facts keep theirs (the LLM pane
        // and D show it whole).
        let short = area.height < SHORT_PANE;
        self.push_last_error(&mut lines, theme, width, short);
        self.push_executor(&mut lines, theme, width);
        for v in &self.values {
            lines.push(Line::from(Span::styled(
                format!("{} {v}", strings::VALUE_SET),
                theme.proposal,
            )));
        }
        if let Some(m) = &self.motion {
            let style = if m.length.is_some() {
                theme.dim
            } else {
                theme.error
            };
            let motion = strings::last_motion(m);
            // Cut to one row in a short pane too, for the same reason as the error.
            let motion = if short {
                cut_to(&motion, width)
            } else {
                motion
            };
            lines.push(Line::from(Span::styled(motion, style)));
        }
        let names = format!("{} {}", strings::OBJECTS, self.objects.join(", "));
        lines.push(Line::from(Span::styled(
            if names.chars().count() <= width {
                names
            } else {
                strings::objects_counted(self.objects.len())
            },
            theme.dim,
        )));
        self.push_facts(&mut lines, theme);
        let block = Block::default()
            .borders(Borders::ALL)
            .border_style(if self.focused {
                theme.focused
            } else {
                theme.border
            })
            .title(Span::styled(strings::WORLD_TITLE, theme.title));
        frame.render_widget(
            Paragraph::new(lines)
                .wrap(Wrap { trim: false })
                .block(block),
            area,
        );
    }

    /// The last error, dim once resolved: cut to one row of `width` in a short pane,
    /// else a heading and the error below it.
    fn push_last_error(&self, lines: &mut Vec<Line<'_>>, theme: &Theme, width: usize, short: bool) {
        if let (Some(e), true) = (&self.last_error, short) {
            let style = if self.error_resolved {
                theme.dim
            } else {
                theme.error
            };
            lines.push(Line::from(Span::styled(
                cut_to(&format!("{} {e}", strings::LAST_ERROR), width),
                style,
            )));
        } else if let Some(e) = &self.last_error {
            if self.error_resolved {
                lines.push(Line::from(Span::styled(
                    strings::LAST_ERROR_RESOLVED,
                    theme.dim,
                )));
                lines.push(Line::from(Span::styled(format!("  {e}"), theme.dim)));
            } else {
                lines.push(Line::from(Span::styled(strings::LAST_ERROR, theme.title)));
                lines.push(Line::from(Span::styled(format!("  {e}"), theme.error)));
            }
        }
    }

    /// Which executor performs the actions and, when it reported what the twin did not
    /// predict, what: one row each.
    fn push_executor(&self, lines: &mut Vec<Line<'_>>, theme: &Theme, width: usize) {
        let Some(executor) = &self.executor else {
            return;
        };
        lines.push(Line::from(Span::styled(
            cut_to(&strings::performed_by(executor), width),
            theme.dim,
        )));
        if let Some(what) = &self.diverged {
            lines.push(Line::from(Span::styled(
                cut_to(&strings::reality_differs(what), width),
                theme.error,
            )));
        }
    }

    /// The facts' heading and the facts from the scroll position on, marked as they
    /// changed (new, gone, the same).
    fn push_facts(&self, lines: &mut Vec<Line<'_>>, theme: &Theme) {
        let rows = self.rows();
        let shown = rows.iter().filter(|(_, _, m)| *m != Mark::False).count();
        lines.push(Line::from(Span::styled(
            strings::facts_heading(shown, self.facts.len(), self.filter.as_deref()),
            theme.title,
        )));
        if rows.is_empty() {
            lines.push(Line::from(strings::NOTHING_TRUE));
        }
        let scroll = self.scroll.min(rows.len().saturating_sub(1));
        if scroll > 0 {
            lines.push(Line::from(Span::styled(
                strings::rows_above(scroll),
                theme.key,
            )));
        }
        for (mark, fact, kind) in rows.into_iter().skip(scroll) {
            let style = match kind {
                Mark::True => theme.new_node,
                Mark::False => theme.dim.add_modifier(Modifier::CROSSED_OUT),
                Mark::Same => ratatui::style::Style::default(),
            };
            lines.push(Line::from(vec![
                Span::styled(mark, style),
                Span::styled(fact.clone(), style),
            ]));
        }
    }
}

/// Panes lower than this show the last error and the last motion in one row each.
const SHORT_PANE: u16 = 12;

/// `text` in at most `width` cells, ending in `…` when cut.
fn cut_to(text: &str, width: usize) -> String {
    if text.chars().count() <= width {
        return text.to_string();
    }
    let mut cut: String = text.chars().take(width.saturating_sub(1)).collect();
    cut.push('…');
    cut
}

/// How the last tick changed a fact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mark {
    True,
    False,
    Same,
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    fn screen(pane: &WorldPane) -> String {
        screen_of(pane, 50, 14)
    }

    fn screen_of(pane: &WorldPane, width: u16, height: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
        terminal
            .draw(|f| pane.draw(f, f.area(), &Theme::default()))
            .unwrap();
        terminal.backend().to_string()
    }

    #[test]
    fn a_tick_marks_what_it_made_true_and_false_and_the_table_filters_and_scrolls() {
        let mut pane = WorldPane::of((1..=100).map(|n| format!("Cup{n}")).collect());
        pane.values = vec!["grasp \"egg\": force = 5 N".into()];
        let facts = |list: &[&str]| list.iter().map(|f| f.to_string()).collect::<Vec<_>>();
        pane.set_facts(
            facts(&[
                "\"red cube\" on \"blue cube\"",
                "hand empty",
                "Cup1 on table",
            ]),
            true,
        );
        pane.set_facts(
            facts(&[
                "\"red cube\" grasped",
                "Cup1 on table",
                "\"blue cube\" clear",
            ]),
            false,
        );
        let s = screen(&pane);
        assert!(s.contains("Objects: 100"), "{s}");
        assert!(s.contains("value set: grasp \"egg\": force = 5 N"), "{s}");
        assert!(s.contains("- \"red cube\" on \"blue cube\""), "{s}");
        assert!(s.contains("+ \"red cube\" grasped"), "{s}");
        assert!(s.contains("  Cup1 on table"), "{s}");
        insta::assert_snapshot!("blackboard_after_a_tick", s);

        pane.set_filter(Some("CUBE".into()));
        let s = screen(&pane);
        assert!(!s.contains("Cup1 on table"), "{s}");
        assert!(s.contains("True now: 2 of 3 holding \"CUBE\""), "{s}");

        pane.set_filter(None);
        pane.scroll_down();
        let s = screen(&pane);
        assert!(s.contains("↑ 4 row(s) above"), "{s}");
    }

    #[test]
    fn the_last_motion_of_a_real_arm_is_one_line_made_or_blocked() {
        let mut pane = WorldPane::of(vec!["red cube".into(), "blue cube".into()]);
        pane.set_facts(vec!["\"red cube\" grasped".into()], true);
        pane.motion = Some(MotionView {
            arm: "yumi_link_7_l".into(),
            length: Some(3.4178),
            seconds: 0.01234,
            attempts: 1,
            blocker: None,
        });
        let s = screen_of(&pane, 90, 8);
        assert!(
            s.contains(
                "last motion: yumi_link_7_l moved, joint path 3.42 rad, planned in 12.3 ms, 1 attempt"
            ),
            "{s}"
        );
        insta::assert_snapshot!("blackboard_with_the_last_motion", s);

        pane.motion = Some(MotionView {
            arm: "yumi_link_7_l".into(),
            length: None,
            seconds: 0.5,
            attempts: 6,
            blocker: Some("red cube".into()),
        });
        let s = screen_of(&pane, 90, 8);
        assert!(
            s.contains(
                "last motion: yumi_link_7_l found no path, blocked by red cube, 500.0 ms, 6 attempts"
            ),
            "{s}"
        );
    }

    #[test]
    fn an_executor_and_what_reality_did_otherwise_are_one_row_each() {
        let mut pane = WorldPane::of(vec!["red cube".into(), "blue cube".into()]);
        pane.set_facts(vec!["\"red cube\" on \"blue cube\"".into()], true);
        pane.executor = Some("follower.py".into());
        let s = screen_of(&pane, 90, 8);
        assert!(
            s.contains("Performed by the follower.py executor; this world is its twin."),
            "{s}"
        );
        assert!(!s.contains("Reality differs"), "{s}");
        pane.diverged = Some("No collision free path found".into());
        let s = screen_of(&pane, 90, 8);
        insta::assert_snapshot!("blackboard_with_an_executor", s);
        assert!(
            s.contains("Reality differs: No collision free path found"),
            "{s}"
        );
    }
}

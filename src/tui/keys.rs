//! Key bindings: one struct with a field per action and its default key. The help overlay
//! is generated from the same struct, so it cannot drift; a TOML file of overrides
//! (`step = "t"`, `quit = "ctrl-q"`) is applied as a patch, and a bad file is reported
//! while the defaults stay.
//!
//! Each action belongs to the live workbench, to the replay of a recording, or to both
//! (help, quit, the log's scrolling): a replay has no engine, so editing, approval and run
//! keys are not bound there, and the two sets may reuse each other's keys.

use std::fmt;
use std::path::Path;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use serde::Deserialize;

/// What a bound key does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    Step,
    Run,
    Plan,
    Instruction,
    Dictate,
    Approve,
    Reject,
    /// Stop the model call under way.
    Cancel,
    Edit,
    Undo,
    Verify,
    Save,
    Load,
    Export,
    KeepRule,
    KeepRuleOnly,
    DeclineRule,
    Knowledge,
    Reset,
    Breakpoint,
    Force,
    BreakOnFailure,
    /// The pending proposal, or the selected node, whole in an overlay.
    Details,
    /// Select the running node after every tick (toggle).
    Follow,
    /// Search the tree's labels; next and previous match.
    Search,
    SearchNext,
    SearchPrevious,
    /// Close every node; open every node; open the way to the running node only.
    CollapseAll,
    ExpandAll,
    ExpandToRunning,
    /// Scroll the tree sideways, for long labels deep in it.
    ScrollLeft,
    ScrollRight,
    /// Move the focus to the next pane (the arrows and PgUp PgDn scroll the focused one).
    FocusNext,
    /// The world's fact table: scroll, and narrow to facts holding a text.
    WorldUp,
    WorldDown,
    WorldFilter,
    LogUp,
    LogDown,
    Help,
    Quit,
    /// Replay: one step (an event or a command) forward.
    EventForward,
    EventBack,
    /// Replay: to the next tick.
    TickForward,
    TickBack,
    /// Replay: to the next failed action.
    NextFailure,
    PreviousFailure,
    /// Replay: to the next question to the model or its reply.
    NextModelCall,
    PreviousModelCall,
    /// Replay: the start and the end of the recording.
    Start,
    End,
}

/// Which screen keys are read for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KeyMode {
    /// The live workbench over a session engine.
    #[default]
    Workbench,
    /// A recording replayed, read-only.
    Replay,
}

/// Where an action is bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scope {
    Both,
    Workbench,
    Replay,
}

impl Scope {
    fn holds(self, mode: KeyMode) -> bool {
        match self {
            Scope::Both => true,
            Scope::Workbench => mode == KeyMode::Workbench,
            Scope::Replay => mode == KeyMode::Replay,
        }
    }

    /// Whether two actions of these scopes can be pressed on one screen.
    fn meets(self, other: Scope) -> bool {
        self == Scope::Both || other == Scope::Both || self == other
    }
}

/// Why a key's name was not understood; each names the text as written.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KeyError {
    #[error("unknown key {text:?} (function keys are f1-f12)")]
    FunctionKey { text: String },
    #[error(
        "unknown key {text:?} (expected one character, space, enter, esc, tab, backspace, left, right, up, down or f1-f12, optionally with ctrl- or alt-)"
    )]
    Unknown { text: String },
}

/// Why a file of key bindings was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KeysFileError {
    #[error(transparent)]
    Toml(#[from] toml::de::Error),
    /// The key given for an action, by the action's name in the file.
    #[error("{action}: {error}")]
    Key {
        action: &'static str,
        error: KeyError,
    },
    #[error("{key} is bound to both {first:?} and {second:?} on one screen")]
    Shared {
        key: Key,
        first: Action,
        second: Action,
    },
}

/// A key with its modifiers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Key {
    pub code: KeyCode,
    pub modifiers: KeyModifiers,
}

impl Key {
    pub const fn plain(c: char) -> Key {
        Key::code(KeyCode::Char(c))
    }

    /// A key without modifiers.
    pub const fn code(code: KeyCode) -> Key {
        Key {
            code,
            modifiers: KeyModifiers::NONE,
        }
    }

    /// Whether `event` is this key (Shift is ignored for characters: `?` arrives shifted).
    pub fn matches(&self, event: &KeyEvent) -> bool {
        let mods = match event.code {
            KeyCode::Char(_) => event.modifiers - KeyModifiers::SHIFT,
            _ => event.modifiers,
        };
        let want = match self.code {
            KeyCode::Char(_) => self.modifiers - KeyModifiers::SHIFT,
            _ => self.modifiers,
        };
        event.code == self.code && mods == want
    }

    /// `space`, `enter`, `esc`, `tab`, `backspace`, `left`, `right`, `up`, `down` (or
    /// `←` `→` `↑` `↓`), `f1`…`f12`, one character, each optionally prefixed by `ctrl-` or
    /// `alt-`.
    pub fn parse(text: &str) -> Result<Key, KeyError> {
        let mut modifiers = KeyModifiers::NONE;
        let mut rest = text.trim();
        loop {
            let lower = rest.to_ascii_lowercase();
            if lower.starts_with("ctrl-") && rest.len() > 5 {
                modifiers |= KeyModifiers::CONTROL;
                rest = &rest[5..];
            } else if lower.starts_with("alt-") && rest.len() > 4 {
                modifiers |= KeyModifiers::ALT;
                rest = &rest[4..];
            } else {
                break;
            }
        }
        let code = match rest.to_ascii_lowercase().as_str() {
            "space" => KeyCode::Char(' '),
            "enter" => KeyCode::Enter,
            "esc" => KeyCode::Esc,
            "tab" => KeyCode::Tab,
            "backspace" => KeyCode::Backspace,
            "left" | "←" => KeyCode::Left,
            "right" | "→" => KeyCode::Right,
            "up" | "↑" => KeyCode::Up,
            "down" | "↓" => KeyCode::Down,
            f if f.len() > 1 && f.starts_with('f') => match f[1..].parse::<u8>() {
                Ok(n @ 1..=12) => KeyCode::F(n),
                _ => {
                    return Err(KeyError::FunctionKey {
                        text: text.to_string(),
                    });
                }
            },
            _ => {
                let mut chars = rest.chars();
                match (chars.next(), chars.next()) {
                    (Some(c), None) => KeyCode::Char(c),
                    _ => {
                        return Err(KeyError::Unknown {
                            text: text.to_string(),
                        });
                    }
                }
            }
        };
        Ok(Key { code, modifiers })
    }
}

impl fmt::Display for Key {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.modifiers.contains(KeyModifiers::CONTROL) {
            f.write_str("ctrl-")?;
        }
        if self.modifiers.contains(KeyModifiers::ALT) {
            f.write_str("alt-")?;
        }
        match self.code {
            KeyCode::Char(' ') => f.write_str("space"),
            KeyCode::Char(c) => write!(f, "{c}"),
            KeyCode::Enter => f.write_str("enter"),
            KeyCode::Esc => f.write_str("esc"),
            KeyCode::Tab => f.write_str("tab"),
            KeyCode::Backspace => f.write_str("backspace"),
            KeyCode::Left => f.write_str("←"),
            KeyCode::Right => f.write_str("→"),
            KeyCode::Up => f.write_str("↑"),
            KeyCode::Down => f.write_str("↓"),
            KeyCode::F(n) => write!(f, "f{n}"),
            other => write!(f, "{other:?}"),
        }
    }
}

macro_rules! bindings {
    ($( $field:ident : $action:ident = $default:expr, $scope:ident );* $(;)?) => {
        /// The key of every action.
        #[derive(Debug, Clone, PartialEq, Eq)]
        pub struct KeyBindings {
            $( pub $field: Key, )*
        }

        impl Default for KeyBindings {
            fn default() -> Self {
                KeyBindings { $( $field: $default, )* }
            }
        }

        /// A file of overrides: every field optional.
        #[derive(Debug, Default, Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Patch {
            $( $field: Option<String>, )*
        }

        impl KeyBindings {
            /// Every action with its key, in help order.
            pub fn entries(&self) -> Vec<(Action, Key)> {
                self.scoped().into_iter().map(|(a, k, _)| (a, k)).collect()
            }

            fn scoped(&self) -> Vec<(Action, Key, Scope)> {
                vec![ $( (Action::$action, self.$field, Scope::$scope), )* ]
            }

            fn apply(&mut self, patch: Patch) -> Result<(), KeysFileError> {
                $( if let Some(text) = patch.$field {
                    self.$field = Key::parse(&text).map_err(|error| KeysFileError::Key {
                        action: stringify!($field),
                        error,
                    })?;
                } )*
                Ok(())
            }
        }
    };
}

bindings! {
    step: Step = Key::plain(' '), Workbench;
    run: Run = Key::plain('r'), Workbench;
    plan: Plan = Key::plain('p'), Workbench;
    instruction: Instruction = Key::plain('i'), Workbench;
    dictate: Dictate = Key::plain('d'), Workbench;
    approve: Approve = Key::plain('a'), Workbench;
    reject: Reject = Key::plain('x'), Workbench;
    cancel: Cancel = Key::code(KeyCode::Esc), Workbench;
    edit: Edit = Key::plain('e'), Workbench;
    undo: Undo = Key::plain('u'), Workbench;
    verify: Verify = Key::plain('v'), Workbench;
    save: Save = Key::plain('s'), Workbench;
    load: Load = Key::plain('l'), Workbench;
    export: Export = Key::plain('o'), Workbench;
    keep_rule: KeepRule = Key::plain('m'), Workbench;
    keep_rule_only: KeepRuleOnly = Key::plain('M'), Workbench;
    decline_rule: DeclineRule = Key::plain('n'), Workbench;
    knowledge: Knowledge = Key::plain('g'), Workbench;
    reset: Reset = Key::plain('w'), Workbench;
    breakpoint: Breakpoint = Key::plain('b'), Workbench;
    force: Force = Key::plain('f'), Workbench;
    break_on_failure: BreakOnFailure = Key::plain('B'), Workbench;
    event_forward: EventForward = Key::code(KeyCode::Right), Replay;
    event_back: EventBack = Key::code(KeyCode::Left), Replay;
    tick_forward: TickForward = Key::plain('.'), Replay;
    tick_back: TickBack = Key::plain(','), Replay;
    next_failure: NextFailure = Key::plain('n'), Replay;
    previous_failure: PreviousFailure = Key::plain('N'), Replay;
    next_model_call: NextModelCall = Key::plain('m'), Replay;
    previous_model_call: PreviousModelCall = Key::plain('M'), Replay;
    start: Start = Key::plain('g'), Replay;
    end: End = Key::plain('G'), Replay;
    details: Details = Key::plain('D'), Both;
    follow: Follow = Key::plain('F'), Both;
    search: Search = Key::plain('/'), Workbench;
    search_next: SearchNext = Key::plain('>'), Workbench;
    search_previous: SearchPrevious = Key::plain('<'), Workbench;
    collapse_all: CollapseAll = Key::plain('C'), Both;
    expand_all: ExpandAll = Key::plain('+'), Both;
    expand_to_running: ExpandToRunning = Key::plain('E'), Both;
    scroll_left: ScrollLeft = Key::plain('H'), Both;
    scroll_right: ScrollRight = Key::plain('L'), Both;
    focus_next: FocusNext = Key::code(KeyCode::Tab), Both;
    world_up: WorldUp = Key::plain('{'), Both;
    world_down: WorldDown = Key::plain('}'), Both;
    world_filter: WorldFilter = Key::plain('W'), Workbench;
    log_up: LogUp = Key::plain('['), Both;
    log_down: LogDown = Key::plain(']'), Both;
    help: Help = Key::plain('?'), Both;
    quit: Quit = Key::plain('q'), Both;
}

impl KeyBindings {
    /// The live workbench's action bound to `event`, if any.
    pub fn action(&self, event: &KeyEvent) -> Option<Action> {
        self.action_in(KeyMode::Workbench, event)
    }

    /// The action bound to `event` on the `mode` screen, if any.
    pub fn action_in(&self, mode: KeyMode, event: &KeyEvent) -> Option<Action> {
        self.entries_in(mode)
            .into_iter()
            .find(|(_, k)| k.matches(event))
            .map(|(a, _)| a)
    }

    /// The actions of the `mode` screen with their keys, in help order.
    pub fn entries_in(&self, mode: KeyMode) -> Vec<(Action, Key)> {
        self.scoped()
            .into_iter()
            .filter(|(_, _, scope)| scope.holds(mode))
            .map(|(a, k, _)| (a, k))
            .collect()
    }

    /// The key of `action`.
    pub fn key(&self, action: Action) -> Option<Key> {
        self.entries()
            .into_iter()
            .find(|(a, _)| *a == action)
            .map(|(_, k)| k)
    }

    /// The defaults patched by a TOML text; two actions of one screen may not share a key.
    pub fn from_toml(text: &str) -> Result<KeyBindings, KeysFileError> {
        let patch: Patch = toml::from_str(text)?;
        let mut keys = KeyBindings::default();
        keys.apply(patch)?;
        let entries = keys.scoped();
        for (i, (a, k, scope)) in entries.iter().enumerate() {
            if let Some((b, _, _)) = entries[..i]
                .iter()
                .find(|(_, other, theirs)| other == k && scope.meets(*theirs))
            {
                return Err(KeysFileError::Shared {
                    key: *k,
                    first: *b,
                    second: *a,
                });
            }
        }
        Ok(keys)
    }

    /// The bindings from `path` when it exists, else the defaults; with the reason a file
    /// was not used.
    pub fn load(path: &Path) -> (KeyBindings, Option<String>) {
        match crate::store::read_text(path, crate::store::SMALL_FILE_BYTES) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => (KeyBindings::default(), None),
            Err(e) => (
                KeyBindings::default(),
                Some(format!("{}: {e}", path.display())),
            ),
            Ok(text) => match KeyBindings::from_toml(&text) {
                Ok(k) => (k, None),
                Err(e) => (
                    KeyBindings::default(),
                    Some(format!("{}: {e}", path.display())),
                ),
            },
        }
    }

    /// The help overlay's lines on the `mode` screen: every binding, then the fixed
    /// navigation keys.
    pub fn help_lines(&self, mode: KeyMode) -> Vec<(String, &'static str)> {
        let mut lines: Vec<(String, &'static str)> = self
            .entries_in(mode)
            .into_iter()
            .map(|(a, k)| (k.to_string(), super::strings::action_help(a)))
            .collect();
        let navigation = match mode {
            KeyMode::Workbench => super::strings::NAVIGATION,
            KeyMode::Replay => super::strings::REPLAY_NAVIGATION,
        };
        lines.extend(navigation.iter().map(|(k, what)| ((*k).to_string(), *what)));
        lines
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn press(c: char, modifiers: KeyModifiers) -> KeyEvent {
        KeyEvent::new(KeyCode::Char(c), modifiers)
    }

    #[test]
    fn defaults_are_the_documented_keys() {
        let k = KeyBindings::default();
        let text: Vec<String> = k
            .entries_in(KeyMode::Workbench)
            .iter()
            .map(|(_, k)| k.to_string())
            .collect();
        assert_eq!(
            text,
            [
                "space", "r", "p", "i", "d", "a", "x", "esc", "e", "u", "v", "s", "l", "o", "m",
                "M", "n", "g", "w", "b", "f", "B", "D", "F", "/", ">", "<", "C", "+", "E", "H",
                "L", "tab", "{", "}", "W", "[", "]", "?", "q"
            ]
        );
        assert_eq!(
            k.action(&press('?', KeyModifiers::SHIFT)),
            Some(Action::Help)
        );
        assert_eq!(k.action(&press('q', KeyModifiers::CONTROL)), None);
    }

    #[test]
    fn overrides_patch_the_defaults_and_bad_files_are_refused() {
        let k = KeyBindings::from_toml("step = \"t\"\nquit = \"ctrl-q\"\n").unwrap();
        assert_eq!(
            k.action(&press('t', KeyModifiers::NONE)),
            Some(Action::Step)
        );
        assert_eq!(
            k.action(&press('q', KeyModifiers::CONTROL)),
            Some(Action::Quit)
        );
        assert_eq!(k.run, Key::plain('r'));
        assert!(KeyBindings::from_toml("jump = \"j\"").is_err());
        let e = KeyBindings::from_toml("step = \"banana\"").unwrap_err();
        assert!(e.to_string().contains("step"), "{e}");
        assert!(
            matches!(
                KeyBindings::from_toml("step = \"q\""),
                Err(KeysFileError::Shared {
                    first: Action::Step,
                    second: Action::Quit,
                    ..
                })
            ),
            "two actions on one key"
        );
        let e = KeyBindings::from_toml("step = \"f13\"").unwrap_err();
        assert!(e.to_string().contains("f1-f12"), "{e}");
        let help = KeyBindings::default().help_lines(KeyMode::Workbench);
        assert!(
            help.iter()
                .any(|(k, what)| k == "space" && what.contains("tick"))
        );
    }

    #[test]
    fn the_replay_has_its_own_keys_and_none_that_edit_or_run() {
        let k = KeyBindings::default();
        let text: Vec<String> = k
            .entries_in(KeyMode::Replay)
            .iter()
            .map(|(_, k)| k.to_string())
            .collect();
        assert_eq!(
            text,
            [
                "→", "←", ".", ",", "n", "N", "m", "M", "g", "G", "D", "F", "C", "+", "E", "H",
                "L", "tab", "{", "}", "[", "]", "?", "q"
            ]
        );
        let right = KeyEvent::new(KeyCode::Right, KeyModifiers::NONE);
        assert_eq!(
            k.action_in(KeyMode::Replay, &right),
            Some(Action::EventForward)
        );
        // The tree's expand key in the workbench.
        assert_eq!(k.action_in(KeyMode::Workbench, &right), None);
        assert_eq!(
            k.action_in(KeyMode::Replay, &press('N', KeyModifiers::SHIFT)),
            Some(Action::PreviousFailure)
        );
        assert_eq!(
            k.action(&press('n', KeyModifiers::NONE)),
            Some(Action::DeclineRule)
        );
        for live in ['a', 'x', 'e', 'r', ' ', 'u', 'i', 'd', 'p'] {
            assert_eq!(
                k.action_in(KeyMode::Replay, &press(live, KeyModifiers::NONE)),
                None,
                "{live:?} does something in a replay"
            );
        }
        // One key for a replay action and a workbench action is fine; not with a shared one.
        let k = KeyBindings::from_toml("tick_forward = \"a\"\nevent_forward = \"right\"").unwrap();
        assert_eq!(k.tick_forward, Key::plain('a'));
        assert!(matches!(
            KeyBindings::from_toml("end = \"q\""),
            Err(KeysFileError::Shared {
                first: Action::End,
                second: Action::Quit,
                ..
            })
        ));
        assert_eq!(Key::parse("←").unwrap(), Key::code(KeyCode::Left));
        let help = k.help_lines(KeyMode::Replay);
        assert!(help.iter().all(|(key, _)| key != "space"), "{help:?}");
        // The arrows move in the recording; Enter folds the tree.
        assert!(!help.iter().any(|(key, _)| key == "← →"), "{help:?}");
    }
}

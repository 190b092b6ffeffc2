//! Reading the LLM-OBTEA goal-interpretation dataset: `easy.txt`, `medium.txt` and
//! `hard.txt`, each a list of cases written as
//!
//! ```text
//! Instruction: Would you mind turning on the air conditioning?
//! Goal: Active_AC
//! ```
//!
//! with blank lines between cases. CRLF line ends, a byte-order mark and spaces around the
//! text are tolerated. The goal text is returned as written; parse it with
//! [`crate::goal::Formula::parse`].

use std::fmt;
use std::path::{Path, PathBuf};

/// The three files of the dataset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Difficulty {
    Easy,
    Medium,
    Hard,
}

impl Difficulty {
    /// In the order the files are read.
    pub const ALL: [Difficulty; 3] = [Difficulty::Easy, Difficulty::Medium, Difficulty::Hard];

    pub fn as_str(self) -> &'static str {
        match self {
            Difficulty::Easy => "easy",
            Difficulty::Medium => "medium",
            Difficulty::Hard => "hard",
        }
    }

    /// The file holding this difficulty's cases, e.g. `easy.txt`.
    pub fn file_name(self) -> String {
        format!("{}.txt", self.as_str())
    }
}

impl fmt::Display for Difficulty {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One instruction with its gold goal.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Case {
    pub difficulty: Difficulty,
    /// 0-based position within its file.
    pub index: usize,
    pub instruction: String,
    pub gold: String,
}

/// Why the dataset could not be read. `line` is 1-based.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    #[error("cannot read {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}:{line}: {message}", path.display())]
    Malformed {
        path: PathBuf,
        line: usize,
        message: String,
    },
}

/// Read `easy.txt`, `medium.txt` and `hard.txt` from `dir`, in that order.
pub fn load(dir: &Path) -> Result<Vec<Case>, DatasetError> {
    let mut cases = Vec::new();
    for difficulty in Difficulty::ALL {
        let path = dir.join(difficulty.file_name());
        let text = std::fs::read_to_string(&path).map_err(|source| DatasetError::Io {
            path: path.clone(),
            source,
        })?;
        cases.extend(parse(&text, difficulty, &path)?);
    }
    Ok(cases)
}

/// Read the cases of one file's `text`; `path` only names the file in errors.
pub fn parse(text: &str, difficulty: Difficulty, path: &Path) -> Result<Vec<Case>, DatasetError> {
    let malformed = |line: usize, message: String| DatasetError::Malformed {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut cases = Vec::new();
    // The instruction waiting for its goal, with its line number.
    let mut pending: Option<(String, usize)> = None;
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        last_line = line_no;
        let line = raw.trim();
        if let Some(rest) = line.strip_prefix("Instruction:") {
            if let Some((_, at)) = pending {
                return Err(malformed(
                    line_no,
                    format!(
                        "expected the Goal: line for the instruction on line {at}, found another Instruction: line"
                    ),
                ));
            }
            let instruction = rest.trim();
            if instruction.is_empty() {
                return Err(malformed(line_no, "empty instruction".into()));
            }
            pending = Some((instruction.to_string(), line_no));
        } else if let Some(rest) = line.strip_prefix("Goal:") {
            let Some((instruction, _)) = pending.take() else {
                return Err(malformed(
                    line_no,
                    "Goal: line without an Instruction: line before it".into(),
                ));
            };
            let gold = rest.trim();
            if gold.is_empty() {
                return Err(malformed(line_no, "empty goal".into()));
            }
            cases.push(Case {
                difficulty,
                index: cases.len(),
                instruction,
                gold: gold.to_string(),
            });
        } else if !line.is_empty() {
            let expected = if pending.is_some() {
                "a Goal: line"
            } else {
                "an Instruction: line or a blank line"
            };
            let shown: String = line.chars().take(40).collect();
            return Err(malformed(
                line_no,
                format!("expected {expected}, found {shown:?}"),
            ));
        } else if let Some((_, at)) = pending {
            return Err(malformed(
                line_no,
                format!(
                    "expected the Goal: line for the instruction on line {at}, found a blank line"
                ),
            ));
        }
    }
    if let Some((_, at)) = pending {
        return Err(malformed(
            last_line,
            format!("the instruction on line {at} has no Goal: line (end of file)"),
        ));
    }
    Ok(cases)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Vec<Case>, DatasetError> {
        parse(text, Difficulty::Medium, Path::new("medium.txt"))
    }

    fn line_of(text: &str) -> (usize, String) {
        match read(text).unwrap_err() {
            DatasetError::Malformed { line, message, .. } => (line, message),
            e => panic!("{e}"),
        }
    }

    #[test]
    fn reads_cases_tolerating_crlf_and_spaces() {
        let text = "\u{feff}Instruction:  Turn on the AC. \r\nGoal: Active_AC  \r\n\r\n\r\nInstruction: Close it.\nGoal:Closed_Curtain";
        let cases = read(text).unwrap();
        assert_eq!(cases.len(), 2);
        assert_eq!(cases[0].instruction, "Turn on the AC.");
        assert_eq!(cases[0].gold, "Active_AC");
        assert_eq!(
            (cases[1].index, cases[1].gold.as_str()),
            (1, "Closed_Curtain")
        );
        assert_eq!(cases[1].difficulty, Difficulty::Medium);
        assert!(read("").unwrap().is_empty());
    }

    #[test]
    fn malformed_files_name_file_and_line() {
        let (line, msg) = line_of("Instruction: a\nGoal: A\n\nInstruction: b\n\nGoal: B\n");
        assert_eq!(line, 5);
        assert!(msg.contains("line 4"), "{msg}");
        let (line, msg) = line_of("Instruction: a\nGoal: A\n\nInstruction: b\n");
        assert_eq!(line, 4);
        assert!(msg.contains("no Goal"), "{msg}");
        let (line, _) = line_of("Goal: A\n");
        assert_eq!(line, 1);
        let (line, msg) = line_of("Instruction: a\nGoal:   \n");
        assert_eq!((line, msg.as_str()), (2, "empty goal"));
        let (line, msg) = line_of("Instruction: a\nGoal: A\nSomething else\n");
        assert_eq!(line, 3);
        assert!(msg.contains("Something else"));
        let e = read("Instruction: a\nInstruction: b\n").unwrap_err();
        assert!(e.to_string().starts_with("medium.txt:2: "), "{e}");
    }

    #[test]
    fn missing_file_is_an_io_error_naming_it() {
        let e = load(Path::new("/nonexistent/llm-obtea")).unwrap_err();
        assert!(matches!(e, DatasetError::Io { .. }));
        assert!(e.to_string().contains("easy.txt"), "{e}");
    }

    #[test]
    fn difficulties_in_order() {
        let names: Vec<&str> = Difficulty::ALL.iter().map(|d| d.as_str()).collect();
        assert_eq!(names, ["easy", "medium", "hard"]);
        assert_eq!(Difficulty::Hard.file_name(), "hard.txt");
    }
}

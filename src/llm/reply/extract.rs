//! Finding the answer in a reply's text: labels anywhere in a line, numbering, bullets,
//! code fences, bold markers and extra prose are tolerated. Only ASCII case folding is
//! used, so byte offsets stay valid in the original text whatever it contains.

/// The reply's lines with code-fence lines removed and markdown emphasis around labels
/// dropped.
pub fn lines(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| !l.trim_start().starts_with("```"))
        .map(|l| l.replace("**", "").trim_end().to_string())
        .collect()
}

/// Where a label (`goal`, `parameter value`, ...) followed by `:` occurs in a line, as the
/// byte offset just after the colon. The label must start the line or follow a character
/// that is not a letter or digit.
pub fn label_end(line: &str, labels: &[&str]) -> Option<usize> {
    let lower = line.to_ascii_lowercase();
    let bytes = lower.as_bytes();
    let mut best: Option<(usize, usize)> = None;
    for label in labels {
        let mut from = 0;
        while let Some(pos) = lower.get(from..).and_then(|s| s.find(label)) {
            let start = from + pos;
            let end = start + label.len();
            let boundary_before = start == 0 || !bytes[start - 1].is_ascii_alphanumeric();
            let mut colon = end;
            while colon < bytes.len() && bytes[colon] == b' ' {
                colon += 1;
            }
            if boundary_before && bytes.get(colon) == Some(&b':') {
                // Prefer the earliest label in the line, then the longest.
                if best.is_none_or(|(s, _)| start < s) {
                    best = Some((start, colon + 1));
                }
                break;
            }
            from = end;
        }
    }
    best.map(|(_, e)| e)
}

/// Every (line index, text after the label) for lines holding one of `labels`.
pub fn labelled(lines: &[String], labels: &[&str]) -> Vec<(usize, String)> {
    lines
        .iter()
        .enumerate()
        .filter_map(|(i, l)| label_end(l, labels).map(|e| (i, l[e..].trim().to_string())))
        .collect()
}

/// Remove list numbering (`1.`, `2)`, `(3)`), bullets and surrounding backticks.
pub fn strip_item(line: &str) -> &str {
    let mut t = line.trim();
    loop {
        let before = t;
        for bullet in ["- ", "* ", "• ", "+ ", "> "] {
            if let Some(rest) = t.strip_prefix(bullet) {
                t = rest.trim_start();
            }
        }
        if t == "-" || t == "*" {
            return "";
        }
        let digits = t.bytes().take_while(u8::is_ascii_digit).count();
        if digits > 0 && matches!(t.as_bytes().get(digits), Some(b'.' | b')' | b':')) {
            t = t[digits + 1..].trim_start();
        } else if t.starts_with('(') && digits == 0 {
            let inner = t[1..].bytes().take_while(u8::is_ascii_digit).count();
            if inner > 0 && t.as_bytes().get(1 + inner) == Some(&b')') {
                t = t[inner + 2..].trim_start();
            }
        }
        if before == t {
            break;
        }
    }
    strip_ticks(t)
}

/// Remove backticks and trailing punctuation that is never part of an answer.
pub fn strip_ticks(text: &str) -> &str {
    let mut t = text.trim();
    loop {
        let before = t;
        t = t.trim_matches('`').trim();
        t = t.trim_end_matches(['.', ',', ';']).trim_end();
        if t == before {
            return t;
        }
    }
}

/// Split a line of conditions at `&` and `,` outside quotes.
pub fn split_conditions(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut in_quote = false;
    let mut start = 0;
    for (i, c) in text.char_indices() {
        match c {
            '"' => in_quote = !in_quote,
            '&' | ',' | ';' if !in_quote => {
                out.push(text[start..i].trim());
                start = i + c.len_utf8();
            }
            _ => {}
        }
    }
    out.push(text[start..].trim());
    out.into_iter()
        .map(strip_ticks)
        .filter(|s| !s.is_empty())
        .collect()
}

/// Whether a piece of text is meant as a condition (so failing to read it is an error,
/// not prose to skip): it starts with `~` or a quote, or is one identifier-like word with
/// an underscore or an upper-case start and no spaces.
pub fn looks_like_condition(text: &str) -> bool {
    let t = text.trim();
    t.starts_with('~')
        || t.starts_with('"')
        || (!t.contains(' ') && t.starts_with(|c: char| c.is_ascii_uppercase()) && t.contains('_'))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_found_inside_lines() {
        assert_eq!(label_end("Goal: A", &["goal"]), Some(5));
        assert!(label_end("So the final goal : A", &["goal"]).is_some());
        assert_eq!(label_end("Goalkeeper: A", &["goal"]), None);
        assert_eq!(label_end("subgoal: A", &["goal"]), None);
        assert_eq!(
            label_end("Parameter value: 5 N", &["parameter value", "value"]),
            Some(16)
        );
    }

    #[test]
    fn items_lose_their_decoration() {
        assert_eq!(strip_item("1. `Exists_Coffee`."), "Exists_Coffee");
        assert_eq!(strip_item("  - (2) ~\"a\" on \"b\""), "~\"a\" on \"b\"");
        assert_eq!(strip_item("• RobotNear_Bar,"), "RobotNear_Bar");
        assert_eq!(
            split_conditions("\"a, b\" on \"c\" & X_Y, `Z_W`"),
            vec!["\"a, b\" on \"c\"", "X_Y", "Z_W"]
        );
    }
}

//! Input echoed in an error message, cut to a readable excerpt: a short text whole, a long
//! one as the stretch around the place the error is about, so a 10,000-character goal
//! does not fill the terminal.

/// Texts up to this many characters are echoed whole.
const WHOLE: usize = 80;
/// Characters shown on each side of the place the error is about.
const AROUND: usize = 30;

/// `text` quoted for an error about the character at byte offset `at` (`None`: the
/// error is about the whole text): whole when short, else the stretch around `at` with
/// `…` where it was cut and the length of the whole.
pub fn excerpt(text: &str, at: Option<usize>) -> String {
    let chars = text.chars().count();
    if chars <= WHOLE {
        return format!("{text:?}");
    }
    let at_char = at
        .and_then(|at| text.get(..at))
        .map_or(0, |before| before.chars().count());
    let start = at_char.saturating_sub(AROUND);
    let end = (at_char + AROUND)
        .min(chars)
        .max(start + 2 * AROUND)
        .min(chars);
    let middle: String = text.chars().skip(start).take(end - start).collect();
    format!(
        "{}{middle:?}{} ({chars} characters)",
        if start > 0 { "…" } else { "" },
        if end < chars { "…" } else { "" }
    )
}

/// `text` cut to `max` characters, with `…` when cut.
pub fn shortened(text: &str, max: usize) -> String {
    if text.chars().count() <= max {
        return text.to_string();
    }
    let mut cut: String = text.chars().take(max.saturating_sub(1)).collect();
    cut.push('…');
    cut
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_text_is_echoed_whole() {
        assert_eq!(excerpt("On_Tea_Table9", Some(3)), "\"On_Tea_Table9\"");
    }

    #[test]
    fn a_long_text_is_cut_around_the_place() {
        let text = format!("{}BAD{}", "(".repeat(5000), ")".repeat(5000));
        let e = excerpt(&text, Some(5000));
        assert!(e.starts_with('…') && e.contains("BAD"), "{e}");
        assert!(e.ends_with("(10003 characters)"), "{e}");
        assert!(e.chars().count() < 100, "{e}");
        // Without a place, the start is shown.
        let e = excerpt(&text, None);
        assert!(e.starts_with("\"((((") && !e.contains("BAD"), "{e}");
        // A place near the end shows the end, uncut there.
        let e = excerpt(&text, Some(text.len() - 1));
        assert!(e.starts_with('…') && e.contains("))\" ("), "{e}");
    }

    #[test]
    fn shortened_marks_the_cut() {
        assert_eq!(shortened("abcdef", 4), "abc…");
        assert_eq!(shortened("abc", 4), "abc");
    }
}

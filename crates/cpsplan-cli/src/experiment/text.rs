//! User-given names (maps, parameter sets, experiments) made safe for the
//! report's Markdown tables and for spreadsheets opening its CSV files.

use serde::Serializer;

/// `text` as one Markdown table cell on one line: `|` escaped, line breaks
/// as spaces, `&`, `<` and `>` as entities (no raw HTML).
pub fn md_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '|' => out.push_str("\\|"),
            '\\' => out.push_str("\\\\"),
            '\n' | '\r' => out.push(' '),
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            c => out.push(c),
        }
    }
    out
}

/// The cells of a Markdown table row made by [`md_text`], as plain text.
pub fn md_cells(line: &str) -> Vec<String> {
    let line = line.trim();
    let line = line.strip_prefix('|').unwrap_or(line);
    let line = line
        .strip_suffix('|')
        .filter(|l| !l.ends_with('\\'))
        .unwrap_or(line);
    let mut cells = vec![String::new()];
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        match c {
            '\\' => {
                if let (Some(next), Some(s)) = (chars.next(), cells.last_mut()) {
                    s.push(next);
                }
            }
            '|' => cells.push(String::new()),
            c => {
                if let Some(s) = cells.last_mut() {
                    s.push(c);
                }
            }
        }
    }
    cells
        .into_iter()
        .map(|c| {
            c.trim()
                .replace("&lt;", "<")
                .replace("&gt;", ">")
                .replace("&amp;", "&")
        })
        .collect()
}

/// `text` safe in a spreadsheet: a cell that would start a formula (`=`,
/// `+`, `-`, `@`, a tab or a carriage return first) starts with `'`.
pub fn csv_text(text: &str) -> String {
    match text.chars().next() {
        Some('=' | '+' | '-' | '@' | '\t' | '\r') => format!("'{text}"),
        _ => text.to_string(),
    }
}

/// Serializes a string field through [`csv_text`].
pub fn csv_safe<S: Serializer>(text: &str, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&csv_text(text))
}

/// Serializes an optional string field through [`csv_text`].
pub fn csv_safe_option<S: Serializer>(text: &Option<String>, s: S) -> Result<S::Ok, S::Error> {
    match text {
        Some(t) => s.serialize_some(&csv_text(t)),
        None => s.serialize_none(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_cells_round_trip_whatever_the_name() {
        for name in [
            "x|y",
            "a\\|b",
            "<img onerror=alert(1)>",
            "a & b",
            "end\\",
            "plain",
        ] {
            let row = format!("| {} | 2 |", md_text(name));
            assert_eq!(md_cells(&row), [name.to_string(), "2".to_string()], "{row}");
            assert!(!md_text(name).contains('<'));
        }
        assert_eq!(md_text("two\nlines"), "two lines");
    }

    #[test]
    fn formulas_are_not_formulas_in_a_spreadsheet() {
        assert_eq!(csv_text("=HYPERLINK(\"x\")"), "'=HYPERLINK(\"x\")");
        assert_eq!(csv_text("-1"), "'-1");
        assert_eq!(csv_text("site/team"), "site/team");
        assert_eq!(csv_text(""), "");
    }
}

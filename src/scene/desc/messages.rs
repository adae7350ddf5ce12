//! Parse errors in the user's words: serde's Rust types said as "a whole
//! number" or "text", hints for the common slips, and the scene line quoted
//! around the place (at most 100 characters of it).

/// A deserializer's message in the user's words: "a whole number", not
/// `i64`; with hints for the common slips (`[camera]` for `[[camera]]`,
/// a key one or two edits from a known one).
pub(super) fn in_words(message: &str, text: &str, offset: usize) -> String {
    let mut m = message.to_string();
    for (rust, words) in [
        ("expected i64", "expected a whole number"),
        ("expected u64", "expected a whole number"),
        ("expected u32", "expected a whole number"),
        ("expected f32", "expected a number"),
        ("expected f64", "expected a number"),
        ("expected a boolean", "expected true or false"),
        ("expected a string", "expected text (in quotes)"),
        (
            "expected an array of length 3",
            "expected a list of 3 numbers, such as [1.0, 0.5, 0.2]",
        ),
        (
            "expected an array of length 2",
            "expected a list of 2 numbers",
        ),
        ("expected a sequence", "expected a list"),
        ("invalid type: string", "found text"),
        ("invalid type: integer", "found the whole number"),
        ("invalid type: floating point", "found the number"),
        ("invalid type: boolean", "found"),
        ("invalid type: map", "found a table"),
        ("invalid type: sequence", "found a list"),
        ("invalid length", "found a list of length"),
    ] {
        m = m.replace(rust, words);
    }
    // `[camera]` where `[[camera]]` (an array of tables) is meant.
    let line = text[offset.min(text.len())..]
        .lines()
        .next()
        .unwrap_or("")
        .trim();
    if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']'))
        && !name.starts_with('[')
        && message.contains("expected a sequence")
    {
        m.push_str(&format!(
            "; write [[{name}]] (double brackets): a scene may have several of them"
        ));
    }
    // An unknown key close to a known one.
    if let Some(rest) = message.strip_prefix("unknown field `")
        && let Some((key, known)) = rest.split_once('`')
    {
        let close = known
            .split('`')
            .skip(1)
            .step_by(2)
            .filter(|k| edit_distance(key, k) <= 2)
            .min_by_key(|k| edit_distance(key, k));
        if let Some(k) = close {
            m = format!("unknown key `{key}`: did you mean `{k}`?");
        }
    }
    m
}

/// Levenshtein distance, for "did you mean".
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

pub(super) fn source_excerpt(text: &str, offset: usize) -> String {
    let offset = offset.min(text.len());
    let start = text[..offset].rfind('\n').map(|i| i + 1).unwrap_or(0);
    let end = text[offset..]
        .find('\n')
        .map(|i| offset + i)
        .unwrap_or(text.len());
    let line_no = text[..offset].matches('\n').count() + 1;
    let line = text[start..end].trim_end();
    if line.is_empty() {
        return String::new();
    }
    // A long line (a generated or hostile file) is shown around the
    // place, at most 100 characters of it.
    const SHOWN: usize = 100;
    if line.chars().count() <= SHOWN {
        return format!("\n  {line_no} | {line}");
    }
    let at = text[start..offset].chars().count();
    let from = at.saturating_sub(SHOWN / 2);
    let piece: String = line.chars().skip(from).take(SHOWN).collect();
    let more = line.chars().count() > from + SHOWN;
    format!(
        "\n  {line_no} | {}{piece}{}",
        if from > 0 { "..." } else { "" },
        if more { "..." } else { "" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(t: &str) -> Result<super::super::SceneDesc, crate::error::Error> {
        super::super::SceneDesc::parse(std::path::Path::new("t.toml"), t)
    }

    #[test]
    fn a_long_line_is_shown_around_the_error_only() {
        let deep = format!("a = {}1{}\n", "[".repeat(50_000), "]".repeat(50_000));
        let e = parse(&deep).unwrap_err().to_string();
        assert!(e.len() < 1_000, "{} bytes: {}", e.len(), &e[..300]);
    }

    #[test]
    fn did_you_mean_is_one_or_two_edits_away() {
        assert_eq!(edit_distance("msaaa", "msaa"), 1);
        assert_eq!(edit_distance("shading", "shadows"), 3);
        let e = parse("[[model]]\npath = \"m.obj\"\n[render]\nmsaaa = 4\n").unwrap_err();
        assert!(e.to_string().contains("did you mean `msaa`?"), "{e}");
    }
}

//! Scenario text to its raw tables, with errors a user can act on: the file and line, the
//! key as the scenario writes it (`[[meshes]] #1 motion.direction`), serde's words for what
//! was expected without the parser's type names, and the line shown cut short.

use std::path::Path;

use anyhow::{Result, bail};
use serde_path_to_error::Segment;

use super::raw::RawScenario;

/// The largest scenario file read: scenarios are small, and long lists belong in files of
/// their own (`[input] particles`, `[[clumps]] file`); a file of gigabytes would take many
/// times its size to parse.
pub const MOST_SCENARIO_BYTES: usize = 16 << 20;

/// The longest part of a line an error shows.
const SHOWN: usize = 120;

/// The raw tables of scenario `text` read from `path`.
pub(super) fn raw_scenario(text: &str, path: &Path) -> Result<RawScenario> {
    let file = path.display();
    if text.len() > MOST_SCENARIO_BYTES {
        bail!(
            "{file}: {} bytes, more than a scenario's {MOST_SCENARIO_BYTES}: put long lists in \
             files of their own ([input] particles, [[clumps]] file)",
            text.len()
        );
    }
    let de = toml::Deserializer::parse(text).map_err(|e| located(text, path, None, &e))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let key = key_of(e.path()).map(|key| {
            // Inside a table of a `type` (a shape, a motion, a radius distribution) the
            // parser's path stops at the table: the field is the one holding what the
            // message quotes.
            match culprit(text, e.path(), e.inner().message()) {
                Some(field) => format!("{key}.{field}"),
                None => key,
            }
        });
        located(text, path, key.as_deref(), e.inner())
    })
}

/// The one field of the table at `path` whose value is what `message` complains of (an
/// array of the length it names, or the value it quotes), if the path ends at a table.
fn culprit(text: &str, path: &serde_path_to_error::Path, message: &str) -> Option<String> {
    let mut value = toml::Value::Table(text.parse::<toml::Table>().ok()?);
    for s in path.iter() {
        value = match s {
            Segment::Map { key } => value.get(key.as_str())?.clone(),
            Segment::Seq { index } => value.get(*index)?.clone(),
            _ => return None,
        };
    }
    let table = value.as_table()?;
    let quoted = |what: &str| -> Option<String> {
        let rest = message.split_once(what)?.1;
        let (open, close) = if rest.starts_with('"') {
            ('"', '"')
        } else {
            ('`', '`')
        };
        let rest = rest.strip_prefix(open)?;
        Some(rest[..rest.find(close)?].to_string())
    };
    let is_it = |v: &toml::Value| -> bool {
        if let Some(n) = message.strip_prefix("invalid length ") {
            let n: usize = n
                .split(',')
                .next()
                .and_then(|n| n.parse().ok())
                .unwrap_or(usize::MAX);
            return v.as_array().is_some_and(|a| a.len() == n);
        }
        match v {
            toml::Value::String(s) => quoted("string ").is_some_and(|q| q == *s),
            toml::Value::Integer(i) => quoted("integer ").is_some_and(|q| q == i.to_string()),
            toml::Value::Float(f) => quoted("floating point ").is_some_and(|q| q == f.to_string()),
            toml::Value::Boolean(b) => quoted("boolean ").is_some_and(|q| q == b.to_string()),
            _ => false,
        }
    };
    let mut found = table.iter().filter(|(k, v)| *k != "type" && is_it(v));
    match (found.next(), found.next()) {
        (Some((k, _)), None) => Some(k.clone()),
        _ => None,
    }
}

/// A TOML error as `FILE:LINE: KEY: message`, with the line (cut short) and a caret.
fn located(text: &str, path: &Path, key: Option<&str>, e: &toml::de::Error) -> anyhow::Error {
    let message = plain(e.message());
    let key = key.map_or(String::new(), |k| format!("{k}: "));
    let Some(span) = e.span() else {
        return anyhow::anyhow!("{}: {key}{message}", path.display());
    };
    let start = span.start.min(text.len());
    let line_start = text[..start].rfind('\n').map_or(0, |k| k + 1);
    let line_no = text[..start].matches('\n').count() + 1;
    let line = text[line_start..].lines().next().unwrap_or("");
    let column = text[line_start..start].chars().count();
    let (shown, cut) = match line.char_indices().nth(SHOWN) {
        Some((at, _)) => (&line[..at], " ..."),
        None => (line, ""),
    };
    let caret = if column <= SHOWN {
        format!("\n  | {}^", " ".repeat(column))
    } else {
        String::new()
    };
    anyhow::anyhow!(
        "{}:{line_no}: {key}{message}\n  | {shown}{cut}{caret}",
        path.display()
    )
}

/// serde's message without the names of the parser's types (`struct RawUntil`).
fn plain(message: &str) -> String {
    let mut out = message.trim_end().to_string();
    while let Some(at) = out.find("struct Raw") {
        let name = at + "struct ".len();
        let end = out[name..]
            .find(|c: char| !c.is_alphanumeric())
            .map_or(out.len(), |k| name + k);
        out.replace_range(at..end, "a table (key = value, ...)");
    }
    let out = out.replace(
        "expected an array of length 3",
        "expected [x, y, z]: 3 numbers",
    );
    // A quoted value may be the whole of a huge line: its middle goes.
    match (
        out.char_indices().nth(SHOWN),
        out.char_indices().rev().nth(40),
    ) {
        (Some((head, _)), Some((tail, _))) if tail > head => {
            format!("{} ... {}", &out[..head], &out[tail..])
        }
        _ => out,
    }
}

/// The key of a deserializer path as the scenario writes it: `[simulation] until`,
/// `[[meshes]] #2 motion.direction`, `[geometry] mesh_radii[1]`.
fn key_of(path: &serde_path_to_error::Path) -> Option<String> {
    let segments: Vec<&Segment> = path.iter().collect();
    let (first, rest) = segments.split_first()?;
    let Segment::Map { key: table } = first else {
        return None;
    };
    let (mut key, rest) = match rest.split_first() {
        Some((Segment::Seq { index }, rest)) => (format!("[[{table}]] #{}", index + 1), rest),
        _ => (format!("[{table}]"), rest),
    };
    let mut dotted = String::new();
    for s in rest {
        match s {
            Segment::Map { key } => {
                if !dotted.is_empty() {
                    dotted.push('.');
                }
                dotted.push_str(key);
            }
            Segment::Seq { index } => dotted.push_str(&format!("[{index}]")),
            Segment::Enum { .. } | Segment::Unknown => {}
        }
    }
    if !dotted.is_empty() {
        key = format!("{key} {dotted}");
    }
    Some(key)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &str) -> String {
        match raw_scenario(text, Path::new("s.toml")) {
            Ok(_) => panic!("accepted: {text}"),
            Err(e) => format!("{e:#}"),
        }
    }

    #[test]
    fn errors_name_the_line_and_the_key_and_no_type_of_the_parser() {
        let e = error("[simulation]\nframes = 3\nuntil = 5\n");
        assert!(
            e.starts_with("s.toml:3: [simulation] until: invalid type: integer `5`"),
            "{e}"
        );
        assert!(e.contains("expected a table (key = value, ...)"), "{e}");
        assert!(!e.contains("Raw"), "{e}");
        let e = error(
            "[[meshes]]\nfile = \"a.off\"\n[[meshes]]\nfile = \"b.off\"\n\
             motion = { type = \"harmonic\", amplitude = 0.1, frequency = 1.0, direction = [0.0, 1.0] }\n",
        );
        assert!(
            e.starts_with("s.toml:5: [[meshes]] #2 motion.direction: "),
            "{e}"
        );
        assert!(
            e.contains("invalid length 2, expected [x, y, z]: 3 numbers"),
            "{e}"
        );
        let e = error(
            "[[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = \"big\" }\n",
        );
        assert!(
            e.contains("s.toml:2: [[meshes]] #1 shape.size: invalid type"),
            "{e}"
        );
        let e = error("[geometry]\nmesh_radii = [0.1, \"x\"]\n");
        assert!(
            e.contains("s.toml:2: [geometry] mesh_radii[1]: invalid type"),
            "{e}"
        );
    }

    #[test]
    fn a_long_line_is_shown_cut_short_and_a_huge_file_is_refused_unread() {
        let long = format!("[material]\ndensity = \"{}\"\n", "x".repeat(100_000));
        let e = error(&long);
        assert!(e.len() < 400, "{} bytes: {e}", e.len());
        assert!(e.contains("s.toml:2: [material] density"), "{e}");
        assert!(e.contains(" ..."), "{e}");
        let huge = "#".repeat(MOST_SCENARIO_BYTES + 1);
        let e = error(&huge);
        assert!(e.contains("more than a scenario's"), "{e}");
    }
}

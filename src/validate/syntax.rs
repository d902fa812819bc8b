//! One-line syntax errors of input files (TOML scenes, impact JSON).

/// A file that does not parse: where and why, on one line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct SyntaxError {
    /// The file as named by the user.
    pub file: String,
    /// Line, from 1.
    pub line: usize,
    /// Column (characters), from 1.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

/// Parses TOML text; an error names the file, line and column of its first
/// character, and toml's message, on one line (toml's own display spreads
/// over several lines, with a caret that a one-line report misplaces).
///
/// ```
/// use topple::validate::parse_toml;
/// let e = parse_toml::<topple::rapier::scene::Scene>("duration = 1\nduration = 2\n", "s.toml").unwrap_err();
/// assert!(e.to_string().starts_with("s.toml:2:1: "), "{e}");
/// ```
#[cfg(feature = "scene-files")]
pub fn parse_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
) -> Result<T, SyntaxError> {
    toml::from_str(text).map_err(|e: toml::de::Error| {
        let start = e.span().map(|s| s.start).unwrap_or(0).min(text.len());
        let before = &text[..floor_char(text, start)];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        SyntaxError {
            file: file.to_string(),
            line,
            column,
            message: e.message().trim().replace('\n', " "),
        }
    })
}

#[cfg(feature = "scene-files")]
fn floor_char(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

//! Scene errors as miette diagnostics: the message with `file:line:column`
//! and, when the file can be read, the offending line underlined.

use miette::{Diagnostic, NamedSource, SourceSpan};
use radiant::scene::SceneError;

#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{error}")]
struct SceneDiagnostic {
    error: SceneError,
    #[source_code]
    source_code: Option<NamedSource<String>>,
    #[label("here")]
    span: Option<SourceSpan>,
}

/// Converts a scene error into a report that shows where it is.
pub fn report(error: SceneError) -> miette::Report {
    let text = std::fs::read_to_string(&error.file).ok();
    let span = match (&text, error.location) {
        (Some(text), Some(loc)) => byte_offset(text, loc.line, loc.column).map(|o| {
            let len = text[o..]
                .find(['\n', ':', ',', ']', '}'])
                .unwrap_or(0)
                .max(1);
            SourceSpan::new(o.into(), len)
        }),
        _ => None,
    };
    let source_code = text.map(|t| NamedSource::new(error.file.display().to_string(), t));
    miette::Report::new(SceneDiagnostic {
        error,
        source_code,
        span,
    })
}

fn byte_offset(text: &str, line: usize, column: usize) -> Option<usize> {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.checked_sub(1)?)
        .map(str::len)
        .sum();
    let line_text = text[start..].split('\n').next()?;
    let col = line_text
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(line_text.len(), |(i, _)| i);
    Some(start + col)
}

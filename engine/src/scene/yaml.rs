//! Reading the scene's YAML tree with positions kept for every node.

use super::SceneError;
use marked_yaml::types::MarkedMappingNode;
use marked_yaml::{Node, Span};
use radiant_core::Params;
use radiant_core::params::Location;
use serde::de::DeserializeOwned;
use std::collections::HashSet;
use std::path::Path;

/// Where a node is.
pub(crate) fn loc(span: &Span) -> Option<Location> {
    Location::of(span)
}

/// The location of byte `at` of `text` (1-based line and column, in
/// characters).
fn location_of_byte(text: &str, at: usize) -> Location {
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    Location { line, column }
}

/// Rejects what the YAML parser would silently drop: a NUL character (the
/// parser stops there) and a second document after `---` or `...` (only the
/// first would be read).
fn check_single_document(file: &Path, text: &str) -> Result<(), SceneError> {
    if let Some(at) = text.find('\0') {
        return Err(SceneError::new(
            file,
            Some(location_of_byte(text, at)),
            "the scene file contains a NUL character; expected plain UTF-8 text",
        ));
    }
    let is_marker = |l: &str| {
        ["---", "..."].iter().any(|m| {
            l.strip_prefix(m)
                .is_some_and(|r| r.is_empty() || r.starts_with([' ', '\t']))
        })
    };
    let is_content = |l: &str| {
        let t = l.trim();
        !t.is_empty() && !t.starts_with('#') && !is_marker(l)
    };
    let lines: Vec<&str> = text.lines().collect();
    let Some(first) = lines.iter().position(|l| is_content(l)) else {
        return Ok(());
    };
    if let Some(marker) = lines[first..].iter().position(|l| is_marker(l)) {
        let marker = first + marker;
        if lines[marker + 1..].iter().any(|l| is_content(l)) {
            return Err(SceneError::new(
                file,
                Some(Location {
                    line: marker + 1,
                    column: 1,
                }),
                "a scene file holds one YAML document; a second one starts here \
                 (remove the `---`/`...` marker or split the file)",
            ));
        }
    }
    Ok(())
}

/// Parses a YAML document into a tree of marked nodes.
pub(crate) fn parse_document(file: &Path, text: &str) -> Result<Node, SceneError> {
    use marked_yaml::LoadError;
    check_single_document(file, text)?;
    let options = marked_yaml::LoaderOptions::default()
        .error_on_duplicate_keys(true)
        .toplevel_mapping();
    marked_yaml::parse_yaml_with_options(0, text, options).map_err(|e| {
        let (marker, message) = match &e {
            LoadError::TopLevelMustBeMapping(m) => (
                Some(*m),
                "the scene must be a YAML mapping (`key: value` lines)".to_string(),
            ),
            LoadError::ScanError(m, err) => (Some(*m), format!("invalid YAML: {}", err.info())),
            LoadError::DuplicateKey(inner) => (
                inner.key.span().start().copied(),
                format!("duplicate key `{}`", inner.key.as_str()),
            ),
            LoadError::UnexpectedAnchor(m) => (
                Some(*m),
                "YAML anchors and aliases are not supported".to_string(),
            ),
            LoadError::UnexpectedTag(m) => (Some(*m), "YAML tags are not supported".to_string()),
            LoadError::MappingKeyMustBeScalar(m) => {
                (Some(*m), "mapping keys must be plain names".to_string())
            }
            other => (None, other.to_string()),
        };
        let location = marker.map(|m| Location {
            line: m.line(),
            column: m.column(),
        });
        SceneError::new(file, location, message)
    })
}

/// Deserializes `node` with serde, keeping positions in errors; values the
/// engine reads itself cannot animate, so `keyframes` in `node` are an
/// error.
pub(crate) fn parse_node<T: DeserializeOwned>(file: &Path, node: &Node) -> Result<T, SceneError> {
    if let Some(k) = super::keyframes::find_keyframes(node) {
        return Err(super::keyframes::cannot_animate(file, k));
    }
    Params::new(node.clone())
        .parse()
        .map_err(|e| SceneError::from_param(file, e))
}

/// A mapping whose keys are checked against the allowed ones.
pub(crate) struct Mapping<'a> {
    file: &'a Path,
    node: &'a MarkedMappingNode,
    span: &'a Span,
    what: &'a str,
    used: HashSet<&'a str>,
}

impl<'a> Mapping<'a> {
    /// Views `node` as a mapping; `what` names it in errors ("shape", …).
    pub(crate) fn new(file: &'a Path, node: &'a Node, what: &'a str) -> Result<Self, SceneError> {
        match node.as_mapping() {
            Some(m) => Ok(Self {
                file,
                node: m,
                span: node.span(),
                what,
                used: HashSet::new(),
            }),
            None => Err(SceneError::new(
                file,
                loc(node.span()),
                format!("expected a mapping (`key: value` lines) for the {what}"),
            )),
        }
    }

    /// Where the mapping starts.
    pub(crate) fn location(&self) -> Option<Location> {
        loc(self.span)
    }

    /// The value of `key`, if present.
    pub(crate) fn get(&mut self, key: &'a str) -> Option<&'a Node> {
        self.used.insert(key);
        self.node.get_node(key)
    }

    /// The value of `key`, or an error naming it.
    pub(crate) fn require(&mut self, key: &'a str) -> Result<&'a Node, SceneError> {
        self.get(key).ok_or_else(|| {
            SceneError::new(
                self.file,
                self.location(),
                format!("the {} needs a `{key}`", self.what),
            )
        })
    }

    /// A scalar string value of `key`, if present.
    pub(crate) fn string(
        &mut self,
        key: &'a str,
    ) -> Result<Option<(String, Option<Location>)>, SceneError> {
        match self.get(key) {
            None => Ok(None),
            Some(n) => match n.as_scalar() {
                Some(s) => Ok(Some((s.as_str().to_string(), loc(n.span())))),
                None => Err(SceneError::new(
                    self.file,
                    loc(n.span()),
                    format!("`{key}` of the {} must be a name", self.what),
                )),
            },
        }
    }

    /// Fails on any key that was not asked for, listing the allowed ones.
    pub(crate) fn finish(self, allowed: &[&str]) -> Result<(), SceneError> {
        for (key, _) in self.node.iter() {
            if !self.used.contains(key.as_str()) {
                return Err(unknown_key(
                    self.file,
                    key.as_str(),
                    loc(key.span()),
                    self.what,
                    allowed,
                ));
            }
        }
        Ok(())
    }
}

/// The error for a key that is not allowed, with the closest allowed one.
pub(crate) fn unknown_key(
    file: &Path,
    key: &str,
    location: Option<Location>,
    what: &str,
    allowed: &[&str],
) -> SceneError {
    let hint = closest(key, allowed)
        .map(|s| format!(" (did you mean `{s}`?)"))
        .unwrap_or_default();
    SceneError::new(
        file,
        location,
        format!(
            "unknown key `{key}` in the {what}{hint}; allowed keys: {}",
            allowed.join(", ")
        ),
    )
}

/// The candidate closest to `word`, if it is close enough to be a typo.
pub(crate) fn closest<'c>(word: &str, candidates: &[&'c str]) -> Option<&'c str> {
    candidates
        .iter()
        .map(|c| (strsim::damerau_levenshtein(word, c), *c))
        .filter(|(d, c)| *d <= 2.max(c.len() / 3))
        .min()
        .map(|(_, c)| c)
}

/// "undefined {what} `name`" at `node`, with the closest of `known` as a
/// hint and all of them listed (`plural` defined under `section:`).
pub(crate) fn undefined(
    file: &Path,
    node: &Node,
    (what, plural, section): (&str, &str, &str),
    name: &str,
    mut known: Vec<&str>,
) -> SceneError {
    known.sort_unstable();
    let hint = closest(name, &known)
        .map(|s| format!(" (did you mean `{s}`?)"))
        .unwrap_or_default();
    let listed = if known.is_empty() {
        "none".to_string()
    } else {
        known.join(", ")
    };
    SceneError::new(
        file,
        loc(node.span()),
        format!("undefined {what} `{name}`{hint}; {plural} defined under `{section}:`: {listed}"),
    )
}

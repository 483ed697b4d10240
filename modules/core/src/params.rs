//! Module parameters: the YAML mapping of one module instance.
//!
//! A module parses its own parameters with serde (`#[serde(deny_unknown_fields)]`
//! recommended); errors keep the line and column of the offending node so the
//! engine can report `scene.yaml:12:5: …`.

use marked_yaml::{Node, Span};
use serde::Deserialize;
use serde::de::{self, DeserializeOwned, Deserializer, SeqAccess, Visitor};
use std::fmt;

pub use marked_yaml::Spanned;

use crate::Rgb;

/// A 1-based line and column in a scene file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Location {
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

impl Location {
    /// The start of `span`, if it has one.
    pub fn of(span: &Span) -> Option<Self> {
        span.start().map(|m| Location {
            line: m.line(),
            column: m.column(),
        })
    }
}

/// A problem with a module's parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct ParamError {
    /// What is wrong, and what would be accepted.
    pub message: String,
    /// Where in the scene file, when known.
    pub location: Option<Location>,
}

impl ParamError {
    /// An error at an unknown place.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            location: None,
        }
    }

    /// An error at `span`.
    pub fn at(span: &Span, message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            location: Location::of(span),
        }
    }
}

/// The text of the scalar that starts at `mark`, found by walking `node`.
fn scalar_at<'a>(node: &'a Node, mark: &marked_yaml::Marker) -> Option<&'a str> {
    match node {
        Node::Scalar(s) => (s.span().start() == Some(mark)).then(|| s.as_str()),
        Node::Mapping(m) => m.values().find_map(|v| scalar_at(v, mark)),
        Node::Sequence(s) => s.iter().find_map(|v| scalar_at(v, mark)),
    }
}

/// What an integer key needs, where the YAML value `text` (at `path`) is
/// not one: a negative number for a count, a fraction, or not a number
/// (`parse_error`, serde's own words, says which).
fn integer_message(path: Option<&str>, text: Option<&str>, parse_error: &str) -> String {
    let (Some(text), Ok(value)) = (text, text.unwrap_or_default().trim().parse::<f64>()) else {
        return format!("expected an integer: {parse_error}");
    };
    let key = path.map_or(String::new(), |p| format!(" for `{p}`"));
    if value < 0.0 {
        format!("expected a non-negative integer{key}, found {text}")
    } else if value.fract() != 0.0 {
        format!("expected a whole number{key}, found {text}")
    } else {
        format!("{text} is too large{key}")
    }
}

/// The parameters of one module instance: a YAML mapping without the keys
/// the engine consumes itself (`type`, and e.g. a camera's pose).
#[derive(Debug, Clone)]
pub struct Params {
    node: Node,
}

impl Params {
    /// Wraps a YAML mapping node.
    pub fn new(node: Node) -> Self {
        Self { node }
    }

    /// Parameters from YAML text (handy in tests and for outside modules).
    pub fn from_yaml(text: &str) -> Result<Self, ParamError> {
        let node = marked_yaml::parse_yaml(0, text).map_err(|e| ParamError::new(e.to_string()))?;
        Ok(Self::new(node))
    }

    /// Deserializes the parameters into `T`.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, ParamError> {
        marked_yaml::from_node(&self.node).map_err(|e| {
            let location = e.start_mark().map(|m| Location {
                line: m.line(),
                column: m.column(),
            });
            let message = match &*e {
                marked_yaml::Error::FloatParseFailure(..) => {
                    format!("expected a number: {e}")
                }
                marked_yaml::Error::IntegerParseFailure(..) => {
                    let text = e.start_mark().and_then(|m| scalar_at(&self.node, &m));
                    integer_message(e.path(), text, &e.to_string())
                }
                marked_yaml::Error::NotBoolean(..) => "expected `true` or `false`".to_string(),
                _ => e.to_string(),
            };
            ParamError { message, location }
        })
    }

    /// The YAML node of the parameters.
    pub fn node(&self) -> &Node {
        &self.node
    }

    /// The YAML node of the parameters, to change values in place (the
    /// engine writes animated values here before a module is rebuilt).
    pub fn node_mut(&mut self) -> &mut Node {
        &mut self.node
    }

    /// Location of the value of `key`, or of the whole mapping if absent.
    pub fn location_of(&self, key: &str) -> Option<Location> {
        let map = self.node.as_mapping();
        let span = map
            .and_then(|m| m.get_node(key))
            .map_or(self.node.span(), |n| n.span());
        Location::of(span)
    }
}

/// A colour parameter that is either a value or a reference to a named
/// texture: `0.5`, `[0.8, 0.2, 0.1]` or `checker`.
#[derive(Debug, Clone, PartialEq)]
pub enum TextureInput {
    /// An inline constant colour (a scalar is used for all channels).
    Value(Rgb),
    /// The name of a texture defined under `textures:`.
    Named(String),
}

impl TextureInput {
    /// An inline constant, as used for defaults.
    pub fn spanned_value(value: Rgb) -> Spanned<Self> {
        Spanned::new(Span::new_blank(), TextureInput::Value(value))
    }
}

impl<'de> Deserialize<'de> for TextureInput {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct InputVisitor;
        impl<'de> Visitor<'de> for InputVisitor {
            type Value = TextureInput;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, an [r, g, b] list or the name of a texture")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(TextureInput::Value(Rgb::splat(v as f32)))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
                self.visit_f64(v as f64)
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
                match v.trim().parse::<f32>() {
                    Ok(x) => Ok(TextureInput::Value(Rgb::splat(x))),
                    Err(_) if v.is_empty() => Err(E::custom(
                        "expected a number, an [r, g, b] list or the name of a texture",
                    )),
                    Err(_) => Ok(TextureInput::Named(v.to_string())),
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut c = [0.0f32; 3];
                for (i, slot) in c.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &"3 colour channels"))?;
                }
                if seq.next_element::<f32>()?.is_some() {
                    return Err(de::Error::invalid_length(4, &"3 colour channels"));
                }
                Ok(TextureInput::Value(Rgb::from_array(c)))
            }
        }
        deserializer.deserialize_any(InputVisitor)
    }
}

/// A constant colour parameter: `0.5` or `[0.8, 0.2, 0.1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Color(pub Rgb);

impl<'de> Deserialize<'de> for Color {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        match TextureInput::deserialize(deserializer)? {
            TextureInput::Value(v) => Ok(Color(v)),
            TextureInput::Named(name) => Err(de::Error::custom(format!(
                "expected a number or an [r, g, b] list, found `{name}`"
            ))),
        }
    }
}

/// `N` numbers written as a YAML list (a point, a direction, a matrix row):
/// exactly `N`, where a plain array would let extra elements through
/// unnoticed (the YAML deserializer does not check for leftovers).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(try_from = "Vec<f64>")]
pub struct Numbers<const N: usize>(pub [f64; N]);

impl<const N: usize> TryFrom<Vec<f64>> for Numbers<N> {
    type Error = String;

    fn try_from(values: Vec<f64>) -> Result<Self, String> {
        let found = values.len();
        values
            .try_into()
            .map(Self)
            .map_err(|_| format!("expected a list of {N} numbers, found {found}"))
    }
}

impl<const N: usize> Default for Numbers<N> {
    /// All zeros (the origin).
    fn default() -> Self {
        Self([0.0; N])
    }
}

impl From<Numbers<3>> for glam::DVec3 {
    fn from(n: Numbers<3>) -> Self {
        Self::from_array(n.0)
    }
}

impl From<Numbers<4>> for glam::DVec4 {
    fn from(n: Numbers<4>) -> Self {
        Self::from_array(n.0)
    }
}

/// Checks that the documented parameters `docs` are exactly the fields that
/// `T` accepts (for modules' own tests: `radiant modules` must not lie).
///
/// `T` must deny unknown fields.
pub fn check_param_docs<T: DeserializeOwned>(docs: &[crate::ParamDoc]) -> Result<(), String> {
    let probe = Params::from_yaml("__probe__: 0\n").map_err(|e| e.to_string())?;
    let err = match marked_yaml::from_node::<T>(probe.node()) {
        Ok(_) => return Err("the parameter type accepts unknown fields".into()),
        Err(e) => e.into_inner(),
    };
    let marked_yaml::Error::UnknownFieldError(_, fields, _) = err else {
        return Err(format!("expected an unknown-field error, got: {err}"));
    };
    let mut accepted: Vec<&str> = fields.to_vec();
    let mut documented: Vec<&str> = docs.iter().map(|d| d.name).collect();
    accepted.sort_unstable();
    documented.sort_unstable();
    if accepted == documented {
        Ok(())
    } else {
        Err(format!(
            "accepted fields {accepted:?} differ from documented {documented:?}"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    struct Example {
        #[allow(dead_code)]
        radius: f32,
        colour: Spanned<TextureInput>,
    }

    #[test]
    fn parses_texture_inputs() {
        let p = Params::from_yaml("radius: 1\ncolour: [0.5, 0.25, 1]\n").unwrap();
        let e: Example = p.parse().unwrap();
        assert_eq!(*e.colour, TextureInput::Value(Rgb::new(0.5, 0.25, 1.0)));
        let p = Params::from_yaml("radius: 1\ncolour: 0.5\n").unwrap();
        let e: Example = p.parse().unwrap();
        assert_eq!(*e.colour, TextureInput::Value(Rgb::splat(0.5)));
        let p = Params::from_yaml("radius: 1\ncolour: wood\n").unwrap();
        let e: Example = p.parse().unwrap();
        assert_eq!(*e.colour, TextureInput::Named("wood".into()));
        assert_eq!(Location::of(e.colour.span()).unwrap().line, 2);
    }

    #[test]
    fn errors_carry_locations() {
        let p = Params::from_yaml("radius: 1\ncolour: 1\nradus: 2\n").unwrap();
        let err = p.parse::<Example>().unwrap_err();
        assert!(err.message.contains("radus"), "{}", err.message);
        assert_eq!(err.location.map(|l| l.line), Some(3));

        let p = Params::from_yaml("radius: big\ncolour: 1\n").unwrap();
        let err = p.parse::<Example>().unwrap_err();
        assert!(err.message.contains("number"), "{}", err.message);
        assert_eq!(err.location, Some(Location { line: 1, column: 9 }));

        let p = Params::from_yaml("radius: 1\ncolour: [1, 2]\n").unwrap();
        let err = p.parse::<Example>().unwrap_err();
        assert_eq!(err.location.map(|l| l.line), Some(2), "{err:?}");
    }
}

//! `radiant modules`: every registered module type with its parameters,
//! then the scene file's own keys (film, sampler, integrator, shapes and
//! meshes) from [`radiant::scene::docs`], in columns that wrap.

use radiant::Registry;
use radiant::core::ParamDoc;
use radiant::scene::docs::SCENE_KEYS;

/// Width of the listing in characters.
const WIDTH: usize = 100;
/// Indent of a parameter's line.
const INDENT: usize = 6;
/// Columns of a parameter's name, type and default.
const NAME: usize = 16;
const TYPE: usize = 26;
const DEFAULT: usize = 14;

/// Prints the registry's documentation and the scene's keys.
pub fn run(registry: &Registry) {
    let mut out = String::new();
    let mut last_kind = None;
    for (kind, info) in registry.modules() {
        if last_kind != Some(kind) {
            out += &format!("{kind}s:\n");
            last_kind = Some(kind);
        }
        out += &format!("  {} — {}\n", info.type_name, info.summary);
        for p in info.params {
            out += &param_lines(p);
        }
    }
    out += "\nscene keys (read by the scene loader, not by modules):\n";
    for section in SCENE_KEYS {
        out += &format!("  {} — {}\n", section.title, section.summary);
        for p in section.keys {
            out += &param_lines(p);
        }
    }
    print!("{out}");
}

/// One parameter in columns: a name, type or default too long for its
/// column ends the line and the columns go on below it; the description
/// wraps at [`WIDTH`] under its own column.
fn param_lines(p: &ParamDoc) -> String {
    let mut lines = Vec::new();
    let mut line = " ".repeat(INDENT);
    for (text, width) in [(p.name, NAME), (p.ty, TYPE), (p.default, DEFAULT)] {
        let end = line.chars().count() + width;
        line += text;
        let len = line.chars().count();
        if len >= end {
            // Too long for its column: the next column starts a new line.
            lines.push(std::mem::replace(&mut line, " ".repeat(end)));
        } else {
            line += &" ".repeat(end - len);
        }
    }
    let doc_column = INDENT + NAME + TYPE + DEFAULT;
    for word in p.doc.split_whitespace() {
        let len = line.chars().count();
        if len > doc_column && len + 1 + word.chars().count() > WIDTH {
            lines.push(std::mem::replace(&mut line, " ".repeat(doc_column)));
        } else if len > doc_column {
            line.push(' ');
        }
        line += word;
    }
    lines.push(line);
    lines
        .iter()
        .map(|l| format!("{}\n", l.trim_end()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_names_and_descriptions_wrap_under_their_columns() {
        let p = ParamDoc {
            name: "flip_invalid_normals_and_more",
            ty: "bool",
            default: "true",
            doc: "Mirror shading normals that face away from the viewer back above the surface, \
                  as Mitsuba does, so that the lit side and the seen side agree everywhere.",
        };
        let text = param_lines(&p);
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines.len() >= 3, "{text}");
        // The long name stands alone; the columns go on below it.
        assert_eq!(lines[0].trim(), "flip_invalid_normals_and_more");
        assert!(lines[1].starts_with(&" ".repeat(INDENT + NAME)), "{text}");
        assert!(lines[1][INDENT + NAME..].starts_with("bool"), "{text}");
        for l in &lines {
            assert!(l.chars().count() <= WIDTH, "too wide: {l}");
        }
        for l in &lines[2..] {
            assert!(
                l.starts_with(&" ".repeat(INDENT + NAME + TYPE + DEFAULT)),
                "{text}"
            );
        }
        let words: Vec<&str> = text.split_whitespace().collect();
        assert_eq!(words.join(" ").matches("Mitsuba does").count(), 1);
    }

    #[test]
    fn a_short_parameter_is_one_line_in_columns() {
        let p = ParamDoc {
            name: "spp",
            ty: "positive integer",
            default: "64",
            doc: "Samples per pixel.",
        };
        let text = param_lines(&p);
        assert_eq!(text.lines().count(), 1, "{text}");
        assert_eq!(text.find("positive"), Some(INDENT + NAME));
        assert_eq!(text.find("64"), Some(INDENT + NAME + TYPE));
        assert_eq!(text.find("Samples"), Some(INDENT + NAME + TYPE + DEFAULT));
    }
}

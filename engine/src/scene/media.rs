//! Participating media in the scene file: the `media:` section (named
//! media, each with an optional `phase:`), `atmosphere:` (the medium the
//! camera and every unbounded ray start in), a camera's `medium:`, and a
//! shape's `interior:`/`exterior:`.
//!
//! The loader keeps the media unbuilt ([`SceneMedia`]); extract builds them
//! through the registry (`extract/media.rs`). A shape that bounds a medium
//! gets a material index of its own (a copy of its material's spec), so the
//! interface travels with the per-primitive material and the geometry
//! needs no extra per-primitive data; the shape must be closed.

use super::yaml::{loc, undefined};
use crate::error::SceneError;
use crate::world::{Geometry, ModuleSpec};
use marked_yaml::Node;
use std::collections::HashMap;
use std::path::Path;

/// "No medium" (vacuum) in medium indices.
pub const NO_MEDIUM: u32 = u32::MAX;

/// One named medium as written.
#[derive(Debug, Clone)]
pub struct MediumDef {
    /// Its name under `media:`.
    pub name: String,
    /// The medium module (without `phase`).
    pub spec: ModuleSpec,
    /// The phase module, `None` for the default (isotropic).
    pub phase: Option<ModuleSpec>,
}

/// The scene's media, unbuilt.
#[derive(Debug, Clone, Default)]
pub struct SceneMedia {
    /// The media in file order; indices are medium numbers.
    pub media: Vec<MediumDef>,
    /// The medium the camera sits in ([`NO_MEDIUM`]: vacuum).
    pub camera: u32,
    /// The medium outside every shape that names no `exterior`
    /// ([`NO_MEDIUM`]: vacuum).
    pub atmosphere: u32,
    /// Materials that bound media: (material index, [interior, exterior]).
    pub interfaces: Vec<(u32, [u32; 2])>,
}

impl SceneMedia {
    /// Reads `media:` and `atmosphere:`.
    pub(crate) fn parse(
        file: &Path,
        media: Option<&Node>,
        atmosphere: Option<&Node>,
    ) -> Result<Self, SceneError> {
        let mut out = SceneMedia {
            camera: NO_MEDIUM,
            atmosphere: NO_MEDIUM,
            ..Default::default()
        };
        if let Some(node) = media {
            let map = node.as_mapping().ok_or_else(|| {
                SceneError::new(
                    file,
                    loc(node.span()),
                    "expected a mapping from medium names to medium definitions",
                )
            })?;
            for (name, def) in map.iter() {
                let spec = ModuleSpec::from_node(file, def, "medium", &["phase"])?;
                let phase = def
                    .as_mapping()
                    .and_then(|m| m.get_node("phase"))
                    .map(|p| ModuleSpec::from_node(file, p, "phase", &[]))
                    .transpose()?;
                out.media.push(MediumDef {
                    name: name.as_str().to_string(),
                    spec,
                    phase,
                });
            }
        }
        out.atmosphere = out.reference(file, atmosphere)?;
        out.camera = out.atmosphere;
        Ok(out)
    }

    /// The medium named at `node` ([`NO_MEDIUM`] where there is no node).
    pub(crate) fn reference(&self, file: &Path, node: Option<&Node>) -> Result<u32, SceneError> {
        let Some(node) = node else {
            return Ok(NO_MEDIUM);
        };
        let name = node.as_scalar().map(|s| s.as_str()).ok_or_else(|| {
            SceneError::new(
                file,
                loc(node.span()),
                "expected the name of a medium defined under `media:`",
            )
        })?;
        let index: HashMap<&str, u32> = self
            .media
            .iter()
            .enumerate()
            .map(|(i, m)| (m.name.as_str(), i as u32))
            .collect();
        index.get(name).copied().ok_or_else(|| {
            let known = index.keys().copied().collect();
            undefined(file, node, ("medium", "media", "media"), name, known)
        })
    }

    /// Reads a shape's `interior:`/`exterior:`; where it has either,
    /// checks that the shape is closed and not instanced and returns the
    /// interface ([interior, exterior], the atmosphere outside where no
    /// `exterior` is named).
    pub(crate) fn interface(
        &self,
        file: &Path,
        shape: &Node,
        geometry: &Geometry,
    ) -> Result<Option<[u32; 2]>, SceneError> {
        let map = shape.as_mapping();
        let get = |key: &str| map.and_then(|m| m.get_node(key));
        let (interior, exterior) = (get("interior"), get("exterior"));
        let Some(first) = interior.or(exterior) else {
            return Ok(None);
        };
        let at = loc(first.span());
        if get("instances").is_some() {
            return Err(SceneError::new(
                file,
                at,
                "a shape with `instances` cannot bound a medium yet: give each copy a shape of its own",
            ));
        }
        if let Some(open) = open_edges(geometry) {
            return Err(SceneError::new(
                file,
                at,
                format!(
                    "a medium needs a closed shape (one with an inside), but this {open}; use a cube, a sphere or a closed mesh"
                ),
            ));
        }
        let exterior = match exterior {
            Some(_) => self.reference(file, exterior)?,
            None => self.atmosphere,
        };
        Ok(Some([self.reference(file, interior)?, exterior]))
    }
}

/// Why `geometry` has no inside, or `None` where it is closed: every edge
/// (vertices compared by position, as meshes split vertices at seams) is
/// shared by an even, non-zero number of triangles.
fn open_edges(geometry: &Geometry) -> Option<String> {
    match geometry {
        Geometry::Cube | Geometry::Sphere => None,
        Geometry::Rectangle => Some("rectangle is open".into()),
        Geometry::Mesh(mesh) => {
            let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
            let id: Vec<u32> = mesh
                .positions
                .iter()
                .map(|p| {
                    let n = ids.len() as u32;
                    *ids.entry(p.to_array().map(f32::to_bits)).or_insert(n)
                })
                .collect();
            let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
            for t in &mesh.triangles {
                for k in 0..3 {
                    let (a, b) = (id[t[k] as usize], id[t[(k + 1) % 3] as usize]);
                    *edges.entry((a.min(b), a.max(b))).or_default() += 1;
                }
            }
            let open = edges.values().filter(|&&c| c % 2 == 1).count();
            (open > 0 || mesh.triangles.is_empty())
                .then(|| format!("mesh has {open} edges with a triangle on one side only"))
        }
    }
}

impl super::Loader<'_> {
    /// The material of a shape that bounds a medium: a copy of `material`
    /// of its own that carries `interface` ([interior, exterior]; swapped
    /// where the shape's normals are flipped, so that "exterior" stays the
    /// side its normals point to).
    pub(super) fn bound_medium(
        &mut self,
        material: crate::world::MaterialRef,
        interface: [u32; 2],
        flip_normals: bool,
        shape: &str,
    ) -> crate::world::MaterialRef {
        let (name, spec) = self.materials[material.0 as usize].clone();
        self.materials
            .push((format!("<{name} bounding the media of {shape}>"), spec));
        let index = self.materials.len() as u32 - 1;
        let [inside, outside] = interface;
        let sides = if flip_normals {
            [outside, inside]
        } else {
            [inside, outside]
        };
        self.media.interfaces.push((index, sides));
        crate::world::MaterialRef(index)
    }
}

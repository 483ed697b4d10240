//! Nested materials: the [`MaterialSource`] through which wrapper shaders
//! (`blend`, `normal_map`, `bump`) build the materials they contain, by
//! name from the scene's `materials:` or inline.
//!
//! A nested material is built afresh for every reference (shaders are
//! small), so the same definition may appear in several wrappers. A stack
//! of the named materials being built catches a material that contains
//! itself, and bounds how deep named materials may nest.

use crate::error::module_error;
use crate::world::{ModuleSpec, Scene};
use marked_yaml::Node;
use radiant_core::registry::ModuleType;
use radiant_core::{BuildContext, MaterialSource, ModuleKind, ParamError, Registry, Shader};
use std::cell::RefCell;
use std::collections::BTreeSet;

/// How deep named materials may nest (a `bump` of a `blend` of … ):
/// deeper chains are an error rather than a stack overflow.
const MAX_NESTING: usize = 32;

/// Builds nested materials for one extract.
pub(super) struct NestedMaterials<'s> {
    registry: &'s Registry,
    scene: &'s Scene,
    /// Indices of the named materials being built, outermost first.
    stack: RefCell<Vec<usize>>,
    /// Module types built here, for `radiant info`.
    pub(super) used: RefCell<BTreeSet<(ModuleKind, String)>>,
}

/// Pops the material stack when a build ends.
pub(super) struct Entered<'a>(&'a RefCell<Vec<usize>>);

impl Drop for Entered<'_> {
    fn drop(&mut self) {
        self.0.borrow_mut().pop();
    }
}

impl<'s> NestedMaterials<'s> {
    pub(super) fn new(registry: &'s Registry, scene: &'s Scene) -> Self {
        Self {
            registry,
            scene,
            stack: RefCell::new(Vec::new()),
            used: RefCell::new(BTreeSet::new()),
        }
    }

    /// Marks the named material `index` as being built until the guard drops.
    pub(super) fn enter(&self, index: usize) -> Entered<'_> {
        self.stack.borrow_mut().push(index);
        Entered(&self.stack)
    }

    fn cycle(&self, index: usize) -> Option<String> {
        let stack = self.stack.borrow();
        let start = stack.iter().position(|&i| i == index)?;
        let names: Vec<&str> = stack[start..]
            .iter()
            .chain(std::iter::once(&index))
            .map(|&i| self.scene.materials[i].0.as_str())
            .collect();
        Some(names.join(" → "))
    }
}

impl MaterialSource for NestedMaterials<'_> {
    fn build_material(
        &self,
        node: &Node,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Box<dyn Shader>, ParamError> {
        let file = &self.scene.file;
        let to_param = |e: crate::error::SceneError| ParamError {
            message: e.message,
            location: e.location,
        };
        let (spec, _guard) = if let Some(name) = node.as_scalar() {
            let name = name.as_str();
            let index = self
                .scene
                .materials
                .iter()
                .position(|(n, _)| n == name && !n.starts_with('<'))
                .ok_or_else(|| {
                    let mut known: Vec<&str> = self
                        .scene
                        .materials
                        .iter()
                        .map(|(n, _)| n.as_str())
                        .filter(|n| !n.starts_with('<'))
                        .collect();
                    known.sort_unstable();
                    ParamError::at(
                        node.span(),
                        format!(
                            "undefined material `{name}`; expected the name of a material defined under `materials:` ({}) or an inline material such as `{{type: diffuse}}`",
                            if known.is_empty() { "none are defined".to_string() } else { known.join(", ") }
                        ),
                    )
                })?;
            if let Some(cycle) = self.cycle(index) {
                return Err(ParamError::at(
                    node.span(),
                    format!("material `{name}` contains itself: {cycle}"),
                ));
            }
            if self.stack.borrow().len() >= MAX_NESTING {
                return Err(ParamError::at(
                    node.span(),
                    format!(
                        "material `{name}` is nested more than {MAX_NESTING} materials deep; \
                         at most {MAX_NESTING} levels of named materials are allowed"
                    ),
                ));
            }
            (
                self.scene.materials[index].1.clone(),
                Some(self.enter(index)),
            )
        } else {
            (
                ModuleSpec::from_node(file, node, "material", &[]).map_err(to_param)?,
                None,
            )
        };
        let shader = self
            .registry
            .build::<dyn Shader>(&spec.type_name, &spec.params, ctx)
            .map_err(|e| to_param(module_error(file, &spec, e)))?;
        self.used
            .borrow_mut()
            .insert((<dyn Shader as ModuleType>::KIND, spec.type_name.clone()));
        Ok(shader)
    }
}

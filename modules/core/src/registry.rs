//! The module registry: YAML `type` names → module builders.
//!
//! Built-in modules register themselves through the same public
//! [`Registry::register`] call an outside crate uses:
//!
//! ```
//! use radiant_core::{Registry, ModuleInfo, ParamDoc, Filter, Params};
//!
//! struct Triangle;
//! impl Filter for Triangle {
//!     fn radius(&self) -> f32 { 1.0 }
//!     fn eval(&self, x: f32, y: f32) -> f32 { (1.0 - x.abs()).max(0.0) * (1.0 - y.abs()).max(0.0) }
//! }
//!
//! let mut registry = Registry::new();
//! registry.register::<dyn Filter>(
//!     ModuleInfo { type_name: "triangle", summary: "A tent of radius 1.", params: &[] },
//!     |params: &Params, _ctx: &mut radiant_core::BuildContext<'_>| {
//!         Ok(Box::new(Triangle) as Box<dyn Filter>)
//!     },
//! );
//! assert!(registry.contains::<dyn Filter>("triangle"));
//! ```

use crate::{
    BuildContext, Camera, Filter, Light, Medium, ParamError, Params, Phase, Sampler, Shader,
    Texture,
};
use std::any::Any;
use std::collections::BTreeMap;
use std::fmt;

/// The kinds of module: the eight this crate defines tables for, and
/// [`ModuleKind::Integrator`], whose trait lives in the engine (it needs the
/// engine's render data) and whose table is an extension table
/// ([`Registry::extension`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ModuleKind {
    /// Generates primary rays.
    Camera,
    /// Emits light.
    Light,
    /// Reconstructs pixels from samples.
    Filter,
    /// Scatters light at surfaces (a BSDF).
    Shader,
    /// Produces sample values.
    Sampler,
    /// Varies a value over a surface.
    Texture,
    /// Fills space with an absorbing and scattering substance.
    Medium,
    /// Scatters light in a medium (a phase function).
    Phase,
    /// Computes light transport: the algorithm that renders the frame.
    Integrator,
}

impl fmt::Display for ModuleKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ModuleKind::Camera => "camera",
            ModuleKind::Light => "light",
            ModuleKind::Filter => "filter",
            ModuleKind::Shader => "shader",
            ModuleKind::Sampler => "sampler",
            ModuleKind::Texture => "texture",
            ModuleKind::Medium => "medium",
            ModuleKind::Phase => "phase",
            ModuleKind::Integrator => "integrator",
        })
    }
}

/// Documentation of one parameter, shown by `radiant modules`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamDoc {
    /// The YAML key.
    pub name: &'static str,
    /// The value's type and unit, e.g. `"degrees"` or `"rgb | texture"`.
    pub ty: &'static str,
    /// The default, or `"required"`.
    pub default: &'static str,
    /// What it does.
    pub doc: &'static str,
}

/// Documentation of a module type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModuleInfo {
    /// The YAML `type` name.
    pub type_name: &'static str,
    /// One line on what the module is.
    pub summary: &'static str,
    /// Its parameters.
    pub params: &'static [ParamDoc],
}

/// Builds a module instance from its parameters.
pub type Builder<T> =
    Box<dyn Fn(&Params, &mut BuildContext<'_>) -> Result<Box<T>, ParamError> + Send + Sync>;

/// A module trait object type that the registry can hold (`dyn Camera`, …).
pub trait ModuleType: 'static {
    /// The module kind.
    const KIND: ModuleKind;
    #[doc(hidden)]
    fn table(registry: &Registry) -> &Table<Self>;
    #[doc(hidden)]
    fn table_mut(registry: &mut Registry) -> &mut Table<Self>;
}

/// The registered types of one kind.
pub struct Table<T: ?Sized> {
    entries: BTreeMap<&'static str, (ModuleInfo, Builder<T>)>,
}

impl<T: ?Sized> Default for Table<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: ?Sized> Table<T> {
    /// A table with no types (`const`, so that a [`ModuleType`] whose
    /// table is an extension can return a static empty one before anything
    /// registered).
    pub const fn new() -> Self {
        Self {
            entries: BTreeMap::new(),
        }
    }
}

/// An extension table as the registry holds it: its documentation for
/// [`Registry::modules`], and the table itself for a downcast.
trait Extension: Send + Sync {
    fn infos(&self) -> Vec<ModuleInfo>;
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

impl<T: ?Sized + 'static> Extension for Table<T>
where
    Table<T>: Send + Sync,
{
    fn infos(&self) -> Vec<ModuleInfo> {
        self.entries.values().map(|(info, _)| *info).collect()
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// Error of [`Registry::build`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// No module of that kind has that name.
    #[error("unknown {kind} type `{name}`{}; known {kind} types: {}", suggestion.map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default(), known.join(", "))]
    UnknownType {
        /// The module kind.
        kind: ModuleKind,
        /// The name that was asked for.
        name: String,
        /// The names that exist.
        known: Vec<&'static str>,
        /// The closest known name, if one is close.
        suggestion: Option<&'static str>,
    },
    /// The module rejected its parameters.
    #[error(transparent)]
    Params(#[from] ParamError),
}

macro_rules! module_types {
    ($($t:ident => $kind:ident, $field:ident;)*) => {
        /// All registered module types, by kind.
        #[derive(Default)]
        pub struct Registry {
            $($field: Table<dyn $t>,)*
            /// Tables of kinds whose trait lives outside this crate (the
            /// engine's integrators), by kind.
            extensions: BTreeMap<ModuleKind, Box<dyn Extension>>,
        }
        $(
            impl ModuleType for dyn $t {
                const KIND: ModuleKind = ModuleKind::$kind;
                fn table(registry: &Registry) -> &Table<Self> { &registry.$field }
                fn table_mut(registry: &mut Registry) -> &mut Table<Self> { &mut registry.$field }
            }
        )*
        impl Registry {
            /// Every registered module with its kind, by kind then name.
            pub fn modules(&self) -> Vec<(ModuleKind, ModuleInfo)> {
                let mut all = Vec::new();
                $(all.extend(self.$field.entries.values().map(|(info, _)| (ModuleKind::$kind, *info)));)*
                for (kind, table) in &self.extensions {
                    all.extend(table.infos().into_iter().map(|info| (*kind, info)));
                }
                all.sort_by_key(|(kind, _)| *kind);
                all
            }
        }
    };
}

module_types! {
    Camera => Camera, cameras;
    Light => Light, lights;
    Filter => Filter, filters;
    Shader => Shader, shaders;
    Sampler => Sampler, samplers;
    Texture => Texture, textures;
    Medium => Medium, media;
    Phase => Phase, phases;
}

impl Registry {
    /// An empty registry (see the engine's `Registry` constructor for one
    /// with the built-in modules).
    pub fn new() -> Self {
        Self::default()
    }

    /// Registers a module type; a later registration of the same name
    /// replaces the earlier one.
    pub fn register<T: ModuleType + ?Sized>(
        &mut self,
        info: ModuleInfo,
        build: impl Fn(&Params, &mut BuildContext<'_>) -> Result<Box<T>, ParamError>
        + Send
        + Sync
        + 'static,
    ) {
        T::table_mut(self)
            .entries
            .insert(info.type_name, (info, Box::new(build)));
    }

    /// The table of kind `T` where `T` is an extension kind (one whose
    /// trait another crate defines: the engine's `dyn Integrator`), or
    /// `None` before anything of that kind registered. Such a kind's
    /// [`ModuleType::table`] returns this or a static empty table, and its
    /// [`ModuleType::table_mut`] returns [`Registry::extension_mut`].
    pub fn extension<T: ModuleType + ?Sized>(&self) -> Option<&Table<T>>
    where
        Table<T>: Send + Sync,
    {
        self.extensions
            .get(&T::KIND)
            .and_then(|t| t.as_any().downcast_ref())
    }

    /// The table of the extension kind `T`, created empty on first use.
    ///
    /// # Panics
    ///
    /// If another trait object type already holds the table of `T::KIND`
    /// (two crates declaring the same kind).
    pub fn extension_mut<T: ModuleType + ?Sized>(&mut self) -> &mut Table<T>
    where
        Table<T>: Send + Sync,
    {
        self.extensions
            .entry(T::KIND)
            .or_insert_with(|| Box::new(Table::<T>::new()))
            .as_any_mut()
            .downcast_mut()
            .unwrap_or_else(|| panic!("two module traits declare the {} kind", T::KIND))
    }

    /// Whether a module type of kind `T` is registered under `name`.
    pub fn contains<T: ModuleType + ?Sized>(&self, name: &str) -> bool {
        T::table(self).entries.contains_key(name)
    }

    /// The registered names of kind `T`, sorted.
    pub fn names<T: ModuleType + ?Sized>(&self) -> Vec<&'static str> {
        T::table(self).entries.keys().copied().collect()
    }

    /// Documentation of the module type `name` of kind `T`.
    pub fn info<T: ModuleType + ?Sized>(&self, name: &str) -> Option<&ModuleInfo> {
        T::table(self).entries.get(name).map(|(info, _)| info)
    }

    /// Builds an instance of module type `name` of kind `T`.
    pub fn build<T: ModuleType + ?Sized>(
        &self,
        name: &str,
        params: &Params,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Box<T>, BuildError> {
        let table = T::table(self);
        match table.entries.get(name) {
            Some((_, build)) => Ok(build(params, ctx)?),
            None => {
                let known = self.names::<T>();
                let suggestion = known
                    .iter()
                    .map(|k| (strsim::damerau_levenshtein(name, k), *k))
                    .filter(|(d, k)| *d <= 2.max(k.len() / 3))
                    .min()
                    .map(|(_, k)| k);
                Err(BuildError::UnknownType {
                    kind: T::KIND,
                    name: name.to_string(),
                    known,
                    suggestion,
                })
            }
        }
    }
}

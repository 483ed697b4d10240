//! Stanford PLY meshes (ASCII, binary little and big endian) through
//! `ply-rs-bw`, the maintained fork of `ply-rs`.
//!
//! The reader takes the `vertex` element's `x`, `y`, `z`, the normals
//! `nx`, `ny`, `nz` and the texture coordinates (`u`/`v`, `s`/`t` or
//! `texture_u`/`texture_v`) in any scalar type, and the `face` element's
//! `vertex_indices` (or `vertex_index`) lists, fanned into triangles;
//! other elements and properties are skipped. It returns the mesh
//! unrepaired: [`super::mesh`] repairs it and adds normals and tangents,
//! as for OBJ.

use crate::world::MeshData;
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{ElementDef, Header, Property, PropertyAccess};
use std::io::BufRead;
use std::path::Path;

/// One `vertex` element: the properties Radiant reads.
#[derive(Debug, Clone, Copy, Default)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
}

/// A scalar property as `f32` (lists are not scalars).
fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Char(v) => f32::from(v),
        Property::UChar(v) => f32::from(v),
        Property::Short(v) => f32::from(v),
        Property::UShort(v) => f32::from(v),
        Property::Int(v) => v as f32,
        Property::UInt(v) => v as f32,
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        _ => return None,
    })
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) {
        let Some(v) = scalar(&property) else {
            return;
        };
        match name {
            "x" => self.position[0] = v,
            "y" => self.position[1] = v,
            "z" => self.position[2] = v,
            "nx" => self.normal[0] = v,
            "ny" => self.normal[1] = v,
            "nz" => self.normal[2] = v,
            "u" | "s" | "texture_u" | "texture_s" => self.uv[0] = v,
            "v" | "t" | "texture_v" | "texture_t" => self.uv[1] = v,
            _ => {}
        }
    }
}

/// One `face` element: its vertex indices (negative ones kept, to be
/// named in the error).
#[derive(Debug, Clone, Default)]
struct Face(Vec<i64>);

impl PropertyAccess for Face {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) {
        if name != "vertex_indices" && name != "vertex_index" {
            return;
        }
        self.0 = match property {
            Property::ListChar(v) => widen(v),
            Property::ListShort(v) => widen(v),
            Property::ListInt(v) => widen(v),
            Property::ListUChar(v) => widen(v),
            Property::ListUShort(v) => widen(v),
            Property::ListUInt(v) => widen(v),
            _ => return,
        };
    }
}

/// A list of indices of any integer type, widened.
fn widen<T: Into<i64>>(v: Vec<T>) -> Vec<i64> {
    v.into_iter().map(Into::into).collect()
}

/// An element Radiant does not read (edges, materials, …).
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

/// Reads a PLY file into one mesh, unrepaired (texture coordinates as
/// (u, 1 − v) with `flip_tex_coords`).
pub fn read_ply(
    path: &Path,
    reader: &mut impl BufRead,
    flip_tex_coords: bool,
) -> Result<MeshData, String> {
    let name = path.display();
    let bad = |e: std::io::Error| format!("mesh file `{name}` is not a valid PLY file: {e}");
    let header = Parser::<Skip>::new().read_header(reader).map_err(bad)?;
    let vertex_def = header.elements.get("vertex").ok_or_else(|| {
        format!("PLY file `{name}` has no `vertex` element (it is a point set or not a mesh)")
    })?;
    for axis in ["x", "y", "z"] {
        if !vertex_def.properties.contains_key(axis) {
            return Err(format!(
                "PLY file `{name}`: its `vertex` element has no `{axis}` property"
            ));
        }
    }
    let face_def = header.elements.get("face").ok_or_else(|| {
        format!(
            "PLY file `{name}` has no `face` element: a point cloud cannot be rendered as a mesh"
        )
    })?;
    if !["vertex_indices", "vertex_index"]
        .iter()
        .any(|k| face_def.properties.contains_key(*k))
    {
        return Err(format!(
            "PLY file `{name}`: its `face` element has no `vertex_indices` list"
        ));
    }
    let (vertices, faces) = read_elements(reader, &header).map_err(bad)?;
    let has = |keys: &[&str]| keys.iter().all(|k| vertex_def.properties.contains_key(*k));
    let has_normals = has(&["nx", "ny", "nz"]);
    let has_uvs = ["u", "s", "texture_u", "texture_s"]
        .iter()
        .any(|k| has(&[k]))
        && ["v", "t", "texture_v", "texture_t"]
            .iter()
            .any(|k| has(&[k]));

    let mut mesh = MeshData {
        source: name.to_string(),
        positions: vertices.iter().map(|v| Vec3::from(v.position)).collect(),
        ..MeshData::default()
    };
    if has_normals {
        mesh.normals = Some(vertices.iter().map(|v| Vec3::from(v.normal)).collect());
    }
    if has_uvs {
        let v = |v: f32| if flip_tex_coords { 1.0 - v } else { v };
        mesh.uvs = Some(
            vertices
                .iter()
                .map(|p| Vec2::new(p.uv[0], v(p.uv[1])))
                .collect(),
        );
    }
    let n = vertices.len();
    for (i, face) in faces.iter().enumerate() {
        let index = |k: usize| match u32::try_from(face.0[k]) {
            Ok(j) if (j as usize) < n => Ok(j),
            _ => Err(format!(
                "PLY file `{name}`: face {} refers to vertex {} but the file has {n} vertices (numbered from 0)",
                i + 1,
                face.0[k]
            )),
        };
        if face.0.len() < 3 {
            return Err(format!(
                "PLY file `{name}`: face {} has {} vertices; a face needs at least 3",
                i + 1,
                face.0.len()
            ));
        }
        // A polygon becomes a fan around its first vertex.
        let first = index(0)?;
        for k in 1..face.0.len() - 1 {
            mesh.triangles.push([first, index(k)?, index(k + 1)?]);
        }
    }
    Ok(mesh)
}

/// The `vertex` and `face` elements' payloads, skipping the others (in the
/// order the header lists them, as the payload stores them).
fn read_elements(
    reader: &mut impl BufRead,
    header: &Header,
) -> std::io::Result<(Vec<Vertex>, Vec<Face>)> {
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for def in header.elements.values() {
        let def: &ElementDef = def;
        match def.name.as_str() {
            "vertex" => {
                vertices = Parser::<Vertex>::new().read_payload_for_element(reader, def, header)?;
            }
            "face" => {
                faces = Parser::<Face>::new().read_payload_for_element(reader, def, header)?
            }
            _ => {
                Parser::<Skip>::new().read_payload_for_element(reader, def, header)?;
            }
        }
    }
    Ok((vertices, faces))
}

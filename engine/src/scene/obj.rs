//! Wavefront OBJ meshes, read through tobj (every object into one mesh,
//! materials ignored). The mesh is returned unrepaired: [`super::mesh`]
//! opens the file, repairs the mesh and adds normals and tangents.

use super::line_limit::{LineLimit, MAX_LINE};
use crate::world::MeshData;
use glam::{Vec2, Vec3};
use std::io::BufRead;
use std::path::Path;

/// Reads every object of an OBJ file into one mesh, unrepaired (texture
/// coordinates as (u, 1 − v) with `flip_tex_coords`).
pub fn read_obj(
    path: &Path,
    reader: impl BufRead,
    flip_tex_coords: bool,
) -> Result<MeshData, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = LineLimit::new(reader, MAX_LINE);
    // Materials are ignored: an `mtllib` line loads nothing.
    let loaded = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let (models, _materials) = loaded.map_err(|e| match reader.long_line() {
        Some(line) => format!(
            "mesh file `{}`: line {line} is longer than {MAX_LINE} bytes (is it an OBJ file?)",
            path.display()
        ),
        None => format!("cannot read mesh file `{}`: {e}", path.display()),
    })?;
    let mut mesh = MeshData {
        source: path.display().to_string(),
        ..MeshData::default()
    };
    let vertices = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    let triangles = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    let reserved = mesh.positions.try_reserve_exact(vertices).is_ok()
        && mesh.triangles.try_reserve_exact(triangles).is_ok();
    if !reserved {
        return Err(format!(
            "mesh file `{}`: its {vertices} vertices and {triangles} triangles do not fit in memory",
            path.display()
        ));
    }
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let all_have_normals = models.iter().all(|m| !m.mesh.normals.is_empty());
    let all_have_uvs = models.iter().all(|m| !m.mesh.texcoords.is_empty());
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if all_have_normals {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        }
        if all_have_uvs {
            let v = |v: f32| if flip_tex_coords { 1.0 - v } else { v };
            uvs.extend(
                m.texcoords
                    .chunks_exact(2)
                    .map(|t| Vec2::new(t[0], v(t[1]))),
            );
        }
        mesh.triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    if all_have_normals {
        mesh.normals = Some(normals);
    }
    if all_have_uvs {
        mesh.uvs = Some(uvs);
    }
    Ok(mesh)
}

//! Wavefront OBJ meshes (through tobj), repaired on load.
//!
//! Degenerate input is repaired, never passed on: triangles with
//! non-finite coordinates or zero area (repeated or collinear vertices)
//! are dropped, vertex normals that are zero or non-finite are marked so
//! the face normal is used instead, and non-finite texture coordinates
//! become (0, 0). Needle triangles (positive but tiny area) are kept: the
//! watertight intersection test handles them; extract drops those whose
//! normal vanishes in single precision. [`MeshRepairs`] counts what was
//! done; `radiant render` warns about it and `radiant info` reports it.

use super::line_limit::{LineLimit, MAX_LINE};
use crate::world::{MeshData, MeshRepairs};
use glam::{DVec3, Vec2, Vec3};
use std::path::Path;

/// Bytes of memory loading an OBJ file takes per byte of the file, at most
/// (an estimate: a face line as short as `f 1 2 3` becomes three 4-byte
/// indices in the parser and again in the mesh, a vertex line `v 0 0 0`
/// twelve bytes of position in each, and the mesh adds tangents).
const MESH_BYTES_PER_FILE_BYTE: u64 = 8;

/// Loads every object of an OBJ file into one mesh (materials are ignored).
/// With `flip_tex_coords` (Mitsuba 3's default), texture coordinates are
/// stored as (u, 1 − v): OBJ's v runs up an image, Radiant's (Mitsuba's)
/// runs down it, so an image made for the OBJ appears upright.
pub fn load_obj(path: &Path, flip_tex_coords: bool) -> Result<MeshData, String> {
    let mut mesh = read_obj(path, flip_tex_coords)?;
    repair(&mut mesh);
    mesh.tangents = super::tangents::mikktspace(&mesh);
    if mesh.triangles.is_empty() {
        return Err(format!(
            "mesh file `{}` has no usable triangles ({} dropped as degenerate, {} for non-finite coordinates)",
            path.display(),
            mesh.repairs.degenerate,
            mesh.repairs.non_finite
        ));
    }
    Ok(mesh)
}

/// Loads one frame of a deforming mesh: as [`load_obj`], but every
/// triangle is kept, degenerate or not, so that all frames of a sequence
/// have the same triangles (a triangle of zero area is never hit, one
/// with non-finite vertices neither).
pub fn load_obj_frame(path: &Path, flip_tex_coords: bool) -> Result<MeshData, String> {
    let mut mesh = read_obj(path, flip_tex_coords)?;
    repair_attributes(&mut mesh);
    mesh.tangents = super::tangents::mikktspace(&mesh);
    if mesh.triangles.is_empty() {
        return Err(format!("mesh file `{}` has no triangles", path.display()));
    }
    Ok(mesh)
}

/// Checks that `mesh`, a frame of a deforming mesh, has the triangles of
/// the sequence's first frame `first`.
pub fn check_topology(first: &MeshData, mesh: &MeshData) -> Result<(), String> {
    let counts = |m: &MeshData| (m.triangles.len(), m.positions.len());
    if counts(first) != counts(mesh) {
        return Err(format!(
            "`{}` has {} triangles and {} vertices, but the sequence's first frame `{}` has {} and {}: \
             every frame of a deforming mesh needs the same triangles",
            mesh.source,
            mesh.triangles.len(),
            mesh.positions.len(),
            first.source,
            first.triangles.len(),
            first.positions.len()
        ));
    }
    if let Some(i) = (0..first.triangles.len()).find(|&i| first.triangles[i] != mesh.triangles[i]) {
        return Err(format!(
            "`{}` has the vertex and triangle counts of the sequence's first frame `{}`, but triangle {} \
             joins other vertices: every frame of a deforming mesh needs the same triangles",
            mesh.source,
            first.source,
            i + 1
        ));
    }
    let attributes = |m: &MeshData| (m.normals.is_some(), m.uvs.is_some());
    if attributes(first) != attributes(mesh) {
        return Err(format!(
            "`{}` and the sequence's first frame `{}` differ in whether they have vertex normals or texture coordinates",
            mesh.source, first.source
        ));
    }
    Ok(())
}

/// Reads every object of an OBJ file into one mesh, unrepaired (texture
/// coordinates as (u, 1 − v) with `flip_tex_coords`).
fn read_obj(path: &Path, flip_tex_coords: bool) -> Result<MeshData, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    radiant_core::input_file::reject_special_file(path)
        .map_err(|e| format!("cannot read the mesh file: {e}"))?;
    let file = std::fs::File::open(path)
        .map_err(|e| format!("cannot open mesh file `{}`: {e}", path.display()))?;
    let size = file.metadata().map_or(0, |m| m.len());
    radiant_core::memory::check(size.saturating_mul(MESH_BYTES_PER_FILE_BYTE), || {
        format!(
            "mesh file `{}` ({}) as a mesh",
            path.display(),
            radiant_core::memory::gib(size)
        )
    })
    .map_err(|e| e.to_string())?;
    let mut reader = LineLimit::new(std::io::BufReader::new(file), MAX_LINE);
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
    let n_vertices = mesh.positions.len();
    if mesh
        .triangles
        .iter()
        .flatten()
        .any(|&i| i as usize >= n_vertices)
    {
        return Err(format!(
            "mesh file `{}` refers to vertices that do not exist",
            path.display()
        ));
    }
    if all_have_normals && normals.len() == n_vertices {
        mesh.normals = Some(normals);
    }
    if all_have_uvs && uvs.len() == n_vertices {
        mesh.uvs = Some(uvs);
    }
    Ok(mesh)
}

/// Drops unusable triangles and marks unusable normals (as zero vectors).
pub fn repair(mesh: &mut MeshData) {
    let mut repairs = MeshRepairs::default();
    let positions = &mesh.positions;
    mesh.triangles.retain(|t| {
        let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
        if !(a.is_finite() && b.is_finite() && c.is_finite()) {
            repairs.non_finite += 1;
            return false;
        }
        if (b - a).cross(c - a) == DVec3::ZERO {
            repairs.degenerate += 1;
            return false;
        }
        true
    });
    mesh.repairs = repairs;
    repair_attributes(mesh);
}

/// Marks unusable normals (as zero vectors, so the face normal is used)
/// and sets non-finite texture coordinates to (0, 0).
fn repair_attributes(mesh: &mut MeshData) {
    let mut repairs = mesh.repairs;
    if let Some(normals) = &mut mesh.normals {
        for n in normals.iter_mut() {
            match n.try_normalize() {
                Some(unit) => *n = unit,
                None => {
                    *n = Vec3::ZERO;
                    repairs.bad_normals += 1;
                }
            }
        }
    }
    match &mut mesh.uvs {
        Some(uvs) => {
            for uv in uvs.iter_mut().filter(|uv| !uv.is_finite()) {
                *uv = Vec2::ZERO;
                repairs.bad_uvs += 1;
            }
        }
        None => repairs.missing_uvs = true,
    }
    mesh.repairs = repairs;
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use std::io::Write;

    #[test]
    fn degenerate_input_is_repaired_and_counted() {
        let mut f = tempfile::Builder::new().suffix(".obj").tempfile().unwrap();
        writeln!(
            f,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nv 2 0 0\n\
             vn 0 0 1\nvn 0 0 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n\
             f 1//1 2//2 3//3\nf 1//1 4//4 3//3\nf 1//1 2//2 5//5\nf 1//1 1//1 3//3\n"
        )
        .unwrap();
        let mesh = load_obj(f.path(), true).unwrap();
        assert_eq!(mesh.triangles.len(), 1);
        assert_eq!(mesh.repairs.non_finite, 1);
        assert_eq!(
            mesh.repairs.degenerate, 2,
            "collinear and repeated-vertex faces"
        );
        assert_eq!(mesh.repairs.bad_normals, 1);
        assert!(mesh.repairs.missing_uvs);
    }

    #[test]
    fn missing_file_is_an_error() {
        let err = load_obj(Path::new("/nonexistent/mesh.obj"), true).unwrap_err();
        assert!(
            err.contains("cannot open mesh file `/nonexistent/mesh.obj`"),
            "{err}"
        );
    }

    #[test]
    fn an_obj_larger_than_memory_is_refused_before_reading() {
        // A sparse file of 1 TiB: no disk space, and nothing is read.
        let f = tempfile::Builder::new().suffix(".obj").tempfile().unwrap();
        f.as_file().set_len(1 << 40).unwrap();
        let start = std::time::Instant::now();
        let err = load_obj(f.path(), true).unwrap_err();
        assert!(
            err.contains("(1024.00 GiB) as a mesh needs about 8192.00 GiB"),
            "{err}"
        );
        assert!(err.contains("is available"), "{err}");
        assert!(start.elapsed().as_secs_f64() < 1.0);
    }
}

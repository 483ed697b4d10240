//! Mesh files, whatever their format: opened, read by [`super::obj`] or
//! [`super::ply`], repaired, given smooth normals where they have none
//! ([`super::normals`]) and MikkTSpace tangents ([`super::tangents`]).
//!
//! The format is a PLY file where the file starts with `ply` (the format's
//! magic line), OBJ otherwise. Degenerate input is repaired, never passed
//! on: triangles with non-finite coordinates or zero area (repeated or
//! collinear vertices) are dropped, vertex normals that are zero or
//! non-finite are marked so the face normal is used instead, and
//! non-finite texture coordinates become (0, 0). Needle triangles
//! (positive but tiny area) are kept: the watertight intersection test
//! handles them; extract drops those whose normal vanishes in single
//! precision. [`MeshRepairs`] counts what was done; `radiant render` warns
//! about it and `radiant info` reports it.

use crate::world::{MeshData, MeshRepairs};
use glam::{DVec3, Vec2, Vec3};
use std::io::{BufRead, BufReader};
use std::path::Path;

/// Bytes of memory loading a mesh file takes per byte of the file, at most
/// (an estimate: an OBJ face line as short as `f 1 2 3` becomes three
/// 4-byte indices in the parser and again in the mesh, a vertex line
/// `v 0 0 0` twelve bytes of position in each, and the mesh adds normals
/// and tangents; a binary PLY's 12-byte vertex and 13-byte face grow
/// about as much).
const MESH_BYTES_PER_FILE_BYTE: u64 = 8;

/// How a shape reads its mesh file (the default: each format's texture
/// coordinate convention, smooth normals where the file has none).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MeshOptions {
    /// Store texture coordinates as (u, 1 − v). `None`: the format's
    /// convention as Mitsuba 3 reads it (flipped for OBJ, whose v runs up
    /// an image, as is for PLY).
    pub flip_tex_coords: Option<bool>,
    /// Keep the facets: drop the file's vertex normals and compute none
    /// (Mitsuba's `face_normals`).
    pub face_normals: bool,
}

/// Loads a mesh file (OBJ or PLY) into one mesh, repaired.
pub fn load(path: &Path, options: MeshOptions) -> Result<MeshData, String> {
    let mut mesh = read(path, options)?;
    repair(&mut mesh);
    shade(&mut mesh, options.face_normals);
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

/// Loads one frame of a deforming mesh: as [`load`], but every triangle
/// is kept, degenerate or not, so that all frames of a sequence have the
/// same triangles (a triangle of zero area is never hit, one with
/// non-finite vertices neither). Normals the file lacks are computed from
/// this frame's positions.
pub fn load_frame(path: &Path, options: MeshOptions) -> Result<MeshData, String> {
    let mut mesh = read(path, options)?;
    repair_attributes(&mut mesh);
    shade(&mut mesh, options.face_normals);
    if mesh.triangles.is_empty() {
        return Err(format!("mesh file `{}` has no triangles", path.display()));
    }
    Ok(mesh)
}

/// Gives `mesh` its shading normals (computed where the file has none,
/// none at all with `face_normals`) and its tangents, which follow them.
pub fn shade(mesh: &mut MeshData, face_normals: bool) {
    if face_normals {
        mesh.normals = None;
        mesh.computed_normals = false;
    } else if mesh.normals.is_none() {
        mesh.normals = Some(super::normals::smooth_normals(
            &mesh.positions,
            &mesh.triangles,
        ));
        mesh.computed_normals = true;
    }
    mesh.tangents = super::tangents::mikktspace(mesh);
}

/// Opens a mesh file and reads it with the reader of its format,
/// unrepaired.
fn read(path: &Path, options: MeshOptions) -> Result<MeshData, String> {
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
    let mut reader = BufReader::new(file);
    let start = reader
        .fill_buf()
        .map_err(|e| format!("cannot read mesh file `{}`: {e}", path.display()))?;
    let mut mesh = if start.starts_with(b"ply") {
        super::ply::read_ply(path, &mut reader, options.flip_tex_coords.unwrap_or(false))?
    } else {
        super::obj::read_obj(path, reader, options.flip_tex_coords.unwrap_or(true))?
    };
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
    let matches = |n: Option<usize>| n.is_none_or(|n| n == n_vertices);
    if !matches(mesh.normals.as_ref().map(Vec::len)) {
        mesh.normals = None;
    }
    if !matches(mesh.uvs.as_ref().map(Vec::len)) {
        mesh.uvs = None;
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
    let attributes = |m: &MeshData| (m.computed_normals, m.normals.is_some(), m.uvs.is_some());
    if attributes(first) != attributes(mesh) {
        return Err(format!(
            "`{}` and the sequence's first frame `{}` differ in whether they have vertex normals or texture coordinates",
            mesh.source, first.source
        ));
    }
    Ok(())
}

/// Drops unusable triangles and marks unusable normals (as zero vectors).
pub(super) fn repair(mesh: &mut MeshData) {
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

    const OBJ: MeshOptions = MeshOptions {
        flip_tex_coords: None,
        face_normals: false,
    };

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
        let mesh = load(f.path(), OBJ).unwrap();
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
        let err = load(Path::new("/nonexistent/mesh.obj"), OBJ).unwrap_err();
        assert!(
            err.contains("cannot open mesh file `/nonexistent/mesh.obj`"),
            "{err}"
        );
    }

    #[test]
    fn a_mesh_larger_than_memory_is_refused_before_reading() {
        // A sparse file of 1 TiB: no disk space, and nothing is read.
        let f = tempfile::Builder::new().suffix(".obj").tempfile().unwrap();
        f.as_file().set_len(1 << 40).unwrap();
        let start = std::time::Instant::now();
        let err = load(f.path(), OBJ).unwrap_err();
        assert!(
            err.contains("(1024.00 GiB) as a mesh needs about 8192.00 GiB"),
            "{err}"
        );
        assert!(err.contains("is available"), "{err}");
        assert!(start.elapsed().as_secs_f64() < 1.0);
    }

    /// A square of two triangles folded 90° along its diagonal, without
    /// normals: smooth by default, flat with `face_normals`, and the
    /// file's own normals dropped with `face_normals` too.
    #[test]
    fn normals_are_smooth_by_default_and_flat_on_request() {
        let mut f = tempfile::Builder::new().suffix(".obj").tempfile().unwrap();
        writeln!(f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\n").unwrap();
        let smooth = load(f.path(), OBJ).unwrap();
        let normals = smooth.normals.as_ref().unwrap();
        assert!(smooth.computed_normals);
        // Vertices 1 and 2 lie on both faces (equal angles): between them.
        let between = Vec3::new(0.0, 1.0, 1.0).normalize();
        assert!(normals[0].abs_diff_eq(between, 1e-6), "{}", normals[0]);
        assert!(normals[1].abs_diff_eq(between, 1e-6), "{}", normals[1]);
        assert_eq!((normals[2], normals[3]), (Vec3::Z, Vec3::Y));
        let flat = load(
            f.path(),
            MeshOptions {
                face_normals: true,
                ..OBJ
            },
        )
        .unwrap();
        assert_eq!(flat.normals, None);

        let mut g = tempfile::Builder::new().suffix(".obj").tempfile().unwrap();
        writeln!(g, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 0 0\nf 1//1 2//1 3//1\n").unwrap();
        let own = load(g.path(), OBJ).unwrap();
        assert_eq!(own.normals, Some(vec![Vec3::X; 3]));
        assert!(!own.computed_normals);
        let dropped = load(
            g.path(),
            MeshOptions {
                face_normals: true,
                ..OBJ
            },
        )
        .unwrap();
        assert_eq!(dropped.normals, None);
    }
}

//! Vertex tangents of meshes: MikkTSpace (Mikkelsen 2008), the tangent
//! space normal-map bakers and glTF assume, through `bevy_mikktspace`
//! (a byte-identical port of the reference implementation).
//!
//! Each triangle's vertices get the unit tangent along ∂p/∂u that the
//! algorithm welds across the faces sharing them, so the shading frame
//! turns smoothly over the mesh. The bitangent's sign (mirrored texture
//! islands) is not kept: shading frames are right-handed, as Mitsuba 3's.

use crate::world::MeshData;
use bevy_mikktspace::{Geometry, TangentSpace, generate_tangents};
use glam::Vec3;

/// The mesh as MikkTSpace reads it, and the tangents it writes.
struct Faces<'a> {
    mesh: &'a MeshData,
    tangents: Vec<[Vec3; 3]>,
}

impl Faces<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.mesh.triangles[face][vert] as usize
    }
}

impl Geometry for Faces<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.vertex(face, vert)].to_array()
    }

    /// The vertex normal, or the face's where the mesh has none (or a
    /// zero one).
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        let vertex = self
            .mesh
            .normals
            .as_ref()
            .map(|n| n[self.vertex(face, vert)])
            .filter(|n| *n != Vec3::ZERO);
        let n = vertex.unwrap_or_else(|| {
            let [a, b, c] = self.mesh.triangles[face].map(|i| self.mesh.positions[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        });
        n.to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uvs = self
            .mesh
            .uvs
            .as_ref()
            .expect("tangents need texture coordinates");
        uvs[self.vertex(face, vert)].to_array()
    }

    fn set_tangent(&mut self, tangent: Option<TangentSpace>, face: usize, vert: usize) {
        self.tangents[face][vert] = tangent.map_or(Vec3::ZERO, |t| Vec3::from(t.tangent()));
    }
}

/// The MikkTSpace tangents of `mesh`'s triangles (zero where the algorithm
/// finds none), or `None` where the mesh has no texture coordinates.
pub fn mikktspace(mesh: &MeshData) -> Option<Vec<[Vec3; 3]>> {
    mesh.uvs.as_ref()?;
    let mut faces = Faces {
        mesh,
        tangents: vec![[Vec3::ZERO; 3]; mesh.triangles.len()],
    };
    // The error type has no values: generation cannot fail.
    let _ = generate_tangents(&mut faces);
    Some(faces.tangents)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// A curved strip (a quarter of a cylinder) with u around it and v
    /// along it, sharing its vertices between triangles.
    fn strip() -> MeshData {
        let (n, m) = (8, 3);
        let mut mesh = MeshData::default();
        let mut normals = Vec::new();
        let mut uvs = Vec::new();
        for j in 0..m {
            for i in 0..n {
                let a = i as f32 / (n - 1) as f32 * std::f32::consts::FRAC_PI_2;
                mesh.positions.push(Vec3::new(a.cos(), j as f32, a.sin()));
                normals.push(Vec3::new(a.cos(), 0.0, a.sin()));
                uvs.push(Vec2::new(
                    i as f32 / (n - 1) as f32,
                    j as f32 / (m - 1) as f32,
                ));
            }
        }
        for j in 0..m - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                let (b, c, d) = (a + 1, a + n as u32 + 1, a + n as u32);
                mesh.triangles.push([a, d, c]);
                mesh.triangles.push([a, c, b]);
            }
        }
        mesh.normals = Some(normals);
        mesh.uvs = Some(uvs);
        mesh
    }

    #[test]
    fn tangents_follow_u_are_orthogonal_to_the_normals_and_shared_at_vertices() {
        let mesh = strip();
        let tangents = mikktspace(&mesh).expect("the strip has texture coordinates");
        let normals = mesh.normals.as_ref().expect("normals");
        let mut at_vertex: Vec<Option<Vec3>> = vec![None; mesh.positions.len()];
        for (tri, ts) in mesh.triangles.iter().zip(&tangents) {
            for (&v, &t) in tri.iter().zip(ts) {
                let (p, n) = (mesh.positions[v as usize], normals[v as usize]);
                assert!((t.length() - 1.0).abs() < 1e-4, "{t}");
                assert!(t.dot(n).abs() < 1e-4, "tangent {t} not orthogonal to {n}");
                // ∂p/∂u on the cylinder: around it, towards growing angle.
                let around = Vec3::new(-p.z, 0.0, p.x).normalize();
                assert!(t.dot(around) > 0.999, "{t} vs {around}");
                // The same tangent wherever a vertex is shared.
                match at_vertex[v as usize] {
                    None => at_vertex[v as usize] = Some(t),
                    Some(u) => assert!((u - t).length() < 1e-5, "{u} vs {t} at {v}"),
                }
            }
        }
        let mut no_uvs = strip();
        no_uvs.uvs = None;
        assert!(mikktspace(&no_uvs).is_none());
    }
}

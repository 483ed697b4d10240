//! A glTF file and its buffers, read and checked: the node hierarchy of
//! its scene with each node's transform, and each triangle primitive as a
//! repaired [`MeshData`] with its normals and tangents. Every accessor a
//! primitive reads is checked against its buffer view and buffer first,
//! so that no read runs past the data.

use crate::world::MeshData;
use glam::{DMat4, Vec2, Vec3};
use gltf::mesh::Mode;
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// A glTF file read with its buffers.
pub(super) struct Asset {
    pub(super) path: PathBuf,
    document: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
}

impl Asset {
    /// Reads the glTF file at `path` and every buffer it names.
    pub(super) fn open(path: &Path) -> Result<Self, String> {
        let name = path.display();
        radiant_core::input_file::reject_special_file(path)
            .map_err(|e| format!("cannot read the glTF file: {e}"))?;
        let bytes =
            std::fs::read(path).map_err(|e| format!("cannot read glTF file `{name}`: {e}"))?;
        let gltf = gltf::Gltf::from_slice(&bytes)
            .map_err(|e| format!("glTF file `{name}` is not valid glTF 2.0: {e}"))?;
        let base = path.parent().unwrap_or(Path::new("."));
        for buffer in gltf.document.buffers() {
            if let gltf::buffer::Source::Uri(uri) = buffer.source()
                && !uri.contains(':')
                && !base.join(uri).is_file()
            {
                return Err(format!(
                    "glTF file `{name}`: buffer {} is the file `{uri}`, which cannot be read \
                     (looked for `{}`)",
                    buffer.index(),
                    base.join(uri).display()
                ));
            }
        }
        let buffers = gltf::import_buffers(&gltf.document, Some(base), gltf.blob)
            .map_err(|e| format!("glTF file `{name}`: cannot load its buffers: {e}"))?;
        Ok(Self {
            path: path.to_path_buf(),
            document: gltf.document,
            buffers,
        })
    }

    /// The scene to show: the default one, else the first.
    pub(super) fn scene(&self) -> Result<gltf::Scene<'_>, String> {
        self.document
            .default_scene()
            .or_else(|| self.document.scenes().next())
            .ok_or_else(|| format!("glTF file `{}` has no scene", self.path.display()))
    }

    /// Every node of the scene with its transform to the scene's space, in
    /// depth-first order.
    pub(super) fn nodes(&self) -> Result<Vec<(gltf::Node<'_>, DMat4)>, String> {
        let mut out = Vec::new();
        let mut stack: Vec<_> = self
            .scene()?
            .nodes()
            .map(|n| (n, DMat4::IDENTITY))
            .collect();
        stack.reverse();
        while let Some((node, parent)) = stack.pop() {
            if out.len() > self.document.nodes().len() {
                return Err(format!(
                    "glTF file `{}`: its node hierarchy has a cycle",
                    self.path.display()
                ));
            }
            let local = node.transform().matrix().map(|c| c.map(f64::from));
            let world = parent * DMat4::from_cols_array_2d(&local);
            let children: Vec<_> = node.children().map(|c| (c, world)).collect();
            stack.extend(children.into_iter().rev());
            out.push((node, world));
        }
        Ok(out)
    }

    /// The encoded bytes of image `index`: its `data:` URI decoded, its
    /// buffer view's bytes, or the file it names beside the glTF file.
    pub(super) fn image_bytes(&self, index: usize) -> Result<Cow<'_, [u8]>, String> {
        let name = self.path.display();
        let image = self.document.images().nth(index).ok_or_else(|| {
            format!(
                "glTF file `{name}` has {} images; there is no image {index}",
                self.document.images().len()
            )
        })?;
        match image.source() {
            gltf::image::Source::View { view, .. } => {
                let bytes = self.view(&view)?;
                Ok(Cow::Borrowed(bytes))
            }
            gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
                let base = self.path.parent().unwrap_or(Path::new("."));
                gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), Some(base))
                    .map(|d| Cow::Owned(d.0))
                    .map_err(|e| format!("glTF file `{name}`: image {index}'s data URI: {e}"))
            }
            gltf::image::Source::Uri { uri, .. } => {
                let file = self.path.parent().unwrap_or(Path::new(".")).join(uri);
                radiant_core::input_file::reject_special_file(&file)
                    .and_then(|()| std::fs::read(&file).map_err(|e| e.to_string()))
                    .map(Cow::Owned)
                    .map_err(|e| {
                        format!(
                            "glTF file `{name}`: image {index} is the file `{uri}`, which cannot \
                             be read (looked for `{}`): {e}",
                            file.display()
                        )
                    })
            }
        }
    }

    /// The bytes of buffer view `view`, checked to lie within its buffer.
    fn view(&self, view: &gltf::buffer::View<'_>) -> Result<&[u8], String> {
        let data = self
            .buffers
            .get(view.buffer().index())
            .map_or(&[][..], |d| &d.0[..]);
        let end = view.offset().saturating_add(view.length());
        data.get(view.offset()..end).ok_or_else(|| {
            format!(
                "glTF file `{}`: buffer view {} ends at byte {end}, but buffer {} holds {} bytes",
                self.path.display(),
                view.index(),
                view.buffer().index(),
                data.len()
            )
        })
    }

    /// Checks that `accessor` lies within its buffer view and the view
    /// within its buffer, so that reading it cannot run past the data.
    pub(super) fn check(&self, accessor: &gltf::Accessor<'_>) -> Result<(), String> {
        let name = self.path.display();
        if accessor.sparse().is_some() {
            return Err(format!(
                "glTF file `{name}`: accessor {} is sparse, which is not supported",
                accessor.index()
            ));
        }
        let Some(view) = accessor.view() else {
            return Err(format!(
                "glTF file `{name}`: accessor {} has no buffer view",
                accessor.index()
            ));
        };
        self.view(&view)?;
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        let needed = match accessor.count() {
            0 => 0,
            n => accessor
                .offset()
                .saturating_add(stride.saturating_mul(n - 1))
                .saturating_add(size),
        };
        if needed > view.length() {
            return Err(format!(
                "glTF file `{name}`: accessor {} needs {needed} bytes of buffer view {}, which has {}",
                accessor.index(),
                view.index(),
                view.length()
            ));
        }
        Ok(())
    }

    /// The mesh of one primitive, repaired, with its tangents and the
    /// texture coordinates of set `tex_coord`; flat where it has no
    /// normals or `face_normals`.
    pub(super) fn primitive(
        &self,
        mesh: &gltf::Mesh<'_>,
        primitive: &gltf::Primitive<'_>,
        tex_coord: u32,
        face_normals: bool,
    ) -> Result<MeshData, String> {
        let what = format!(
            "glTF file `{}`: mesh {} primitive {}",
            self.path.display(),
            mesh.name()
                .map_or_else(|| mesh.index().to_string(), |n| format!("`{n}`")),
            primitive.index()
        );
        for (semantic, accessor) in primitive.attributes() {
            if matches!(
                semantic,
                gltf::Semantic::Positions | gltf::Semantic::Normals
            ) || semantic == gltf::Semantic::TexCoords(tex_coord)
            {
                self.check(&accessor)?;
            }
        }
        if let Some(indices) = primitive.indices() {
            self.check(&indices)?;
        }
        let reader = primitive.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| format!("{what} has no POSITION attribute"))?
            .map(Vec3::from)
            .collect();
        let n = positions.len();
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
            return Err(format!(
                "{what} refers to vertex {bad}, but it has {n} vertices"
            ));
        }
        let triangles: Vec<[u32; 3]> = match primitive.mode() {
            Mode::Triangles => indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
            // Every other triangle of a strip turns the other way round.
            Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                .map(|i| {
                    let t = [indices[i], indices[i + 1], indices[i + 2]];
                    if i % 2 == 0 { t } else { [t[1], t[0], t[2]] }
                })
                .collect(),
            Mode::TriangleFan => (1..indices.len().saturating_sub(1))
                .map(|i| [indices[0], indices[i], indices[i + 1]])
                .collect(),
            other => {
                return Err(format!(
                    "{what} draws {other:?}, which Radiant does not render: a mesh needs \
                     triangles (mode 4, or strips 5 and fans 6)"
                ));
            }
        };
        let mut data = MeshData {
            source: format!("{}#mesh{}", self.path.display(), mesh.index()),
            normals: reader.read_normals().map(|n| n.map(Vec3::from).collect()),
            uvs: reader
                .read_tex_coords(tex_coord)
                .map(|t| t.into_f32().map(Vec2::from).collect()),
            positions,
            triangles,
            ..MeshData::default()
        };
        for attribute in [
            data.normals.as_ref().map(Vec::len),
            data.uvs.as_ref().map(Vec::len),
        ] {
            if attribute.is_some_and(|len| len != n) {
                return Err(format!(
                    "{what}: its attributes have different numbers of vertices"
                ));
            }
        }
        crate::scene::mesh::repair(&mut data);
        let flat = face_normals || data.normals.is_none();
        crate::scene::mesh::shade(&mut data, flat);
        if data.triangles.is_empty() {
            return Err(format!("{what} has no usable triangles"));
        }
        Ok(data)
    }
}

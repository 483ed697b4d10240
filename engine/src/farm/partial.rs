//! Partial EXR files: what one sample partition of a frame leaves for
//! [`merge`](super::merge), and what a progressive render leaves for
//! `--resume` (its samples so far). Beside a viewable preview (`R`, `G`,
//! `B`: the file's own developed image) they hold the film's exact
//! weighted sums ([`Sums`]: Σ w·r, Σ w·g, Σ w·b, Σ w in 128-bit fixed
//! point) bit for bit, as four 32-bit unsigned words per sum, least
//! significant first (`sum.R.0` … `sum.R.3`, `sum.G.*`, `sum.B.*`,
//! `sum.W.*`), because a frame is Σ w·L / Σ w over all its samples:
//! averaging the developed images would weight them wrongly wherever their
//! filter weights differ, and adding exact sums gives the uninterrupted
//! render's image bit for bit. The header records the render they belong
//! to ([`Header`], as `radiant.*` text attributes), so that a merge or a
//! resume can refuse files of other scenes, frames, sizes or seeds.

use crate::farm::partition::Partition;
use crate::film::Film;
use crate::film::exact::Sums;
use crate::film::output::temp_file_beside;
use crate::settings::RenderSettings;
use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
};
use radiant_core::exr_file::MAX_EXR_PIXELS;
use std::collections::HashMap;
use std::io::BufWriter;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The sums' channels, in the order of [`Sums::to_words`].
const SUM_CHANNELS: [&str; 16] = [
    "sum.R.0", "sum.R.1", "sum.R.2", "sum.R.3", "sum.G.0", "sum.G.1", "sum.G.2", "sum.G.3",
    "sum.B.0", "sum.B.1", "sum.B.2", "sum.B.3", "sum.W.0", "sum.W.1", "sum.W.2", "sum.W.3",
];

/// `radiant.partition` of a progressive render's state.
const NO_PARTITION: &str = "none";

/// What rendered a partial file: the render it is part of and its part.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// The scene file, as the render was given it.
    pub scene: String,
    /// CRC-32 of the scene file's bytes: files of different scenes (or of
    /// an edited scene) do not merge.
    pub scene_digest: u32,
    /// The frame.
    pub frame: i64,
    /// Film width in pixels.
    pub width: u32,
    /// Film height in pixels.
    pub height: u32,
    /// Samples per pixel of the whole frame (of a progressive render: the
    /// most it renders, which samplers that stratify over the frame's
    /// samples depend on).
    pub spp: u32,
    /// The frame's sampler seed.
    pub seed: u64,
    /// Longest path in segments (-1: unlimited).
    pub max_depth: i32,
    /// The partition this file renders; `None` for a progressive render's
    /// state (samples `0..n` of `spp`, for `--resume`).
    pub partition: Option<Partition>,
    /// Its sample indices.
    pub samples: Range<u32>,
    /// Samples that were NaN or infinite and recorded as black.
    pub invalid_samples: u64,
}

impl Header {
    /// The header of a render of `frame` of the scene file `scene` (whose
    /// bytes are `scene_bytes`) with `settings`: `partition` and `samples`
    /// as given, no invalid samples yet.
    pub fn new(
        scene: &Path,
        scene_bytes: &[u8],
        frame: i64,
        settings: &RenderSettings,
        partition: Option<Partition>,
        samples: Range<u32>,
    ) -> Self {
        Self {
            scene: scene.display().to_string(),
            scene_digest: crc32fast::hash(scene_bytes),
            frame,
            width: settings.width,
            height: settings.height,
            spp: settings.spp,
            seed: settings.seed,
            max_depth: settings.max_depth,
            partition,
            samples,
            invalid_samples: 0,
        }
    }

    /// What must agree for two files to be parts of one frame, as (what,
    /// value compared, value shown). Scenes compare by content, so the same
    /// scene named by different paths on different machines still merges.
    pub fn identity(&self) -> [(&'static str, String, String); 6] {
        let same = |what, value: String| (what, value.clone(), value);
        [
            (
                "scene",
                format!("{:08x}", self.scene_digest),
                format!("`{}`, CRC-32 {:08x}", self.scene, self.scene_digest),
            ),
            same("size", format!("{}x{}", self.width, self.height)),
            same("frame", self.frame.to_string()),
            same("samples per pixel", self.spp.to_string()),
            same("seed", self.seed.to_string()),
            same("max_depth", self.max_depth.to_string()),
        ]
    }

    /// The header as EXR text attributes.
    fn attributes(&self) -> Vec<(String, String)> {
        let text = [
            ("scene", self.scene.clone()),
            ("scene_crc32", format!("{:08x}", self.scene_digest)),
            ("frame", self.frame.to_string()),
            ("spp", self.spp.to_string()),
            ("seed", self.seed.to_string()),
            ("max_depth", self.max_depth.to_string()),
            (
                "partition",
                self.partition
                    .map_or(NO_PARTITION.to_string(), |p| p.to_string()),
            ),
            (
                "samples",
                format!("{}..{}", self.samples.start, self.samples.end),
            ),
            ("invalid_samples", self.invalid_samples.to_string()),
        ];
        text.into_iter()
            .map(|(k, v)| (format!("radiant.{k}"), v))
            .collect()
    }
}

/// A partial file's header and sums.
#[derive(Debug, Clone)]
pub struct Partial {
    /// What rendered it.
    pub header: Header,
    /// Σ w·r, Σ w·g, Σ w·b, Σ w per pixel, row-major from the top row.
    pub sums: Vec<Sums>,
}

/// Why a partial file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum PartialError {
    /// The file could not be read as an EXR image (missing, truncated,
    /// damaged, not a regular file).
    #[error("cannot read `{path}`: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The file is an image, but not one partition of a frame.
    #[error(
        "`{path}` is not a sample partition of a frame ({missing}): merge takes the files that `radiant render --partition K/N` writes"
    )]
    NotPartial {
        /// The file.
        path: PathBuf,
        /// The attribute or channel it lacks.
        missing: String,
    },
    /// An attribute holds something unreadable.
    #[error("`{path}`: the attribute `{name}` holds `{value}`, which is not valid")]
    BadAttribute {
        /// The file.
        path: PathBuf,
        /// The attribute.
        name: String,
        /// Its text.
        value: String,
    },
    /// The file could not be written.
    #[error("cannot write `{path}`: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// Writes `film`, rendered as `header` says, to `path` (atomically: a
/// temporary file beside it, renamed into place).
pub fn write(path: &Path, header: &Header, film: &Film) -> Result<(), PartialError> {
    let error = |message: String| PartialError::Write {
        path: path.to_path_buf(),
        message,
    };
    let preview = film.try_develop().map_err(|e| error(e.to_string()))?;
    let sums = film.sums();
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
        let values = preview.pixels.iter().map(|p| p[c]).collect();
        channels.push(AnyChannel::new(name, FlatSamples::F32(values)));
    }
    for (c, name) in SUM_CHANNELS.into_iter().enumerate() {
        let values = sums.iter().map(|s| s.to_words()[c]).collect();
        channels.push(AnyChannel::new(name, FlatSamples::U32(values)));
    }
    let mut attributes = LayerAttributes::named("rgb");
    for (name, value) in header.attributes() {
        let (name, value) = (Text::new_or_none(&name), Text::new_or_none(&value));
        let (Some(name), Some(value)) = (name, value) else {
            return Err(error(
                "the scene's path cannot be stored in an EXR attribute".into(),
            ));
        };
        attributes.other.insert(name, AttributeValue::Text(value));
    }
    let layer = Layer::new(
        (header.width as usize, header.height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let mut tmp = temp_file_beside(path, ".tmp").map_err(|e| error(e.to_string()))?;
    Image::from_layer(layer)
        .write()
        .to_buffered(BufWriter::new(tmp.as_file_mut()))
        .map_err(|e| error(e.to_string()))?;
    tmp.as_file().sync_all().map_err(|e| error(e.to_string()))?;
    tmp.persist(path).map_err(|e| error(e.error.to_string()))?;
    Ok(())
}

/// Reads the header of the partial file at `path` (not its pixels).
pub fn read_header(path: &Path) -> Result<Header, PartialError> {
    let read_error = |message: String| PartialError::Read {
        path: path.to_path_buf(),
        message,
    };
    radiant_core::input_file::reject_special_file(path).map_err(read_error)?;
    let meta =
        exr::meta::MetaData::read_from_file(path, false).map_err(|e| read_error(e.to_string()))?;
    let Some(layer) = meta.headers.first() else {
        return Err(read_error("it has no layer".into()));
    };
    // Checked before any pixel memory is taken.
    let size = layer.layer_size;
    if size
        .width()
        .checked_mul(size.height())
        .is_none_or(|n| n > MAX_EXR_PIXELS)
    {
        return Err(read_error(format!(
            "its layer is {}x{} pixels, more than an image may have (is the header damaged?)",
            size.width(),
            size.height()
        )));
    }
    parse_header(path, &layer.own_attributes.other, size)
}

/// Reads the partial file at `path`: its header and sums.
pub fn read(path: &Path) -> Result<Partial, PartialError> {
    let header = read_header(path)?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| PartialError::Read {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let layer = image.layer_data;
    let mut words = vec![[0u32; 16]; layer.size.area()];
    for (c, name) in SUM_CHANNELS.into_iter().enumerate() {
        let not_partial = |missing: String| PartialError::NotPartial {
            path: path.to_path_buf(),
            missing,
        };
        let channel = layer
            .channel_data
            .list
            .iter()
            .find(|ch| ch.name.eq(name))
            .ok_or_else(|| not_partial(format!("it has no `{name}` channel")))?;
        let FlatSamples::U32(values) = &channel.sample_data else {
            return Err(not_partial(format!(
                "its `{name}` channel does not hold 32-bit integers"
            )));
        };
        for (pixel, &v) in words.iter_mut().zip(values) {
            pixel[c] = v;
        }
    }
    let sums = words.iter().map(Sums::from_words).collect();
    Ok(Partial { header, sums })
}

/// The `radiant.*` attributes of a partial file's layer.
struct Attributes<'a> {
    path: &'a Path,
    map: &'a HashMap<Text, AttributeValue>,
}

impl Attributes<'_> {
    /// The text of `radiant.{key}`.
    fn text(&self, key: &str) -> Result<String, PartialError> {
        let name = format!("radiant.{key}");
        match self.map.get(&Text::from(name.as_str())) {
            Some(AttributeValue::Text(t)) => Ok(t.to_string()),
            _ => Err(PartialError::NotPartial {
                path: self.path.to_path_buf(),
                missing: format!("it has no `{name}` attribute"),
            }),
        }
    }

    /// `radiant.{key}` as `read` reads it (`None`: not valid).
    fn read<T>(&self, key: &str, read: impl FnOnce(&str) -> Option<T>) -> Result<T, PartialError> {
        let value = self.text(key)?;
        read(&value).ok_or_else(|| PartialError::BadAttribute {
            path: self.path.to_path_buf(),
            name: format!("radiant.{key}"),
            value,
        })
    }

    /// `radiant.{key}` parsed.
    fn parse<T: std::str::FromStr>(&self, key: &str) -> Result<T, PartialError> {
        self.read(key, |v| v.parse().ok())
    }
}

/// The [`Header`] stored in `attributes` of a `size` layer of the file at
/// `path`.
fn parse_header(
    path: &Path,
    attributes: &HashMap<Text, AttributeValue>,
    size: exr::prelude::Vec2<usize>,
) -> Result<Header, PartialError> {
    let a = Attributes {
        path,
        map: attributes,
    };
    let spp = a.parse("spp")?;
    let partition = a.read("partition", |v| match v {
        NO_PARTITION => Some(None),
        v => v.parse::<Partition>().ok().map(Some),
    })?;
    // The range must be the partition's (merges rely on it), or a
    // progressive render's first samples.
    let samples = a.read("samples", |v| {
        let (start, end) = v.split_once("..")?;
        let samples = start.parse().ok()?..end.parse().ok()?;
        let valid = match partition {
            Some(p) => p.samples(spp).ok()? == samples,
            None => samples.start == 0 && samples.end <= spp,
        };
        valid.then_some(samples)
    })?;
    Ok(Header {
        scene: a.text("scene")?,
        scene_digest: a.read("scene_crc32", |v| u32::from_str_radix(v, 16).ok())?,
        frame: a.parse("frame")?,
        // The layer's size is at most 2^28 pixels (checked), so each side
        // fits in u32.
        width: size.width() as u32,
        height: size.height() as u32,
        spp,
        seed: a.parse("seed")?,
        max_depth: a.parse("max_depth")?,
        partition,
        samples,
        invalid_samples: a.parse("invalid_samples")?,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A header for a 3×2 film, partition `index`/4 of 16 spp.
    pub(crate) fn header(index: u32) -> Header {
        let partition = Partition::new(index, 4).expect("valid");
        Header {
            scene: "scenes/x.yaml".into(),
            scene_digest: 0xdead_beef,
            frame: 7,
            width: 3,
            height: 2,
            spp: 16,
            seed: 11,
            max_depth: -1,
            partition: Some(partition),
            samples: partition.samples(16).expect("enough samples"),
            invalid_samples: 2,
        }
    }

    #[test]
    fn round_trips_the_sums_bit_for_bit() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("part.exr");
        let mut film = Film::new(3, 2);
        let layer: Vec<f32> = (0..24).map(|i| (i as f32 * 0.1).sin() / 3.0).collect();
        film.add_layers(&layer, 2);
        write(&path, &header(2), &film).expect("writes");
        let partial = read(&path).expect("reads");
        assert_eq!(partial.header, header(2));
        assert_eq!(partial.sums, film.sums());
        // Sums beyond f32's range and precision survive too.
        let mut exact = Film::new(3, 2);
        let mut sums = vec![Sums::ZERO; 6];
        sums[1] = Sums([i128::MAX, -1, 1, i128::MIN]);
        sums[4] = Sums([(1 << 100) + 1, 3, -(1 << 90), 1 << 64]);
        exact.add_sums(&sums, 0);
        write(&path, &header(2), &exact).expect("writes");
        assert_eq!(read(&path).expect("reads").sums, sums);
        write(&path, &header(2), &film).expect("writes");
        // The preview is the partition's own image.
        let preview = crate::film::output::read_exr(&path).expect("reads as an image");
        assert_eq!(preview, film.develop());
        assert_eq!(std::fs::read_dir(dir.path()).expect("lists").count(), 1);
        // A sample range that is not its partition's is refused.
        let mut wrong = header(2);
        wrong.samples = 0..8;
        write(&path, &wrong, &film).expect("writes");
        let e = read_header(&path).expect_err("inconsistent");
        assert!(
            e.to_string()
                .ends_with("the attribute `radiant.samples` holds `0..8`, which is not valid"),
            "{e}"
        );
    }

    #[test]
    fn a_plain_image_is_not_a_partial() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("plain.exr");
        crate::film::output::write(&path, &Film::new(2, 2).develop()).expect("writes");
        let e = read(&path).expect_err("not a partial");
        assert!(matches!(e, PartialError::NotPartial { .. }), "{e}");
        assert!(e.to_string().contains("plain.exr"), "{e}");
    }
}

//! Multi-layer EXR output: the beauty image with its alpha and the
//! requested output variables as named channels of one file.
//!
//! One part, channels named `layer.channel`, the convention Nuke and
//! Blender read as layers: the beauty is the default layer (`R`, `G`, `B`,
//! and `A` = coverage), then `albedo.R/G/B`, `normal.X/Y/Z`, `depth.Z`
//! (Nuke's depth channel), `position.X/Y/Z` and `spp.Y`, all 32-bit float.
//! The file is written atomically, like every other output.

use super::Image;
use super::aov::{Aov, AovImage};
use super::output::{ImageError, io_error, temp_file_beside};
use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image as ExrImage, Layer, LayerAttributes,
    SmallVec, WritableImage,
};
use std::io::BufWriter;
use std::path::Path;

/// The channel name of `aov`'s channel `c` (`albedo.R`).
pub fn channel_name(aov: Aov, c: usize) -> String {
    format!("{}.{}", aov.name(), aov.channels()[c])
}

/// Writes `image` (RGB), `planes.alpha` (A) and the planes `aovs` of
/// `planes` to the EXR file `path`, atomically.
///
/// # Panics
///
/// If `planes` is not the size of `image`.
pub fn write(
    path: &Path,
    image: &Image,
    planes: &AovImage,
    aovs: &[Aov],
) -> Result<(), ImageError> {
    assert_eq!((image.width, image.height), (planes.width, planes.height));
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
        let values = image.pixels.iter().map(|p| p[c]).collect();
        channels.push(AnyChannel::new(name, FlatSamples::F32(values)));
    }
    channels.push(AnyChannel::new("A", FlatSamples::F32(planes.alpha.clone())));
    for &aov in aovs {
        for c in 0..aov.channels().len() {
            let values = (0..planes.alpha.len())
                .map(|i| planes.channel(aov, c, i))
                .collect();
            channels.push(AnyChannel::new(
                channel_name(aov, c).as_str(),
                FlatSamples::F32(values),
            ));
        }
    }
    let layer = Layer::new(
        (image.width as usize, image.height as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let mut tmp = temp_file_beside(path, ".tmp").map_err(|e| io_error(path, e))?;
    ExrImage::from_layer(layer)
        .write()
        .to_buffered(BufWriter::new(tmp.as_file_mut()))
        .map_err(|e| io_error(path, e))?;
    tmp.as_file().sync_all().map_err(|e| io_error(path, e))?;
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(())
}

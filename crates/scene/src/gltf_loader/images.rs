//! A glTF file's images, each one's size read from its header and checked before it
//! is decoded: a small PNG that declares 20000² pixels would otherwise take gigabytes
//! before anything could refuse it. Then their pixels converted to RGBA8, and their
//! samplers' wrapping.

use std::path::Path;

use gltf::image::Format;

use super::sources::{Budget, UriScope};
use crate::Wrap;

/// The largest texture side Gnomon loads: what WebGPU devices commonly bind
/// (`max_texture_dimension_2d` is 16384 on lavapipe and on desktop GPUs).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Decodes every image of `document`, after checking each one's declared size and
/// charging its decoded pixels to `budget` (twelve references to one 16384² PNG each
/// pass the side limit, and together took 7.4 GB).
pub fn import(
    document: &gltf::Document,
    base: &Path,
    buffers: &[gltf::buffer::Data],
    scope: UriScope,
    budget: &mut Budget,
) -> Result<Vec<gltf::image::Data>, String> {
    // Every image's size first, from its header, charged before any is decoded: the
    // sum is what a file of many references to one small PNG would take.
    let mut encoded_images = Vec::new();
    for image in document.images() {
        let label = format!("image {}{}", image.index(), super::sources::named(image.name()));
        let encoded = encoded_bytes(&image, base, buffers, scope, &label)?;
        let reader = image::ImageReader::new(std::io::Cursor::new(&encoded[..]))
            .with_guessed_format()
            .map_err(|e| format!("{label}: {e}"))?;
        let (width, height) = reader
            .into_dimensions()
            .map_err(|e| format!("{label}: not a PNG or JPEG image it can read: {e}"))?;
        if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
            return Err(format!(
                "{label} is {width}×{height} pixels; the largest texture is {MAX_IMAGE_SIDE}×{MAX_IMAGE_SIDE}: \
                 downscale it"
            ));
        }
        // Decoded (up to 8 bytes a pixel, 16-bit RGBA), then converted to RGBA8 beside
        // it (4 more).
        let pixels = u64::from(width) * u64::from(height);
        budget.take(pixels * 12, &format!("{label}, {width}×{height} pixels decoded,"))?;
        encoded_images.push((label, encoded, pixels * 8));
    }
    let mut decoded = Vec::new();
    for (label, encoded, charged) in encoded_images {
        let mut reader = image::ImageReader::new(std::io::Cursor::new(&encoded[..]))
            .with_guessed_format()
            .map_err(|e| format!("{label}: {e}"))?;
        // The decoder may take what was charged for it (and a little for its own state),
        // not the image crate's default 512 MiB, whose error names no size.
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(charged + (1 << 20));
        reader.limits(limits);
        let pixels = reader.decode().map_err(|e| match e {
            image::ImageError::Limits(_) => {
                format!(
                    "{label}: decoding it would take more than the {} charged for it",
                    super::sources::size(charged)
                )
            }
            other => format!("{label}: {other}"),
        })?;
        decoded.push(decoded_image(pixels));
    }
    Ok(decoded)
}

/// The encoded (PNG or JPEG) bytes of `image`: a slice of a buffer, a data URI or a
/// file beside the model (checked by `sources::resolve`; read whole, its size first
/// checked against the budget's whole).
fn encoded_bytes(
    image: &gltf::Image,
    base: &Path,
    buffers: &[gltf::buffer::Data],
    scope: UriScope,
    label: &str,
) -> Result<Vec<u8>, String> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buffer = buffers
                .get(view.buffer().index())
                .ok_or_else(|| format!("{label}: its buffer view names no buffer"))?;
            let range = view.offset()..view.offset() + view.length();
            buffer.0.get(range).map(<[u8]>::to_vec).ok_or_else(|| {
                format!("{label}: its buffer view {} reaches past the end of its buffer", view.index())
            })
        }
        gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
            super::sources::data_uri(uri, label)
        }
        gltf::image::Source::Uri { uri, .. } => {
            let path = super::sources::resolve(base, uri, scope, label)?;
            let length =
                std::fs::metadata(&path).map_err(|e| format!("{label}: cannot read `{uri}`: {e}"))?.len();
            if length > crate::limits::MAX_MODEL_BYTES {
                return Err(format!(
                    "{label}: its file `{uri}` is {}, more than a model may take",
                    super::sources::size(length)
                ));
            }
            super::sources::read_prefix(&path, length, label, uri)
        }
    }
}

/// A decoded image in the form the rest of the loader reads (the gltf crate's).
fn decoded_image(pixels: image::DynamicImage) -> gltf::image::Data {
    let (width, height) = (pixels.width(), pixels.height());
    let (format, pixels) = match pixels {
        image::DynamicImage::ImageLuma8(p) => (Format::R8, p.into_raw()),
        image::DynamicImage::ImageLumaA8(p) => (Format::R8G8, p.into_raw()),
        image::DynamicImage::ImageRgb8(p) => (Format::R8G8B8, p.into_raw()),
        other => (Format::R8G8B8A8, other.into_rgba8().into_raw()),
    };
    gltf::image::Data { pixels, format, width, height }
}

/// The sampler's wrapping mode as Gnomon's.
pub(super) fn wrap(mode: gltf::texture::WrappingMode) -> Wrap {
    match mode {
        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
    }
}

/// Converts a decoded glTF image to RGBA8.
pub(super) fn to_rgba8(image: &gltf::image::Data) -> Result<Vec<u8>, String> {
    let p = &image.pixels;
    let n = (image.width as usize) * (image.height as usize);
    let rgba: Vec<u8> = match image.format {
        Format::R8 => p.iter().flat_map(|&r| [r, r, r, 255]).collect(),
        Format::R8G8 => p.chunks_exact(2).flat_map(|c| [c[0], c[0], c[0], c[1]]).collect(),
        Format::R8G8B8 => p.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 255]).collect(),
        Format::R8G8B8A8 => p.clone(),
        Format::R16G16B16A16 => p.chunks_exact(2).map(|c| c[1]).collect(),
        Format::R16G16B16 => p.chunks_exact(6).flat_map(|c| [c[1], c[3], c[5], 255]).collect(),
        other => return Err(format!("an image in the unsupported pixel format {other:?}")),
    };
    if rgba.len() != 4 * n {
        return Err(format!("an image of {}×{} with {} bytes of pixels", image.width, image.height, p.len()));
    }
    Ok(rgba)
}

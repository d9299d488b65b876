//! A glTF file's images, each one's size read from its header and checked before it
//! is decoded: a small PNG that declares 20000² pixels would otherwise take gigabytes
//! before anything could refuse it. Then their pixels converted to RGBA8, and their
//! samplers' wrapping.

use std::path::Path;

use gltf::image::Format;

use crate::Wrap;

/// The largest texture side Gnomon loads: what WebGPU devices commonly bind
/// (`max_texture_dimension_2d` is 16384 on lavapipe and on desktop GPUs).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Decodes every image of `document`, after checking each one's declared size.
pub fn import(
    document: &gltf::Document,
    base: &Path,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<gltf::image::Data>, String> {
    let mut decoded = Vec::new();
    for image in document.images() {
        let label = format!("image {} (`{}`)", image.index(), image.name().unwrap_or(""));
        let encoded = encoded_bytes(&image, base, buffers).map_err(|e| format!("{label}: {e}"))?;
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
        decoded.push(
            gltf::image::Data::from_source(image.source(), Some(base), buffers)
                .map_err(|e| format!("{label}: {e}"))?,
        );
    }
    Ok(decoded)
}

/// The encoded (PNG or JPEG) bytes of `image`: a slice of a buffer, a data URI or a file.
fn encoded_bytes(
    image: &gltf::Image,
    base: &Path,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<u8>, String> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buffer = buffers.get(view.buffer().index()).ok_or("its buffer view names no buffer")?;
            let range = view.offset()..view.offset() + view.length();
            buffer
                .0
                .get(range)
                .map(<[u8]>::to_vec)
                .ok_or_else(|| format!("its buffer view {} reaches past the end of its buffer", view.index()))
        }
        gltf::image::Source::Uri { uri, .. } => {
            gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), Some(base))
                .map(|data| data.0)
                .map_err(|e| format!("cannot read `{uri}`: {e}"))
        }
    }
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

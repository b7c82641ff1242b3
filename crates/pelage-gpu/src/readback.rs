//! Reading pictures and buffers back from the GPU: a texture copied into a
//! mapped buffer, BGRA swapped to RGBA in one place ([`read_texture`]).

use crate::{GpuContext, GpuError};

/// Copies `texture` (4 bytes a pixel) into a buffer, submits `encoder` and returns
/// the pixels.
pub(crate) fn read_back(
    ctx: &GpuContext,
    mut encoder: wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    width: u32,
    height: u32,
) -> Result<image::RgbaImage, GpuError> {
    let device = &ctx.device;

    // Rows of a texture-to-buffer copy are padded to 256 bytes.
    let row = width * 4;
    let padded_row =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(padded_row) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded_row),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
    );
    ctx.queue.submit([encoder.finish()]);
    let pixels = map_read(ctx, &readback, |mapped| {
        let mut pixels = Vec::with_capacity((row * height) as usize);
        for y in 0..height as usize {
            let start = y * padded_row as usize;
            pixels.extend_from_slice(&mapped[start..start + row as usize]);
        }
        pixels
    })?;
    image::RgbaImage::from_raw(width, height, pixels)
        .ok_or_else(|| GpuError::Readback("the image size does not match".into()))
}

/// Maps `buffer` (`MAP_READ`, its copy already submitted), waits for the
/// GPU, and hands its bytes to `read`.
pub(crate) fn map_read<T>(
    ctx: &GpuContext,
    buffer: &wgpu::Buffer,
    read: impl FnOnce(&[u8]) -> T,
) -> Result<T, GpuError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |result| {
        let _ = sender.send(result);
    });
    let waited = ctx
        .device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.into()));
    // A resource that could not be made explains everything after it.
    ctx.check()?;
    waited?;
    receiver
        .recv()
        .map_err(|e| GpuError::Readback(e.into()))?
        .map_err(|e| GpuError::Readback(e.into()))?;
    let mapped = buffer
        .get_mapped_range(..)
        .map_err(|e| GpuError::Readback(e.into()))?;
    let value = read(&mapped);
    drop(mapped);
    buffer.unmap();
    Ok(value)
}

/// Finishes `encoder` with a copy of `texture` (8-bit RGBA or BGRA, such as
/// an offscreen twin of a window's surface) and reads it back as RGBA.
///
/// Every picture pelage reads back goes through here, so BGRA targets (a
/// window surface's usual format) come back as RGBA in one place.
pub fn read_texture(
    ctx: &GpuContext,
    encoder: wgpu::CommandEncoder,
    texture: &wgpu::Texture,
) -> Result<image::RgbaImage, GpuError> {
    let bgra = is_bgra(texture.format())?;
    let size = texture.size();
    let mut image = read_back(ctx, encoder, texture, size.width, size.height)?;
    if bgra {
        image.pixels_mut().for_each(|p| p.0.swap(0, 2));
    }
    Ok(image)
}

/// Whether `format` is 8-bit BGRA (false: 8-bit RGBA); an error for any
/// format pelage cannot read back.
pub(crate) fn is_bgra(format: wgpu::TextureFormat) -> Result<bool, GpuError> {
    use wgpu::TextureFormat as F;
    match format {
        F::Rgba8UnormSrgb | F::Rgba8Unorm => Ok(false),
        F::Bgra8UnormSrgb | F::Bgra8Unorm => Ok(true),
        format => Err(GpuError::Format(format!("{format:?}"))),
    }
}

//! The depth pyramid of a light's shadow map (`depth_pyramid.wgsl`): what
//! the penumbra classification of a light with an area reads
//! (`penumbra_classify.wgsl`), to bound in a few loads which casters the map holds
//! near a receiver's cone to the light. Level m of the pyramid covers the map in
//! squares of 2^(m+2) texels, every layer (a cascade, a cube face), down to one
//! texel; its side is a power of two, so that every level halves the one before
//! and a square of any level lies in one texel of every coarser one.

use crate::pool::{Binding, Pool, ViewKey};

/// The format of the pyramid's planes: a square's depth at its centre, its depth
/// per map texel along x and y, and the least residual below that plane.
pub(crate) const PLANES_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The format of the pyramid's ranges: a square's least and greatest depth.
pub(crate) const RANGES_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Float;

/// Map texels along each side of one texel of the pyramid's first level.
pub(crate) const FIRST_LEVEL_TEXELS: u32 = 4;

/// The shape of a map's pyramid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct PyramidLayout {
    /// The first level's side, in its texels: the least power of two covering the
    /// map's side over [`FIRST_LEVEL_TEXELS`].
    pub side: u32,
    /// Levels, down to one texel.
    pub levels: u32,
    /// The map's layers.
    pub layers: u32,
}

impl PyramidLayout {
    /// The pyramid of a map `resolution` texels a side with `layers` layers.
    pub fn of(resolution: u32, layers: u32) -> Self {
        let side = resolution.div_ceil(FIRST_LEVEL_TEXELS).next_power_of_two();
        Self { side, levels: side.ilog2() + 1, layers }
    }

    /// The texture's size.
    pub fn size(&self) -> wgpu::Extent3d {
        wgpu::Extent3d { width: self.side, height: self.side, depth_or_array_layers: self.layers }
    }

    /// Its usage: written level by level as storage, read by the mask pass, and
    /// copied out by the tests that check it.
    pub const USAGE: wgpu::TextureUsages = wgpu::TextureUsages::STORAGE_BINDING
        .union(wgpu::TextureUsages::TEXTURE_BINDING)
        .union(wgpu::TextureUsages::COPY_SRC);

    /// Its two textures, with every level.
    pub fn create(&self, device: &wgpu::Device) -> Pyramid {
        let texture = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: self.size(),
                mip_level_count: self.levels,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: Self::USAGE,
                view_formats: &[],
            })
        };
        Pyramid {
            planes: texture("depth pyramid, planes", PLANES_FORMAT),
            ranges: texture("depth pyramid, ranges", RANGES_FORMAT),
        }
    }
}

/// A pyramid's textures (`depth_pyramid.wgsl`): per square, its plane and least
/// residual, and its range of depths.
#[derive(Clone, Debug)]
pub(crate) struct Pyramid {
    pub planes: wgpu::Texture,
    pub ranges: wgpu::Texture,
}

/// How the pyramid's first level reads a map's depths (`PyramidParams` in
/// depth_pyramid.wgsl): a cube face's distance over `range` (`cube` 1) becomes
/// 1 − `near` / z, z along the face's axis.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct PyramidParams {
    pub cube: u32,
    pub range: f32,
    pub near: f32,
    pub _pad: u32,
}

/// What a pyramid is built from.
pub(crate) struct PyramidInput<'a> {
    /// The depth map, every layer.
    pub map: &'a wgpu::TextureView,
    pub params: PyramidParams,
    pub queue: &'a wgpu::Queue,
    pub layout: PyramidLayout,
}

/// The pyramid's two pipelines: the first level from the map, each next from the
/// one before.
pub(crate) struct PyramidPass {
    /// Nearest and clamped, for level 0's gathers of the map.
    gather: wgpu::Sampler,
    first_layout: wgpu::BindGroupLayout,
    next_layout: wgpu::BindGroupLayout,
    first: wgpu::ComputePipeline,
    next: wgpu::ComputePipeline,
}

/// Invocations of a workgroup along x and y (`@workgroup_size(8, 8, 1)`).
const GROUP_SIDE: u32 = 8;

impl PyramidPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let compute = wgpu::ShaderStages::COMPUTE;
        let entry =
            |binding, ty| wgpu::BindGroupLayoutEntry { binding, visibility: compute, ty, count: None };
        let array = wgpu::TextureViewDimension::D2Array;
        let written = |binding, format| {
            entry(
                binding,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format,
                    view_dimension: array,
                },
            )
        };
        let read = |binding, sample_type| {
            entry(
                binding,
                wgpu::BindingType::Texture { sample_type, view_dimension: array, multisampled: false },
            )
        };
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries })
        };
        let outputs = [written(3, PLANES_FORMAT), written(4, RANGES_FORMAT)];
        let params = entry(
            5,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
        );
        let sampler = entry(6, wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering));
        let first_layout = layout(
            "depth pyramid, first level",
            &[vec![read(0, wgpu::TextureSampleType::Depth), params, sampler], outputs.to_vec()].concat(),
        );
        let unfiltered = wgpu::TextureSampleType::Float { filterable: false };
        let next_layout = layout(
            "depth pyramid, next level",
            &[vec![read(1, unfiltered), read(2, unfiltered)], outputs.to_vec()].concat(),
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("depth pyramid"),
            source: wgpu::ShaderSource::Wgsl(depth_pyramid_wgsl().into()),
        });
        let pipeline = |layout: &wgpu::BindGroupLayout, entry_point: &str| {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry_point),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let first = pipeline(&first_layout, "cs_pyramid_first");
        let next = pipeline(&next_layout, "cs_pyramid_next");
        let gather = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("depth pyramid, gather"),
            ..Default::default()
        });
        Self { gather, first_layout, next_layout, first, next }
    }

    /// Records every level of `pyramid` (of `layout`) from the depth map `map` (all
    /// its layers, as a 2D array, read as `params` says) into one compute pass.
    pub fn record(
        &self,
        pool: &mut Pool,
        pass: &mut wgpu::ComputePass,
        input: PyramidInput,
        pyramid: &Pyramid,
    ) {
        let PyramidInput { map, params, queue, layout } = input;
        let params = pool.uniform(queue, "depth pyramid", &params);
        let levels_view = |pool: &mut Pool, texture: &wgpu::Texture, base_mip, mips| {
            Binding::View(pool.view(
                texture,
                ViewKey {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    base_mip,
                    mips: Some(mips),
                    ..Default::default()
                },
            ))
        };
        for level in 0..layout.levels {
            let mut bindings = vec![
                (3, levels_view(pool, &pyramid.planes, level, 1)),
                (4, levels_view(pool, &pyramid.ranges, level, 1)),
            ];
            let group = if level == 0 {
                pass.set_pipeline(&self.first);
                bindings.push((0, Binding::View(map.clone())));
                bindings.push((5, Binding::Buffer(params.clone())));
                bindings.push((6, Binding::Sampler(self.gather.clone())));
                pool.bind_group_numbered("depth pyramid, first level", &self.first_layout, bindings)
            } else {
                pass.set_pipeline(&self.next);
                // Every finer level, so that the shader knows which is the last.
                bindings.push((1, levels_view(pool, &pyramid.planes, 0, level)));
                bindings.push((2, levels_view(pool, &pyramid.ranges, 0, level)));
                pool.bind_group_numbered("depth pyramid, next level", &self.next_layout, bindings)
            };
            pass.set_bind_group(0, &group, &[]);
            let side = (layout.side >> level).max(1);
            let groups = side.div_ceil(GROUP_SIDE);
            pass.dispatch_workgroups(groups, groups, layout.layers);
        }
    }
}

/// `depth_pyramid.wgsl`, composed (it imports the generated constants).
pub(crate) fn depth_pyramid_wgsl() -> String {
    crate::passes::compose_wgsl(&[include_str!("depth_pyramid.wgsl")])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pyramid_covers_its_map_in_levels_that_halve_down_to_one_texel() {
        for (resolution, side, levels) in [(2048, 512, 10), (256, 64, 7), (1000, 256, 9), (8192, 2048, 12)] {
            let layout = PyramidLayout::of(resolution, 6);
            assert_eq!((layout.side, layout.levels), (side, levels), "{resolution}");
            assert!(layout.side * FIRST_LEVEL_TEXELS >= resolution);
            assert_eq!(layout.side >> (layout.levels - 1), 1);
        }
    }
}

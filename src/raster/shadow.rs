//! Shadow maps: how a rasterizer's lights reach surfaces, six 90° faces per point light and an
//! orthographic map per directional light, rendered once per scene.

use bytemuck::Zeroable;
use glam::{DMat3, DMat4, DVec3, DVec4};

use super::{NEAR, columns, depth_attachment, extent, perspective, raster_pipeline, view};
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, bind_group, layer_view, texture_array};
use crate::shared::{FACES, LIGHT_KINDS, ShadowView};
use crate::trace::{GpuScene, surface_constants};

/// The shadow maps of a scene's lights: a depth texture array with [`GpuScene::shadow_layers`]
/// layers of `size`², rendered once (lights and geometry do not move), read through a
/// comparison sampler.
pub struct ShadowMaps {
    size: u32,
    views: Vec<ShadowView>,
    pub(super) lookup_layout: wgpu::BindGroupLayout,
    pub(super) lookup: wgpu::BindGroup,
}

impl ShadowMaps {
    /// The layers' views: for a point light, its six faces in [`FACES`] order (world axes) as
    /// 90° perspectives; for a directional light, an orthographic view along it that covers
    /// the scene's bounding box.
    fn layer_views(scene: &GpuScene, size: u32) -> Vec<ShadowView> {
        let near = NEAR * extent(scene);
        let mut out = Vec::new();
        for light in &scene.lights {
            let vector = DVec3::from(light.vector.map(f64::from));
            if light.kind == LIGHT_KINDS[0].1 {
                for face in &FACES {
                    out.push(ShadowView {
                        clip: columns(perspective(1.0, near) * view(face.rotation(), vector)),
                        texel: [2.0 / size as f32, 0.0, 0.0, 0.0],
                    });
                }
            } else {
                out.push(Self::directional(scene, vector, size));
            }
        }
        out
    }

    /// An orthographic map looking along `travel` over the scene's bounds, square texels,
    /// depth 1 nearest the light.
    fn directional(scene: &GpuScene, travel: DVec3, size: u32) -> ShadowView {
        let forward = travel.normalize();
        let right = forward.any_orthonormal_vector();
        let rotation = DMat3::from_cols(right, forward.cross(right), forward);
        let to_light = view(rotation, DVec3::ZERO);
        let (lo, hi) = scene.bounds.unwrap_or((DVec3::ZERO, DVec3::ZERO));
        let (mut a, mut b) = (DVec3::MAX, DVec3::MIN);
        for i in 0..8 {
            let corner = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let p = to_light.transform_point3(corner);
            (a, b) = (a.min(p), b.max(p));
        }
        // A margin, so that nothing on the bounds is clipped.
        let margin = 0.01 * (b - a).max_element() + f64::MIN_POSITIVE;
        let (a, b) = (a - margin, b + margin);
        let half = 0.5 * (b.x - a.x).max(b.y - a.y);
        let centre = 0.5 * (a + b);
        let ortho = DMat4::from_cols(
            DVec4::new(1.0 / half, 0.0, 0.0, 0.0),
            DVec4::new(0.0, -1.0 / half, 0.0, 0.0),
            DVec4::new(0.0, 0.0, -1.0 / (b.z - a.z), 0.0),
            DVec4::new(-centre.x / half, centre.y / half, b.z / (b.z - a.z), 1.0),
        );
        ShadowView {
            clip: columns(ortho * to_light),
            texel: [(2.0 * half / f64::from(size)) as f32, 0.0, 0.0, 0.0],
        }
    }

    /// Renders the shadow maps of `scene`'s lights at `size`² texels per layer.
    pub fn new(ctx: &GpuContext, scene: &GpuScene, size: u32) -> Result<Self> {
        let limits = ctx.device.limits();
        if size == 0 || size > limits.max_texture_dimension_2d {
            return Err(Error::Limit(format!(
                "shadow map size {size}: must be between 1 and the adapter's limit of {}",
                limits.max_texture_dimension_2d
            )));
        }
        if scene.shadow_layers > limits.max_texture_array_layers {
            return Err(Error::Limit(format!(
                "{} lights need {} shadow-map layers (6 per point light, 1 per sun); the \
                 adapter allows {}",
                scene.lights.len(),
                scene.shadow_layers,
                limits.max_texture_array_layers
            )));
        }
        let views = Self::layer_views(scene, size);
        ctx.checked("rendering the shadow maps", || {
            let device = &ctx.device;
            let layers = scene.shadow_layers.max(1);
            let texture = texture_array(
                device,
                "fisheye.raster.shadow_map",
                size,
                layers,
                wgpu::TextureFormat::Depth32Float,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let placeholder = [ShadowView::zeroed()];
            let data = if views.is_empty() {
                &placeholder[..]
            } else {
                &views[..]
            };
            let buffer = crate::gpu::buffer_init(
                device,
                "fisheye.raster.shadow_views",
                bytemuck::cast_slice(data),
                wgpu::BufferUsages::STORAGE,
            );
            let views_entry = wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: crate::gpu::ALL_STAGES,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            };
            let lookup_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.raster.shadow_lookup"),
                entries: &[
                    views_entry,
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: crate::gpu::ALL_STAGES,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Depth,
                            view_dimension: wgpu::TextureViewDimension::D2Array,
                            multisampled: false,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: crate::gpu::ALL_STAGES,
                        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                        count: None,
                    },
                ],
            });
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("fisheye.raster.shadow_sampler"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                // Reversed depth: lit where the point is at least as near the light as the map.
                compare: Some(wgpu::CompareFunction::GreaterEqual),
                ..Default::default()
            });
            let array = layer_view(&texture, None);
            let lookup = bind_group(
                device,
                "fisheye.raster.shadow_lookup",
                &lookup_layout,
                [
                    buffer.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&array),
                    wgpu::BindingResource::Sampler(&sampler),
                ],
            );
            // The depth pass sees the views only (the map is its attachment).
            let render_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.raster.shadow_render"),
                entries: &[views_entry],
            });
            let render_group = bind_group(
                device,
                "fisheye.raster.shadow_render",
                &render_layout,
                [buffer.as_entire_binding()],
            );
            let empty = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.raster.empty"),
                entries: &[],
            });
            let pipeline = raster_pipeline(
                device,
                &scene.arrays,
                &surface_constants(scene.features),
                &[&empty, &scene.layout, &render_layout],
                "raster",
                ("shadow_vs", None),
                None,
            );
            let no_bindings = bind_group(device, "fisheye.raster.empty", &empty, []);
            let mut encoder = device.create_command_encoder(&Default::default());
            for layer in 0..scene.shadow_layers {
                let target = layer_view(&texture, Some(layer));
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("fisheye.raster.shadow"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(depth_attachment(&target)),
                    ..Default::default()
                });
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &no_bindings, &[]);
                pass.set_bind_group(1, &scene.bind_group, &[]);
                pass.set_bind_group(2, &render_group, &[]);
                pass.draw(0..3 * scene.triangles, layer..layer + 1);
            }
            ctx.queue.submit([encoder.finish()]);
            Self {
                size,
                views,
                lookup_layout,
                lookup,
            }
        })
    }

    /// Texels per side of each layer.
    pub fn size(&self) -> u32 {
        self.size
    }

    /// The layers' views (tests check them against the lights).
    pub fn views(&self) -> &[ShadowView] {
        &self.views
    }
}

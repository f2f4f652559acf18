//! Rasterized cube faces: the classic way engines make fisheye images, with wgpu render
//! pipelines, so that [`crate::cube::CubeMap`] can compare it with direct ray tracing.
//!
//! The scene's triangles are drawn straight from the tracer's buffers by vertex pulling (no
//! vertex buffer), and shaded by the same WGSL as the tracer's (`wgsl/surface.wgsl`), in three
//! ways ([`RasterMethod`]): forward (one render pass per face, lighting in the fragment
//! shader), deferred (per face a G-buffer pass, then one compute pass that lights only the
//! visible surfaces) and single pass (all faces in one multiview render pass).
//!
//! What a rasterizer cannot do, it does not, and that is part of what the comparison shows:
//! - Lights reach surfaces through shadow maps ([`ShadowMaps`]: six faces per point light, an
//!   orthographic map per directional light), filtered over 2×2 texels, so shadow edges are
//!   softened and shifted by about a texel where the tracer's shadow rays are exact.
//! - Mirrors and glass reflect and transmit the sky (as an engine's environment map would),
//!   weighted by their tint and Fresnel reflectance; they show no scene geometry.
//! - Partially transparent surfaces (`d` < 1) are drawn opaque, and cast full shadows.
//!
//! Faces are rendered as the tracer renders them: each is a 90° view plus a one-texel border,
//! with reversed depth and no far plane, at the same pixel centres, so on diffuse, unshadowed
//! surfaces both give the same texels (a test holds them to it).

mod shadow;

use std::num::NonZeroU32;

use bytemuck::Zeroable;
use glam::{DAffine3, DMat3, DMat4, DVec3, DVec4};

use crate::cube::faces::{Region, bordered, bordered_focal};
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, Span, bind_group, layer_view, texture_array};
use crate::scene::Camera;
use crate::shader;
use crate::shared::{FACES, WORKGROUP_2D};
pub use crate::shared::{ShadowView, Views};
use crate::trace::{GpuScene, surface_constants};
pub use shadow::ShadowMaps;

/// How [`RasterFaces`] renders the faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RasterMethod {
    /// One render pass per face, lighting in the fragment shader.
    Forward,
    /// Per face a G-buffer pass (triangle and barycentrics), then one compute pass that lights
    /// every visible surface once.
    Deferred,
    /// Every face in one multiview render pass, lighting in the fragment shader.
    SinglePass,
}

/// The near plane of every view, relative to the scene's size: with reversed f32 depth the
/// precision is relative, so it can be tiny (geometry nearer than this is clipped).
const NEAR: f64 = 1e-6;

/// Reversed-depth perspective with no far plane for a view whose image half-width is at
/// `x/z = 1/focal`: camera space (x right, y down, z forward) to clip space, depth `near / z`.
fn perspective(focal: f64, near: f64) -> DMat4 {
    DMat4::from_cols(
        DVec4::new(focal, 0.0, 0.0, 0.0),
        DVec4::new(0.0, -focal, 0.0, 0.0),
        DVec4::new(0.0, 0.0, 0.0, 1.0),
        DVec4::new(0.0, 0.0, near, 0.0),
    )
}

/// Scene space to the camera space of a view at `eye` whose axes (right, down, forward) are
/// the columns of `rotation`.
fn view(rotation: DMat3, eye: DVec3) -> DMat4 {
    let inverse = rotation.transpose();
    DMat4::from(DAffine3::from_mat3_translation(inverse, -(inverse * eye)))
}

fn columns(m: DMat4) -> [f32; 16] {
    m.as_mat4().to_cols_array()
}

/// The scene's size, for near planes (1 for an empty scene).
fn extent(scene: &GpuScene) -> f64 {
    scene
        .bounds
        .map_or(1.0, |(lo, hi)| (hi - lo).length().max(f64::MIN_POSITIVE))
}

/// A depth attachment cleared to 0 (reversed depth: 0 is infinitely far).
fn depth_attachment(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(0.0),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// A render pipeline over the scene's triangles (no vertex buffers, no culling: the tracer
/// sees both sides), with reversed depth, specialised by `constants` (the scene's features).
/// `fragment` is the entry point and colour format, `None` for depth only.
fn raster_pipeline(
    device: &wgpu::Device,
    arrays: &crate::split::SceneArrays,
    constants: &[(&str, f64)],
    layouts: &[&wgpu::BindGroupLayout],
    file: &str,
    (vertex, multiview_mask): (&str, Option<NonZeroU32>),
    fragment: Option<(&str, wgpu::TextureFormat)>,
) -> wgpu::RenderPipeline {
    let module = shader::module(device, file, arrays);
    let options = wgpu::PipelineCompilationOptions {
        constants,
        ..Default::default()
    };
    let label = format!("fisheye.{file}.{vertex}");
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    });
    let targets = fragment.map(|(_, format)| [Some(wgpu::ColorTargetState::from(format))]);
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(&label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some(vertex),
            compilation_options: options.clone(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: fragment.map(|(entry, _)| wgpu::FragmentState {
            module: &module,
            entry_point: Some(entry),
            compilation_options: options,
            targets: targets.as_ref().expect("a colour target"),
        }),
        multiview_mask,
        cache: None,
    })
}

/// The rasterizer's half of the cube-map path: draws the faces that the lens reaches (only
/// their reachable regions, by scissor) into the cube's texture array of bordered faces, which
/// `wgsl/cube_sample.wgsl` resamples.
pub struct RasterFaces {
    method: RasterMethod,
    regions: [Option<Region>; 6],
    triangles: u32,
    sky: wgpu::Color,
    views: wgpu::Buffer,
    draw: wgpu::RenderPipeline,
    /// Per face (forward and deferred), or all faces (single pass): the cube or the G-buffer,
    /// and depth.
    targets: Vec<(wgpu::TextureView, wgpu::TextureView)>,
    draw_group: wgpu::BindGroup,
    /// The deferred lighting pass and its bind group.
    lighting: Option<(wgpu::ComputePipeline, wgpu::BindGroup)>,
    side: u32,
    shadows: ShadowMaps,
    multiview_mask: Option<NonZeroU32>,
}

impl RasterFaces {
    /// Faces of `size` texels (plus the border), rendered by `method` where `regions` says,
    /// into `cube` (an `Rgba32Float` array of six bordered faces); shadow maps of
    /// `shadow_size`².
    pub fn new(
        ctx: &GpuContext,
        scene: &GpuScene,
        size: u32,
        regions: [Option<Region>; 6],
        method: RasterMethod,
        shadow_size: u32,
        cube: &wgpu::Texture,
    ) -> Result<Self> {
        if scene.features.instanced {
            return Err(Error::Scene(
                "the rasterizer draws flat scenes: upload a flattened copy \
                 (`Scene::flattened`) for it"
                    .into(),
            ));
        }
        let mut multiview_mask = None;
        if method == RasterMethod::SinglePass {
            if !ctx.has(wgpu::Features::MULTIVIEW) {
                return Err(Error::MissingFeature {
                    what: "the single-pass cube (wgpu has no geometry shaders)",
                    feature: "MULTIVIEW",
                    adapter: ctx.adapter_info().name,
                });
            }
            let views = ctx.device.limits().max_multiview_view_count;
            if views < 6 {
                return Err(Error::Gpu {
                    during: "creating the single-pass cube".into(),
                    message: format!("multiview allows {views} views here, and a cube has 6"),
                });
            }
            // Only the faces the lens reaches, where the adapter can skip views.
            let mut mask = 0b11_1111;
            if ctx.has(wgpu::Features::SELECTIVE_MULTIVIEW) {
                mask = regions
                    .iter()
                    .enumerate()
                    .filter(|(_, r)| r.is_some())
                    .fold(0, |m, (i, _)| m | 1 << i);
            }
            multiview_mask = NonZeroU32::new(mask);
        }
        let shadows = ShadowMaps::new(ctx, scene, shadow_size)?;
        let side = bordered(size);
        ctx.checked("creating the rasterized cube faces", || {
            let device = &ctx.device;
            let texture = |label: &str, format: wgpu::TextureFormat| {
                texture_array(
                    device,
                    label,
                    side,
                    6,
                    format,
                    wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                )
            };
            let depth = texture("fisheye.raster.depth", wgpu::TextureFormat::Depth32Float);
            // Forward passes draw into the cube itself; the deferred G-buffer is its own.
            let gbuffer = (method == RasterMethod::Deferred)
                .then(|| texture("fisheye.raster.gbuffer", wgpu::TextureFormat::Rgba32Uint));
            let colour = gbuffer.as_ref().unwrap_or(cube);
            let targets = match method {
                RasterMethod::SinglePass => {
                    vec![(layer_view(colour, None), layer_view(&depth, None))]
                }
                _ => (0..6)
                    .map(|f| (layer_view(colour, Some(f)), layer_view(&depth, Some(f))))
                    .collect(),
            };
            let views = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fisheye.raster.views"),
                size: std::mem::size_of::<Views>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let entry = |binding: u32, ty: wgpu::BindingType| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: crate::gpu::ALL_STAGES,
                ty,
                count: None,
            };
            let views_entry = entry(
                0,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            );
            let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.raster.draw"),
                entries: &[views_entry],
            });
            let draw_group = bind_group(
                device,
                "fisheye.raster.draw",
                &draw_layout,
                [views.as_entire_binding()],
            );
            let constants = surface_constants(scene.features);
            // Deferred lighting: reads the G-buffer, writes the cube.
            let lighting = gbuffer.as_ref().map(|gbuffer| {
                let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("fisheye.raster.lighting"),
                    entries: &[
                        views_entry,
                        entry(
                            1,
                            wgpu::BindingType::Texture {
                                sample_type: wgpu::TextureSampleType::Uint,
                                view_dimension: wgpu::TextureViewDimension::D2Array,
                                multisampled: false,
                            },
                        ),
                        wgpu::BindGroupLayoutEntry {
                            visibility: wgpu::ShaderStages::COMPUTE,
                            ..entry(
                                2,
                                wgpu::BindingType::StorageTexture {
                                    access: wgpu::StorageTextureAccess::WriteOnly,
                                    format: wgpu::TextureFormat::Rgba32Float,
                                    view_dimension: wgpu::TextureViewDimension::D2Array,
                                },
                            )
                        },
                    ],
                });
                let (read, write) = (layer_view(gbuffer, None), layer_view(cube, None));
                let group = bind_group(
                    device,
                    "fisheye.raster.lighting",
                    &layout,
                    [
                        views.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&read),
                        wgpu::BindingResource::TextureView(&write),
                    ],
                );
                let pipeline = shader::scene_pipeline(
                    device,
                    "raster",
                    (&scene.arrays, &[]),
                    "deferred_lighting",
                    &constants,
                    &[&layout, &scene.layout, &shadows.lookup_layout],
                );
                (pipeline, group)
            });
            let lit = [&draw_layout, &scene.layout, &shadows.lookup_layout];
            let (file, vertex, fragment, layouts) = match method {
                RasterMethod::Forward => ("raster", "face_vs", "forward_fs", &lit[..]),
                RasterMethod::Deferred => ("raster", "face_vs", "gbuffer_fs", &lit[..2]),
                RasterMethod::SinglePass => {
                    ("raster_multiview", "multiview_vs", "multiview_fs", &lit[..])
                }
            };
            let draw = raster_pipeline(
                device,
                &scene.arrays,
                &constants,
                layouts,
                file,
                (vertex, multiview_mask),
                Some((fragment, colour.format())),
            );
            Self {
                method,
                regions,
                triangles: scene.triangles,
                sky: scene_sky(scene),
                views,
                draw,
                targets,
                draw_group,
                lighting,
                side,
                shadows,
                multiview_mask,
            }
        })
    }

    /// The shadow maps in use.
    pub fn shadows(&self) -> &ShadowMaps {
        &self.shadows
    }

    /// How the faces are drawn.
    pub fn method(&self) -> RasterMethod {
        self.method
    }

    /// Points the faces at `pose` (the cube's orientation follows the camera's) for the frames
    /// encoded from now on.
    pub fn set_pose(&self, ctx: &GpuContext, scene: &GpuScene, pose: &Camera) {
        let size = self.side - 2;
        let near = NEAR * extent(scene);
        let eye = pose.position - scene.origin;
        let projection = perspective(bordered_focal(size), near);
        let rotation = pose.rotation();
        let mut views = Views::zeroed();
        for (i, face) in FACES.iter().enumerate() {
            views.clip[i] = columns(projection * view(rotation * face.rotation(), eye));
            if let Some(r) = self.regions[i] {
                views.regions[i] = [r.x0, r.y0, r.x1, r.y1];
            }
        }
        let e = eye.as_vec3();
        views.eye = [e.x, e.y, e.z, 1.0];
        ctx.queue
            .write_buffer(&self.views, 0, bytemuck::bytes_of(&views));
    }

    /// Begins a render pass into `colour` and `depth` with the pipeline and its bind groups.
    fn begin<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        (colour, depth): &(wgpu::TextureView, wgpu::TextureView),
        scene: &GpuScene,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        let lit = self.method != RasterMethod::Deferred;
        // The G-buffer clears to 0 (no surface), colour to the sky.
        let clear = if lit {
            self.sky
        } else {
            wgpu::Color::TRANSPARENT
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("fisheye.raster.faces"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: colour,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(depth_attachment(depth)),
            multiview_mask: self.multiview_mask,
            timestamp_writes,
            ..Default::default()
        });
        pass.set_pipeline(&self.draw);
        pass.set_bind_group(0, &self.draw_group, &[]);
        pass.set_bind_group(1, &scene.bind_group, &[]);
        if lit {
            pass.set_bind_group(2, &self.shadows.lookup, &[]);
        }
        pass
    }

    /// Records the faces' render passes, timed as one span by `faces`, and for deferred faces
    /// the lighting pass, timed by `lighting`.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        faces: Option<Span<'_>>,
        lighting: Option<Span<'_>>,
    ) {
        let reached = || {
            self.regions
                .iter()
                .enumerate()
                .filter_map(|(i, r)| r.map(|r| (i as u32, r)))
        };
        let vertices = 0..3 * self.triangles;
        let scissor = |pass: &mut wgpu::RenderPass<'_>, r: Region| {
            pass.set_scissor_rect(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0);
        };
        if self.method == RasterMethod::SinglePass {
            // Timestamps inside a multiview pass take one query per view (Vulkan's
            // vkCmdWriteTimestamp), which wgpu does not allow for, so empty compute passes
            // around it take them.
            let marker = |encoder: &mut wgpu::CommandEncoder, first: bool| {
                if let Some(writes) = faces.and_then(|s| s.compute(first, !first)) {
                    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("fisheye.raster.timestamp"),
                        timestamp_writes: Some(writes),
                    });
                }
            };
            marker(encoder, true);
            let mut pass = self.begin(encoder, &self.targets[0], scene, None);
            let union = reached().map(|(_, r)| r).reduce(|a, b| Region {
                x0: a.x0.min(b.x0),
                y0: a.y0.min(b.y0),
                x1: a.x1.max(b.x1),
                y1: a.y1.max(b.y1),
            });
            if let Some(r) = union {
                scissor(&mut pass, r);
                pass.draw(vertices.clone(), 0..1);
            }
            drop(pass);
            marker(encoder, false);
        } else {
            let count = reached().count();
            for (k, (face, r)) in reached().enumerate() {
                let writes = faces.and_then(|s| s.render(k == 0, k + 1 == count));
                let target = &self.targets[face as usize];
                let mut pass = self.begin(encoder, target, scene, writes);
                scissor(&mut pass, r);
                pass.draw(vertices.clone(), face..face + 1);
            }
        }
        if let Some((pipeline, group)) = &self.lighting {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("fisheye.raster.lighting"),
                timestamp_writes: lighting.and_then(|s| s.compute(true, true)),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.set_bind_group(1, &scene.bind_group, &[]);
            pass.set_bind_group(2, &self.shadows.lookup, &[]);
            let tiles = self.side.div_ceil(WORKGROUP_2D);
            pass.dispatch_workgroups(tiles, tiles, 6);
        }
    }
}

fn scene_sky(scene: &GpuScene) -> wgpu::Color {
    let [r, g, b] = scene.sky.to_array().map(f64::from);
    wgpu::Color { r, g, b, a: 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_views_put_texel_centres_where_the_tracer_does() {
        // The bordered face camera of the tracer: pixel (i, j) of side N + 2 looks along
        // ((2 (i + 0.5) / (N + 2) - 1) / f, (2 (j + 0.5) / (N + 2) - 1) / f, 1) with
        // f = N / (N + 2). The raster view must put that direction at the same pixel centre.
        let size = 6;
        let side = f64::from(bordered(size));
        let f = bordered_focal(size);
        let m = perspective(f, 1e-3);
        for (i, j) in [(0.0, 0.0), (3.0, 5.0), (7.0, 7.0)] {
            let n = |k: f64| (2.0 * (k + 0.5) / side - 1.0) / f;
            let d = DVec3::new(n(i), n(j), 1.0) * 2.5;
            let clip = m * d.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            // wgpu's viewport: x right, y up in NDC, rows down in the framebuffer.
            let px = (ndc.x + 1.0) * 0.5 * side - 0.5;
            let py = (1.0 - ndc.y) * 0.5 * side - 0.5;
            assert!(
                (px - i).abs() < 1e-12 && (py - j).abs() < 1e-12,
                "{px} {py}"
            );
            // Reversed depth: near / z, in (0, 1].
            assert!((ndc.z - 1e-3 / 2.5).abs() < 1e-15);
        }
        // A view's camera space: the eye maps to the origin, its forward axis to +z.
        let rotation = FACES[0].rotation();
        let eye = DVec3::new(1.0, 2.0, 3.0);
        let v = view(rotation, eye);
        assert!(v.transform_point3(eye).length() < 1e-15);
        let ahead = v.transform_point3(eye + FACES[0].forward.as_dvec3());
        assert!((ahead - DVec3::Z).length() < 1e-15);
    }
}

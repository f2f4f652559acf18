//! The ray tracer: a scene on the GPU ([`GpuScene`], built and uploaded once), the trace pass
//! for a lens and image size ([`TracePass`]), and [`render`], which does both in one call.
//! `cpu` holds the f64 reference the GPU output is tested against; `cast` casts arbitrary rays
//! with the same traversal.

pub mod cast;
pub mod cpu;
mod display;
mod output;
mod ray_query;
pub mod sampling;

use bytemuck::Pod;
use glam::{DMat3, DVec3, Vec3};

pub use display::{
    ColourFile, Display, MASKED_RGB, Tone, colour_image, colour_image_with, linear_to_srgb,
    refuse_non_regular, save_png, write_atomically, write_colour, write_file,
};
pub use output::{Channel, RenderOutput, Values};
pub use ray_query::RayQueryScene;

pub use crate::shared::{
    Frame, GpuLight, GpuMaterial, LIGHT_KINDS, MAX_DEPTH_LIMIT, MAX_SHADOW_LAYERS, NO_HIT,
    NO_TEXTURE, Shading,
};

use crate::bvh::{BvhQuality, SceneBvh};
use crate::error::{Error, Result};
use crate::gpu::{
    GpuContext, bind_buffers, bind_group, dispatch_over_image, storage_entry, uniform_entry,
};
use crate::lens::LensCamera;
use crate::lens::gpu::{DirectionSource, LensRays, lens_constants, params_buffer};
use crate::scene::{Camera, Features, Scene, Surface};
use crate::shader;
use crate::shared::TRACE_STORAGE_BUFFERS;
use crate::split::{SceneArrays, Split};

/// Bytes between the frame uniforms of a [`TracePass`]'s views: wgpu's default (and largest)
/// `min_uniform_buffer_offset_alignment`.
const FRAME_SLOT: u64 = 256;

/// The WGSL id of a surface kind.
pub fn surface_id(surface: Surface) -> u32 {
    match surface {
        Surface::Diffuse => crate::shared::SURFACE_DIFFUSE,
        Surface::Mirror => crate::shared::SURFACE_MIRROR,
        Surface::Glass => crate::shared::SURFACE_GLASS,
    }
}

/// How to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Deepest reflection/refraction (0: primary rays and shadows only).
    pub max_depth: u32,
    /// BVH build preset.
    pub bvh: BvhQuality,
    /// Where primary ray directions come from.
    pub directions: DirectionSource,
    /// How rays find their hits.
    pub traversal: Traversal,
    /// Rays per pixel (a square: jittered stratified samples, box-filtered; see
    /// [`sampling`]). Ground-truth outputs stay the one ray through the pixel's centre.
    pub spp: u32,
}

/// How the tracer's rays find their hits; lens and shading code are the same for both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Traversal {
    /// The obvhs CWBVH, traversed in WGSL (`wgsl/bvh.wgsl`): runs on any adapter.
    #[default]
    Software,
    /// Hardware ray queries over an acceleration structure built by the driver
    /// (`wgsl/bvh_rq.wgsl`); needs `Features::EXPERIMENTAL_RAY_QUERY`.
    RayQuery,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            max_depth: 5,
            bvh: BvhQuality::default(),
            directions: DirectionSource::Computed,
            traversal: Traversal::Software,
            spp: 1,
        }
    }
}

fn to3(v: glam::Vec3) -> [f32; 3] {
    v.to_array()
}

/// Per stored triangle: vertex normals when smooth, UVs when textured, as `vec4<f32>`s.
pub fn shading_vertices(scene: &Scene, features: Features) -> Vec<[f32; 4]> {
    let stored = scene.triangles.len();
    let mut out = Vec::with_capacity(stored * shading_vectors_per_triangle(features));
    for i in 0..stored {
        if features.smooth_normals {
            let n = scene.normals.as_ref().expect("smooth normals")[i];
            out.extend(n.map(|n| [n.x, n.y, n.z, 0.0]));
        }
        if features.textures {
            let t = scene.uvs.as_ref().expect("textures need UVs")[i];
            out.push([t[0].x, t[0].y, t[1].x, t[1].y]);
            out.push([t[2].x, t[2].y, 0.0, 0.0]);
        }
    }
    out
}

/// The scene's lights as the GPU reads them, relative to `origin`, and the shadow-map layers
/// they need (see [`GpuLight::shadow_layer`]). Errors if a light's position, direction or
/// colour does not survive the rounding to f32.
pub fn gpu_lights(scene: &Scene, origin: DVec3) -> Result<(Vec<GpuLight>, u32)> {
    let mut shadow_layers = 0;
    let mut lights = Vec::new();
    for (i, light) in scene.lights.iter().enumerate() {
        let (point, vector, colour) = light.relative_to(origin);
        // A point light may sit at the camera; a direction must not vanish.
        if !(vector.is_finite() && (point || vector != Vec3::ZERO) && colour.is_finite()) {
            return Err(Error::Scene(format!(
                "light {} ({light:?}) is beyond the f32 range the GPU computes in, relative \
                 to the camera at {origin}",
                i + 1
            )));
        }
        lights.push(GpuLight {
            vector: vector.to_array(),
            kind: LIGHT_KINDS[usize::from(!point)].1,
            colour: to3(colour),
            shadow_layer: shadow_layers,
        });
        shadow_layers += if point { 6 } else { 1 };
    }
    Ok((lights, shadow_layers))
}

/// How many `vec4<f32>` of [`shading_vertices`] each triangle has.
fn shading_vectors_per_triangle(f: Features) -> usize {
    3 * usize::from(f.smooth_normals) + 2 * usize::from(f.textures)
}

/// Refuses a scene whose textures would not fit one storage binding of the adapter, with the
/// numbers, before the BVH is built for nothing. (Triangles, nodes and shading data are split
/// across as many bindings as they need: [`check_bindings`].)
fn check_textures(ctx: &GpuContext, scene: &Scene, features: Features) -> Result<()> {
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    let texels: u64 = scene
        .textures
        .iter()
        .filter(|_| features.textures)
        .map(|t| 4 * u64::from(t.width) * u64::from(t.height))
        .sum();
    if texels > limit {
        return Err(Error::Limit(format!(
            "the scene's {} textures take {:.1} MiB, above this adapter's limit of {:.0} MiB \
             per storage binding; use smaller textures",
            scene.textures.len(),
            mib(texels),
            mib(limit)
        )));
    }
    Ok(())
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / f64::from(1 << 20)
}

/// Refuses a scene whose arrays, split as `arrays` says, need more storage bindings than a
/// kernel of the device may have (those of the trace kernel's other group counted), with the
/// numbers. `triangles` counts the scene's stored triangles, for the message.
fn check_bindings(ctx: &GpuContext, arrays: &SceneArrays, triangles: u64) -> Result<()> {
    let limits = ctx.device.limits();
    let needed = TRACE_STORAGE_BUFFERS + arrays.extra_bindings();
    let has = limits.max_storage_buffers_per_shader_stage;
    if needed > has {
        return Err(Error::Limit(format!(
            "{triangles} triangles are too many for this device: split into storage bindings of \
             at most {:.2} MiB, their nodes, triangles and shading data take {}, {} and {} \
             bindings, and the trace kernel would bind {needed} storage buffers, above the \
             device's limit of {has} per shader stage (a device with more storage buffers or \
             larger bindings takes the scene)",
            mib(limits.max_storage_buffer_binding_size),
            arrays.nodes.chunks,
            arrays.triangles.chunks,
            arrays.vertices.chunks,
        )));
    }
    Ok(())
}

/// Storage buffers holding `data` in the chunks `split` says, or one zero element where
/// `data` is empty (bindings may not be empty), each checked against the binding limit.
fn chunked_storage<T: Pod>(
    ctx: &GpuContext,
    label: &str,
    data: &[T],
    split: &Split,
    extra: wgpu::BufferUsages,
) -> Result<Vec<wgpu::Buffer>> {
    split
        .ranges(data.len())
        .into_iter()
        .enumerate()
        .map(|(c, range)| storage_for(ctx, &format!("{label}.{c}"), &data[range], extra))
        .collect()
}

/// The overrides of `wgsl/surface.wgsl` for a scene's features: code for what the scene does
/// not use is dead.
pub fn surface_constants(f: Features) -> [(&'static str, f64); 5] {
    let flag = |b: bool| f64::from(u8::from(b));
    [
        ("HAS_MIRRORS", flag(f.mirrors)),
        ("HAS_GLASS", flag(f.glass)),
        ("HAS_TEXTURES", flag(f.textures)),
        ("SMOOTH_NORMALS", flag(f.smooth_normals)),
        ("INSTANCED", flag(f.instanced)),
    ]
}

/// The frame of `pose` for a scene uploaded relative to `origin`.
fn frame_for(origin: DVec3, pose: &Camera) -> Frame {
    view_frame(origin, pose.position, pose.rotation(), [0, 0])
}

/// `frame` for each band of output rows `(first row, rows)`: its dispatch starts at the
/// band's first row, and its outputs hold rows from there on (one band from row 0: the frame
/// itself).
fn band_frames(bands: &[(u32, u32)], frame: Frame) -> Vec<Frame> {
    bands
        .iter()
        .map(|&(first, _)| Frame {
            offset: [0, first, 0, first],
            ..frame
        })
        .collect()
}

/// The frame of an eye and a camera-to-world rotation for a scene uploaded relative to
/// `origin`.
fn view_frame(origin: DVec3, eye: DVec3, rotation: DMat3, offset: [u32; 2]) -> Frame {
    let col = |v: DVec3| {
        let v = v.as_vec3();
        [v.x, v.y, v.z, 0.0]
    };
    Frame {
        right: col(rotation.x_axis),
        down: col(rotation.y_axis),
        forward: col(rotation.z_axis),
        eye: col(eye - origin),
        offset: [offset[0], offset[1], 0, 0],
    }
}

/// A storage buffer holding `data`, or one zero element where `data` is empty (bindings may
/// not be empty), checked against the binding limit.
fn storage<T: Pod>(ctx: &GpuContext, label: &str, data: &[T]) -> Result<wgpu::Buffer> {
    storage_for(ctx, label, data, wgpu::BufferUsages::empty())
}

/// As [`storage`], with `extra` usages.
fn storage_for<T: Pod>(
    ctx: &GpuContext,
    label: &str,
    data: &[T],
    extra: wgpu::BufferUsages,
) -> Result<wgpu::Buffer> {
    let zero = [T::zeroed()];
    let data = if data.is_empty() { &zero[..] } else { data };
    let bytes: &[u8] = bytemuck::cast_slice(data);
    ctx.check_binding(label, bytes.len() as u64)?;
    Ok(crate::gpu::buffer_init(
        &ctx.device,
        label,
        bytes,
        wgpu::BufferUsages::STORAGE | extra,
    ))
}

/// A scene on the GPU: its BVH, triangles, materials, lights, shading data and textures, in
/// bind group 1 of the trace kernel. Built once; every frame reuses it.
pub struct GpuScene {
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) bind_group: wgpu::BindGroup,
    /// How the nodes, triangles and shading data are split across storage bindings; kernels
    /// that read the scene are composed for it.
    pub arrays: SceneArrays,
    /// What the scene uses; the trace kernel is specialised to it.
    pub features: Features,
    /// The world position the scene was made relative to (the camera's).
    pub origin: DVec3,
    /// Triangles stored (in BVH order on the GPU): the rasterizer draws `3 × triangles`
    /// vertices of a flat scene.
    pub triangles: u32,
    /// Scene triangles: the stored ones where the scene is flat, every instance's where it is
    /// not.
    pub scene_triangles: u64,
    /// The lights as uploaded.
    pub lights: Vec<GpuLight>,
    /// Layers the rasterizer's shadow maps need (see [`GpuLight::shadow_layer`]).
    pub shadow_layers: u32,
    /// The scene's bounding box relative to [`GpuScene::origin`] (`None` if empty).
    pub bounds: Option<(DVec3, DVec3)>,
    /// Radiance of escaping rays.
    pub sky: glam::Vec3,
    /// The BVH's statistics.
    pub bvh_nodes: usize,
    /// Deepest BVH node.
    pub bvh_depth: u32,
    /// obvhs's build time.
    pub bvh_build_time: std::time::Duration,
    /// The acceleration structure, with [`Traversal::RayQuery`].
    pub ray_query: Option<RayQueryScene>,
    /// What the scene's buffers hold on the device.
    pub bytes: SceneBytes,
    /// The camera-to-world rotation.
    frame: Frame,
}

/// The bytes a scene's buffers take on the device, by what they hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneBytes {
    /// The triangles the traversal tests (48 bytes each).
    pub geometry: u64,
    /// The BVH's nodes (80 bytes each, obvhs's CWBVH) and instances (144 bytes each).
    pub bvh: u64,
    /// Shading data: per-vertex normals and UVs, materials, lights.
    pub shading: u64,
    /// Texels and their table.
    pub textures: u64,
}

impl SceneBytes {
    /// Everything but the textures, per triangle.
    pub fn per_triangle(&self, triangles: u32) -> f64 {
        (self.geometry + self.bvh + self.shading) as f64 / f64::from(triangles.max(1))
    }
}

impl GpuScene {
    /// Builds the BVH and uploads everything, relative to the scene camera's position.
    pub fn new(ctx: &GpuContext, scene: &Scene, options: &RenderOptions) -> Result<Self> {
        if options.max_depth > MAX_DEPTH_LIMIT {
            return Err(Error::Limit(format!(
                "max depth {} is above the limit of {MAX_DEPTH_LIMIT}",
                options.max_depth
            )));
        }
        if options.traversal == Traversal::RayQuery {
            RayQueryScene::check(ctx, scene.len() as u64)?;
        }
        // The driver's acceleration structure takes the scene flattened (its instancing is not
        // exposed through wgpu's ray queries here).
        let flat;
        let scene = if options.traversal == Traversal::RayQuery && scene.is_instanced() {
            flat = scene.flattened(usize::MAX)?;
            &flat
        } else {
            scene
        };
        let features = scene.features();
        check_textures(ctx, scene, features)?;
        let binding_limit = ctx.device.limits().max_storage_buffer_binding_size;
        let stored = scene.triangles.len() as u64;
        let vertex_vectors = stored * shading_vectors_per_triangle(features) as u64;
        // Before the build, with the triangles as they are stored (nodes and pre-splits not
        // yet known); after it, exactly.
        let plan =
            |nodes, triangles| SceneArrays::plan(binding_limit, nodes, triangles, vertex_vectors);
        check_bindings(ctx, &plan(0, stored), stored)?;
        let origin = scene.camera.position;
        let bvh = SceneBvh::build(scene, origin, options.bvh)?;
        let arrays = plan(bvh.nodes.len() as u64, bvh.triangles.len() as u64);
        check_bindings(ctx, &arrays, stored)?;
        let materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .map(|m| GpuMaterial {
                diffuse: to3(m.diffuse),
                surface: surface_id(m.surface),
                specular: to3(m.specular),
                shininess: m.shininess,
                emission: to3(m.emission),
                ior: m.ior,
                transmission: to3(m.transmission),
                texture: m.diffuse_texture.unwrap_or(NO_TEXTURE),
                opacity: m.opacity,
                pad: [0; 3],
            })
            .collect();
        let (lights, shadow_layers) = gpu_lights(scene, origin)?;
        let mut texture_info = Vec::new();
        let mut texels: Vec<u32> = Vec::new();
        if features.textures {
            for t in &scene.textures {
                texture_info.push([texels.len() as u32, t.width, t.height, 0]);
                texels.extend(bytemuck::cast_slice::<u8, u32>(&t.rgba));
            }
        }
        let shading = Shading {
            sky: to3(scene.sky),
            light_count: lights.len() as u32,
            ambient: to3(scene.ambient),
            max_depth: options.max_depth,
        };
        let frame = frame_for(origin, &scene.camera);

        let rq_input = if options.traversal == Traversal::RayQuery {
            wgpu::BufferUsages::BLAS_INPUT
        } else {
            wgpu::BufferUsages::empty()
        };
        let none = wgpu::BufferUsages::empty();
        let nodes = chunked_storage(
            ctx,
            "fisheye.scene.bvh_nodes",
            &bvh.nodes,
            &arrays.nodes,
            none,
        )?;
        let triangles = chunked_storage(
            ctx,
            "fisheye.scene.triangles",
            &bvh.triangles,
            &arrays.triangles,
            rq_input,
        )?;
        let vertices = chunked_storage(
            ctx,
            "fisheye.scene.vertex_data",
            &shading_vertices(scene, features),
            &arrays.vertices,
            none,
        )?;
        let materials = storage(ctx, "fisheye.scene.materials", &materials)?;
        let lights_buffer = storage(ctx, "fisheye.scene.lights", &lights)?;
        let texture_info = storage(ctx, "fisheye.scene.texture_info", &texture_info)?;
        let texels = storage(ctx, "fisheye.scene.texels", &texels)?;
        let instances = storage(ctx, "fisheye.scene.instances", &bvh.instances)?;
        let scene = ctx.checked("uploading the scene", || {
            let device = &ctx.device;
            let uniform = crate::gpu::buffer_init(
                device,
                "fisheye.scene.shading",
                bytemuck::bytes_of(&shading),
                wgpu::BufferUsages::UNIFORM,
            );
            // Binding order = @binding(n) order in wgsl/triangles.wgsl, wgsl/surface.wgsl and
            // the generated scene_arrays (`split::SceneArrays::bindings`: each array's first
            // chunk at 0, 1 and 4, the others from 9 on); the rasterizer reads them in its
            // vertex and fragment stages.
            let resources: Vec<&wgpu::Buffer> = [
                &nodes[0],
                &triangles[0],
                &materials,
                &lights_buffer,
                &vertices[0],
                &texture_info,
                &texels,
                &uniform,
                &instances,
            ]
            .into_iter()
            .chain(nodes[1..].iter())
            .chain(triangles[1..].iter())
            .chain(vertices[1..].iter())
            .collect();
            let mut entries: Vec<_> = (0..resources.len() as u32)
                .map(|b| storage_entry(b, true))
                .collect();
            entries[7] = uniform_entry(7);
            for entry in &mut entries {
                entry.visibility = crate::gpu::ALL_STAGES;
            }
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.scene"),
                entries: &entries,
            });
            let bind_group = bind_buffers(device, "fisheye.scene", &layout, &resources);
            let ray_query = (options.traversal == Traversal::RayQuery).then(|| {
                RayQueryScene::new(ctx, &triangles, &arrays.triangles, bvh.triangles.len())
            });
            let size =
                |buffers: &[wgpu::Buffer]| buffers.iter().map(wgpu::Buffer::size).sum::<u64>();
            let bytes = SceneBytes {
                // The instances' buffer holds one unused element in a flat scene.
                bvh: size(&nodes)
                    + (size_of::<crate::bvh::GpuInstance>() * bvh.instances.len()) as u64,
                geometry: size(&triangles),
                shading: materials.size() + lights_buffer.size() + size(&vertices),
                textures: texture_info.size() + texels.size(),
            };
            Self {
                layout,
                bind_group,
                arrays,
                features,
                triangles: scene.triangles.len() as u32,
                scene_triangles: scene.len() as u64,
                lights,
                shadow_layers,
                sky: scene.sky,
                ray_query,
                bounds: scene.bounds().map(|(lo, hi)| (lo - origin, hi - origin)),
                origin,
                bvh_nodes: bvh.nodes.len(),
                bvh_depth: bvh.depth,
                bvh_build_time: bvh.build_time,
                bytes,
                frame,
            }
        })?;
        // Surfaces a failed acceleration-structure build here rather than at the first frame.
        ctx.wait()?;
        Ok(scene)
    }
}

/// The trace kernel for one lens, image size and scene: owns its pipeline, its frame bind
/// group (group 0) and its outputs; records one frame per [`TracePass::encode`].
pub struct TracePass {
    pipeline: wgpu::ComputePipeline,
    /// One bind group per view, each with its slot of `frame`.
    bind_groups: Vec<wgpu::BindGroup>,
    /// The outputs the kernel writes: the whole image's, or one band's.
    colour: wgpu::Buffer,
    geometry: wgpu::Buffer,
    ids: wgpu::Buffer,
    frame: wgpu::Buffer,
    camera: LensCamera,
    /// The bands of rows traced one after another, `(first row, rows)`: one for an image
    /// whose outputs fit one storage binding.
    bands: Vec<(u32, u32)>,
    /// With several bands, the whole image's outputs, each band copied in after its dispatch.
    whole: Option<[wgpu::Buffer; 3]>,
}

impl TracePass {
    /// Creates the pipeline (specialised to the lens, direction source and the scene's
    /// features) and the output buffers; with [`DirectionSource::Table`] also computes the
    /// direction table once.
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
    ) -> Result<Self> {
        Self::with_views(ctx, camera, scene, source, 1, 1)
    }

    /// As [`TracePass::new`], with `spp` rays per pixel (a square; see [`sampling`]): the
    /// colour is their mean over those the lens covers, its `w` the covered share.
    pub fn supersampled(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        spp: u32,
    ) -> Result<Self> {
        let side = sampling::samples_per_side(spp)?;
        Self::with_views(ctx, camera, scene, source, 1, side)
    }

    /// As [`TracePass::new`], with `views` camera poses (numbered from 0) that can be set
    /// before one submission and traced in it, as the faces of a cube map are, and
    /// `samples_per_side`² rays per pixel.
    pub fn with_views(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        views: u32,
        samples_per_side: u32,
    ) -> Result<Self> {
        ctx.check_image(camera.size)?;
        let pixels = camera.size.pixels() as u64;
        let bands = output_bands(ctx, camera.size, views)?;
        // Rows in the largest band: what the kernel's outputs hold.
        let band_pixels = u64::from(camera.size.width) * u64::from(bands[0].1);
        let table = LensRays::for_source(ctx, camera, source)?;
        ctx.checked("creating the trace pass", || {
            let device = &ctx.device;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.trace.frame"),
                // Lens and table as wgsl/primary.wgsl declares them, then the frame.
                entries: &[
                    uniform_entry(0),
                    storage_entry(1, true),
                    uniform_entry(2),
                    storage_entry(3, false),
                    storage_entry(4, false),
                    storage_entry(5, false),
                ],
            });
            let mut constants = lens_constants(camera).to_vec();
            constants.extend(surface_constants(scene.features));
            constants.extend([
                ("DIRECTION_SOURCE", f64::from(source as u32)),
                ("SAMPLES_PER_SIDE", f64::from(samples_per_side)),
                (
                    "HAS_TRANSLUCENT",
                    f64::from(u8::from(scene.features.translucent)),
                ),
            ]);
            let mut layouts = vec![&layout, &scene.layout];
            let file = match &scene.ray_query {
                Some(rq) => {
                    layouts.push(&rq.layout);
                    "trace_rq"
                }
                None => "trace",
            };
            let pipeline =
                shader::scene_pipeline(device, file, &scene.arrays, "main", &constants, &layouts);
            let output = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | usage,
                    mapped_at_creation: false,
                })
            };
            let none = wgpu::BufferUsages::empty();
            let colour = output("fisheye.trace.colour", 16 * band_pixels, none);
            let geometry = output("fisheye.trace.geometry", 16 * band_pixels, none);
            let ids = output("fisheye.trace.ids", 4 * band_pixels, none);
            let whole = (bands.len() > 1).then(|| {
                let into = wgpu::BufferUsages::COPY_DST;
                [
                    output("fisheye.trace.colour.whole", 16 * pixels, into),
                    output("fisheye.trace.geometry.whole", 16 * pixels, into),
                    output("fisheye.trace.ids.whole", 4 * pixels, into),
                ]
            });
            // A slot per view, or per band (each band's frame starts at its first row).
            let frames = match bands.len() {
                1 => vec![scene.frame; views as usize],
                _ => band_frames(&bands, scene.frame),
            };
            let slots = frame_slots(&frames);
            let frame = crate::gpu::buffer_init(
                device,
                "fisheye.trace.frame",
                &slots,
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            );
            let placeholder = output("fisheye.trace.no_table", 16, none);
            let table = table.as_ref().map_or(&placeholder, |t| &t.directions);
            let lens = params_buffer(device, camera);
            let bind_groups = (0..frames.len() as u64)
                .map(|view| {
                    let slot = wgpu::BufferBinding {
                        buffer: &frame,
                        offset: view * FRAME_SLOT,
                        size: wgpu::BufferSize::new(size_of::<Frame>() as u64),
                    };
                    bind_group(
                        device,
                        "fisheye.trace.frame",
                        &layout,
                        [
                            lens.as_entire_binding(),
                            table.as_entire_binding(),
                            wgpu::BindingResource::Buffer(slot),
                            colour.as_entire_binding(),
                            geometry.as_entire_binding(),
                            ids.as_entire_binding(),
                        ],
                    )
                })
                .collect();
            Self {
                pipeline,
                bind_groups,
                colour,
                geometry,
                ids,
                frame,
                camera: *camera,
                bands,
                whole,
            }
        })
    }

    /// Moves the camera to `pose` for the frames encoded from now on (a camera path). The scene
    /// stays where it was uploaded, relative to its own camera, so poses far from it lose the
    /// precision that relative upload buys; paths through a scene are fine.
    pub fn set_pose(&self, ctx: &GpuContext, scene: &GpuScene, pose: &Camera) {
        let frames = band_frames(&self.bands, frame_for(scene.origin, pose));
        ctx.queue
            .write_buffer(&self.frame, 0, &frame_slots(&frames));
    }

    /// As [`TracePass::set_pose`] for view number `view` (see [`TracePass::with_views`]), with
    /// the camera-to-world rotation given (columns: the camera's right, down and forward axes
    /// in world space), and the first pixel that [`TracePass::encode_region`] traces.
    pub fn set_view(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        view: u32,
        eye: DVec3,
        rotation: DMat3,
        offset: [u32; 2],
    ) {
        let frame = view_frame(scene.origin, eye, rotation, offset);
        ctx.queue.write_buffer(
            &self.frame,
            u64::from(view) * FRAME_SLOT,
            bytemuck::bytes_of(&frame),
        );
    }

    /// Records a move of the camera to `pose` into `encoder`, for the frames recorded after
    /// it: a copy of the 80-byte frame from a new buffer, so frames recorded into one encoder
    /// may each have their own pose (see [`TracePass::set_pose`] for precision).
    pub fn encode_pose(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
    ) {
        let slots = frame_slots(&band_frames(&self.bands, frame_for(scene.origin, pose)));
        let staging = crate::gpu::buffer_init(
            device,
            "fisheye.trace.pose",
            &slots,
            wgpu::BufferUsages::COPY_SRC,
        );
        encoder.copy_buffer_to_buffer(&staging, 0, &self.frame, 0, slots.len() as u64);
    }

    /// The colour output of the last frame (as [`RenderOutput::colour`]), for passes that
    /// read it on the GPU.
    pub fn colour_buffer(&self) -> &wgpu::Buffer {
        self.buffers()[0]
    }

    /// The colour, geometry and id outputs of the last frame (as [`RenderOutput`] reads them).
    /// For an image traced in bands these are larger than one storage binding: bind a range.
    pub fn buffers(&self) -> [&wgpu::Buffer; 3] {
        match &self.whole {
            Some([colour, geometry, ids]) => [colour, geometry, ids],
            None => [&self.colour, &self.geometry, &self.ids],
        }
    }

    /// How many bands of rows a frame is traced in: 1 unless the image's outputs exceed one
    /// storage binding.
    pub fn bands(&self) -> usize {
        self.bands.len()
    }

    /// Records one frame, optionally timed: one dispatch, or one per band, each band's
    /// outputs copied into the whole image's after it (the timestamps span them all).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let Some(whole) = &self.whole else {
            self.encode_region(encoder, scene, 0, self.camera.size, timestamp_writes);
            return;
        };
        let width = self.camera.size.width;
        let last = self.bands.len() - 1;
        for (band, &(first, rows)) in self.bands.iter().enumerate() {
            let writes = timestamp_writes
                .as_ref()
                .filter(|_| band == 0 || band == last)
                .map(|w| wgpu::ComputePassTimestampWrites {
                    query_set: w.query_set,
                    beginning_of_pass_write_index: w
                        .beginning_of_pass_write_index
                        .filter(|_| band == 0),
                    end_of_pass_write_index: w.end_of_pass_write_index.filter(|_| band == last),
                });
            let extent = crate::lens::ImageSize::new(width, rows).expect("a band has rows");
            self.encode_region(encoder, scene, band as u32, extent, writes);
            let pixels = u64::from(width) * u64::from(rows);
            let from = u64::from(width) * u64::from(first);
            for (out, into, bytes) in [
                (&self.colour, &whole[0], 16),
                (&self.geometry, &whole[1], 16),
                (&self.ids, &whole[2], 4),
            ] {
                encoder.copy_buffer_to_buffer(out, 0, into, from * bytes, pixels * bytes);
            }
        }
    }

    /// Records a frame of view `view` of only the `extent` pixels from the offset given to
    /// [`TracePass::set_view`] (the whole image from a zero offset); the other pixels keep what
    /// they had.
    pub fn encode_region(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        view: u32,
        extent: crate::lens::ImageSize,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut groups = vec![&self.bind_groups[view as usize], &scene.bind_group];
        if let Some(rq) = &scene.ray_query {
            groups.push(&rq.bind_group);
        }
        dispatch_over_image(
            encoder,
            "fisheye.trace",
            &self.pipeline,
            &groups,
            extent,
            timestamp_writes,
        );
    }

    /// Traces one frame, reporting a GPU error as `what` failing, and reads it back.
    pub fn trace(&self, ctx: &GpuContext, scene: &GpuScene, what: &str) -> Result<RenderOutput> {
        ctx.checked(what, || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, scene, None);
            ctx.queue.submit([encoder.finish()]);
        })?;
        self.read(ctx)
    }

    /// Reads the last frame's outputs back.
    pub fn read(&self, ctx: &GpuContext) -> Result<RenderOutput> {
        let [colour, geometry, ids] = self.buffers();
        Ok(RenderOutput {
            size: self.camera.size,
            colour: ctx.read_buffer(colour)?,
            geometry: ctx.read_buffer(geometry)?,
            ids: ctx.read_buffer(ids)?,
        })
    }
}

/// The frames' bytes, each in its `FRAME_SLOT`.
fn frame_slots(frames: &[Frame]) -> Vec<u8> {
    frames
        .iter()
        .flat_map(|frame| {
            let mut slot = bytemuck::bytes_of(frame).to_vec();
            slot.resize(FRAME_SLOT as usize, 0);
            slot
        })
        .collect()
}

/// The bands of rows `(first row, rows)` a trace of `size` is dispatched in: one where the
/// colour and geometry outputs (16 bytes a pixel) fit one storage binding, else as many rows
/// a band as fit (only for a single view; a cube map's faces fit or are refused). The whole
/// image's outputs must still fit one buffer.
fn output_bands(
    ctx: &GpuContext,
    size: crate::lens::ImageSize,
    views: u32,
) -> Result<Vec<(u32, u32)>> {
    let limits = ctx.device.limits();
    let (width, height) = (size.width, size.height);
    let pixels = size.pixels() as u64;
    let row = 16 * u64::from(width);
    let rows = (limits.max_storage_buffer_binding_size / row).min(u64::from(height)) as u32;
    if rows == height {
        return Ok(vec![(0, height)]);
    }
    if views > 1 || rows == 0 {
        ctx.check_binding("the colour output", 16 * pixels)?;
    }
    if 16 * pixels > limits.max_buffer_size {
        return Err(Error::Limit(format!(
            "a {size} image's colour output needs a buffer of {:.1} MiB, above this adapter's \
             limit of {:.1} MiB per buffer; use a smaller image",
            (16 * pixels) as f64 / f64::from(1 << 20),
            limits.max_buffer_size as f64 / f64::from(1 << 20)
        )));
    }
    Ok((0..height)
        .step_by(rows as usize)
        .map(|first| (first, rows.min(height - first)))
        .collect())
}

/// The world-space direction of every pixel's ray (f64 lens model, rotated by the pose),
/// row-major, `None` where the lens masks the pixel.
pub fn world_directions(camera: &LensCamera, pose: &crate::scene::Camera) -> Vec<Option<DVec3>> {
    rotated(&camera.directions(), pose)
}

/// Camera-frame directions (as [`LensCamera::directions`] gives them, made once per camera)
/// turned into world space by `pose`.
pub fn rotated(directions: &[Option<DVec3>], pose: &crate::scene::Camera) -> Vec<Option<DVec3>> {
    let rotation = pose.rotation();
    directions.iter().map(|d| d.map(|d| rotation * d)).collect()
}

/// Renders `scene` through `camera` in one call: builds and uploads the scene, traces one
/// frame and reads it back.
pub fn render(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &LensCamera,
    options: &RenderOptions,
) -> Result<RenderOutput> {
    let gpu_scene = GpuScene::new(ctx, scene, options)?;
    let pass = TracePass::supersampled(ctx, camera, &gpu_scene, options.directions, options.spp)?;
    pass.trace(ctx, &gpu_scene, "tracing")
}

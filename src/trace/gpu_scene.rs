//! A scene on the GPU ([`GpuScene`]): its BVH, triangles, materials, lights, shading data and
//! textures uploaded once, split across storage bindings as needed, and what they cost
//! ([`SceneBytes`]).

use super::RayQueryScene;
use super::options::{RenderOptions, Traversal, surface_id};
use crate::bvh::SceneBvh;
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, bind_buffers, storage_entry, uniform_entry};
use crate::scene::{Camera, Features, Scene};
use crate::shared::TRACE_STORAGE_BUFFERS;
use crate::shared::{
    Frame, GpuLight, GpuMaterial, LIGHT_KINDS, LIGHT_VEC4S, MATERIAL_VEC4S, MAX_DEPTH_LIMIT,
    NO_TEXTURE, Shading,
};
use crate::split::{SceneArrays, Split};
use bytemuck::Pod;
use glam::{DMat3, DVec3, Vec3};

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

/// Refuses a scene whose records (its textures, with its instances, lights and materials:
/// one storage binding) would not fit one storage binding of the adapter, with the numbers,
/// before the BVH is built for nothing. (Triangles, nodes and shading vertices are split
/// across as many bindings as they need: [`check_bindings`]; moving instances' knots, known
/// once the BVH is, are checked with the upload.)
fn check_records(ctx: &GpuContext, scene: &Scene, features: Features) -> Result<()> {
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    let texels: u64 = scene
        .textures
        .iter()
        .filter(|_| features.textures)
        .map(|t| {
            let level_bytes =
                |k: u32| 4 * u64::from((t.width >> k).max(1)) * u64::from((t.height >> k).max(1));
            (0..super::mip_level_count(t)).map(level_bytes).sum::<u64>()
        })
        .sum();
    let others = size_of::<crate::bvh::GpuInstance>() * scene.instances.len()
        + size_of::<GpuLight>() * scene.lights.len()
        + size_of::<GpuMaterial>() * scene.materials.len();
    if texels + others as u64 > limit {
        return Err(Error::Limit(format!(
            "the scene's {} textures take {:.1} MiB with their mip levels, and with its instances, lights and \
             materials {:.1} MiB, above this adapter's limit of {:.0} MiB per storage binding, \
             which they share; use smaller textures",
            scene.textures.len(),
            mib(texels),
            mib(texels + others as u64),
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

/// A storage buffer holding `data`, or one zero element where `data` is empty (bindings may
/// not be empty), checked against the binding limit, with `extra` usages.
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
    /// The lights found to reach whole triangles, whose shadow rays shading skips.
    pub unshadowed: crate::bvh::unshadowed::Unshadowed,
    /// The acceleration structure, with [`Traversal::RayQuery`].
    pub ray_query: Option<RayQueryScene>,
    /// What the scene's buffers hold on the device.
    pub bytes: SceneBytes,
    /// The camera-to-world rotation.
    pub(super) frame: Frame,
    /// Where instances move: their top level, and the buffers [`GpuScene::place_at`] writes
    /// it to (the nodes' first chunk, the records, which begin with the instances).
    moving: Option<(crate::bvh::TopLevel, wgpu::Buffer, wgpu::Buffer)>,
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
        Self::upload(ctx, scene, options, true)
    }

    /// As [`GpuScene::new`], for a scene only the rasterized cube faces draw (they read
    /// shadow maps): no search for the lights that reach whole triangles
    /// ([`crate::bvh::unshadowed`]), which only shading by rays uses.
    pub fn for_rasterizer(
        ctx: &GpuContext,
        scene: &Scene,
        options: &RenderOptions,
    ) -> Result<Self> {
        Self::upload(ctx, scene, options, false)
    }

    fn upload(
        ctx: &GpuContext,
        scene: &Scene,
        options: &RenderOptions,
        shaded: bool,
    ) -> Result<Self> {
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
        check_records(ctx, scene, features)?;
        let binding_limit = ctx.device.limits().max_storage_buffer_binding_size;
        let stored = scene.triangles.len() as u64;
        let vertex_vectors = stored * shading_vectors_per_triangle(features) as u64;
        // Before the build, with the triangles as they are stored (nodes and pre-splits not
        // yet known); after it, exactly.
        let plan =
            |nodes, triangles| SceneArrays::plan(binding_limit, nodes, triangles, vertex_vectors);
        check_bindings(ctx, &plan(0, stored), stored)?;
        let origin = scene.camera.position;
        let bvh = SceneBvh::build(scene, origin, options.bvh, shaded)?;
        let arrays = plan(bvh.nodes.len() as u64, bvh.triangles.len() as u64);
        check_bindings(ctx, &arrays, stored)?;
        // The scene's records (`records` in wgsl/triangles.wgsl), in vec4s of words: the
        // instances, with room for every one to show at some time and for moving ones' knots;
        // the lights; the materials; the textures' texels one after another, each texture's
        // mip levels after it.
        let mut records: Vec<[u32; 4]> = bytemuck::cast_slice(&bvh.instances).to_vec();
        if let Some(top) = &bvh.top {
            let knots = top.knot_capacity(scene) as u32 * crate::shared::KNOT_VEC4S;
            records.resize((top.knots_at() + knots) as usize, [0; 4]);
        }
        let instance_bytes = 16 * records.len() as u64;
        let (lights, shadow_layers) = gpu_lights(scene, origin)?;
        let lights_at = records.len() as u32;
        let materials_at = lights_at + LIGHT_VEC4S * lights.len() as u32;
        let texels_at = 4 * (materials_at + MATERIAL_VEC4S * scene.materials.len() as u32);
        let mut texels: Vec<u32> = Vec::new();
        let mut placed = Vec::new();
        if features.textures {
            for t in &scene.textures {
                let levels = super::mip_level_count(t);
                placed.push((texels_at + texels.len() as u32, t.width, t.height, levels));
                texels.extend(bytemuck::cast_slice::<u8, u32>(&t.rgba));
                for level in super::mip_levels(t) {
                    texels.extend(bytemuck::cast_slice::<u8, u32>(&level.rgba));
                }
            }
        }
        let materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .map(|m| {
                let (texture, texture_width, texture_height, texture_levels) = m
                    .diffuse_texture
                    .and_then(|t| placed.get(t as usize).copied())
                    .unwrap_or((NO_TEXTURE, 0, 0, 0));
                GpuMaterial {
                    diffuse: to3(m.diffuse),
                    surface: surface_id(m.surface),
                    specular: to3(m.specular),
                    shininess: m.shininess,
                    emission: to3(m.emission),
                    ior: m.ior,
                    transmission: to3(m.transmission),
                    texture,
                    opacity: m.opacity,
                    texture_width,
                    texture_height,
                    texture_levels,
                }
            })
            .collect();
        records.extend_from_slice(bytemuck::cast_slice(&lights));
        records.extend_from_slice(bytemuck::cast_slice(&materials));
        let texel_bytes = 4 * texels.len() as u64;
        texels.resize(texels.len().next_multiple_of(4), 0);
        records.extend(texels.chunks_exact(4).map(|w| [w[0], w[1], w[2], w[3]]));
        let shading = Shading {
            sky: to3(scene.sky),
            light_count: lights.len() as u32,
            ambient: to3(scene.ambient),
            max_depth: options.max_depth,
            lights_at,
            materials_at,
            pad: [0; 2],
        };
        let frame = frame_for(origin, &scene.camera);

        let rq_input = if options.traversal == Traversal::RayQuery {
            wgpu::BufferUsages::BLAS_INPUT
        } else {
            wgpu::BufferUsages::empty()
        };
        let none = wgpu::BufferUsages::empty();
        // A moving scene's top level is rewritten at each time.
        let rewritten = match bvh.top {
            Some(_) => wgpu::BufferUsages::COPY_DST,
            None => none,
        };
        let nodes = chunked_storage(
            ctx,
            "fisheye.scene.bvh_nodes",
            &bvh.nodes,
            &arrays.nodes,
            rewritten,
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
        let records = storage_for(ctx, "fisheye.scene.records", &records, rewritten)?;
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
            // chunk at 0, 1 and 3, the others from 5 on); the rasterizer reads them in its
            // vertex and fragment stages.
            let resources: Vec<&wgpu::Buffer> =
                [&nodes[0], &triangles[0], &records, &vertices[0], &uniform]
                    .into_iter()
                    .chain(nodes[1..].iter())
                    .chain(triangles[1..].iter())
                    .chain(vertices[1..].iter())
                    .collect();
            let mut entries: Vec<_> = (0..resources.len() as u32)
                .map(|b| storage_entry(b, true))
                .collect();
            entries[4] = uniform_entry(4);
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
                bvh: size(&nodes) + instance_bytes,
                geometry: size(&triangles),
                shading: records.size() - instance_bytes - texel_bytes + size(&vertices),
                textures: texel_bytes,
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
                unshadowed: bvh.unshadowed,
                bytes,
                frame,
                moving: bvh.top.map(|top| (top, nodes[0].clone(), records.clone())),
            }
        })?;
        // Surfaces a failed acceleration-structure build here rather than at the first frame.
        ctx.wait()?;
        Ok(scene)
    }
}

impl GpuScene {
    /// Places `scene`'s moving instances (the scene this was made from) for the work
    /// submitted from now on: a frame at scene time `stamp` whose rays span `window` seconds
    /// from it ([`crate::lens::LensCamera::exposure_span`]; `(0, 0)` for an instant). The top
    /// level is rebuilt over them and written over the last, with moving instances' knots
    /// over the window; the meshes' BVHs stay as built. Nothing to do where nothing moves.
    pub fn place_at(
        &self,
        ctx: &GpuContext,
        scene: &Scene,
        stamp: f64,
        window: (f64, f64),
    ) -> Result<()> {
        if !scene.moves() {
            return Ok(());
        }
        // Only a scene flattened for ray queries moves without a top level.
        let Some((top, nodes, records)) = &self.moving else {
            return Err(Error::Limit(
                "moving instances are placed by the BVH traversal; ray queries take the scene \
                 flattened once (use the software traversal)"
                    .into(),
            ));
        };
        let built = top.build_over(scene, stamp, window, self.origin)?;
        ctx.queue
            .write_buffer(nodes, 0, bytemuck::cast_slice(&built.nodes));
        if !built.instances.is_empty() {
            ctx.queue
                .write_buffer(records, 0, bytemuck::cast_slice(&built.instances));
        }
        if !built.knots.is_empty() {
            let at = u64::from(top.knots_at()) * 16;
            ctx.queue
                .write_buffer(records, at, bytemuck::cast_slice(&built.knots));
        }
        Ok(())
    }
}

/// The frame of an eye and a camera-to-world rotation for a scene uploaded relative to
/// `origin`.
pub(super) fn view_frame(origin: DVec3, eye: DVec3, rotation: DMat3, offset: [u32; 2]) -> Frame {
    let col = |v: DVec3| {
        let v = v.as_vec3();
        [v.x, v.y, v.z, 0.0]
    };
    let mut frame: Frame = bytemuck::Zeroable::zeroed();
    frame.right = col(rotation.x_axis);
    frame.down = col(rotation.y_axis);
    frame.forward = col(rotation.z_axis);
    frame.eye = col(eye - origin);
    frame.offset = [offset[0], offset[1], 0, 0];
    // One knot at rest: a kernel that moves its camera keeps it still.
    frame.motion = [1, 0, 0, 0];
    frame.knots[0].rotation = [0.0, 0.0, 0.0, 1.0];
    frame
}

/// The frame of `pose` for a scene uploaded relative to `origin`.
pub(super) fn frame_for(origin: DVec3, pose: &Camera) -> Frame {
    view_frame(origin, pose.position, pose.rotation(), [0, 0])
}

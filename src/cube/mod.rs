//! The cube map around a camera: its six faces, which face and where on it a direction lands,
//! and bilinear sampling with a one-texel border so that filtering is correct across seams.
//!
//! The cube lives in the camera's space (x right, y down, z forward). Each face is a 90° view
//! with its own right, down and forward axes, all ±1 permutations of the camera's, so the face
//! coordinates of a direction are exact component selections: on the +z face
//! `uv = (d.xy / d.z + 1) / 2`. `wgsl/cube.wgsl` is the GPU twin; its face table is generated
//! from [`FACES`], and a test checks that both pick the same face and UV.

use glam::{DMat3, DVec3, Vec2, Vec3};

use crate::error::{Error, Result};
use crate::gpu::{
    GpuContext, Span, bind_buffers, bind_group, dispatch_over_image, layer_view, storage_entry,
    texture_array, uniform_entry,
};
use crate::lens::gpu::{DirectionSource, lens_constants, params_buffer};
use crate::lens::{ClassicLens, ImageSize, LensCamera, LensModel};
use crate::raster::{RasterFaces, RasterMethod};
use crate::scene::Camera;
use crate::shader;
use crate::trace::{GpuScene, TracePass};

/// One face of the cube: its name and its axes in camera space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    /// `+x`, `-x`, `+y`, `-y`, `+z`, `-z` (y is down: `+y` looks at the floor).
    pub name: &'static str,
    /// The face image's right (u) axis.
    pub right: Vec3,
    /// The face image's down (v) axis.
    pub down: Vec3,
    /// The axis the face looks along.
    pub forward: Vec3,
}

impl Face {
    /// Face-to-camera rotation: columns right, down, forward (a proper rotation).
    pub fn rotation(&self) -> DMat3 {
        DMat3::from_cols(
            self.right.as_dvec3(),
            self.down.as_dvec3(),
            self.forward.as_dvec3(),
        )
    }
}

/// The faces in id order: the axis of largest magnitude picks `2 · axis + (negative ? 1 : 0)`.
pub const FACES: [Face; 6] = [
    Face {
        name: "+x",
        right: Vec3::NEG_Z,
        down: Vec3::Y,
        forward: Vec3::X,
    },
    Face {
        name: "-x",
        right: Vec3::Z,
        down: Vec3::Y,
        forward: Vec3::NEG_X,
    },
    Face {
        name: "+y",
        right: Vec3::X,
        down: Vec3::NEG_Z,
        forward: Vec3::Y,
    },
    Face {
        name: "-y",
        right: Vec3::X,
        down: Vec3::Z,
        forward: Vec3::NEG_Y,
    },
    Face {
        name: "+z",
        right: Vec3::X,
        down: Vec3::Y,
        forward: Vec3::Z,
    },
    Face {
        name: "-z",
        right: Vec3::NEG_X,
        down: Vec3::Y,
        forward: Vec3::NEG_Z,
    },
];

/// The face a direction lands on, and its UV in [0, 1]² (u right, v down), in f32 as the GPU
/// computes it. The axis of largest magnitude wins; exact ties go to x over y over z, and a
/// zero component counts as positive. The zero vector maps to the centre of `+z`.
pub fn face_uv(d: Vec3) -> (u32, Vec2) {
    let a = d.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    if a[axis] == 0.0 {
        return (4, Vec2::splat(0.5));
    }
    let face = 2 * axis as u32 + u32::from(d[axis] < 0.0);
    let f = &FACES[face as usize];
    let major = d.dot(f.forward);
    let uv = (Vec2::new(d.dot(f.right), d.dot(f.down)) / major + 1.0) * 0.5;
    (face, uv)
}

/// The WGSL declaration of [`FACES`] as face-to-camera matrices (columns right, down,
/// forward), prepended to every module.
pub fn wgsl_faces() -> String {
    let v = |v: Vec3| format!("vec3<f32>({:.1}, {:.1}, {:.1})", v.x, v.y, v.z);
    let faces: Vec<String> = FACES
        .iter()
        .map(|f| {
            format!(
                "mat3x3<f32>({}, {}, {})",
                v(f.right),
                v(f.down),
                v(f.forward)
            )
        })
        .collect();
    format!(
        "const CUBE_FACES = array<mat3x3<f32>, 6>({});\n",
        faces.join(", ")
    )
}

/// Faces with a one-texel border: a face of `size` texels is stored as `(size + 2)²` texels,
/// the border holding the neighbouring faces' samples (rendered as directions just past the
/// edge), so that bilinear filtering near a seam reads real neighbours, never clamped ones.
pub fn bordered(size: u32) -> u32 {
    size + 2
}

/// The rectilinear focal length (in the lens module's normalized units, half-width = 1) of a
/// bordered face image: its inner `size` texels span exactly 90°.
pub fn bordered_focal(size: u32) -> f64 {
    f64::from(size) / f64::from(bordered(size))
}

/// Bilinear lookup of a bordered face at `uv`, as `wgsl/cube.wgsl` does: texels are
/// `texels[face][row][column]` of side `size + 2`, centres at `(i + 0.5) / size` past the border.
pub fn sample_bordered(texels: &[[f32; 4]], size: u32, face: u32, uv: Vec2) -> [f32; 4] {
    let side = bordered(size) as usize;
    let st = uv * size as f32 + 0.5;
    let base = st.floor();
    let f = st - base;
    let x = (base.x.max(0.0) as usize).min(side - 2);
    let y = (base.y.max(0.0) as usize).min(side - 2);
    let at = |x: usize, y: usize| texels[(face as usize * side + y) * side + x];
    let mix = |a: [f32; 4], b: [f32; 4], t: f32| std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t);
    let top = mix(at(x, y), at(x + 1, y), f.x);
    let bottom = mix(at(x, y + 1), at(x + 1, y + 1), f.x);
    mix(top, bottom, f.y)
}

/// A rectangle of a bordered face, in texels: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Region {
    /// Number of texels.
    pub fn texels(&self) -> u64 {
        u64::from(self.x1 - self.x0) * u64::from(self.y1 - self.y0)
    }
}

/// The part of each bordered face of `size` texels that sampling `directions` reads: the
/// bilinear footprints of every direction that lands on the face or within a small margin of
/// it, grown by one texel, so that the GPU's f32 directions (about 1e-7 rad from these f64
/// ones) never read a texel that was not rendered. `None` for faces nothing reaches.
pub fn face_regions(directions: impl IntoIterator<Item = DVec3>, size: u32) -> [Option<Region>; 6] {
    const MARGIN: f64 = 1e-4;
    let side = i64::from(bordered(size));
    let mut regions: [Option<Region>; 6] = [None; 6];
    for d in directions {
        for (i, f) in FACES.iter().enumerate() {
            let forward = d.dot(f.forward.as_dvec3());
            let (sc, tc) = (d.dot(f.right.as_dvec3()), d.dot(f.down.as_dvec3()));
            if forward <= 0.0 || forward * (1.0 + MARGIN) < sc.abs().max(tc.abs()) {
                continue;
            }
            // As `sample_bordered`: texels floor(st) and floor(st) + 1, clamped, then ±1.
            let texel = |c: f64| {
                let st = ((c / forward + 1.0) * 0.5) * f64::from(size) + 0.5;
                let x = (st.floor() as i64).clamp(0, side - 2);
                ((x - 1).max(0) as u32, (x + 3).min(side) as u32)
            };
            let ((x0, x1), (y0, y1)) = (texel(sc), texel(tc));
            let r = regions[i].get_or_insert(Region { x0, y0, x1, y1 });
            *r = Region {
                x0: r.x0.min(x0),
                y0: r.y0.min(y0),
                x1: r.x1.max(x1),
                y1: r.y1.max(y1),
            };
        }
    }
    regions
}

/// How much of each face [`CubeMap`] renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// Only the part of each face the lens can reach ([`face_regions`]).
    Reachable,
    /// Every texel of every face the lens reaches (to compare).
    WholeFaces,
}

/// How the cube's faces are rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeMethod {
    /// By the tracer, as 90° pinhole views: compared with the direct fisheye render, this
    /// isolates the error of cube-map resampling alone.
    Traced,
    /// By the rasterizer ([`crate::raster`]).
    Raster(RasterMethod),
}

impl CubeMethod {
    /// Every method, in the order of `fisheye render --method`'s names.
    pub const ALL: [CubeMethod; 4] = [
        Self::Traced,
        Self::Raster(RasterMethod::Forward),
        Self::Raster(RasterMethod::Deferred),
        Self::Raster(RasterMethod::SinglePass),
    ];

    /// The name on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Traced => "cube-rt",
            Self::Raster(RasterMethod::Forward) => "cube-forward",
            Self::Raster(RasterMethod::Deferred) => "cube-deferred",
            Self::Raster(RasterMethod::SinglePass) => "cube-single",
        }
    }
}

/// How [`CubeMap`] renders its faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CubeSettings {
    /// Inner texels per face side.
    pub size: u32,
    /// What renders the faces.
    pub method: CubeMethod,
    /// How much of each face.
    pub coverage: Coverage,
    /// Texels per side of each shadow-map layer (rasterized faces only).
    pub shadow_size: u32,
}

impl CubeSettings {
    /// Faces of `size` by `method`, only where the lens reaches, shadow maps of 2048².
    pub fn new(size: u32, method: CubeMethod) -> Self {
        Self {
            size,
            method,
            coverage: Coverage::Reachable,
            shadow_size: 2048,
        }
    }
}

/// The rectilinear camera of one bordered face of `size` inner texels, as the tracer renders
/// it: `(size + 2)²` pixels, 90° across the inner `size`.
pub fn face_camera(size: u32) -> Result<LensCamera> {
    let side = bordered(size);
    let lens = ClassicLens::new(LensModel::Rectilinear, bordered_focal(size))?;
    Ok(LensCamera::new(lens, ImageSize::new(side, side)?))
}

enum Faces {
    Traced(TracedFaces),
    Raster(RasterFaces),
}

/// The tracer's half of the cube-map path: one bordered face at a time through the face
/// camera, each copied into its layer of the cube.
struct TracedFaces {
    pass: TracePass,
    store: wgpu::ComputePipeline,
    /// Per face: the trace pass's colour output and that face's layer of the cube.
    store_groups: Vec<wgpu::BindGroup>,
    side: u32,
}

impl TracedFaces {
    fn new(ctx: &GpuContext, scene: &GpuScene, size: u32, cube: &wgpu::Texture) -> Result<Self> {
        let camera = face_camera(size)?;
        let pass = TracePass::with_views(ctx, &camera, scene, DirectionSource::Computed, 6)?;
        ctx.checked("creating the traced cube faces", || {
            let device = &ctx.device;
            let store = shader::compute_pipeline(device, "cube_store", "main", &[], &[]);
            let layout = store.get_bind_group_layout(0);
            let store_groups = (0..6)
                .map(|face| {
                    let layer = layer_view(cube, Some(face));
                    bind_group(
                        device,
                        "fisheye.cube_store",
                        &layout,
                        [
                            pass.colour_buffer().as_entire_binding(),
                            wgpu::BindingResource::TextureView(&layer),
                        ],
                    )
                })
                .collect();
            Self {
                pass,
                store,
                store_groups,
                side: bordered(size),
            }
        })
    }

    /// Points each face's view at `pose` and records, face after face, the trace of its
    /// region and the copy into its layer (one span over all of them).
    fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
        regions: &[Option<Region>; 6],
        span: Option<Span<'_>>,
    ) {
        let rotation = pose.rotation();
        let reached: Vec<(usize, Region)> = regions
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.map(|r| (i, r)))
            .collect();
        let side = ImageSize::new(self.side, self.side).expect("a face");
        for (k, &(i, r)) in reached.iter().enumerate() {
            let view = i as u32;
            let face = rotation * FACES[i].rotation();
            self.pass
                .set_view(ctx, scene, view, pose.position, face, [r.x0, r.y0]);
            let extent = ImageSize::new(r.x1 - r.x0, r.y1 - r.y0).expect("a non-empty region");
            let (first, last) = (k == 0, k + 1 == reached.len());
            let writes = span.and_then(|s| s.compute(first, false));
            self.pass
                .encode_region(encoder, scene, view, extent, writes);
            dispatch_over_image(
                encoder,
                "fisheye.cube_store",
                &self.store,
                &[&self.store_groups[i]],
                side,
                span.and_then(|s| s.compute(false, last)),
            );
        }
    }
}

/// Timestamp spans of a cube-map frame (see [`CubeMap::encode`]); any may be `None`.
#[derive(Clone, Copy, Default)]
pub struct CubeSpans<'a> {
    /// Rendering the faces: tracing them, or their raster passes (for deferred faces, the
    /// G-buffer passes).
    pub faces: Option<Span<'a>>,
    /// The deferred faces' lighting pass (written only by [`RasterMethod::Deferred`]).
    pub lighting: Option<Span<'a>>,
    /// Resampling the cube into the lens image.
    pub sampler: Option<Span<'a>>,
}

/// The cube-map path: renders each face the lens can reach (by the tracer or the rasterizer,
/// plus a one-texel border), then a compute pass resamples the cube into the lens image.
pub struct CubeMap {
    regions: [Option<Region>; 6],
    faces: Faces,
    cube: wgpu::Texture,
    sampler: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    colour: wgpu::Buffer,
    camera: LensCamera,
}

impl CubeMap {
    /// The cube for `camera` on `scene`, rendered as `settings` say.
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        settings: &CubeSettings,
    ) -> Result<Self> {
        let size = settings.size;
        let max = ctx.device.limits().max_texture_dimension_2d;
        if size == 0 || bordered(size) > max {
            return Err(Error::Scene(format!(
                "cube face size {size}: must be between 1 and {} (the adapter's limit of {max}, \
                 less the two-texel border)",
                max - 2
            )));
        }
        ctx.check_image(camera.size)?;
        let side = bordered(size);
        ctx.check_binding(
            "the cube-map colour output",
            16 * camera.size.pixels() as u64,
        )?;
        let mut regions = face_regions(camera.directions().into_iter().flatten(), size);
        if settings.coverage == Coverage::WholeFaces {
            for r in regions.iter_mut().flatten() {
                *r = Region {
                    x0: 0,
                    y0: 0,
                    x1: side,
                    y1: side,
                };
            }
        }
        // A texture array, not a storage buffer: no binding-size limit on the faces.
        let cube = ctx.checked("creating the cube faces", || {
            texture_array(
                &ctx.device,
                "fisheye.cube.faces",
                side,
                6,
                wgpu::TextureFormat::Rgba32Float,
                wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC,
            )
        })?;
        let faces = match settings.method {
            CubeMethod::Traced => Faces::Traced(TracedFaces::new(ctx, scene, size, &cube)?),
            CubeMethod::Raster(method) => Faces::Raster(RasterFaces::new(
                ctx,
                scene,
                size,
                regions,
                method,
                settings.shadow_size,
                &cube,
            )?),
        };
        ctx.checked("creating the cube-map sampler", || {
            let device = &ctx.device;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.cube_sample"),
                // Lens and table as wgsl/primary.wgsl declares them, faces, output.
                entries: &[
                    uniform_entry(0),
                    storage_entry(1, true),
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2Array,
                            multisampled: false,
                        },
                        count: None,
                    },
                    storage_entry(3, false),
                ],
            });
            let mut constants = lens_constants(camera).to_vec();
            constants.push((
                "DIRECTION_SOURCE",
                f64::from(DirectionSource::Computed as u32),
            ));
            let sampler =
                shader::compute_pipeline(device, "cube_sample", "main", &constants, &[&layout]);
            let buffer = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage,
                    mapped_at_creation: false,
                })
            };
            use wgpu::BufferUsages as U;
            let colour = buffer(
                "fisheye.cube.colour",
                16 * camera.size.pixels() as u64,
                U::STORAGE | U::COPY_SRC,
            );
            let no_table = buffer("fisheye.cube.no_table", 16, U::STORAGE);
            let lens = params_buffer(device, camera);
            let faces_view = layer_view(&cube, None);
            let bind_group = bind_group(
                device,
                "fisheye.cube_sample",
                &layout,
                [
                    lens.as_entire_binding(),
                    no_table.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&faces_view),
                    colour.as_entire_binding(),
                ],
            );
            Self {
                regions,
                faces,
                cube,
                sampler,
                bind_group,
                colour,
                camera: *camera,
            }
        })
    }

    /// The rendered part of each face (in [`FACES`] order), `None` for faces the lens never
    /// reaches.
    pub fn regions(&self) -> [Option<Region>; 6] {
        self.regions
    }

    /// The rasterized faces' shadow maps (`None` for traced faces).
    pub fn shadow_maps(&self) -> Option<&crate::raster::ShadowMaps> {
        match &self.faces {
            Faces::Traced(_) => None,
            Faces::Raster(r) => Some(r.shadows()),
        }
    }

    /// Whether a frame has a deferred lighting pass (timed by [`CubeSpans::lighting`]).
    pub fn has_lighting_pass(&self) -> bool {
        matches!(&self.faces, Faces::Raster(r) if r.method() == RasterMethod::Deferred)
    }

    /// Points the cube at `pose` and records a frame into `encoder`: the reachable faces (or
    /// parts), then the resampling into the lens image. Submit `encoder` before the next call.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
        spans: CubeSpans<'_>,
    ) {
        match &self.faces {
            Faces::Traced(faces) => {
                faces.encode(ctx, encoder, scene, pose, &self.regions, spans.faces)
            }
            Faces::Raster(faces) => {
                faces.set_pose(ctx, scene, pose);
                faces.encode(encoder, scene, spans.faces, spans.lighting);
            }
        }
        dispatch_over_image(
            encoder,
            "fisheye.cube_sample",
            &self.sampler,
            &[&self.bind_group],
            self.camera.size,
            spans.sampler.and_then(|s| s.compute(true, true)),
        );
    }

    /// The lens image's colours of the last submitted frame (as
    /// [`RenderOutput::colour`](crate::trace::RenderOutput::colour)).
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>> {
        ctx.read_buffer(&self.colour)
    }

    /// Renders one frame from `pose` in one submission and reads the lens image back (as
    /// [`CubeMap::read`]).
    pub fn render(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        pose: &Camera,
    ) -> Result<Vec<[f32; 4]>> {
        ctx.checked("rendering the cube map", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(ctx, &mut encoder, scene, pose, CubeSpans::default());
            ctx.queue.submit([encoder.finish()]);
        })?;
        self.read(ctx)
    }

    /// The faces of the last render: `6 × (size + 2)²` texels, row-major per face (texels
    /// outside the regions hold nothing meaningful).
    pub fn texels(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>> {
        ctx.read_texture(&self.cube)
    }
}

/// Runs `wgsl/cube.wgsl`'s face selection on the GPU for each direction.
pub fn face_uv_gpu(ctx: &GpuContext, directions: &[Vec3]) -> Result<Vec<(u32, Vec2)>> {
    let input: Vec<[f32; 4]> = directions.iter().map(|d| [d.x, d.y, d.z, 0.0]).collect();
    ctx.check_binding("the probe directions", 16 * input.len() as u64)?;
    let out = ctx.checked("probing cube faces", || {
        let device = &ctx.device;
        let pipeline = shader::compute_pipeline(device, "cube_probe", "main", &[], &[]);
        let points = crate::gpu::buffer_init(
            device,
            "fisheye.cube_probe.directions",
            bytemuck::cast_slice(&input),
            wgpu::BufferUsages::STORAGE,
        );
        let results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.cube_probe.results"),
            size: points.size(),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind_group = bind_buffers(
            device,
            "fisheye.cube_probe",
            &pipeline.get_bind_group_layout(0),
            &[&points, &results],
        );
        crate::gpu::submit_over_elements(ctx, &pipeline, &bind_group, input.len());
        results
    })?;
    let raw: Vec<[f32; 4]> = ctx.read_buffer(&out)?;
    Ok(raw
        .into_iter()
        .map(|v| (v[0].to_bits(), Vec2::new(v[1], v[2])))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_rotations_and_uv_follows_the_axes() {
        for (i, f) in FACES.iter().enumerate() {
            let r = f.rotation();
            assert!((r.determinant() - 1.0).abs() < 1e-15, "{}", f.name);
            // The face's centre, and its right and down edges.
            assert_eq!(face_uv(f.forward), (i as u32, Vec2::splat(0.5)));
            let right = face_uv(f.forward + 0.5 * f.right);
            assert_eq!(right, (i as u32, Vec2::new(0.75, 0.5)), "{}", f.name);
            let down = face_uv(f.forward + 0.5 * f.down);
            assert_eq!(down, (i as u32, Vec2::new(0.5, 0.75)), "{}", f.name);
        }
        // The formula on +z.
        let d = Vec3::new(0.3, -0.2, 0.9);
        assert_eq!(face_uv(d), (4, (Vec2::new(d.x, d.y) / d.z + 1.0) * 0.5));
        // Ties: x over y over z, zero counts as positive.
        assert_eq!(face_uv(Vec3::new(1.0, 1.0, 1.0)).0, 0);
        assert_eq!(face_uv(Vec3::new(0.0, -1.0, 1.0)).0, 3);
        assert_eq!(face_uv(Vec3::new(-1.0, 1.0, 0.0)).0, 1);
        assert_eq!(face_uv(Vec3::ZERO), (4, Vec2::splat(0.5)));
    }

    #[test]
    fn bilinear_sampling_reads_the_border() {
        // A face of 2 texels (4 × 4 bordered) whose texel (x, y) holds x + 10 y: sampling is
        // exact for this linear function anywhere, the border included.
        let size = 2;
        let side = bordered(size) as usize;
        let texels: Vec<[f32; 4]> = (0..6 * side * side)
            .map(|i| {
                let (x, y) = ((i % side) as f32, ((i / side) % side) as f32);
                [x + 10.0 * y, 0.0, 0.0, 1.0]
            })
            .collect();
        for (u, v) in [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0), (0.1, 0.9), (0.75, 0.25)] {
            let s = sample_bordered(&texels, size, 3, Vec2::new(u, v));
            // Texel centre of bordered column x is at u = (x - 0.5) / size.
            let expected = (u * 2.0 + 0.5) + 10.0 * (v * 2.0 + 0.5);
            assert!(
                (s[0] - expected).abs() < 1e-5,
                "{u} {v}: {s:?} vs {expected}"
            );
        }
    }

    #[test]
    fn regions_follow_the_field_of_view() {
        let reached = |r: [Option<Region>; 6]| r.map(|r| r.is_some());
        // Straight ahead only: the centre of the front face, with its footprint.
        let ahead = face_regions([DVec3::Z], 8);
        assert_eq!(reached(ahead), [false, false, false, false, true, false]);
        assert_eq!(
            ahead[4],
            Some(Region {
                x0: 3,
                y0: 3,
                x1: 7,
                y1: 7
            })
        );
        // A hemisphere: all of the front face, the front half of each side face, never the
        // back face.
        let hemisphere = (0..=90).flat_map(|t| {
            (0..360).map(move |p| {
                let (t, p) = (f64::from(t).to_radians(), f64::from(p).to_radians());
                DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
            })
        });
        let size = 64;
        let r = face_regions(hemisphere, size);
        assert_eq!(reached(r), [true, true, true, true, true, false]);
        let side = bordered(size);
        assert_eq!(r[4].unwrap().texels(), u64::from(side * side));
        for i in 0..4 {
            let t = r[i].unwrap().texels() as f64 / f64::from(side * side);
            assert!((0.5..0.56).contains(&t), "face {}: {t}", FACES[i].name);
        }
    }
}

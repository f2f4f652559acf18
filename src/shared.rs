//! What the GPU and Rust share, in one leaf module that reads nothing else of the crate: ids,
//! limits, workgroup sizes, the cube's face table, and the `repr(C)` structs the kernels read
//! (each `Pod`, its size pinned here; `shader`'s tests check every one against naga's layout
//! of its WGSL twin). [`wgsl_constants`] lists the constants that `shader` prepends to every
//! WGSL module, so each is defined once, here (adaptive sampling's in `shared/adaptive.rs`).

use bytemuck::{Pod, Zeroable};
use glam::{DMat3, Vec3};

mod adaptive;
pub use adaptive::*;

/// Side of the square workgroups of per-pixel kernels.
pub const WORKGROUP_2D: u32 = 8;
/// Width of the workgroups of per-element kernels.
pub const WORKGROUP_1D: u32 = 64;

/// The traversal stack of `wgsl/bvh.wgsl` holds this many node groups; a BVH deeper than this
/// is refused at build time rather than traversed wrongly.
pub const TRAVERSAL_STACK: u32 = 32;

/// Storage buffers the trace kernel binds: three outputs (group 0) and the scene's four
/// (group 1: nodes, triangles, records, shading vertices), and the direction table where it
/// reads one ([`DirectionSource::storage_buffers`]): within WebGPU's and wgpu's default
/// limit of 8.
pub const TRACE_STORAGE_BUFFERS: u32 = 7;

/// The most samples per pixel side (`RenderOptions::spp` is a square of at most this).
pub const MAX_SAMPLES_PER_SIDE: u32 = 16;

/// The samples per side whose pattern is nested (`trace::sampling`): its first 2 × 2 samples
/// are the 2 × 2 pattern, so adaptive sampling's estimate is the start of its supersampling.
pub const NESTED_SIDE: u32 = 4;
/// The nested pattern's coordinates count 48ths of a pixel.
pub const NESTED_UNITS: u32 = 48;
/// The nested pattern in one of its arrangements, in 48ths of a pixel from its top-left
/// corner: first the 2 × 2 rotated grid (the centres of four of its 4 × 4 cells), then one
/// sample in each other stratum of the 4 × 4, two thirds of the way across and down a cell of
/// the 16 × 16 (see `trace::sampling` for how they were chosen).
pub const NESTED_SAMPLES: [[u32; 2]; 16] = [
    [6, 6],
    [42, 18],
    [18, 42],
    [30, 30],
    [11, 14],
    [5, 35],
    [2, 47],
    [17, 5],
    [23, 23],
    [14, 29],
    [35, 2],
    [26, 17],
    [29, 41],
    [38, 11],
    [47, 26],
    [41, 38],
];

/// The deepest Whitted recursion a kernel can run (its ray stack has one more entry).
pub const MAX_DEPTH_LIMIT: u32 = 8;
/// A shadow ray passes at most this many partially transparent surfaces; behind more, the
/// light counts as blocked.
pub const MAX_SHADOW_LAYERS: u32 = 8;
/// [`GpuMaterial::texture`] of an untextured material.
pub const NO_TEXTURE: u32 = u32::MAX;
/// The id of a miss or a masked pixel (`RenderOutput::ids`, the `id` output).
pub const NO_HIT: u32 = u32::MAX;
/// The WGSL id of a diffuse surface (`Surface::Diffuse`).
pub const SURFACE_DIFFUSE: u32 = 0;
/// The WGSL id of a mirror.
pub const SURFACE_MIRROR: u32 = 1;
/// The WGSL id of glass.
pub const SURFACE_GLASS: u32 = 2;

/// The WGSL id of a light kind: `LIGHT_POINT`, `LIGHT_DIRECTIONAL`.
pub const LIGHT_KINDS: [(&str, u32); 2] = [("LIGHT_POINT", 0), ("LIGHT_DIRECTIONAL", 1)];
/// The GPU glass's most surfaces and its exit pupil's radial bins (`lens::glass_gpu`).
pub const GLASS_SIZES: [(&str, u32); 2] = [("GLASS_SURFACES", 32), ("PUPIL_BINS", 64)];

/// The WGSL id of the stable direction formula (`DirectionFormula::Stable`), for the
/// `DIRECTION_FORMULA` override.
pub const FORMULA_STABLE: u32 = 0;
/// The WGSL id of the thesis's direction formula.
pub const FORMULA_THESIS: u32 = 1;

/// The tolerance of the WGSL root finder, relative to its bracket (`wgsl/calibrated.wgsl`).
pub const NEWTON_TOLERANCE: f64 = 1.0 / (1 << 22) as f64;

/// The most iterations the WGSL root finder takes: `lens::newton_bound` at
/// [`NEWTON_TOLERANCE`].
pub const NEWTON_STEPS: u32 = 22;

/// Which WGSL code path a lens runs: the `LENS_KIND` override. The classic models keep their
/// own closed forms; `General*` are the trigonometric paths of the general form.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum LensKind {
    /// `r = f tan θ`.
    Rectilinear = 0,
    /// `r = 2f tan(θ/2)`.
    Stereographic = 1,
    /// `r = f θ` (also the general form with `k2 = 0`).
    Equidistant = 2,
    /// `r = 2f sin(θ/2)`.
    Equisolid = 3,
    /// `r = f sin θ`.
    Orthographic = 4,
    /// `r = (f/k1) tan(k2 θ)`.
    GeneralTan = 5,
    /// `r = (f/k1) sin(|k2| θ)`.
    GeneralSin = 6,
    /// Kannala–Brandt (calibrated).
    KannalaBrandt = 7,
    /// Double sphere (calibrated).
    DoubleSphere = 8,
    /// Extended unified, and unified as its β = 1 case (calibrated).
    ExtendedUnified = 9,
    /// Devernay and Faugeras's FOV model (calibrated).
    FovModel = 10,
    /// Scaramuzza's polynomial (calibrated).
    Scaramuzza = 11,
    /// f-theta (calibrated).
    FTheta = 12,
    /// Radial-tangential (calibrated).
    RadTan = 13,
}

impl LensKind {
    /// Every kind, for emitting the WGSL constants.
    pub const ALL: [LensKind; 14] = [
        Self::Rectilinear,
        Self::Stereographic,
        Self::Equidistant,
        Self::Equisolid,
        Self::Orthographic,
        Self::GeneralTan,
        Self::GeneralSin,
        Self::KannalaBrandt,
        Self::DoubleSphere,
        Self::ExtendedUnified,
        Self::FovModel,
        Self::Scaramuzza,
        Self::FTheta,
        Self::RadTan,
    ];

    /// The WGSL constant naming this kind, e.g. `LENS_GENERAL_TAN`.
    pub fn const_name(&self) -> String {
        let name = match self {
            Self::Rectilinear => "RECTILINEAR",
            Self::Stereographic => "STEREOGRAPHIC",
            Self::Equidistant => "EQUIDISTANT",
            Self::Equisolid => "EQUISOLID",
            Self::Orthographic => "ORTHOGRAPHIC",
            Self::GeneralTan => "GENERAL_TAN",
            Self::GeneralSin => "GENERAL_SIN",
            Self::KannalaBrandt => "KANNALA_BRANDT",
            Self::DoubleSphere => "DOUBLE_SPHERE",
            Self::ExtendedUnified => "EXTENDED_UNIFIED",
            Self::FovModel => "FOV_MODEL",
            Self::Scaramuzza => "SCARAMUZZA",
            Self::FTheta => "FTHETA",
            Self::RadTan => "RADTAN",
        };
        format!("LENS_{name}")
    }
}

/// Where a kernel that consumes ray directions gets them: `wgsl/primary.wgsl`, or
/// `wgsl/primary_table.wgsl` in its place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectionSource {
    /// Evaluate the lens per pixel, every frame.
    Computed,
    /// Read the direction table that `LensRays` computed once.
    Table,
}

impl DirectionSource {
    /// The files a kernel reading its directions from here is composed with in place of
    /// others (`shader::compose_for`).
    pub fn swaps(self) -> &'static [(&'static str, &'static str)] {
        match self {
            Self::Computed => &[],
            Self::Table => &[("primary", "primary_table")],
        }
    }

    /// The storage buffers it binds: the table, or none.
    pub fn storage_buffers(self) -> u32 {
        match self {
            Self::Computed => 0,
            Self::Table => 1,
        }
    }

    /// The name used on the command line and in benchmark tables.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Computed => "computed",
            Self::Table => "table",
        }
    }
}

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

/// Rays whose weight falls below this are not traced (the GPU's and the reference's Whitted
/// recursion alike).
pub const MIN_WEIGHT: f32 = 1e-3;

/// The least cosine between a reflected or refracted ray and the geometric surface it leaves
/// (on its own side): interpolated normals lean away from the facets, and a reflection or
/// refraction about one can cross the facet it leaves and see the object's inside, the black
/// speckles along mirror and glass silhouettes. Such a ray is bent to graze the surface at
/// this cosine instead (about 0.06°), as renderers adapt shading normals so that reflections
/// stay above the geometry (Keller et al. 2017, "The Iray Light Transport Simulation and
/// Rendering System", arXiv:1705.01263).
pub const GRAZING_COSINE: f32 = 1e-3;

/// The WGSL declaration of [`NESTED_SAMPLES`], prepended to every module.
pub fn wgsl_nested_samples() -> String {
    let points: Vec<String> = NESTED_SAMPLES
        .iter()
        .map(|[x, y]| format!("vec2<u32>({x}u, {y}u)"))
        .collect();
    format!(
        "const NESTED_SAMPLES = array<vec2<u32>, {}>({});\n",
        NESTED_SAMPLES.len(),
        points.join(", ")
    )
}

/// The lights below this index can be marked as reaching every point of a triangle
/// ([`GpuTriangle::unshadowed`], a bit each); shading traces the others' shadow rays always.
pub const UNSHADOWED_LIGHTS: u32 = 32;

/// The f32 constants every WGSL module sees, as `const NAME: f32` lines.
pub fn wgsl_float_constants() -> [(&'static str, f32); 2] {
    [
        ("MIN_WEIGHT", MIN_WEIGHT),
        ("GRAZING_COSINE", GRAZING_COSINE),
    ]
}

/// The constants every WGSL module sees, as `const NAME: u32` lines (see `shader::compose`).
pub fn wgsl_constants() -> Vec<(String, u32)> {
    let mut out: Vec<(String, u32)> = [
        ("WORKGROUP_2D", WORKGROUP_2D),
        ("WORKGROUP_1D", WORKGROUP_1D),
        ("NEWTON_STEPS", NEWTON_STEPS),
        ("FORMULA_STABLE", FORMULA_STABLE),
        ("FORMULA_THESIS", FORMULA_THESIS),
        ("TRAVERSAL_STACK", TRAVERSAL_STACK),
        ("MAX_DEPTH_LIMIT", MAX_DEPTH_LIMIT),
        ("NO_TEXTURE", NO_TEXTURE),
        ("MAX_SHADOW_LAYERS", MAX_SHADOW_LAYERS),
        ("UNSHADOWED_LIGHTS", UNSHADOWED_LIGHTS),
        ("NO_HIT", NO_HIT),
        ("ADAPTIVE_BLOCK", ADAPTIVE_BLOCK),
        ("ADAPTIVE_STRIP", ADAPTIVE_STRIP),
        ("MAX_KNOTS", MAX_KNOTS as u32),
        ("INSTANCE_VEC4S", INSTANCE_VEC4S),
        ("KNOT_VEC4S", KNOT_VEC4S),
        ("LIGHT_VEC4S", LIGHT_VEC4S),
        ("MATERIAL_VEC4S", MATERIAL_VEC4S),
        ("ADAPTIVE_HEADER", ADAPTIVE_HEADER),
        ("ADAPTIVE_COUNT", ADAPTIVE_COUNT),
        ("ADAPTIVE_ESTIMATE_SIDE", ADAPTIVE_ESTIMATE_SIDE),
        ("ADAPTIVE_FIRST", ADAPTIVE_FIRST),
        ("ADAPTIVE_END", ADAPTIVE_END),
        ("ADAPTIVE_MODE", ADAPTIVE_MODE),
        ("MODE_CENTRE", MODE_CENTRE),
        ("MODE_SAMPLES", MODE_SAMPLES),
        ("MODE_TRUTH", MODE_TRUTH),
        ("MODE_ESTIMATE", MODE_ESTIMATE),
        ("MODE_LATTICE", MODE_LATTICE),
        ("MODE_EVERY_PIXEL", MODE_EVERY_PIXEL),
        ("ADAPTIVE_KEY_MORE", ADAPTIVE_KEY_MORE),
        ("NESTED_SIDE", NESTED_SIDE),
        ("NESTED_UNITS", NESTED_UNITS),
        ("SURFACE_DIFFUSE", SURFACE_DIFFUSE),
        ("SURFACE_MIRROR", SURFACE_MIRROR),
        ("SURFACE_GLASS", SURFACE_GLASS),
    ]
    .into_iter()
    .chain(LIGHT_KINDS)
    .chain(GLASS_SIZES)
    .chain(READOUT_ORDERS)
    .map(|(n, v)| (n.to_string(), v))
    .collect();
    out.extend(LensKind::ALL.iter().map(|k| (k.const_name(), *k as u32)));
    out
}

/// The `vec4`s of a [`GpuLight`] in the scene's records (instances, lights, materials, texels).
pub const LIGHT_VEC4S: u32 = 2;
/// The `vec4`s of a [`GpuMaterial`] in the scene's records.
pub const MATERIAL_VEC4S: u32 = 5;
const _: () = assert!(std::mem::size_of::<GpuLight>() == 16 * LIGHT_VEC4S as usize);
const _: () = assert!(std::mem::size_of::<GpuMaterial>() == 16 * MATERIAL_VEC4S as usize);

/// A material as `wgsl/surface.wgsl`'s `material_at` reads it (80 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    /// `Kd`.
    pub diffuse: [f32; 3],
    /// A `SURFACE_*` id.
    pub surface: u32,
    /// `Ks`.
    pub specular: [f32; 3],
    /// `Ns`.
    pub shininess: f32,
    /// `Ke`.
    pub emission: [f32; 3],
    /// `Ni`.
    pub ior: f32,
    /// `Tf`.
    pub transmission: [f32; 3],
    /// The diffuse texture's first texel (a word of the scene's records), or [`NO_TEXTURE`].
    pub texture: u32,
    /// `d`.
    pub opacity: f32,
    /// The texture's width in texels (0 without).
    pub texture_width: u32,
    /// Its height.
    pub texture_height: u32,
    /// Its mip levels, level 0 included, one after another from `texture` (0 without).
    pub texture_levels: u32,
}

/// A light as `wgsl/surface.wgsl`'s `light_at` reads it (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    /// Camera-relative position (point) or travel direction (directional).
    pub vector: [f32; 3],
    /// A `LIGHT_KINDS` id.
    pub kind: u32,
    /// Intensity or irradiance.
    pub colour: [f32; 3],
    /// The light's first layer in the rasterizer's shadow maps: six for a point light (one
    /// per cube face, in [`FACES`] order), one for a directional light.
    pub shadow_layer: u32,
}

/// Per-scene shading constants (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Shading {
    /// Radiance of escaping rays.
    pub sky: [f32; 3],
    /// Number of lights.
    pub light_count: u32,
    /// Ambient term.
    pub ambient: [f32; 3],
    /// Deepest secondary ray.
    pub max_depth: u32,
    /// Where the lights begin in the scene's records (`vec4`s).
    pub lights_at: u32,
    /// Where the materials begin there.
    pub materials_at: u32,
    /// Padding.
    pub pad: [u32; 2],
}

/// The camera pose of a frame (2,160 bytes): the camera-to-world rotation's columns (camera x,
/// y, z axes) and the eye; with `MOTION` (a rolling shutter or an exposure, see
/// `lens::Shutter`), those are the camera's pose in a moving body, and the body's poses at
/// `knots` (slerp and lerp between them) carry it to the world at each ray's time.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Frame {
    /// Camera x (right).
    pub right: [f32; 4],
    /// Camera y (down).
    pub down: [f32; 4],
    /// Camera z (forward).
    pub forward: [f32; 4],
    /// Eye position relative to the scene's origin (`GpuScene::origin`), xyz; with `MOTION`,
    /// relative to the body's origin.
    pub eye: [f32; 4],
    /// The pixel of the first invocation (x, y), for dispatches over a part of the image;
    /// w: the first image row the outputs hold (a band of rows, when the whole image's
    /// outputs exceed one storage binding; 0 otherwise).
    pub offset: [u32; 4],
    /// With `MOTION`: the knots in use (x, at least 1) and the readout order (y, a
    /// `READOUT_*` of [`READOUT_ORDERS`]).
    pub motion: [u32; 4],
    /// With `MOTION`: seconds between two lines' readouts (x) and the exposure (y, seconds).
    pub shutter: [f32; 4],
    /// With `MOTION`: the body's poses, in increasing time.
    pub knots: [Knot; MAX_KNOTS],
}

/// The most poses of a moving body one frame holds ([`Frame::knots`]): a readout and exposure
/// may span that many stamps of a trajectory.
pub const MAX_KNOTS: usize = 64;

/// The WGSL id of each readout order of a rolling shutter (`lens::Readout`).
pub const READOUT_ORDERS: [(&str, u32); 4] = [
    ("READOUT_DOWN", 0),
    ("READOUT_UP", 1),
    ("READOUT_RIGHT", 2),
    ("READOUT_LEFT", 3),
];

/// A moving body's pose at a time within a frame (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Knot {
    /// The body-to-world rotation, a unit quaternion (x, y, z, w).
    pub rotation: [f32; 4],
    /// The body's origin relative to the scene's (xyz); w: seconds from the frame's stamp.
    pub position: [f32; 4],
}

/// Adaptive sampling's settings as `wgsl/adaptive.wgsl` reads them (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct AdaptiveParams {
    /// Displayed-colour difference at which two samples disagree.
    pub threshold: f32,
    /// The least cosine between two corners' normals on one smooth surface.
    pub normal_cosine: f32,
    /// The farthest a corner's hit may lie from another's tangent plane, relative to range.
    pub plane_distance: f32,
    /// Padding.
    pub _pad0: u32,
    /// Lattice points across and down.
    pub lattice: [u32; 2],
    /// Blocks across and down.
    pub blocks: [u32; 2],
    /// The half-blocks' corners across and down.
    pub half_lattice: [u32; 2],
    /// Half-blocks across and down.
    pub halves: [u32; 2],
}

/// One triangle as `wgsl/bvh.wgsl` reads it: 48 bytes, three `vec4<f32>` whose `w` carry the
/// scene triangle index and the material index (as bits).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuTriangle {
    /// First corner: camera-relative, or in its mesh's space (an instanced mesh's triangle).
    pub v0: [f32; 3],
    /// Index of the triangle in `Scene::triangles`.
    pub triangle: u32,
    /// Second corner.
    pub v1: [f32; 3],
    /// Index into `Scene::materials`.
    pub material: u32,
    /// Third corner.
    pub v2: [f32; 3],
    /// The lights no other triangle stands between any point of it and (bit `k` for light
    /// `k`, [`crate::bvh::unshadowed`]): shading skips their shadow rays.
    pub unshadowed: u32,
}

const _: () = assert!(std::mem::size_of::<GpuTriangle>() == 48);

/// A ray as `wgsl/cast.wgsl` reads it (32 bytes): origin relative to the scene's upload origin
/// (`GpuScene::origin`), direction of any length (distances are measured along it), and the
/// interval (tmin, tmax] searched.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct CastRay {
    /// Origin, relative to the scene's upload origin.
    pub origin: [f32; 3],
    /// Hits at t ≤ tmin do not count.
    pub tmin: f32,
    /// Direction.
    pub dir: [f32; 3],
    /// Hits beyond tmax do not count.
    pub tmax: f32,
}

/// An instance as `wgsl/triangles.wgsl` reads it (160 bytes): a mesh's BVH and the affine
/// maps between the camera-relative world and the mesh's space, or a moving one's knots.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuInstance {
    /// World (camera-relative) to mesh space: rows of the 3×3 part, translation in `w`.
    pub to_mesh: [[f32; 4]; 3],
    /// Mesh space to world (camera-relative), likewise.
    pub to_world: [[f32; 4]; 3],
    /// First row of the normal matrix (the inverse transpose of `to_world`'s 3×3 part).
    pub normal_x: [f32; 3],
    /// The node the mesh's BVH starts at.
    pub root: u32,
    /// Second row of the normal matrix.
    pub normal_y: [f32; 3],
    /// The scene triangle id of the mesh's first triangle in this instance.
    pub id_base: u32,
    /// Third row of the normal matrix.
    pub normal_z: [f32; 3],
    /// The mesh's first stored triangle (`Scene::triangles`).
    pub first: u32,
    /// Where it moves within a frame: the vec4 its [`InstanceKnot`]s start at in the
    /// instances' buffer and how many (with fewer than 2 the maps above place it); then 1 where
    /// it shows (0 where its placement flattens it), and a zero.
    pub motion: [u32; 4],
}

const _: () = assert!(std::mem::size_of::<GpuInstance>() == 16 * INSTANCE_VEC4S as usize);

/// The vec4s of a [`GpuInstance`] in the instances' buffer.
pub const INSTANCE_VEC4S: u32 = 10;

/// A moving instance's placement at a time within a frame (64 bytes), after the instances in
/// their buffer: the polar decomposition M = R·A of its 3×3 part (R a rotation, A symmetric),
/// between knots R by slerp and A and the translation linearly.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct InstanceKnot {
    /// R, a unit quaternion (x, y, z, w).
    pub rotation: [f32; 4],
    /// The translation, camera-relative (xyz), and the time in seconds from the frame's stamp.
    pub translation: [f32; 4],
    /// A's xx, yy, zz, xy.
    pub diagonal: [f32; 4],
    /// A's xz, yz, then zeros.
    pub off_diagonal: [f32; 4],
}

/// The vec4s of an [`InstanceKnot`].
pub const KNOT_VEC4S: u32 = 4;

const _: () = assert!(std::mem::size_of::<InstanceKnot>() == 16 * KNOT_VEC4S as usize);

/// The lens as WGSL's `LensParams` reads it (96 bytes; `wgsl/lens.wgsl` mirrors it and a test
/// checks the layouts agree). See the WGSL struct for the fields' meaning; the first eight
/// fields serve classic lenses, the last three calibrated ones (zero for classic lenses).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct LensParams {
    /// Focal length.
    pub f: f32,
    /// `k1/f` of the general form.
    pub k1_over_f: f32,
    /// Rate `|k2|` of the general form.
    pub rate: f32,
    /// Radius of the domain edge, `f32::MAX` when unbounded.
    pub r_max: f32,
    /// Largest θ of a ray.
    pub theta_max: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// `N_max` of `LensCamera::mask_limit`.
    pub mask_limit: u32,
    /// Calibrated: fx, fy, cx, cy in pixels.
    pub intrinsics: [f32; 4],
    /// Calibrated: the model's parameters, packed per kind as `calibrated_coefficients` says.
    pub coefficients: [[f32; 4]; 2],
    /// Calibrated: Scaramuzza's affine c, d, e.
    pub affine: [f32; 4],
}

const _: () = assert!(std::mem::size_of::<LensParams>() == 96);

/// Per-frame face views as `wgsl/raster.wgsl` reads them (496 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Views {
    /// Per face: scene space to clip space (column-major).
    pub clip: [[f32; 16]; 6],
    /// Per face: the rendered texels `x0, y0, x1, y1`, empty for skipped faces.
    pub regions: [[u32; 4]; 6],
    /// The eye in scene space (xyz).
    pub eye: [f32; 4],
}

/// One layer of the shadow maps as `wgsl/raster.wgsl` reads it (80 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct ShadowView {
    /// Scene space to the layer's clip space (column-major), depth reversed.
    pub clip: [f32; 16],
    /// `x`: a texel's width in scene units, at unit distance for a point light's face.
    pub texel: [f32; 4],
}

#[cfg(test)]
mod tests;

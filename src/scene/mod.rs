//! Scenes: triangles in f64 world space, Whitted materials, lights, a sky and a camera pose.
//!
//! Positions stay in f64 until upload, where they are made relative to the camera and rounded
//! to f32 once, so a scene far from the origin renders as it does at the origin.

pub mod animation;
pub mod builtin;
pub mod file;
pub mod gltf;
mod lint;
mod mesh;
pub mod obj;
mod view;

use glam::{DAffine3, DMat3, DVec3, Vec2, Vec3};

use crate::input::InputKind;
use crate::lens::LensCamera;

pub use mesh::{MeshBuilder, MeshId, checker};

/// How loaders read the files a scene names: [`disk`], or bytes held in memory (tests and the
/// fuzz targets).
pub type ReadFile<'a> = &'a dyn Fn(&std::path::Path, InputKind) -> std::io::Result<Vec<u8>>;

/// Reads a file from the file system, within its kind's budget (see [`crate::input`]).
pub fn disk(path: &std::path::Path, kind: InputKind) -> std::io::Result<Vec<u8>> {
    crate::input::read(path, kind)
}

/// How a surface scatters light in the Whitted model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// Lambert diffuse plus Phong highlights, lit by the lights with shadow rays.
    Diffuse,
    /// A perfect mirror tinted by `Ks` (MTL `illum` 3 and 5).
    Mirror,
    /// A dielectric with index `Ni`: Fresnel-weighted reflection and refraction, total internal
    /// reflection, transmission tinted by `Tf` (MTL `illum` 4, 6 and 7).
    Glass,
}

/// A material with the MTL fields a Whitted tracer uses.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The MTL name (for messages).
    pub name: String,
    /// How the surface scatters.
    pub surface: Surface,
    /// `Kd`, linear RGB.
    pub diffuse: Vec3,
    /// Index into [`Scene::textures`] of `map_Kd`, multiplied with `diffuse`.
    pub diffuse_texture: Option<u32>,
    /// `Ks`: Phong highlight colour, and the mirror's tint.
    pub specular: Vec3,
    /// `Ns`: Phong exponent.
    pub shininess: f32,
    /// `Ke`: emitted radiance.
    pub emission: Vec3,
    /// `Ni`: index of refraction.
    pub ior: f32,
    /// `Tf`: transmission filter of glass.
    pub transmission: Vec3,
    /// `d` (or `1 - Tr`): the fraction of light the surface stops. Below 1 the rest passes
    /// straight through, for camera, secondary and shadow rays alike.
    pub opacity: f32,
}

impl Material {
    /// A grey diffuse material.
    pub fn diffuse(name: &str, colour: Vec3) -> Self {
        Self {
            name: name.to_string(),
            surface: Surface::Diffuse,
            diffuse: colour,
            diffuse_texture: None,
            specular: Vec3::ZERO,
            shininess: 1.0,
            emission: Vec3::ZERO,
            ior: 1.0,
            transmission: Vec3::ONE,
            opacity: 1.0,
        }
    }

    /// A mirror tinted by `tint`.
    pub fn mirror(name: &str, tint: Vec3) -> Self {
        Self {
            surface: Surface::Mirror,
            specular: tint,
            ..Self::diffuse(name, Vec3::ZERO)
        }
    }

    /// Clear glass of index `ior`.
    pub fn glass(name: &str, ior: f32) -> Self {
        Self {
            surface: Surface::Glass,
            ior,
            ..Self::diffuse(name, Vec3::ZERO)
        }
    }
}

/// An RGBA8 texture, sRGB-encoded as image files are.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it came from (a path, or the name of a procedural texture).
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major RGBA8, top row first.
    pub rgba: Vec<u8>,
}

/// A light source. Emissive materials also light what they are seen from, but cast no shadow
/// rays (Whitted's model has no area lights).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A point light: radiance falls off with the squared distance.
    Point {
        /// Position, world space.
        position: DVec3,
        /// Intensity (RGB, W/sr-like units: irradiance at distance 1).
        intensity: Vec3,
    },
    /// A light at infinity (the sun).
    Directional {
        /// Direction the light travels, world space.
        direction: DVec3,
        /// Irradiance on a surface facing it.
        irradiance: Vec3,
    },
}

impl Light {
    /// The light as the tracers see it, relative to `origin` and rounded to f32 once:
    /// `(is_point, position or unit travel direction, intensity or irradiance)`.
    pub fn relative_to(&self, origin: DVec3) -> (bool, Vec3, Vec3) {
        match *self {
            Light::Point {
                position,
                intensity,
            } => (true, (position - origin).as_vec3(), intensity),
            Light::Directional {
                direction,
                irradiance,
            } => (false, direction.normalize().as_vec3(), irradiance),
        }
    }
}

/// Where the camera is and where it looks. World space is y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: DVec3,
    /// A point the optical axis passes through.
    pub look_at: DVec3,
    /// The world's up direction, used to level the camera.
    pub up: DVec3,
}

impl Camera {
    /// Camera-to-world rotation: its columns are the camera's x (right), y (down) and z
    /// (forward) axes in world space, as the lens module's directions use them.
    pub fn rotation(&self) -> DMat3 {
        let forward = (self.look_at - self.position).normalize();
        let mut right = forward.cross(self.up);
        if right.length_squared() < 1e-24 {
            // Looking along `up`: any level is as good as another.
            right = forward.any_orthonormal_vector();
        }
        let right = right.normalize();
        DMat3::from_cols(right, forward.cross(right), forward)
    }
}

/// A mesh placed in the world by a transform: its triangles are stored once (in
/// [`Scene::triangles`], in the mesh's own space) however many instances place them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// The mesh's first stored triangle.
    pub first: u32,
    /// Its number of triangles.
    pub count: u32,
    /// Mesh space to world space (its 3×3 part invertible).
    pub transform: DAffine3,
    /// Its object ([`Scene::objects`]): each instance is one of its own.
    pub object: u32,
    /// Where it moves: an index into [`Scene::animations`] (`transform` is then its placement
    /// at the time the scene was posed at, [`Scene::at`]).
    pub animation: Option<u32>,
}

impl Instance {
    /// Whether its placement shows its mesh: finite and not flattening it (a moving instance
    /// scaled to zero is hidden; [`MeshBuilder::place`] refuses such a fixed one).
    pub fn visible(&self) -> bool {
        shows(&self.transform)
    }
}

/// Whether a placement shows its mesh: finite and not flattening it.
pub fn shows(transform: &DAffine3) -> bool {
    transform.is_finite() && transform.matrix3.determinant().is_normal()
}

/// A labelled object of a scene, for the instance and semantic outputs: its name (a glTF
/// node's, an OBJ object's, a scene file's mesh's, a material's where nothing names it) and
/// its class (a glTF `extras.class`, else its mesh's name; a scene file's `class`; else the
/// name).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Object {
    /// The object's name.
    pub name: String,
    /// Its semantic class.
    pub class: String,
}

/// The instance and class of a pixel that sees nothing (`Scene::objects_of`).
pub const NO_OBJECT: u32 = u32::MAX;

/// The most triangles an instanced scene is flattened to for the paths that draw world
/// triangles only (the rasterized cube map): 50M, 2.4 GB of f64 corners on the host and more
/// than the rasterizer could draw at interactive rates anyway.
pub const MAX_FLATTENED: usize = 50_000_000;

/// Everything the tracer renders.
///
/// Triangles are stored once: the first [`Scene::world_triangles`] in world space, then the
/// meshes [`Scene::instances`] place, each in its own space. A scene triangle (as ids name it)
/// is a stored world triangle, numbered first, or a triangle of an instance: instance k's
/// triangles follow those of instances before it, in mesh order, as [`Scene::flattened`]
/// lays them out.
///
/// ```
/// use fisheye_rt::scene::builtin;
/// // Or from files: scene::obj::load_obj, scene::gltf::load_gltf, scene::file::load_scene_file.
/// let scene = builtin::scene("default").expect("a built-in scene");
/// assert!(scene.len() > 0 && !scene.lights.is_empty());
/// assert!(!scene.is_instanced()); // every triangle in world space
/// ```
#[derive(Clone, Debug)]
pub struct Scene {
    /// The corners of every stored triangle: world space, then mesh space.
    pub triangles: Vec<[DVec3; 3]>,
    /// How many of `triangles` (the first) are in world space; the rest are meshes.
    pub world_triangles: usize,
    /// The placed meshes; empty in a flat scene.
    pub instances: Vec<Instance>,
    /// Per stored triangle: vertex normals, if any mesh had them (others get their face
    /// normal).
    pub normals: Option<Vec<[Vec3; 3]>>,
    /// Per-triangle texture coordinates, if any mesh had them (others get zeros).
    pub uvs: Option<Vec<[Vec2; 3]>>,
    /// Index into `materials` of each triangle.
    pub material_of: Vec<u32>,
    /// The materials.
    pub materials: Vec<Material>,
    /// Diffuse textures.
    pub textures: Vec<Texture>,
    /// The lights.
    pub lights: Vec<Light>,
    /// Radiance of rays that escape.
    pub sky: Vec3,
    /// Ambient light reaching every diffuse surface (Whitted's ambient term).
    pub ambient: Vec3,
    /// The camera pose.
    pub camera: Camera,
    /// Keyframes of a camera path (for benchmarks); empty if the scene has none.
    pub camera_path: Vec<Camera>,
    /// Cameras the scene's file defines (a glTF file's camera nodes), for `--camera gltf:N`.
    pub cameras: Vec<Camera>,
    /// The point light (index into `lights`) that sits at the camera, as a bare OBJ's
    /// headlight does: [`Scene::set_camera`] moves it with the eye.
    pub headlight: Option<usize>,
    /// The bounds the camera was placed to frame, where the scene did not give one (a bare
    /// OBJ, a scene file without `[camera]`): [`Scene::frame_for`] re-frames them for a lens.
    pub framed: Option<(DVec3, DVec3)>,
    /// The labelled objects: the world triangles' (`object_of`), then each instance's.
    pub objects: Vec<Object>,
    /// The object of each world triangle (the first [`Scene::world_triangles`]).
    pub object_of: Vec<u32>,
    /// How moving instances move ([`Instance::animation`]).
    pub animations: Vec<animation::Animation>,
}

/// The share of the picture a scene's bounding sphere fills when [`Scene::frame_for`] places
/// the camera (see [`LensCamera::fill_angle`]): 0.8, a margin of a fifth of the image
/// circle's radius (or of the frame's half-height) around it.
pub const FRAME_FILL: f64 = 0.8;

/// The widest half-angle (degrees) under which [`Scene::frame_for`] sees the bounding
/// sphere: 80°, the eye 1.015 radii from the centre, for lenses so wide (past 200°) that
/// filling [`FRAME_FILL`] of their picture would put the eye inside the sphere; there the
/// sphere fills less.
pub const WIDEST_FRAMING: f64 = 80.0;

impl Scene {
    /// Number of scene triangles: the world's and every instance's (100M for a thousand
    /// instances of a 100k-triangle mesh, of which only 100k are stored).
    pub fn len(&self) -> usize {
        self.world_triangles
            + self
                .instances
                .iter()
                .map(|i| i.count as usize)
                .sum::<usize>()
    }

    /// Whether the scene has no triangles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether some instance moves.
    pub fn moves(&self) -> bool {
        self.instances.iter().any(|i| i.animation.is_some())
    }

    /// The first and last key time of the animations that move its instances (seconds);
    /// `None` where nothing moves. Before the first key instances stay where it puts them,
    /// and after the last where that one does.
    pub fn key_span(&self) -> Option<(f64, f64)> {
        if !self.moves() {
            return None;
        }
        self.animations
            .iter()
            .flat_map(|a| a.key_times())
            .fold(None, |span, t| match span {
                None => Some((t, t)),
                Some((a, b)) => Some((t.min(a), t.max(b))),
            })
    }

    /// The scene still at scene time `t` (seconds): each moving instance fixed where its
    /// animation puts it then (a placement that flattens its mesh hides it: see
    /// [`Instance::visible`]).
    pub fn at(&self, t: f64) -> Scene {
        let mut posed = self.clone();
        for (instance, transform) in posed.instances.iter_mut().zip(self.placements_at(t)) {
            instance.transform = transform;
            instance.animation = None;
        }
        posed.animations.clear();
        posed
    }

    /// Every instance's placement at scene time `t`.
    pub fn placements_at(&self, t: f64) -> Vec<DAffine3> {
        self.instances
            .iter()
            .map(|i| match i.animation {
                Some(a) => self.animations[a as usize].at(t),
                None => i.transform,
            })
            .collect()
    }

    /// Whether some mesh is placed by instances.
    pub fn is_instanced(&self) -> bool {
        !self.instances.is_empty()
    }

    /// The scene with every instance's triangles copied into world space, numbered as scene
    /// triangles are (mirroring transforms swap two corners, so faces keep their side, as
    /// [`MeshBuilder::transform_since`] does). Refuses a result of more than `limit`
    /// triangles, before allocating it.
    pub fn flattened(&self, limit: usize) -> crate::error::Result<Scene> {
        if !self.is_instanced() {
            return Ok(self.clone());
        }
        if self.len() > limit {
            return Err(crate::error::Error::Limit(format!(
                "flattening the scene's {} instances makes {} triangles, more than the {limit} \
                 this path takes (only the BVH traversal draws instances without copying them)",
                self.instances.len(),
                self.len()
            )));
        }
        let mut b = MeshBuilder::with_materials(self.materials.clone(), self.textures.clone());
        let copy = |b: &mut MeshBuilder, i: usize| {
            b.triangle(
                self.triangles[i],
                self.normals.as_ref().map(|n| n[i]),
                self.uvs.as_ref().map(|t| t[i]),
                self.material_of[i],
            )
        };
        for i in 0..self.world_triangles {
            copy(&mut b, i);
        }
        for instance in &self.instances {
            let first = b.len();
            for i in instance.first..instance.first + instance.count {
                copy(&mut b, i as usize);
            }
            b.transform_since(first, instance.transform);
        }
        let flat = b.finish(self.lights.clone(), self.sky, self.ambient, self.camera);
        // The same objects: each instance's copied triangles keep its object.
        let object_of = self
            .object_of
            .iter()
            .copied()
            .chain(
                self.instances
                    .iter()
                    .flat_map(|i| std::iter::repeat_n(i.object, i.count as usize)),
            )
            .collect();
        Ok(Scene {
            camera_path: self.camera_path.clone(),
            cameras: self.cameras.clone(),
            headlight: self.headlight,
            framed: self.framed,
            objects: self.objects.clone(),
            object_of,
            ..flat
        })
    }

    /// The object ([`Scene::objects`]) of each scene triangle id (as the `id` output gives
    /// them), [`NO_OBJECT`] for a miss.
    pub fn objects_of(&self, ids: &[u32]) -> Vec<u32> {
        let starts = self.instance_starts();
        ids.iter()
            .map(|&id| match id {
                crate::shared::NO_HIT => NO_OBJECT,
                id if (id as usize) < self.world_triangles => self.object_of[id as usize],
                id => {
                    let k = starts.partition_point(|&s| s <= u64::from(id)) - 1;
                    self.instances[k].object
                }
            })
            .collect()
    }

    /// The scene triangle id each instance's triangles start at, after the world's: instance
    /// `k` holds ids `starts[k]..starts[k] + count`.
    pub fn instance_starts(&self) -> Vec<u64> {
        self.instances
            .iter()
            .scan(self.world_triangles as u64, |next, i| {
                let start = *next;
                *next += u64::from(i.count);
                Some(start)
            })
            .collect()
    }

    /// The semantic classes, in the order their objects first name them, and each object's
    /// class (an index into them).
    pub fn classes(&self) -> (Vec<String>, Vec<u32>) {
        let mut names: Vec<String> = Vec::new();
        let mut index: std::collections::HashMap<&str, u32> = Default::default();
        let of = self
            .objects
            .iter()
            .map(|o| {
                *index.entry(&o.class).or_insert_with(|| {
                    names.push(o.class.clone());
                    names.len() as u32 - 1
                })
            })
            .collect();
        (names, of)
    }

    /// Puts the camera at `pose`, and the headlight, if the scene has one, at its eye.
    pub fn set_camera(&mut self, pose: Camera) {
        self.camera = pose;
        if let Some(Light::Point { position, .. }) =
            self.headlight.and_then(|i| self.lights.get_mut(i))
        {
            *position = pose.position;
        }
    }

    /// Moves a camera the scene did not give (see [`Scene::framed`]) so that the bounding
    /// sphere fills [`FRAME_FILL`] of `lens`'s picture, looking at it from the same side;
    /// the headlight, if any, goes with the eye, as bright at the scene's centre as before.
    /// Returns the half-angle (radians) the sphere is seen under, or `None` (nothing moved) for
    /// a scene with a camera of its own or a lens whose axis is outside its picture.
    pub fn frame_for(&mut self, lens: &LensCamera) -> Option<f64> {
        let (lo, hi) = self.framed?;
        let angle = lens
            .fill_angle(FRAME_FILL)?
            .min(WIDEST_FRAMING.to_radians());
        self.camera = obj::framing(lo, hi, 1.0 / angle.sin());
        if let Some(light) = self.headlight.and_then(|i| self.lights.get_mut(i)) {
            *light = obj::headlight(&self.camera);
        }
        Some(angle)
    }

    /// The axis-aligned bounds of all triangles (`None` when empty); an instance counts with
    /// the box around its mesh's transformed bounding box.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let world = bounds(&self.triangles[..self.world_triangles]);
        self.instances
            .iter()
            .fold(world, |acc, i| union(acc, self.instance_bounds(i)))
    }

    /// The world bounds of `instance` (see [`placed_bounds`]).
    pub fn instance_bounds(&self, instance: &Instance) -> Option<(DVec3, DVec3)> {
        if !instance.visible() {
            return None;
        }
        let mesh = &self.triangles[instance.first as usize..][..instance.count as usize];
        placed_bounds(mesh, instance.transform)
    }

    /// The pose at `s` ∈ [0, 1] along the camera path: keyframes equally spaced, positions and
    /// look-at points interpolated linearly between them. The scene camera without a path.
    pub fn camera_on_path(&self, s: f64) -> Camera {
        let keys = &self.camera_path;
        match keys.len() {
            0 => self.camera,
            1 => keys[0],
            n => {
                let x = s.clamp(0.0, 1.0) * (n - 1) as f64;
                let i = (x.floor() as usize).min(n - 2);
                let f = x - i as f64;
                let (a, b) = (keys[i], keys[i + 1]);
                Camera {
                    position: a.position.lerp(b.position, f),
                    look_at: a.look_at.lerp(b.look_at, f),
                    up: a.up,
                }
            }
        }
    }

    /// Which features the scene uses, for specialising kernels.
    pub fn features(&self) -> Features {
        let used: Vec<&Material> = {
            let mut seen = vec![false; self.materials.len()];
            for &m in &self.material_of {
                seen[m as usize] = true;
            }
            self.materials
                .iter()
                .zip(seen)
                .filter_map(|(m, s)| s.then_some(m))
                .collect()
        };
        Features {
            mirrors: used.iter().any(|m| m.surface == Surface::Mirror),
            glass: used.iter().any(|m| m.surface == Surface::Glass),
            textures: self.uvs.is_some() && used.iter().any(|m| m.diffuse_texture.is_some()),
            smooth_normals: self.normals.is_some(),
            translucent: used.iter().any(|m| m.opacity < 1.0),
            instanced: self.is_instanced(),
            moving: self.moves(),
        }
    }
}

/// Loads a scene from `builtin:NAME`, a scene file (`.toml`) or a bare OBJ (`.obj`).
pub fn load(spec: &str) -> crate::error::Result<obj::Loaded> {
    load_with(spec, None)
}

/// As [`load`], with the scene `gltf_scene` of a glTF file (its default scene if `None`).
pub fn load_with(spec: &str, gltf_scene: Option<usize>) -> crate::error::Result<obj::Loaded> {
    use crate::error::Error;
    if let Some(name) = spec.strip_prefix("builtin:") {
        let scene = builtin::scene(name).ok_or_else(|| {
            let names: Vec<&str> = builtin::SCENES.iter().map(|(n, _)| *n).collect();
            Error::Scene(format!(
                "no built-in scene {name:?}; there are {}",
                names.join(", ")
            ))
        })?;
        return Ok(obj::Loaded {
            scene,
            warnings: Vec::new(),
        });
    }
    let path = std::path::Path::new(spec);
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("toml") => file::load_scene_file(path),
        Some("obj") => obj::load_obj(path),
        Some("gltf" | "glb") => gltf::load_gltf(path, gltf_scene),
        _ => Err(Error::Scene(format!(
            "{spec:?}: expected `builtin:NAME`, a scene file (.toml), an OBJ file (.obj) or a \
             glTF file (.gltf, .glb)"
        ))),
    }
}

/// The optional shading features a scene uses; kernels compile only these.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    /// Some surface is a mirror.
    pub mirrors: bool,
    /// Some surface is glass.
    pub glass: bool,
    /// Some surface has a diffuse texture (and the scene has UVs).
    pub textures: bool,
    /// Vertex normals are interpolated.
    pub smooth_normals: bool,
    /// Some surface is partially transparent (`d` < 1).
    pub translucent: bool,
    /// Meshes are placed by instances (a two-level BVH).
    pub instanced: bool,
    /// Some instance moves ([`Scene::moves`]).
    pub moving: bool,
}

/// The axis-aligned bounds of some triangles (`None` when there are none).
pub fn bounds(triangles: &[[DVec3; 3]]) -> Option<(DVec3, DVec3)> {
    let mut corners = triangles.iter().flatten();
    let first = *corners.next()?;
    Some(corners.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
}

/// The box around the transformed bounding box of `mesh` (`None` when empty): bounds a
/// placed mesh without transforming its triangles.
pub fn placed_bounds(mesh: &[[DVec3; 3]], transform: DAffine3) -> Option<(DVec3, DVec3)> {
    Some(placed_box(bounds(mesh)?, transform))
}

/// The box around box `(lo, hi)`'s corners moved by `transform`.
pub fn placed_box((lo, hi): (DVec3, DVec3), transform: DAffine3) -> (DVec3, DVec3) {
    (0..8)
        .map(|k| {
            let pick = |bit: u32, a: f64, b: f64| if k & bit == 0 { a } else { b };
            let c = DVec3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            );
            transform.transform_point3(c)
        })
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), p| {
            (a.min(p), b.max(p))
        })
}

/// The union of two optional boxes.
pub fn union(a: Option<(DVec3, DVec3)>, b: Option<(DVec3, DVec3)>) -> Option<(DVec3, DVec3)> {
    match (a, b) {
        (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
        (a, b) => a.or(b),
    }
}

/// The vertex normal of a triangle's face (not normalized when degenerate).
pub fn face_normal(t: &[DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero()
}

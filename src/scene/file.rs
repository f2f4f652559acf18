//! Scene files (TOML): meshes placed in the world, material overrides, lights, a sky and a
//! camera with an optional path. Unknown keys are errors, and paths resolve relative to the
//! scene file.
//!
//! ```toml
//! sky = [0.35, 0.4, 0.5]          # radiance of escaping rays (default as for a bare OBJ)
//! ambient = [0.05, 0.05, 0.05]    # Whitted's ambient term
//!
//! [camera]                        # default: frames the scene's bounds from the front
//! position = [0.0, 1.0, 3.4]
//! look_at = [0.0, 1.0, 0.0]
//! up = [0.0, 1.0, 0.0]            # default
//!
//! [[camera.path]]                 # keyframes for benchmarks, equally spaced
//! position = [0.5, 1.0, 3.4]
//! look_at = [0.0, 1.0, 0.0]
//!
//! [[mesh]]
//! path = "box.obj"                # OBJ or glTF (.gltf, .glb: its default scene's meshes and
//!                                 # materials); or shape = "box" (the unit cube) or "sphere"
//!                                 # (unit radius)
//! scale = 1.0                     # or [x, y, z]
//! rotation = [0.0, 90.0, 0.0]     # degrees about x, then y, then z
//! translation = [0.0, 0.0, 0.0]
//! material = { diffuse = [0.8, 0.8, 0.8] }   # replaces every material of this mesh
//!                                 # (entries naming the same file or shape with the same
//!                                 # material are one mesh, stored once and placed by each)
//!
//! [[mesh.key]]                    # keyframes move it: at scene time `time` (seconds) the
//! time = 0.0                      # placement the key gives (what it leaves out, the mesh's);
//! translation = [-1.0, 0.0, 0.0]  # linear between keys (rotations by slerp), held before
//! [[mesh.key]]                    # the first and after the last (see `fisheye render
//! time = 2.0                      # --time` and `dataset render`)
//! translation = [1.0, 0.0, 0.0]
//! rotation = [0.0, 90.0, 0.0]
//!
//! [[material]]                    # overrides the fields it names in materials of that name
//! name = "light"
//! emission = [17.0, 12.0, 4.0]
//!
//! [[light]]
//! type = "point"                  # or "sun" with direction and irradiance
//! position = [0.0, 1.9, 0.0]
//! intensity = [1.0, 1.0, 1.0]
//! ```

use std::path::{Path, PathBuf};

use std::f64::consts::PI;

use glam::{DAffine3, DMat3, DQuat, DVec3, Vec3};
use serde::Deserialize;

use super::animation::{Animation, Factor, Interpolation, Keys, Trs};
use super::obj::{
    DEFAULT_AMBIENT, DEFAULT_DISTANCE, DEFAULT_SKY, Loaded, because, framing, load_into,
};
use super::{Camera, Light, Material, MeshBuilder, MeshId, ReadFile, Surface};
use crate::error::{Error, Result};
use crate::input::InputKind;

type Triple = [f64; 3];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    sky: Option<Triple>,
    ambient: Option<Triple>,
    camera: Option<CameraSpec>,
    #[serde(default, rename = "mesh")]
    meshes: Vec<MeshSpec>,
    #[serde(default, rename = "material")]
    materials: Vec<MaterialSpec>,
    #[serde(default, rename = "light")]
    lights: Vec<LightSpec>,
}

fn world_up() -> Triple {
    [0.0, 1.0, 0.0]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSpec {
    position: Triple,
    look_at: Triple,
    #[serde(default = "world_up")]
    up: Triple,
    #[serde(default)]
    path: Vec<Keyframe>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Keyframe {
    position: Triple,
    look_at: Triple,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum Shape {
    Box,
    Sphere,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(untagged, expecting = "a number or an [x, y, z] array")]
enum Scale {
    Uniform(f64),
    Axes(Triple),
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshSpec {
    /// The object's name and class for the instance and semantic outputs.
    name: Option<String>,
    class: Option<String>,
    path: Option<PathBuf>,
    shape: Option<Shape>,
    #[serde(default)]
    scale: Scale,
    #[serde(default)]
    rotation: Triple,
    #[serde(default)]
    translation: Triple,
    material: Option<MaterialSpec>,
    #[serde(default, rename = "key")]
    keys: Vec<KeySpec>,
}

/// A keyframe of a mesh's placement.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeySpec {
    time: f64,
    scale: Option<Scale>,
    rotation: Option<Triple>,
    translation: Option<Triple>,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum SurfaceSpec {
    Diffuse,
    Mirror,
    Glass,
}

#[derive(Deserialize, Clone, Default, PartialEq)]
#[serde(deny_unknown_fields)]
struct MaterialSpec {
    name: Option<String>,
    surface: Option<SurfaceSpec>,
    diffuse: Option<Triple>,
    specular: Option<Triple>,
    shininess: Option<f64>,
    emission: Option<Triple>,
    ior: Option<f64>,
    transmission: Option<Triple>,
    opacity: Option<f64>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum LightSpec {
    Point {
        position: Triple,
        intensity: Triple,
    },
    Sun {
        direction: Triple,
        irradiance: Triple,
    },
}

/// Checks a value the parser accepted (TOML allows `nan` and `inf`).
struct Check<'a> {
    path: &'a Path,
}

impl Check<'_> {
    fn fail<T>(&self, message: String) -> Result<T> {
        Err(Error::SceneFile {
            path: self.path.to_path_buf(),
            message,
        })
    }

    fn finite(&self, what: &str, v: Triple) -> Result<DVec3> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(DVec3::from(v))
        } else {
            self.fail(format!("{what} = {v:?}: every component must be finite"))
        }
    }

    fn colour(&self, what: &str, v: Triple) -> Result<Vec3> {
        let c = self.finite(what, v)?;
        if c.min_element() < 0.0 {
            return self.fail(format!("{what} = {v:?}: must not be negative"));
        }
        if !c.as_vec3().is_finite() {
            return self.fail(format!(
                "{what} = {v:?}: beyond the f32 range the GPU computes in"
            ));
        }
        Ok(c.as_vec3())
    }

    fn number(&self, what: &str, x: f64, lo: f64, hi: f64) -> Result<f32> {
        if x.is_finite() && (lo..=hi).contains(&x) {
            Ok(x as f32)
        } else {
            self.fail(format!("{what} = {x}: must lie in [{lo}, {hi}]"))
        }
    }

    fn camera(&self, what: &str, position: Triple, look_at: Triple, up: DVec3) -> Result<Camera> {
        let position = self.finite(&format!("{what}.position"), position)?;
        let look_at = self.finite(&format!("{what}.look_at"), look_at)?;
        if position == look_at {
            return self.fail(format!(
                "{what}: position and look_at are the same point, so it looks nowhere"
            ));
        }
        Ok(Camera {
            position,
            look_at,
            up,
        })
    }

    /// Applies the fields `spec` sets to `m`.
    fn apply(&self, what: &str, spec: &MaterialSpec, m: &mut Material) -> Result<()> {
        if let Some(s) = spec.surface {
            m.surface = match s {
                SurfaceSpec::Diffuse => Surface::Diffuse,
                SurfaceSpec::Mirror => Surface::Mirror,
                SurfaceSpec::Glass => Surface::Glass,
            };
        }
        if let Some(v) = spec.diffuse {
            m.diffuse = self.colour(&format!("{what}.diffuse"), v)?;
        }
        if let Some(v) = spec.specular {
            m.specular = self.colour(&format!("{what}.specular"), v)?;
        }
        if let Some(x) = spec.shininess {
            m.shininess = self.number(&format!("{what}.shininess"), x, 1.0, 1e6)?;
        }
        if let Some(v) = spec.emission {
            m.emission = self.colour(&format!("{what}.emission"), v)?;
        }
        if let Some(x) = spec.ior {
            m.ior = self.number(&format!("{what}.ior"), x, 1e-3, 100.0)?;
        }
        if let Some(v) = spec.transmission {
            m.transmission = self.colour(&format!("{what}.transmission"), v)?;
        }
        if let Some(x) = spec.opacity {
            m.opacity = self.number(&format!("{what}.opacity"), x, 0.0, 1.0)?;
        }
        Ok(())
    }

    /// The mesh's placement: scale, then rotation about x, y and z, then translation.
    fn transform(&self, what: &str, mesh: &MeshSpec) -> Result<DAffine3> {
        let (scale, rotation, translation) =
            self.trs(what, mesh.scale, mesh.rotation, mesh.translation)?;
        if scale.abs().min_element() == 0.0 {
            return self.fail(format!("{what}.scale = {scale}: must be non-zero"));
        }
        Ok(DAffine3::from_scale_rotation_translation(
            scale,
            rotation,
            translation,
        ))
    }

    /// A scale, a rotation in degrees about x, then y, then z, and a translation, checked.
    fn trs(
        &self,
        what: &str,
        scale: Scale,
        rotation: Triple,
        translation: Triple,
    ) -> Result<(DVec3, DQuat, DVec3)> {
        let scale = match scale {
            Scale::Uniform(s) => DVec3::splat(s),
            Scale::Axes(v) => DVec3::from(v),
        };
        if !scale.is_finite() {
            return self.fail(format!("{what}.scale = {scale}: must be finite"));
        }
        let r = self.finite(&format!("{what}.rotation"), rotation)? * (PI / 180.0);
        let rotation =
            DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x);
        let translation = self.finite(&format!("{what}.translation"), translation)?;
        Ok((scale, DQuat::from_mat3(&rotation), translation))
    }

    /// The animation a mesh's keys give (each key's missing parts the mesh's own).
    fn animation(&self, what: &str, mesh: &MeshSpec) -> Result<Animation> {
        let mut keys = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (k, key) in mesh.keys.iter().enumerate() {
            let (scale, rotation, translation) = self.trs(
                &format!("{what}.key {}", k + 1),
                key.scale.unwrap_or(mesh.scale),
                key.rotation.unwrap_or(mesh.rotation),
                key.translation.unwrap_or(mesh.translation),
            )?;
            keys.0.push(key.time);
            keys.1.push(translation);
            keys.2.push(rotation);
            keys.3.push(scale);
        }
        let (times, translations, rotations, scales) = keys;
        let linear = |values| Keys {
            times: times.clone(),
            values,
            interpolation: Interpolation::Linear,
        };
        let trs = Trs {
            translation: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            scale: DVec3::ONE,
            translation_keys: Some(linear(translations)),
            rotation_keys: Some(Keys {
                times: times.clone(),
                values: rotations,
                interpolation: Interpolation::Linear,
            }),
            scale_keys: Some(linear(scales)),
        };
        if let Err(e) = trs.translation_keys.as_ref().map_or(Ok(()), Keys::check) {
            return self.fail(format!("{what}'s keys: {e}"));
        }
        Ok(Animation {
            factors: vec![Factor::Keyed(trs)],
        })
    }
}

/// Loads the triangles of one `[[mesh]]` entry into `b`, in its own space, with its material
/// override.
fn load_mesh(
    check: &Check,
    what: &str,
    mesh: &MeshSpec,
    dir: &Path,
    read: ReadFile,
    b: &mut MeshBuilder,
    warnings: &mut Vec<String>,
) -> Result<()> {
    let first = b.len();
    match (&mesh.path, mesh.shape) {
        (Some(file), None) => {
            let file = dir.join(file);
            let gltf = file
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"));
            if gltf {
                let content = super::gltf::load_into(&file, read, None, b, warnings)?;
                if !content.lights.is_empty() || !content.cameras.is_empty() {
                    warnings.push(format!(
                        "{}: its lights and cameras are not used in a scene file (give \
                         [[light]] and [camera])",
                        file.display()
                    ));
                }
            } else {
                load_into(&file, read, b, warnings)?;
            }
        }
        (None, Some(shape)) => {
            let grey = b.material(Material::diffuse(what, Vec3::splat(0.8)));
            match shape {
                Shape::Box => b.cuboid(DVec3::splat(-0.5), DVec3::splat(0.5), grey),
                Shape::Sphere => b.sphere(DVec3::ZERO, 1.0, 64, 32, false, grey),
            }
        }
        _ => return check.fail(format!("{what}: give exactly one of path and shape")),
    }
    if let Some(spec) = &mesh.material {
        let mut m = Material::diffuse(what, Vec3::splat(0.8));
        check.apply(&format!("{what}.material"), spec, &mut m)?;
        let id = b.material(m);
        b.set_material_since(first, id);
    }
    Ok(())
}

/// Loads a scene file: its meshes (OBJ files loaded with their MTL, or shapes), material
/// overrides, lights, sky and camera. Problems that do not stop the load come back as warnings.
pub fn load_scene_file(path: &Path) -> Result<Loaded> {
    load_scene_file_from(path, &super::disk)
}

/// As [`load_scene_file`], reading the file and the files it names through `read`.
pub fn load_scene_file_from(path: &Path, read: ReadFile) -> Result<Loaded> {
    let check = Check { path };
    let bytes = read(path, InputKind::SceneFile).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        reason: source,
    })?;
    let text = match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            return check.fail(format!("not UTF-8 text (byte {at}), as TOML must be"));
        }
    };
    let file: SceneFile = toml::from_str(&text).map_err(|e| Error::SceneFile {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut warnings = Vec::new();
    let mut b = MeshBuilder::new();
    if file.meshes.is_empty() {
        return check.fail("no [[mesh]]: a scene needs at least one".into());
    }
    // Entries that name the same file or shape with the same material are one mesh, stored
    // once and placed by each (a file whose own meshes are instanced is loaded for each).
    let same = |a: &MeshSpec, b: &MeshSpec| {
        a.path == b.path && a.shape == b.shape && a.material == b.material
    };
    let mut shared: Vec<Option<MeshId>> = vec![None; file.meshes.len()];
    for (i, mesh) in file.meshes.iter().enumerate() {
        let what = format!("mesh {}", i + 1);
        let transform = check.transform(&what, mesh)?;
        // Its label: as given, else an OBJ's own objects name its parts, else "mesh N".
        let name = mesh.name.clone().unwrap_or_else(|| what.clone());
        b.object(&name, mesh.class.as_deref().unwrap_or(&name));
        let animation = match mesh.keys.is_empty() {
            true => None,
            false => Some(check.animation(&what, mesh)?),
        };
        // Placed by `transform`, or moved by its keys.
        let place = |b: &mut MeshBuilder, id: MeshId| {
            let placed = match &animation {
                Some(a) => b.place_moving(id, a.clone()),
                None => b.place(id, transform),
            };
            match placed {
                true => Ok(()),
                false => check.fail(format!("{what}: its transform flattens the mesh")),
            }
        };
        let kind = file.meshes.iter().position(|m| same(m, mesh)).unwrap_or(i);
        if let Some(id) = shared[kind] {
            place(&mut b, id)?;
            continue;
        }
        let (first, placed) = (b.len(), b.placed_count());
        load_mesh(&check, &what, mesh, dir, read, &mut b, &mut warnings)?;
        if b.len() == first {
            warnings.push(format!("{what}: no triangles"));
        }
        let repeated = file.meshes[i + 1..].iter().any(|m| same(m, mesh));
        let own = b.len() > first && b.placed_count() == placed;
        if own && (repeated || animation.is_some()) {
            let id = b.mesh_since(first);
            place(&mut b, id)?;
            if repeated {
                shared[kind] = Some(id);
            }
        } else if animation.is_some() && b.len() > first {
            return check.fail(format!(
                "{what}: keys move a mesh stored once, and {} places meshes of its own",
                mesh.path
                    .as_ref()
                    .map_or("it".into(), |p| p.display().to_string())
            ));
        } else {
            b.transform_since(first, transform);
        }
    }
    for spec in &file.materials {
        let Some(name) = &spec.name else {
            return check
                .fail("a [[material]] needs the name of the materials it overrides".into());
        };
        let what = format!("material {name:?}");
        let mut found = false;
        for m in b.materials_mut().iter_mut().filter(|m| &m.name == name) {
            check.apply(&what, spec, m)?;
            found = true;
        }
        if !found {
            let mut names: Vec<String> = b.materials_mut().iter().map(|m| m.name.clone()).collect();
            names.sort();
            names.dedup();
            return check.fail(format!(
                "{what} matches no material of the meshes; they have: {}",
                names.join(", ")
            ));
        }
    }
    if b.is_empty() {
        return check.fail(format!("no triangles to render{}", because(&warnings)));
    }
    let mut lights = Vec::new();
    for (i, light) in file.lights.iter().enumerate() {
        let what = format!("light {}", i + 1);
        lights.push(match *light {
            LightSpec::Point {
                position,
                intensity,
            } => Light::Point {
                position: check.finite(&format!("{what}.position"), position)?,
                intensity: check.colour(&format!("{what}.intensity"), intensity)?,
            },
            LightSpec::Sun {
                direction,
                irradiance,
            } => {
                let direction = check.finite(&format!("{what}.direction"), direction)?;
                if direction == DVec3::ZERO {
                    return check.fail(format!("{what}.direction is zero"));
                }
                Light::Directional {
                    direction,
                    irradiance: check.colour(&format!("{what}.irradiance"), irradiance)?,
                }
            }
        });
    }
    let sky = match file.sky {
        Some(v) => check.colour("sky", v)?,
        None => DEFAULT_SKY,
    };
    let ambient = match file.ambient {
        Some(v) => check.colour("ambient", v)?,
        None => DEFAULT_AMBIENT,
    };
    let mut framed = None;
    let (camera, path_keys) = match &file.camera {
        Some(c) => {
            let up = check.finite("camera.up", c.up)?;
            let camera = check.camera("camera", c.position, c.look_at, up)?;
            let keys = c
                .path
                .iter()
                .enumerate()
                .map(|(i, k)| {
                    check.camera(&format!("camera.path {}", i + 1), k.position, k.look_at, up)
                })
                .collect::<Result<Vec<_>>>()?;
            (camera, keys)
        }
        None => {
            let bounds = b.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
            framed = Some(bounds);
            (framing(bounds.0, bounds.1, DEFAULT_DISTANCE), Vec::new())
        }
    };
    let mut scene = b.finish(lights, sky, ambient, camera);
    scene.camera_path = path_keys;
    scene.framed = framed;
    let emits = scene
        .materials
        .iter()
        .any(|m| m.emission.max_element() > 0.0);
    if scene.lights.is_empty() && !emits && sky.max_element() == 0.0 && ambient.max_element() == 0.0
    {
        warnings.push("nothing lights this scene: no lights, emission, sky or ambient".into());
    } else if scene.lights.is_empty() {
        // Emission and the sky light nothing else under Whitted shading.
        warnings.push(
            "no [[light]]: surfaces get the ambient term alone, so the scene renders flat and \
             casts no shadows; add a [[light]] (point or sun)"
                .into(),
        );
    }
    Ok(Loaded { scene, warnings })
}

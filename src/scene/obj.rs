//! Wavefront OBJ + MTL scenes through `tobj` (triangulated, parsed in f64).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec2, Vec3};

use super::lint::{self, LineError};
use super::{Camera, Light, Material, MeshBuilder, ReadFile, Scene, Surface, Texture};
use crate::error::{Error, Result};
use crate::input::InputKind;

/// A loaded scene and what was repaired or ignored on the way, for the user to read.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// One line per problem that did not stop the load (missing MTL or texture, dropped
    /// non-finite triangles), naming the file or mesh.
    pub warnings: Vec<String>,
}

fn vec3(v: [f64; 3]) -> Vec3 {
    DVec3::from(v).as_vec3()
}

/// The scene's material for an MTL material (the fields a Whitted tracer uses).
fn material(
    m: &tobj::Material,
    textures: &mut Vec<Texture>,
    dir: &Path,
    read: ReadFile,
    warnings: &mut Vec<String>,
) -> Result<Material> {
    let surface = match m.illumination_model {
        Some(3 | 5) => Surface::Mirror,
        Some(4 | 6 | 7) => Surface::Glass,
        _ => Surface::Diffuse,
    };
    let floats = |key: &str| -> Option<Vec<f32>> {
        let text = m.unknown_param.get(key)?;
        text.split_whitespace().map(|w| w.parse().ok()).collect()
    };
    let transmission = match floats("Tf").as_deref() {
        Some([r, g, b]) => Vec3::new(*r, *g, *b),
        Some([x]) => Vec3::splat(*x),
        _ => Vec3::ONE,
    };
    let mut diffuse_texture = None;
    if let Some(name) = &m.diffuse_texture {
        let path = dir.join(name.replace('\\', "/"));
        let image = match read(&path, InputKind::Texture) {
            Ok(bytes) => image::load_from_memory(&bytes).map_err(|e| e.to_string()),
            // A missing texture is common and harmless; a special or oversized file is not.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(e.to_string()),
            Err(e) => {
                return Err(Error::Io {
                    path,
                    reason: std::io::Error::other(format!("texture of material {}: {e}", m.name)),
                });
            }
        };
        match image {
            Ok(img) => {
                let rgba = img.to_rgba8();
                textures.push(Texture {
                    name: path.display().to_string(),
                    width: rgba.width(),
                    height: rgba.height(),
                    rgba: rgba.into_raw(),
                });
                diffuse_texture = Some(textures.len() as u32 - 1);
            }
            Err(e) => warnings.push(format!(
                "material {}: texture {}: {e}; using Kd alone",
                m.name,
                path.display()
            )),
        }
    }
    // `d` is opacity; some exporters write `Tr` (= 1 - d) instead.
    let opacity = m
        .dissolve
        .or_else(|| floats("Tr").and_then(|t| t.first().map(|t| 1.0 - f64::from(*t))))
        .map_or(1.0, |d| {
            if !d.is_finite() {
                warnings.push(format!("material {}: opacity d = {d}; using 1", m.name));
            }
            if d.is_finite() {
                d.clamp(0.0, 1.0) as f32
            } else {
                1.0
            }
        });
    Ok(Material {
        name: m.name.clone(),
        opacity,
        surface,
        diffuse: m.diffuse.map_or(Vec3::splat(0.8), vec3),
        diffuse_texture,
        specular: m.specular.map_or(Vec3::ZERO, vec3),
        shininess: m.shininess.map_or(1.0, |s| s as f32).max(1.0),
        emission: m.emissive.map_or(Vec3::ZERO, vec3),
        ior: m.optical_density.map_or(1.5, |n| n as f32),
        transmission,
    })
}

/// An error on a line of an OBJ or MTL file.
fn line_error(path: &Path, e: LineError) -> Error {
    Error::Obj {
        path: path.to_path_buf(),
        message: format!("line {}: {}", e.line, e.message),
    }
}

/// Loads an OBJ (and its MTL files and textures, through `read`) into a [`MeshBuilder`].
///
/// Every line is checked before tobj reads it (see `lint`); triangles with non-finite corners
/// or no area are dropped with a warning naming their mesh.
pub fn load_into(
    path: &Path,
    read: ReadFile,
    b: &mut MeshBuilder,
    warnings: &mut Vec<String>,
) -> Result<()> {
    let obj_error = |message: String| Error::Obj {
        path: path.to_path_buf(),
        message,
    };
    let bytes =
        read(path, InputKind::Obj).map_err(|e| obj_error(format!("cannot read the file: {e}")))?;
    let text = lint::clean(&String::from_utf8_lossy(&bytes));
    let facts = lint::check_obj(&text).map_err(|e| line_error(path, e))?;
    let shown = path.display();
    warnings.extend(facts.warnings.iter().map(|w| format!("{shown}: {w}")));
    let dir = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
    let mut mtls = HashMap::new();
    for name in &facts.mtllibs {
        let mtl_path = dir.join(name);
        match read(&mtl_path, InputKind::Mtl) {
            Ok(bytes) => {
                let mtl = lint::clean(&String::from_utf8_lossy(&bytes));
                let checked = lint::check_mtl(&mtl).map_err(|e| line_error(&mtl_path, e))?;
                let shown = mtl_path.display();
                warnings.extend(checked.warnings.iter().map(|w| format!("{shown}: {w}")));
                mtls.insert(PathBuf::from(name), mtl);
            }
            // A missing MTL is common and harmless; a special or oversized file is not.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => warnings.push(format!(
                "{shown}: its MTL {} could not be read ({e}); using grey",
                mtl_path.display()
            )),
            Err(e) => {
                return Err(Error::Io {
                    path: mtl_path,
                    reason: std::io::Error::other(format!("the MTL of {shown}: {e}")),
                });
            }
        }
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // The check above keeps tobj from the inputs it panics on; should it still panic, the
    // user gets an error, not a crash.
    let loaded = std::panic::catch_unwind(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &options, |p| match mtls.get(p) {
            Some(mtl) => tobj::load_mtl_buf(&mut mtl.as_bytes()),
            None => Err(tobj::LoadError::OpenFileFailed),
        })
    })
    .map_err(|_| obj_error("the OBJ loader (tobj) failed on this file".into()))?;
    let (models, materials) = loaded.map_err(|e| obj_error(e.to_string()))?;
    // Every MTL that was read passed the check, so tobj read it too.
    let materials = materials.unwrap_or_default();
    for (name, line) in &facts.used_materials {
        if !materials.iter().any(|m| &m.name == name) {
            warnings.push(format!(
                "{shown}: line {line}: usemtl {name:?}: no MTL defines it; using grey"
            ));
        }
    }
    let mut textures = Vec::new();
    let converted: Vec<Material> = materials
        .iter()
        .map(|m| material(m, &mut textures, &dir, read, warnings))
        .collect::<Result<_>>()?;
    let texture_base = b.texture_count();
    for t in textures {
        b.texture(t);
    }
    let base = b.material_count();
    for mut m in converted {
        m.diffuse_texture = m.diffuse_texture.map(|t| t + texture_base);
        b.material(m);
    }
    let default = b.material(Material::diffuse("default", Vec3::splat(0.8)));
    // Each OBJ object or group (tobj splits one by material into models of the same name)
    // is an object for the instance and semantic outputs, its name its class too.
    let mut last: Option<&str> = None;
    for model in &models {
        if last != Some(model.name.as_str()) {
            b.object(&model.name, &model.name);
            last = Some(&model.name);
        }
        add_mesh(path, model, base, default, b, warnings);
    }
    Ok(())
}

/// Adds one tobj mesh's triangles, dropping (with a warning naming the mesh) those with
/// non-finite corners, which are undefined behaviour in hardware acceleration structures, and
/// those with no area, which no ray hits.
fn add_mesh(
    path: &Path,
    model: &tobj::Model,
    material_base: u32,
    default: u32,
    b: &mut MeshBuilder,
    warnings: &mut Vec<String>,
) {
    let mesh = &model.mesh;
    let material = mesh
        .material_id
        .map_or(default, |m| material_base + m as u32);
    let vertices = mesh.positions.len() / 3;
    let warn = |what: String| format!("{}: mesh {:?}: {what}", path.display(), model.name);
    // A mesh whose faces give texture coordinates or normals to some vertices only gets a
    // shorter array from tobj: use neither then.
    let has_normals = !mesh.normals.is_empty();
    let has_uvs = !mesh.texcoords.is_empty();
    let normals_ok = mesh.normals.len() == 3 * vertices;
    let uvs_ok = mesh.texcoords.len() == 2 * vertices;
    for (has, ok, what) in [
        (has_normals, normals_ok, "normals"),
        (has_uvs, uvs_ok, "texture coordinates"),
    ] {
        if has && !ok {
            warnings.push(warn(format!(
                "some faces give {what} and some do not; ignoring its {what}"
            )));
        }
    }
    let position = |i: u32| {
        let k = 3 * i as usize;
        DVec3::new(
            mesh.positions[k],
            mesh.positions[k + 1],
            mesh.positions[k + 2],
        )
    };
    let normal = |i: u32| {
        let k = 3 * i as usize;
        DVec3::new(mesh.normals[k], mesh.normals[k + 1], mesh.normals[k + 2]).as_vec3()
    };
    let uv = |i: u32| {
        let k = 2 * i as usize;
        Vec2::new(mesh.texcoords[k] as f32, mesh.texcoords[k + 1] as f32)
    };
    let mut dropped = Dropped::default();
    for face in mesh.indices.chunks_exact(3) {
        let face = [face[0], face[1], face[2]];
        let corners = face.map(position);
        if !dropped.keeps(&corners) {
            continue;
        }
        let normals = (has_normals && normals_ok)
            .then(|| face.map(normal))
            .filter(|n| n.iter().all(|n| n.is_finite() && n.length_squared() > 0.0));
        let uvs = (has_uvs && uvs_ok).then(|| face.map(uv));
        b.triangle(corners, normals, uvs, material);
    }
    dropped.warn(|what| warnings.push(warn(what)));
}

/// Counts the triangles a loader drops: non-finite corners (undefined behaviour in hardware
/// acceleration structures) and no area (no ray hits them).
#[derive(Default)]
pub(crate) struct Dropped {
    non_finite: usize,
    flat: usize,
}

impl Dropped {
    /// Whether a triangle with these corners is kept (else it is counted).
    pub(crate) fn keeps(&mut self, corners: &[DVec3; 3]) -> bool {
        if !corners.iter().all(|p| p.is_finite()) {
            self.non_finite += 1;
            false
        } else if (corners[1] - corners[0]).cross(corners[2] - corners[0]) == DVec3::ZERO {
            self.flat += 1;
            false
        } else {
            true
        }
    }

    /// A warning for each kind dropped, through `warn`.
    pub(crate) fn warn(&self, mut warn: impl FnMut(String)) {
        if self.non_finite > 0 {
            warn(format!(
                "dropped {} triangles with non-finite vertices",
                self.non_finite
            ));
        }
        if self.flat > 0 {
            warn(format!(
                "dropped {} triangles of zero area (corners on one line)",
                self.flat
            ));
        }
    }
}

/// The sky of scenes that do not set one.
pub const DEFAULT_SKY: Vec3 = Vec3::new(0.35, 0.4, 0.5);
/// The ambient light of scenes that do not set one.
pub const DEFAULT_AMBIENT: Vec3 = Vec3::splat(0.08);

/// How far, in bounding radii, the automatic camera stands from a scene's centre before it
/// knows the lens ([`super::Scene::frame_for`] moves it for one): 1.33, as the bounding sphere
/// is seen under a half-angle of 48.6°.
pub const DEFAULT_DISTANCE: f64 = 1.334_166_4;

/// A camera that frames the box `lo`..`hi` from the front (+z, 13° above) at `distance`
/// bounding radii from its centre, whatever its units or offset.
pub fn framing(lo: DVec3, hi: DVec3, distance: f64) -> Camera {
    let centre = (lo + hi) / 2.0;
    let direction = DVec3::new(0.0, 0.3, 1.3).normalize();
    Camera {
        position: centre + direction * (distance * bounding_radius(lo, hi)),
        look_at: centre,
        up: DVec3::Y,
    }
}

/// The radius of the box `lo`..`hi`'s bounding sphere (at least 1e-6), scaled so that the
/// length of a box beyond 1e154 does not overflow.
pub fn bounding_radius(lo: DVec3, hi: DVec3) -> f64 {
    let half = (hi - lo) / 2.0;
    let scale = half.max_element().max(1e-6);
    (scale * (half / scale).length()).max(1e-6)
}

/// A headlight at `camera`'s eye that gives 0.6 irradiance at the scene's centre (its look-at
/// point), and a sun from above and behind the viewer's left: a bare OBJ's lights.
pub fn headlight_and_sun(camera: &Camera) -> Vec<Light> {
    vec![
        headlight(camera),
        Light::Directional {
            direction: DVec3::new(-0.3, -1.0, -0.4).normalize(),
            irradiance: Vec3::splat(0.6),
        },
    ]
}

/// A point light at `camera`'s eye giving 0.6 irradiance at its look-at point.
pub(crate) fn headlight(camera: &Camera) -> Light {
    let distance = camera.position.distance(camera.look_at);
    Light::Point {
        position: camera.position,
        intensity: Vec3::splat((0.6 * distance * distance) as f32),
    }
}

/// A bare OBJ as a scene, [`framing`] its bounds so that any OBJ shows something.
pub fn load_obj(path: &Path) -> Result<Loaded> {
    load_obj_from(path, &super::disk)
}

/// As [`load_obj`], reading the OBJ and the files it names through `read`.
///
/// Errors if no triangle is left to render.
pub fn load_obj_from(path: &Path, read: ReadFile) -> Result<Loaded> {
    let mut b = MeshBuilder::new();
    let mut warnings = Vec::new();
    load_into(path, read, &mut b, &mut warnings)?;
    if b.is_empty() {
        return Err(Error::Obj {
            path: path.to_path_buf(),
            message: format!("no triangles to render{}", because(&warnings)),
        });
    }
    let (lo, hi) = b.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
    let camera = framing(lo, hi, DEFAULT_DISTANCE);
    let mut scene = b.finish(
        headlight_and_sun(&camera),
        DEFAULT_SKY,
        DEFAULT_AMBIENT,
        camera,
    );
    scene.headlight = Some(0);
    scene.framed = Some((lo, hi));
    Ok(Loaded { scene, warnings })
}

/// `": " + the warnings`, to say why a load left nothing (empty when there are none).
pub(crate) fn because(warnings: &[String]) -> String {
    match warnings {
        [] => String::new(),
        w => format!(" ({})", w.join("; ")),
    }
}

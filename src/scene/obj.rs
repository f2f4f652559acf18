//! Wavefront OBJ + MTL scenes through `tobj` (triangulated, parsed in f64).

use std::path::{Path, PathBuf};

use glam::{DVec3, Vec2, Vec3};

use super::{Camera, Light, Material, MeshBuilder, Scene, Surface, Texture};
use crate::error::{Error, Result};

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
    warnings: &mut Vec<String>,
) -> Material {
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
    let diffuse_texture = m.diffuse_texture.as_ref().and_then(|name| {
        let path = dir.join(name.replace('\\', "/"));
        match image::open(&path) {
            Ok(img) => {
                let rgba = img.to_rgba8();
                textures.push(Texture {
                    name: path.display().to_string(),
                    width: rgba.width(),
                    height: rgba.height(),
                    rgba: rgba.into_raw(),
                });
                Some(textures.len() as u32 - 1)
            }
            Err(e) => {
                warnings.push(format!(
                    "material {}: texture {}: {e}; using Kd alone",
                    m.name,
                    path.display()
                ));
                None
            }
        }
    });
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
    Material {
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
    }
}

/// Loads an OBJ (and its MTL files and textures) into a [`MeshBuilder`].
pub fn load_into(path: &Path, b: &mut MeshBuilder, warnings: &mut Vec<String>) -> Result<()> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(path, &options).map_err(|e| Error::Obj {
        path: path.to_path_buf(),
        message: match e {
            tobj::LoadError::OpenFileFailed => "cannot open the file".into(),
            other => other.to_string(),
        },
    })?;
    let dir = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
    let materials = materials.unwrap_or_else(|e| {
        warnings.push(format!(
            "{}: its MTL could not be loaded ({e}); using grey",
            path.display()
        ));
        Vec::new()
    });
    let mut textures = Vec::new();
    let converted: Vec<Material> = materials
        .iter()
        .map(|m| material(m, &mut textures, &dir, warnings))
        .collect();
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
    for model in &models {
        let mesh = &model.mesh;
        let material = mesh.material_id.map_or(default, |m| base + m as u32);
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
        let mut dropped = 0;
        for face in mesh.indices.chunks_exact(3) {
            let corners = [face[0], face[1], face[2]].map(position);
            if !corners.iter().all(|p| p.is_finite()) {
                dropped += 1;
                continue;
            }
            let normals = (!mesh.normals.is_empty())
                .then(|| [face[0], face[1], face[2]].map(normal))
                .filter(|n| n.iter().all(|n| n.is_finite() && n.length_squared() > 0.0));
            let uvs = (!mesh.texcoords.is_empty()).then(|| [face[0], face[1], face[2]].map(uv));
            b.triangle(corners, normals, uvs, material);
        }
        if dropped > 0 {
            warnings.push(format!(
                "{}: mesh {:?}: dropped {dropped} triangles with non-finite vertices",
                path.display(),
                model.name
            ));
        }
    }
    Ok(())
}

/// The sky of scenes that do not set one.
pub const DEFAULT_SKY: Vec3 = Vec3::new(0.35, 0.4, 0.5);
/// The ambient light of scenes that do not set one.
pub const DEFAULT_AMBIENT: Vec3 = Vec3::splat(0.08);

/// A camera that frames the box `lo`..`hi` from the front (+z, slightly above) at 1.3 bounding
/// radii, whatever its units or offset, with a headlight at the camera and a sun.
pub fn framing(lo: DVec3, hi: DVec3) -> (Camera, Vec<Light>) {
    let centre = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(1e-6);
    let position = centre + DVec3::new(0.0, 0.3 * radius, 1.3 * radius);
    let lights = vec![
        Light::Point {
            position,
            intensity: Vec3::splat((0.6 * (1.3 * radius).powi(2)) as f32),
        },
        Light::Directional {
            direction: DVec3::new(-0.3, -1.0, -0.4).normalize(),
            irradiance: Vec3::splat(0.6),
        },
    ];
    let camera = Camera {
        position,
        look_at: centre,
        up: DVec3::Y,
    };
    (camera, lights)
}

/// A bare OBJ as a scene, [`framing`] its bounds so that any OBJ shows something.
pub fn load_obj(path: &Path) -> Result<Loaded> {
    let mut b = MeshBuilder::new();
    let mut warnings = Vec::new();
    load_into(path, &mut b, &mut warnings)?;
    let (lo, hi) = b.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
    let (camera, lights) = framing(lo, hi);
    let scene = b.finish(lights, DEFAULT_SKY, DEFAULT_AMBIENT, camera);
    Ok(Loaded { scene, warnings })
}

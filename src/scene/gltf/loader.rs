//! The walk over a glTF scene's nodes: transforms composed, meshes flattened or instanced,
//! materials, textures, lights and cameras mapped to this project's scene.

/// Nodes nested deeper than this are refused (glTF's hierarchy is a tree; no stack overflow on
/// hostile input).
pub(super) const MAX_DEPTH: usize = 256;

/// Node visits (a node as often as the hierarchy reaches it) beyond which a file is refused:
/// the spec makes the hierarchy a tree, but a file may share children between parents and
/// reach the same nodes exponentially often.
pub(super) const MAX_NODE_VISITS: usize = 1 << 20;

/// What a glTF file gives beyond its triangles and materials.
pub struct Content {
    /// Its lights, world space.
    pub lights: Vec<Light>,
    /// Its camera nodes' poses, in node order of the traversal.
    pub cameras: Vec<Camera>,
}

use super::animation::NodeKeys;
use super::uri::{Missing, uri_data};
use crate::error::{Error, Result};
use crate::scene::animation::{Animation, Factor, Trs};
use crate::scene::obj::Dropped;
use crate::scene::{Camera, Light, Material, MeshBuilder, MeshId, ReadFile, Surface, Texture};
use glam::{DAffine3, DMat4, DQuat, DVec3, Vec2, Vec3};
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

pub(super) struct Loader<'a> {
    pub(super) path: &'a Path,
    pub(super) dir: &'a Path,
    pub(super) read: ReadFile<'a>,
    pub(super) buffers: &'a [Vec<u8>],
    /// Our material of each glTF material (`None`: the default material).
    pub(super) materials: HashMap<Option<usize>, u32>,
    /// Our texture of each glTF texture (`None`: it could not be loaded).
    pub(super) textures: HashMap<usize, Option<u32>>,
    /// How many nodes use each glTF mesh: those used more than once are instanced.
    pub(super) uses: HashMap<usize, usize>,
    /// The stored mesh of each instanced glTF mesh.
    pub(super) meshes: HashMap<usize, MeshId>,
    /// Nodes visited so far.
    pub(super) visits: usize,
    /// The animations' keys, by node.
    pub(super) keyed: HashMap<usize, NodeKeys>,
    pub(super) content: Content,
    /// Features left out, for one warning each.
    pub(super) ignored: BTreeSet<String>,
    pub(super) warnings: &'a mut Vec<String>,
}

impl Loader<'_> {
    pub(super) fn fail(&self, message: String) -> Error {
        Error::Gltf {
            path: self.path.to_path_buf(),
            message,
        }
    }

    /// Adds a node and its children under `parent`'s transform; `ancestors` are the indices
    /// of the nodes above it, root first; `moving`, where an animation keys one of them, the
    /// factors of their placement.
    pub(super) fn node(
        &mut self,
        node: &gltf::Node,
        parent: DMat4,
        moving: &[Factor],
        ancestors: &mut Vec<usize>,
        b: &mut MeshBuilder,
    ) -> Result<()> {
        if let Some(at) = ancestors.iter().position(|&a| a == node.index()) {
            let chain: Vec<String> = ancestors[at..]
                .iter()
                .chain([&node.index()])
                .map(|i| format!("nodes[{i}]"))
                .collect();
            return Err(self.fail(format!(
                "nodes[{}] lists nodes[{}] as a child, which is its own ancestor: the hierarchy \
                 has a cycle ({})",
                ancestors.last().expect("a node's own ancestor is above it"),
                node.index(),
                chain.join(" -> ")
            )));
        }
        if ancestors.len() > MAX_DEPTH {
            return Err(self.fail(format!(
                "nodes[{}]: the hierarchy is deeper than {MAX_DEPTH} nodes",
                node.index()
            )));
        }
        self.visits += 1;
        if self.visits > MAX_NODE_VISITS {
            return Err(self.fail(format!(
                "nodes[{}]: the hierarchy reaches more than {MAX_NODE_VISITS} nodes (are \
                 children shared between parents?)",
                node.index()
            )));
        }
        let local = match node.transform() {
            gltf::scene::Transform::Matrix { matrix } => {
                DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
            }
            gltf::scene::Transform::Decomposed {
                translation,
                rotation,
                scale,
            } => {
                let [x, y, z, w] = rotation.map(f64::from);
                DMat4::from_scale_rotation_translation(
                    Vec3::from(scale).as_dvec3(),
                    DQuat::from_xyzw(x, y, z, w).normalize(),
                    Vec3::from(translation).as_dvec3(),
                )
            }
        };
        let world = parent * local;
        if !world.is_finite() {
            return Err(self.fail(format!(
                "nodes[{}]: its transform is not finite",
                node.index()
            )));
        }
        // Where it or a node above it is animated: its placement's factors (the still part
        // above the first keyed node in one), and its placement at time 0.
        let mut factors = moving.to_vec();
        if let Some(keys) = self.keyed.get(&node.index()) {
            let gltf::scene::Transform::Decomposed {
                translation,
                rotation,
                scale,
            } = node.transform()
            else {
                return Err(self.fail(format!(
                    "nodes[{}]: an animation keys it, and its transform is a matrix (glTF \
                     animates nodes given by translation, rotation and scale)",
                    node.index()
                )));
            };
            if factors.is_empty() {
                factors.push(Factor::Fixed(DAffine3::from_mat4(parent)));
            }
            let [x, y, z, w] = rotation.map(f64::from);
            factors.push(Factor::Keyed(Trs {
                translation: Vec3::from(translation).as_dvec3(),
                rotation: DQuat::from_xyzw(x, y, z, w).normalize(),
                scale: Vec3::from(scale).as_dvec3(),
                translation_keys: keys.translation.clone(),
                rotation_keys: keys.rotation.clone(),
                scale_keys: keys.scale.clone(),
            }));
        } else if !factors.is_empty() {
            factors.push(Factor::Fixed(DAffine3::from_mat4(local)));
        }
        let animation = (!factors.is_empty()).then(|| Animation {
            factors: factors.clone(),
        });
        let affine = match &animation {
            Some(a) => a.at(0.0),
            None => DAffine3::from_mat4(world),
        };
        if !affine.is_finite() {
            return Err(self.fail(format!(
                "nodes[{}]: its animated transform at time 0 is not finite",
                node.index()
            )));
        }
        if let Some(mesh) = node.mesh() {
            // Its label: the node's name, and the class its extras (or its mesh's) give,
            // else the mesh's name.
            let name = node
                .name()
                .map_or_else(|| format!("nodes[{}]", node.index()), String::from);
            let class = class_of(node.extras())
                .or_else(|| class_of(mesh.extras()))
                .or_else(|| mesh.name().map(String::from))
                .unwrap_or_else(|| name.clone());
            b.object(&name, &class);
            if node.skin().is_some() {
                self.ignored.insert("skins".into());
            }
            // A mesh that moves, or that several nodes use, is stored once in its own space.
            let shared = self.uses.get(&mesh.index()).is_some_and(|&n| n > 1);
            if shared || animation.is_some() {
                let id = match self.meshes.get(&mesh.index()) {
                    Some(&id) => id,
                    None => {
                        let first = b.len();
                        self.mesh(&mesh, DAffine3::IDENTITY, b)?;
                        let id = b.mesh_since(first);
                        self.meshes.insert(mesh.index(), id);
                        id
                    }
                };
                let placed = match &animation {
                    Some(a) => b.place_moving(id, a.clone()),
                    None => b.place(id, affine),
                };
                if !placed {
                    self.ignored
                        .insert("nodes whose transform flattens a shared mesh".into());
                }
            } else {
                self.mesh(&mesh, affine, b)?;
            }
        }
        if animation.is_some() && (node.light().is_some() || node.camera().is_some()) {
            self.ignored.insert(
                "the motion of animated lights and cameras (they stay where they are at time \
                 0)"
                .into(),
            );
        }
        if let Some(light) = node.light() {
            self.light(&light, affine);
        }
        if node.camera().is_some() {
            let position = affine.translation;
            let forward = -affine.matrix3.z_axis;
            let up = affine.matrix3.y_axis;
            if forward.length_squared() > 0.0 && up.length_squared() > 0.0 {
                self.content.cameras.push(Camera {
                    position,
                    look_at: position + forward.normalize(),
                    up: up.normalize(),
                });
            }
        }
        ancestors.push(node.index());
        for child in node.children() {
            self.node(&child, world, &factors, ancestors, b)?;
        }
        ancestors.pop();
        Ok(())
    }

    pub(super) fn light(&mut self, light: &gltf::khr_lights_punctual::Light, at: DAffine3) {
        use gltf::khr_lights_punctual::Kind;
        let colour = Vec3::from(light.color()) * light.intensity() / 683.0;
        match light.kind() {
            Kind::Directional => {
                let direction = -at.matrix3.z_axis.normalize_or_zero();
                if direction == DVec3::ZERO {
                    self.ignored
                        .insert("directional lights whose nodes scale to nothing".into());
                    return;
                }
                self.content.lights.push(Light::Directional {
                    direction,
                    irradiance: colour,
                });
            }
            kind => {
                if matches!(kind, Kind::Spot { .. }) {
                    self.ignored
                        .insert("spot lights' cones (they light as points)".into());
                }
                self.content.lights.push(Light::Point {
                    position: at.translation,
                    intensity: colour,
                });
            }
        }
    }

    pub(super) fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        at: DAffine3,
        b: &mut MeshBuilder,
    ) -> Result<()> {
        for primitive in mesh.primitives() {
            let what = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            if primitive.morph_targets().next().is_some() {
                self.ignored.insert("morph targets".into());
            }
            let mode = primitive.mode();
            use gltf::mesh::Mode;
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.ignored.insert("points and lines".into());
                continue;
            }
            self.check_types(&primitive, &what)?;
            let material = self.material(&primitive.material(), b)?;
            let buffers = self.buffers;
            let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(Vec::as_slice));
            let accessor = |semantic: gltf::Semantic| primitive.get(&semantic).map(|a| a.index());
            let beyond = |index: Option<usize>| {
                format!(
                    "{what}: accessors[{}] reaches beyond its buffer",
                    index.map_or("?".into(), |i| i.to_string())
                )
            };
            let Some(positions) = reader.read_positions() else {
                return match accessor(gltf::Semantic::Positions) {
                    None => Err(self.fail(format!("{what}: no POSITION attribute"))),
                    index => Err(self.fail(beyond(index))),
                };
            };
            let positions: Vec<DVec3> = positions.map(|p| Vec3::from(p).as_dvec3()).collect();
            let count = positions.len();
            let normals: Option<Vec<Vec3>> = match reader.read_normals() {
                Some(n) => Some(n.map(Vec3::from).collect()),
                None if accessor(gltf::Semantic::Normals).is_some() => {
                    return Err(self.fail(beyond(accessor(gltf::Semantic::Normals))));
                }
                None => None,
            };
            let uvs: Option<Vec<Vec2>> = match reader.read_tex_coords(0) {
                // glTF puts v = 0 at the image's top; the shaders, as OBJ, at its bottom.
                Some(t) => Some(t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect()),
                None if accessor(gltf::Semantic::TexCoords(0)).is_some() => {
                    return Err(self.fail(beyond(accessor(gltf::Semantic::TexCoords(0)))));
                }
                None => None,
            };
            for (name, len) in [
                ("NORMAL", normals.as_ref().map(Vec::len)),
                ("TEXCOORD_0", uvs.as_ref().map(Vec::len)),
            ] {
                if len.is_some_and(|n| n != count) {
                    return Err(self.fail(format!(
                        "{what}: {name} has {} values for {count} positions",
                        len.unwrap_or(0)
                    )));
                }
            }
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None if primitive.indices().is_some() => {
                    return Err(self.fail(beyond(primitive.indices().map(|a| a.index()))));
                }
                None => (0..count as u32).collect(),
            };
            if let Some(&bad) = indices.iter().find(|&&i| i as usize >= count) {
                return Err(self.fail(format!(
                    "{what}: index {bad} in accessors[{}] is beyond its {count} vertices",
                    primitive.indices().map_or(0, |a| a.index())
                )));
            }
            let faces: Vec<[u32; 3]> = match mode {
                Mode::TriangleStrip => (2..indices.len())
                    .map(|k| {
                        let (a, b, c) = (indices[k - 2], indices[k - 1], indices[k]);
                        if k % 2 == 0 { [a, b, c] } else { [b, a, c] }
                    })
                    .collect(),
                Mode::TriangleFan => (2..indices.len())
                    .map(|k| [indices[0], indices[k - 1], indices[k]])
                    .collect(),
                _ => indices
                    .chunks_exact(3)
                    .map(|f| [f[0], f[1], f[2]])
                    .collect(),
            };
            let first = b.len();
            let mut dropped = Dropped::default();
            for face in faces {
                let corners = face.map(|i| at.transform_point3(positions[i as usize]));
                if !dropped.keeps(&corners) {
                    continue;
                }
                let local = face.map(|i| positions[i as usize]);
                let normal = normals
                    .as_ref()
                    .map(|n| face.map(|i| n[i as usize]))
                    .filter(|n| n.iter().all(|n| n.is_finite() && n.length_squared() > 0.0));
                let uv = uvs.as_ref().map(|t| face.map(|i| t[i as usize]));
                b.triangle(local, normal, uv, material);
            }
            b.transform_since(first, at);
            let path = self.path.display().to_string();
            dropped.warn(|w| self.warnings.push(format!("{path}: {what}: {w}")));
        }
        Ok(())
    }

    /// Refuses accessors of a type the spec does not allow where they are used (the gltf
    /// crate's validation does not check them, and its readers assume them: found by
    /// fuzzing).
    pub(super) fn check_types(&self, primitive: &gltf::Primitive, what: &str) -> Result<()> {
        use gltf::accessor::{DataType as D, Dimensions as N};
        let allowed: [(Option<gltf::Accessor>, &str, &[D], N); 4] = [
            (
                primitive.get(&gltf::Semantic::Positions),
                "POSITION",
                &[D::F32],
                N::Vec3,
            ),
            (
                primitive.get(&gltf::Semantic::Normals),
                "NORMAL",
                &[D::F32],
                N::Vec3,
            ),
            (
                primitive.get(&gltf::Semantic::TexCoords(0)),
                "TEXCOORD_0",
                &[D::F32, D::U8, D::U16],
                N::Vec2,
            ),
            (
                primitive.indices(),
                "indices",
                &[D::U8, D::U16, D::U32],
                N::Scalar,
            ),
        ];
        for (accessor, name, types, dimensions) in allowed {
            let Some(accessor) = accessor else { continue };
            if !types.contains(&accessor.data_type()) || accessor.dimensions() != dimensions {
                return Err(self.fail(format!(
                    "{what}: {name} is accessors[{}], of {:?} {:?}; it must be {dimensions:?} \
                     of {types:?}",
                    accessor.index(),
                    accessor.dimensions(),
                    accessor.data_type()
                )));
            }
        }
        Ok(())
    }

    /// Our material for a glTF material (made at its first use).
    pub(super) fn material(&mut self, m: &gltf::Material, b: &mut MeshBuilder) -> Result<u32> {
        if let Some(&id) = self.materials.get(&m.index()) {
            return Ok(id);
        }
        let pbr = m.pbr_metallic_roughness();
        let [r, g, bl, alpha] = pbr.base_color_factor();
        let base = Vec3::new(r, g, bl);
        let name = m.name().map_or_else(
            || format!("material {}", m.index().map_or(-1, |i| i as i64)),
            String::from,
        );
        let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
        let metallic = pbr.metallic_factor().clamp(0.0, 1.0);
        let roughness = pbr.roughness_factor().clamp(0.0, 1.0);
        let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
        let opacity = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => 1.0,
            gltf::material::AlphaMode::Mask => {
                f32::from(u8::from(alpha >= m.alpha_cutoff().unwrap_or(0.5)))
            }
            gltf::material::AlphaMode::Blend => alpha.clamp(0.0, 1.0),
        };
        let mut material = if transmission >= 0.5 {
            Material {
                transmission: base,
                ..Material::glass(&name, m.ior().unwrap_or(1.5))
            }
        } else if metallic >= 0.5 && roughness <= 0.25 {
            Material::mirror(&name, base)
        } else {
            let a = (roughness * roughness).max(1e-3);
            Material {
                specular: Vec3::splat(0.04).lerp(base, metallic),
                shininess: (2.0 / (a * a) - 2.0).clamp(1.0, 1e4),
                ..Material::diffuse(&name, base * (1.0 - metallic))
            }
        };
        material.emission = emission;
        material.opacity = opacity;
        if let Some(info) = pbr.base_color_texture() {
            if info.tex_coord() != 0 {
                self.ignored
                    .insert("texture coordinate sets other than the first".into());
            }
            if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
                self.ignored
                    .insert("alpha from base colour textures".into());
            }
            if material.surface == Surface::Diffuse {
                material.diffuse_texture = self.texture(&info.texture(), b)?;
            }
        }
        for (present, feature) in [
            (m.normal_texture().is_some(), "normal textures"),
            (m.occlusion_texture().is_some(), "occlusion textures"),
            (m.emissive_texture().is_some(), "emissive textures"),
            (
                pbr.metallic_roughness_texture().is_some(),
                "metallic-roughness textures",
            ),
        ] {
            if present {
                self.ignored.insert(feature.into());
            }
        }
        let id = b.material(material);
        self.materials.insert(m.index(), id);
        Ok(id)
    }

    /// Our texture for a glTF texture, or `None` (warned) where its image is missing or cannot
    /// be decoded; an error for a special or oversized file or a bad URI.
    pub(super) fn texture(
        &mut self,
        texture: &gltf::Texture,
        b: &mut MeshBuilder,
    ) -> Result<Option<u32>> {
        if let Some(&id) = self.textures.get(&texture.index()) {
            return Ok(id);
        }
        use gltf::texture::{MagFilter, WrappingMode};
        let sampler = texture.sampler();
        if sampler.wrap_s() != WrappingMode::Repeat || sampler.wrap_t() != WrappingMode::Repeat {
            self.ignored
                .insert("texture wrap modes other than repeat (textures repeat)".into());
        }
        if sampler.mag_filter() == Some(MagFilter::Nearest) {
            self.ignored
                .insert("nearest texture filtering (textures are filtered linearly)".into());
        }
        let image = texture.source();
        let what = format!("images[{}]", image.index());
        let bytes = match image.source() {
            gltf::image::Source::View { view, .. } => self
                .buffers
                .get(view.buffer().index())
                .and_then(|data| data.get(view.offset()..view.offset() + view.length()))
                .map(<[u8]>::to_vec)
                .ok_or_else(|| {
                    Missing::Bad(format!(
                        "bufferViews[{}] reaches beyond its buffer",
                        view.index()
                    ))
                }),
            gltf::image::Source::Uri { uri, .. } => uri_data(uri, self.dir, self.read),
        };
        let decoded = match bytes {
            Ok(bytes) => {
                image::load_from_memory(&bytes).map_err(|e| format!("cannot decode it: {e}"))
            }
            Err(Missing::NotFound(e)) => Err(e),
            Err(Missing::Bad(e)) => return Err(self.fail(format!("{what}: {e}"))),
        };
        let id = match decoded {
            Ok(decoded) => {
                let rgba = decoded.to_rgba8();
                Some(b.texture(Texture {
                    name: format!("{} {what}", self.path.display()),
                    width: rgba.width(),
                    height: rgba.height(),
                    rgba: rgba.into_raw(),
                }))
            }
            Err(e) => {
                self.warnings.push(format!(
                    "{}: {what}: {e}; its materials use their base colour factor alone",
                    self.path.display()
                ));
                None
            }
        };
        self.textures.insert(texture.index(), id);
        Ok(id)
    }
}

/// The `class` (or `semantic`, `category`) string of a glTF object's `extras`, if it has one.
fn class_of(extras: &gltf::json::Extras) -> Option<String> {
    let value: serde_json::Value = serde_json::from_str(extras.as_ref()?.get()).ok()?;
    ["class", "semantic", "category"]
        .iter()
        .find_map(|key| value.get(key)?.as_str().map(String::from))
}

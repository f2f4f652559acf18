//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, `.glb`) through the `gltf`
//! crate's document model and validation. Buffers and images are read here, through the
//! loader's `read` (so within the input budgets). A mesh that one node uses is placed in world
//! space; a mesh that several nodes use, or that an animation moves, is stored once, in its
//! own space, and each node places an instance of it (see [`crate::scene::Instance`]).
//!
//! What maps to what (the README's table says the same):
//! - the default scene (or the one asked for), its node hierarchy with TRS or matrix transforms;
//! - triangle primitives (strips and fans split into triangles; points and lines skipped with a
//!   warning), u8/u16/u32 and sparse accessors, normals, the first UV set (v flipped to the
//!   OBJ convention the shaders use);
//! - materials: base colour factor and texture (sRGB); emissive factor times
//!   `KHR_materials_emissive_strength`; `KHR_materials_transmission` ≥ 0.5 is glass of
//!   `KHR_materials_ior` (1.5 by default) tinted by the base colour; else metallic ≥ 0.5 with
//!   roughness ≤ 0.25 is a mirror tinted by the base colour; else a diffuse of base colour × (1 -
//!   metallic) with a Phong lobe of F0 = mix(0.04, base, metallic) and exponent 2/α² - 2 (α =
//!   roughness², Walter et al.'s Beckmann–Phong correspondence), 1 to 10⁴; alpha `MASK` is opacity
//!   0 or 1 by the cutoff, `BLEND` the factor's alpha;
//! - `KHR_lights_punctual`: point lights (candela / 683 lm/W as W/sr), directional (lux / 683 as
//!   W/m²), spot lights as points without their cone (warned);
//! - camera nodes: their poses (looking down the node's -z, up its +y), for `--camera gltf:N`;
//! - animations' translation, rotation and scale channels (step, linear, cubic spline): a
//!   mesh under a keyed node is placed by a moving instance ([`crate::scene::animation`]);
//! - anything else (morph-target weights, skins, morph targets, other textures, other
//!   extensions, sampler modes other than repeat and linear) is left out with one warning per
//!   feature.

mod animation;
mod loader;
mod uri;

pub use loader::Content;
use loader::{Loader, MAX_DEPTH, MAX_NODE_VISITS};
use uri::*;

use std::collections::{BTreeSet, HashMap};
use std::path::Path;

use glam::{DMat4, DVec3};

use super::obj::Loaded;
use super::{MeshBuilder, ReadFile};
use crate::error::{Error, Result};
use crate::input::InputKind;

/// Extensions whose content is used (others are warned about).
const USED_EXTENSIONS: [&str; 4] = [
    "KHR_lights_punctual",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_emissive_strength",
];

/// Loads the glTF file at `path` (and the files it names, through `read`) into `b`: the scene
/// `scene` (else the document's default, else its first). Warnings name what was left out.
pub fn load_into(
    path: &Path,
    read: ReadFile,
    scene: Option<usize>,
    b: &mut MeshBuilder,
    warnings: &mut Vec<String>,
) -> Result<Content> {
    let fail = |message: String| Error::Gltf {
        path: path.to_path_buf(),
        message,
    };
    let bytes =
        read(path, InputKind::Gltf).map_err(|e| fail(format!("cannot read the file: {e}")))?;
    // The gltf crate subtracts the 12-byte header from the GLB's declared length unchecked
    // (an overflow where overflow checks are on; found by fuzzing).
    if let Some(length) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
        .filter(|&l| l < 12)
    {
        return Err(fail(format!(
            "not valid glTF: the GLB header declares {length} bytes, less than the header itself"
        )));
    }
    let unchecked = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| fail(format!("not valid glTF: {e}")))?;
    let blob = unchecked.blob;
    let json = unchecked.document.into_json();
    // gltf-json's validation reads a primitive's POSITION accessor before it checks that the
    // index exists (and panics if not; found by fuzzing): check attribute indices first.
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive
                .attributes
                .values()
                .find(|i| i.value() >= json.accessors.len())
            {
                return Err(fail(format!(
                    "not valid glTF: meshes[{m}].primitives[{p}] names accessors[{}], and \
                     there are {}",
                    index.value(),
                    json.accessors.len()
                )));
            }
        }
    }
    // Its image accessor unwraps an image's mimeType (with a bufferView) or uri (without).
    for (i, image) in json.images.iter().enumerate() {
        let complete = match image.buffer_view {
            Some(_) => image.mime_type.is_some(),
            None => image.uri.is_some(),
        };
        if !complete {
            return Err(fail(format!(
                "not valid glTF: images[{i}] needs a uri, or a bufferView with a mimeType"
            )));
        }
    }
    let document =
        &gltf::Document::from_json(json).map_err(|e| fail(format!("not valid glTF: {e}")))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let buffers: Vec<Vec<u8>> = document
        .buffers()
        .map(|buffer| {
            let what = format!("buffers[{}]", buffer.index());
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => blob
                    .clone()
                    .ok_or_else(|| fail(format!("{what}: no binary chunk in the file")))?,
                gltf::buffer::Source::Uri(uri) => {
                    uri_data(uri, dir, read).map_err(|e| fail(format!("{what}: {}", e.text())))?
                }
            };
            if data.len() < buffer.length() {
                return Err(fail(format!(
                    "{what} holds {} bytes, not the {} it declares",
                    data.len(),
                    buffer.length()
                )));
            }
            Ok(data)
        })
        .collect::<Result<_>>()?;
    let mut ignored = BTreeSet::new();
    let keyed = animation::read(document, &buffers, &mut ignored).map_err(fail)?;
    if document.skins().next().is_some() {
        ignored.insert("skins".to_string());
    }
    for extension in document.extensions_used() {
        if !USED_EXTENSIONS.contains(&extension) {
            ignored.insert(format!("the extension {extension}"));
        }
    }
    let chosen = match scene {
        Some(n) => document.scenes().nth(n).ok_or_else(|| {
            fail(format!(
                "no scene {n}: the file has {}",
                document.scenes().count()
            ))
        })?,
        None => document
            .default_scene()
            .or_else(|| document.scenes().next())
            .ok_or_else(|| fail("no scene to render".into()))?,
    };
    // Meshes that several nodes use are stored once and placed by instances.
    let mut uses = HashMap::new();
    let mut visits = 0;
    for node in chosen.nodes() {
        count_uses(&node, 0, &mut visits, &mut uses);
    }
    let mut loader = Loader {
        path,
        dir,
        read,
        buffers: &buffers,
        uses,
        meshes: HashMap::new(),
        visits: 0,
        keyed,
        materials: HashMap::new(),
        textures: HashMap::new(),
        content: Content {
            lights: Vec::new(),
            cameras: Vec::new(),
        },
        ignored,
        warnings,
    };
    for node in chosen.nodes() {
        loader.node(&node, DMat4::IDENTITY, &[], &mut Vec::new(), b)?;
    }
    let Loader {
        ignored,
        warnings,
        content,
        ..
    } = loader;
    for what in ignored {
        warnings.push(format!("{}: {what} not rendered", path.display()));
    }
    Ok(content)
}

/// Counts the nodes under `node` (itself included) that use each mesh, up to [`MAX_DEPTH`]
/// levels and [`MAX_NODE_VISITS`] nodes (where loading stops with an error anyway).
fn count_uses(
    node: &gltf::Node,
    depth: usize,
    visits: &mut usize,
    uses: &mut HashMap<usize, usize>,
) {
    *visits += 1;
    if depth > MAX_DEPTH || *visits > MAX_NODE_VISITS {
        return;
    }
    if let Some(mesh) = node.mesh() {
        *uses.entry(mesh.index()).or_default() += 1;
    }
    for child in node.children() {
        count_uses(&child, depth + 1, visits, uses);
    }
}

/// A glTF file as a scene: its lights (else a headlight and a sun), its first camera (else a
/// view framing its bounds), and its cameras for `--camera gltf:N`.
pub fn load_gltf(path: &Path, scene: Option<usize>) -> Result<Loaded> {
    load_gltf_from(path, &super::disk, scene)
}

/// As [`load_gltf`], reading the files through `read`.
pub fn load_gltf_from(path: &Path, read: ReadFile, scene: Option<usize>) -> Result<Loaded> {
    let mut b = MeshBuilder::new();
    let mut warnings = Vec::new();
    let content = load_into(path, read, scene, &mut b, &mut warnings)?;
    if b.is_empty() {
        return Err(Error::Gltf {
            path: path.to_path_buf(),
            message: format!("no triangles to render{}", super::obj::because(&warnings)),
        });
    }
    let (lo, hi) = b.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
    let given = content.cameras.first().copied();
    let camera = given.unwrap_or_else(|| super::obj::framing(lo, hi, super::obj::DEFAULT_DISTANCE));
    let lit = !content.lights.is_empty();
    let lights = if lit {
        content.lights
    } else {
        super::obj::headlight_and_sun(&camera)
    };
    let mut scene = b.finish(
        lights,
        super::obj::DEFAULT_SKY,
        super::obj::DEFAULT_AMBIENT,
        camera,
    );
    scene.cameras = content.cameras;
    if !lit {
        scene.headlight = Some(0);
    }
    if given.is_none() {
        scene.framed = Some((lo, hi));
    }
    Ok(Loaded { scene, warnings })
}

//! A glTF buffer's or image's URI: a `data:` URI decoded, or a file beside the glTF file read
//! within the input budget.

//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, `.glb`) through the `gltf`
//! crate's document model and validation. Buffers and images are read here, through the
//! loader's `read` (so within the input budgets). A mesh that one node uses is placed in world
//! space; a mesh that several nodes use is stored once, in its own space, and each node places
//! an instance of it (see [`crate::scene::Instance`]).
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
//! - anything else (animations, skins, morph targets, other textures, other extensions, sampler
//!   modes other than repeat and linear) is left out with one warning per feature.

use crate::error::Result;
use crate::input::InputKind;
use crate::scene::ReadFile;
use base64::Engine;
use std::path::Path;

/// Why a URI's bytes could not be had.
pub(super) enum Missing {
    /// The file does not exist (a missing image is a warning).
    NotFound(String),
    /// Anything else: a bad URI, a special or oversized file (always an error).
    Bad(String),
}

impl Missing {
    pub(super) fn text(self) -> String {
        match self {
            Missing::NotFound(t) | Missing::Bad(t) => t,
        }
    }
}

/// The bytes of a URI: a `data:` URI's base64, or a file relative to the glTF's folder.
pub(super) fn uri_data(uri: &str, dir: &Path, read: ReadFile) -> Result<Vec<u8>, Missing> {
    if let Some(data) = uri.strip_prefix("data:") {
        let (header, payload) = data
            .split_once(',')
            .ok_or_else(|| Missing::Bad("a data URI without a comma".into()))?;
        if !header.ends_with(";base64") {
            return Err(Missing::Bad("a data URI that is not base64".into()));
        }
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| Missing::Bad(format!("its data URI is not valid base64: {e}")));
    }
    let name = percent_decoded(uri).map_err(Missing::Bad)?;
    let file = dir.join(&name);
    read(&file, InputKind::Gltf).map_err(|e| {
        let text = format!("{}: {e}", file.display());
        if e.kind() == std::io::ErrorKind::NotFound {
            Missing::NotFound(text)
        } else {
            Missing::Bad(text)
        }
    })
}

/// A relative URI's path with its `%XX` escapes decoded.
pub(super) fn percent_decoded(uri: &str) -> Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = uri
                .get(i + 1..i + 3)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("the URI {uri:?} has a bad % escape"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("the URI {uri:?} is not UTF-8"))
}

//! A glTF buffer's or image's URI: a `data:` URI decoded, or a file beside the glTF file read
//! within the input budget.

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

//! The library's errors. Every variant names what was wrong and, where it helps, what to do.

use thiserror::Error;

/// A bad lens, lens spec or image size.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum LensError {
    /// A numeric lens parameter outside its range.
    #[error("lens parameter {name} = {value}: {reason}")]
    Parameter {
        /// The parameter's name as written in specs (`f`, `k1`, `k2`, `fov`).
        name: &'static str,
        /// The offending value (degrees for `fov`).
        value: f64,
        /// The range it must lie in.
        reason: &'static str,
    },
    /// A lens spec that does not parse.
    #[error("lens spec {spec:?}: {reason}")]
    Spec {
        /// The spec as given.
        spec: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A field of view the model cannot reach: its mapping turns back (a non-monotonic
    /// calibration) or its domain ends before.
    #[error(
        "{model}: cannot reach the requested {}° field of view: {why} at a {reach:.2}° field \
         of view",
        (fov * 1e6).round() / 1e6
    )]
    Unreachable {
        /// The model's spec name.
        model: &'static str,
        /// The requested full field of view, degrees.
        fov: f64,
        /// The widest full field of view it reaches, degrees.
        reach: f64,
        /// Why it ends there.
        why: &'static str,
    },
    /// A calibration file that cannot be read.
    #[error("calibration file {path}: {reason}")]
    Calibration {
        /// The file.
        path: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A lens prescription that cannot be read (`line` 0: the file as a whole).
    #[error("lens prescription {path}{}: {reason}", at_line(*line))]
    Prescription {
        /// The file.
        path: String,
        /// The line at fault, from 1; 0 for the file as a whole.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A calibration format that cannot express a model.
    #[error("the {format} calibration format cannot express {model}")]
    Unsupported {
        /// The format's name.
        format: &'static str,
        /// The model's name.
        model: &'static str,
    },
    /// A model that needs a parameter that was not given.
    #[error("{model} needs {what}")]
    Needs {
        /// The model's spec name.
        model: &'static str,
        /// What it needs.
        what: &'static str,
    },
    /// An image size of 0 or beyond what we can address.
    #[error("image size {text:?}: {reason}")]
    ImageSize {
        /// The size as given.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
}

/// ", line N" for a line from 1; nothing for 0 (the file as a whole).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(", line {line}")
    }
}

impl LensError {
    pub(crate) fn parameter(name: &'static str, value: f64, reason: &'static str) -> Self {
        Self::Parameter {
            name,
            value,
            reason,
        }
    }
}

/// Any error of the library.
#[derive(Debug, Error)]
pub enum Error {
    /// No adapter was found on any enabled backend.
    #[error(
        "no GPU adapter found (backends tried: {backends}). On a machine without a GPU, install \
         a software Vulkan driver: on Debian/Ubuntu `apt-get install mesa-vulkan-drivers` \
         (Mesa 25 or later, e.g. from bookworm-backports, for ray queries)"
    )]
    NoAdapter {
        /// The backends that were enumerated.
        backends: String,
    },
    /// `WGPU_ADAPTER_NAME` matched no adapter.
    #[error("WGPU_ADAPTER_NAME={wanted:?} matches no adapter; available: {available}")]
    AdapterNotFound {
        /// The requested name (a case-insensitive substring).
        wanted: String,
        /// The adapters that exist.
        available: String,
    },
    /// The adapter refused to create a device.
    #[error("could not create a device on {adapter}: {reason}")]
    RequestDevice {
        /// The adapter's name.
        adapter: String,
        /// wgpu's reason (in the message, not a separate source: said once).
        reason: wgpu::RequestDeviceError,
    },
    /// An operation needs a device feature the adapter lacks.
    #[error("{what} needs the GPU feature {feature}, which {adapter} does not have")]
    MissingFeature {
        /// What needed it.
        what: &'static str,
        /// The wgpu feature.
        feature: &'static str,
        /// The adapter's name.
        adapter: String,
    },
    /// A validation, out-of-memory or internal error reported by wgpu.
    #[error("GPU error during {during}: {message}")]
    Gpu {
        /// The operation that failed.
        during: String,
        /// wgpu's message.
        message: String,
    },
    /// The device was lost (driver reset, GPU removed, or an earlier fatal error).
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    /// An OBJ file that could not be loaded.
    #[error("{path}: {message}")]
    Obj {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A glTF file that could not be loaded, naming the object (accessor, node, image).
    #[error("{path}: {message}")]
    Gltf {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong, and where in the document.
        message: String,
    },
    /// A scene file (TOML) that could not be read, parsed or checked.
    #[error("{path}: {message}")]
    SceneFile {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong, with the line and key where the parser knows them.
        message: String,
    },
    /// A trajectory, rig or dataset folder that cannot be used.
    #[error("{path}: {message}")]
    Dataset {
        /// The file or folder.
        path: std::path::PathBuf,
        /// What is wrong, with the line where it is in a file.
        message: String,
    },
    /// A render option out of its range (with the choices).
    #[error("{0}")]
    Option(String),
    /// Something is larger than the adapter or the kernels allow (a storage binding, a
    /// texture, the traversal stack, the bounce depth, an acceleration structure), with the
    /// numbers.
    #[error("{0}")]
    Limit(String),
    /// The device's limits are below what the kernels need.
    #[error(
        "the device's limits are too low: {0}; create it with at least \
         fisheye_rt::renderer::required_limits()"
    )]
    Limits(String),
    /// A texture handed to [`crate::renderer::Renderer`] that it cannot write (format, size
    /// or usage), with what it writes.
    #[error("the renderer cannot write {0}")]
    Target(String),
    /// A scene that cannot be rendered (with what is wrong).
    #[error("scene: {0}")]
    Scene(String),
    /// A bad lens or image size.
    #[error(transparent)]
    Lens(#[from] LensError),
    /// A file could not be read or written.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The OS's reason (in the message, not a separate source: said once).
        reason: std::io::Error,
    },
    /// A plot could not be drawn.
    #[error("{path}: {message}")]
    Plot {
        /// The plot's file.
        path: std::path::PathBuf,
        /// What went wrong.
        message: String,
    },
    /// An image could not be encoded or written.
    #[error("{path}: {reason}")]
    Image {
        /// The file.
        path: std::path::PathBuf,
        /// The encoder's reason (in the message, not a separate source: said once).
        reason: image::ImageError,
    },
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

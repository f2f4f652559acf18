//! The `fisheye_rt` Python module: lens models that map numpy arrays of pixels and directions
//! (the f64 reference, or the WGSL code on the GPU), scenes, and a renderer that uploads a
//! scene once and renders it through any lens from any pose into numpy arrays. The GIL is
//! released while the GPU (or a long CPU loop) works. Errors are Python exceptions carrying
//! the library's message: `ValueError` for bad input, `OSError` for files, `RuntimeError` for
//! the GPU.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, OnceLock};

use fisheye_rt::dataset::camera_from_transform;
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::glass::camera_for;
use fisheye_rt::lens::points::{self, PixelOrigin};
use fisheye_rt::lens::{ImageSize, LensCamera, calib};
use fisheye_rt::scene::Camera;
use fisheye_rt::trace::{
    Channel, Display, FramePass, GpuScene, PixelFilter, PixelRays, RenderOptions, RenderOutput,
    Sampling, Tone, Values, colour_image_with, rotated,
};
use fisheye_rt::{Error, LensError};
use glam::{DAffine3, DVec2, DVec3};
use numpy::ndarray::IxDyn;
use numpy::{AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The library's error as the Python exception of its kind, with its message.
fn raise(error: Error) -> PyErr {
    let message = error.to_string();
    match error {
        Error::Io { .. } | Error::Image { .. } => PyOSError::new_err(message),
        Error::NoAdapter { .. }
        | Error::AdapterNotFound { .. }
        | Error::RequestDevice { .. }
        | Error::MissingFeature { .. }
        | Error::Gpu { .. }
        | Error::DeviceLost(_)
        | Error::Limits(_)
        | Error::Limit(_) => PyRuntimeError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

fn lens_error(error: LensError) -> PyErr {
    raise(Error::Lens(error))
}

/// The one GPU context of the process, made at first use.
fn context() -> PyResult<&'static GpuContext> {
    static CONTEXT: OnceLock<GpuContext> = OnceLock::new();
    if let Some(ctx) = CONTEXT.get() {
        return Ok(ctx);
    }
    let ctx = GpuContext::new().map_err(raise)?;
    Ok(CONTEXT.get_or_init(|| ctx))
}

fn pixel_origin(name: &str) -> PyResult<PixelOrigin> {
    match name {
        "corner" => Ok(PixelOrigin::Corner),
        "opencv" => Ok(PixelOrigin::OpenCv),
        other => Err(PyValueError::new_err(format!(
            "pixel_origin={other:?}: use \"corner\" (the top-left pixel's corner at (0, 0)) or \
             \"opencv\" (its centre at (0, 0))"
        ))),
    }
}

/// An array of points, `(..., n)`: its leading shape and its points, row-major.
fn points_of<const N: usize>(
    array: &PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    what: &str,
) -> PyResult<(Vec<usize>, Vec<[f64; N]>)> {
    let view = array.as_array();
    let shape = view.shape().to_vec();
    if shape.last() != Some(&N) {
        return Err(PyValueError::new_err(format!(
            "{what} has shape {shape:?}; give an array of shape (..., {N})"
        )));
    }
    let values: Vec<f64> = view.iter().copied().collect();
    let points = values
        .chunks_exact(N)
        .map(|c| <[f64; N]>::try_from(c).expect("chunks of N"))
        .collect();
    Ok((shape[..shape.len() - 1].to_vec(), points))
}

/// One point of `N` finite numbers (a tuple, a list or a numpy array).
fn point_of<const N: usize>(
    array: &PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    what: &str,
) -> PyResult<[f64; N]> {
    let view = array.as_array();
    let values: Vec<f64> = view.iter().copied().collect();
    match <[f64; N]>::try_from(values) {
        Ok(point) if view.ndim() == 1 && point.iter().all(|v| v.is_finite()) => Ok(point),
        Ok(point) if view.ndim() == 1 => Err(PyValueError::new_err(format!(
            "{what}={point:?}: give finite numbers"
        ))),
        _ => Err(PyValueError::new_err(format!(
            "{what} has shape {:?}; give {N} numbers",
            view.shape()
        ))),
    }
}

/// `values` as an array of shape `leading + (n,)`.
fn array_of<'py>(
    py: Python<'py>,
    leading: &[usize],
    n: usize,
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let mut shape = leading.to_vec();
    shape.push(n);
    PyArray1::from_vec(py, values).reshape(IxDyn(&shape))
}

/// A lens at an image size: a classic model or a calibrated camera.
#[pyclass(frozen, module = "fisheye_rt")]
struct Lens {
    camera: LensCamera,
}

#[pymethods]
impl Lens {
    /// A lens from its spec (see `fisheye lens list`: `"samyang-7.5mm"`,
    /// `"equisolid:f=0.6,fov=180"`, `"kb:fx=...,k1=..."`, or
    /// `"prescription:FILE[,sensor=MM][,fstop=N][,focus=METRES][,rays=glass|fit][,model=kb|ds|equidistant]"`
    /// for a lens's glass: rendered through its surfaces, mapped by its chief rays) at
    /// `size = (width, height)` (a tuple, a list or a numpy array).
    #[staticmethod]
    fn from_spec(spec: &str, size: Vec<u32>) -> PyResult<Self> {
        let [width, height] = size[..] else {
            return Err(PyValueError::new_err(format!(
                "size={size:?}: give (width, height)"
            )));
        };
        let size = ImageSize::new(width, height).map_err(lens_error)?;
        Ok(Self {
            camera: camera_for(spec, size).map_err(lens_error)?,
        })
    }

    /// Camera `camera` (0 is the first) of a calibration file (OpenCV YAML/XML, a Kalibr
    /// camchain or Basalt JSON), at its calibrated size.
    #[staticmethod]
    #[pyo3(signature = (path, camera = 0))]
    fn from_calibration(path: PathBuf, camera: usize) -> PyResult<Self> {
        let cameras = calib::read(&path).map_err(lens_error)?;
        let Some(c) = cameras.get(camera) else {
            return Err(PyValueError::new_err(format!(
                "{} holds {} camera(s); camera={camera} is not one",
                path.display(),
                cameras.len()
            )));
        };
        Ok(Self {
            camera: LensCamera::new(c.lens, c.size),
        })
    }

    /// `(width, height)` in pixels.
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.camera.size.width, self.camera.size.height)
    }

    /// The lens as a spec `from_spec` reads back.
    #[getter]
    fn spec(&self) -> String {
        self.camera.lens.to_string()
    }

    fn __repr__(&self) -> String {
        format!(
            "Lens.from_spec({:?}, size=({}, {}))",
            self.spec(),
            self.camera.size.width,
            self.camera.size.height
        )
    }

    /// Unit directions (camera frame: x right, y down, z forward) of pixels, an array of shape
    /// (..., 2); rows are NaN where a pixel has no ray (outside the image or the lens's
    /// field). `pixel_origin` is "corner" (this project's: the top-left pixel's corner at
    /// (0, 0)) or "opencv" (its centre at (0, 0)). `gpu=True` runs the lens's WGSL code (f32)
    /// instead of the f64 reference.
    #[pyo3(signature = (pixels, pixel_origin = "corner", gpu = false))]
    fn unproject<'py>(
        &self,
        py: Python<'py>,
        pixels: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        pixel_origin: &str,
        gpu: bool,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let origin = self::pixel_origin(pixel_origin)?;
        let (leading, points) = points_of::<2>(&pixels, "pixels")?;
        let ctx = if gpu { Some(context()?) } else { None };
        let camera = self.camera;
        let dirs = py.detach(move || {
            let pixels: Vec<DVec2> = points.into_iter().map(DVec2::from).collect();
            points::unproject(&camera, &pixels, origin, ctx)
        });
        let values = dirs
            .map_err(raise)?
            .into_iter()
            .flat_map(|d| d.map_or([f64::NAN; 3], |d| d.to_array()))
            .collect();
        array_of(py, &leading, 3, values)
    }

    /// Pixels where directions (camera frame, an array of shape (..., 3), any length) land;
    /// rows are NaN where one lands outside the lens's field or the image. `pixel_origin` and
    /// `gpu` as for `unproject`.
    #[pyo3(signature = (directions, pixel_origin = "corner", gpu = false))]
    fn project<'py>(
        &self,
        py: Python<'py>,
        directions: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        pixel_origin: &str,
        gpu: bool,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let origin = self::pixel_origin(pixel_origin)?;
        let (leading, points) = points_of::<3>(&directions, "directions")?;
        let ctx = if gpu { Some(context()?) } else { None };
        let camera = self.camera;
        let pixels = py.detach(move || {
            let dirs: Vec<DVec3> = points.into_iter().map(DVec3::from).collect();
            points::project(&camera, &dirs, origin, ctx)
        });
        let values = pixels
            .map_err(raise)?
            .into_iter()
            .flat_map(|p| p.map_or([f64::NAN; 2], |p| p.to_array()))
            .collect();
        array_of(py, &leading, 2, values)
    }
}

/// The 4×4 `T_scene_camera` (OpenCV camera frame) of a look-at camera.
fn transform_of(camera: &Camera) -> [[f64; 4]; 4] {
    fisheye_rt::pose::rows(&DAffine3 {
        matrix3: camera.rotation(),
        translation: camera.position,
    })
}

fn matrix<'py>(py: Python<'py>, m: [[f64; 4]; 4]) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    PyArray1::from_vec(py, m.concat()).reshape(IxDyn(&[4, 4]))
}

/// A scene: built-in, a scene file or an OBJ.
#[pyclass(frozen, module = "fisheye_rt")]
struct Scene {
    scene: Arc<fisheye_rt::scene::Scene>,
    name: String,
    warnings: Vec<String>,
}

#[pymethods]
impl Scene {
    /// Loads `"builtin:NAME"`, a scene file (`.toml`) or an OBJ file; what was repaired on the
    /// way is in `warnings`.
    #[staticmethod]
    fn load(spec: PathBuf) -> PyResult<Self> {
        let name = spec.to_string_lossy().into_owned();
        let loaded = fisheye_rt::scene::load(&name).map_err(raise)?;
        Ok(Self {
            scene: Arc::new(loaded.scene),
            name,
            warnings: loaded.warnings,
        })
    }

    /// How many triangles it has.
    #[getter]
    fn triangles(&self) -> usize {
        self.scene.len()
    }

    /// Its own camera as `T_scene_camera`, a 4×4 array (OpenCV camera frame).
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        matrix(py, transform_of(&self.scene.camera))
    }

    /// What loading repaired, one line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The first and last key times (seconds) of what moves it (glTF animations, scene-file
    /// keys), for `Renderer.render(time=...)`; None where nothing moves.
    #[getter]
    fn key_span(&self) -> Option<(f64, f64)> {
        self.scene.key_span()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene.load({:?})  # {} triangles",
            self.name,
            self.scene.len()
        )
    }
}

/// `T_scene_camera` (4×4, OpenCV camera frame) of a camera at `eye` looking at `target`, level
/// with `up` (`(0, 1, 0)` if not given); each three numbers, as a tuple, a list or a numpy array.
#[pyfunction]
#[pyo3(signature = (eye, target, up = None))]
fn look_at<'py>(
    py: Python<'py>,
    eye: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    target: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    up: Option<PyArrayLikeDyn<'py, f64, AllowTypeChange>>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let up = match up {
        Some(up) => point_of::<3>(&up, "up")?,
        None => [0.0, 1.0, 0.0],
    };
    let camera = Camera {
        position: point_of::<3>(&eye, "eye")?.into(),
        look_at: point_of::<3>(&target, "target")?.into(),
        up: up.into(),
    };
    if (camera.look_at - camera.position).length_squared() == 0.0 {
        return Err(PyValueError::new_err("eye and target are the same point"));
    }
    matrix(py, transform_of(&camera))
}

/// The outputs `render` can return.
const OUTPUTS: [&str; 10] = [
    "colour",
    "srgb",
    "range",
    "normal",
    "id",
    "direction",
    "mask",
    "depth",
    "point",
    "spp",
];

/// `render`'s `spp`: a count of rays per pixel, or `"auto[:THRESHOLD[:MAX[:LEAST]]]"`.
#[derive(FromPyObject)]
enum Spp {
    Count(u32),
    Text(String),
}

impl Spp {
    fn sampling(&self) -> PyResult<Sampling> {
        let text = match self {
            Spp::Count(n) => n.to_string(),
            Spp::Text(t) => t.clone(),
        };
        Sampling::parse(&text).map_err(|e| PyValueError::new_err(format!("spp: {e}")))
    }
}

/// A pass's key: the camera (its lens, size and glass, as `Debug` writes them), the sampling
/// (as `--spp` writes it) and whether the ground truth is traced everywhere.
type PassKey = (String, String, bool);

/// What a renderer keeps between calls: the scene on the GPU and the passes of each lens and
/// sampling.
struct State {
    scene: GpuScene,
    passes: HashMap<PassKey, FramePass>,
}

/// A scene on the GPU, rendered through any lens from any pose into numpy arrays; the scene is
/// uploaded (and its BVH built) once.
#[pyclass(frozen, module = "fisheye_rt")]
struct Renderer {
    scene: Arc<fisheye_rt::scene::Scene>,
    options: RenderOptions,
    state: Mutex<State>,
}

#[pymethods]
impl Renderer {
    /// Builds the scene's BVH and uploads it. `max_depth` bounds reflection and refraction
    /// (0 to 8); `bvh` is the build preset ("fastest", "very-fast", "fast", "medium",
    /// "slow").
    #[new]
    #[pyo3(signature = (scene, max_depth = 5, bvh = "fast"))]
    fn new(py: Python<'_>, scene: &Scene, max_depth: u32, bvh: &str) -> PyResult<Self> {
        let bvh = fisheye_rt::bvh::BvhQuality::from_name(bvh).ok_or_else(|| {
            PyValueError::new_err(format!(
                "bvh={bvh:?}: use fastest, very-fast, fast, medium or slow"
            ))
        })?;
        let options = RenderOptions {
            max_depth,
            bvh,
            ..RenderOptions::default()
        };
        let ctx = context()?;
        let shared = Arc::clone(&scene.scene);
        let gpu = py
            .detach(move || GpuScene::new(ctx, &shared, &options))
            .map_err(raise)?;
        Ok(Self {
            scene: Arc::clone(&scene.scene),
            options,
            state: Mutex::new(State {
                scene: gpu,
                passes: HashMap::new(),
            }),
        })
    }

    /// The GPU adapter it renders on.
    #[getter]
    fn adapter(&self) -> PyResult<String> {
        Ok(context()?.adapter_name())
    }

    /// Renders the scene through `lens` from `pose` (a 4×4 `T_scene_camera`, OpenCV camera
    /// frame, e.g. from `look_at`; the scene's own camera if None) with `spp` rays per pixel
    /// (a square, 1 to 256, or "auto[:THRESHOLD[:MAX[:LEAST]]]" for adaptive sampling, as
    /// `fisheye render --spp` takes it), and returns a dict of arrays, one per name in `outputs`:
    /// "colour" (H×W×4 float32: linear RGB, alpha the lens's coverage), "srgb" (H×W×4 uint8,
    /// through `exposure` stops and the `tone` curve "aces" or "clamp", as `fisheye render`
    /// writes PNGs), and the centre ray's ground truth "range" (H×W float32), "normal"
    /// (H×W×3 float32), "id" (H×W uint32, 4294967295 for none), "direction" (H×W×3 float32,
    /// scene frame), "mask" (H×W uint8), "depth" (H×W float32: the hit's z in the camera's
    /// frame, where range is along the ray) and "point" (H×W×3 float32: the hit in the
    /// camera's frame, x right, y down, z forward). The same arrays `fisheye render --outputs`
    /// writes, bit for bit. "spp" (H×W uint32) is the rays each pixel's colour took: adaptive
    /// sampling's count (0 where a pixel was interpolated), or `spp` at each pixel with a ray.
    /// Moving objects (glTF animations, scene-file keys) are placed at scene time `time`
    /// (seconds), as `fisheye render --time` places them, without building the meshes' BVHs
    /// again. `filter` is "box" (each pixel its own rays' mean) or "tent"
    /// (at one ray a pixel at most, each pixel blended with its neighbours, as
    /// `fisheye render --filter tent`; with more rays a `UserWarning` says it keeps the box).
    #[pyo3(signature = (lens, pose = None, spp = Spp::Count(16), outputs = vec!["colour".to_string(), "srgb".to_string()], exposure = 0.0, tone = "aces", time = 0.0, filter = "box"))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        lens: &Lens,
        pose: Option<PyArrayLikeDyn<'py, f64, AllowTypeChange>>,
        spp: Spp,
        outputs: Vec<String>,
        exposure: f32,
        tone: &str,
        time: f64,
        filter: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        let filter: PixelFilter = filter
            .parse()
            .map_err(|e| PyValueError::new_err(format!("filter: {e}")))?;
        if !time.is_finite() {
            return Err(PyValueError::new_err(format!(
                "time={time}: give a finite number of seconds"
            )));
        }
        if let Some(bad) = outputs.iter().find(|o| !OUTPUTS.contains(&o.as_str())) {
            return Err(PyValueError::new_err(format!(
                "outputs: {bad:?} is not one of {}",
                OUTPUTS.join(", ")
            )));
        }
        let sampling = spp.sampling()?;
        // As `fisheye render --filter` notes, a warning where the filter changes nothing.
        let filter = if filter.applies_to(sampling) {
            filter
        } else {
            let message = format!(
                "filter={:?} changes frames of one ray a pixel; at spp={sampling} each pixel \
                 keeps its rays' mean",
                filter.name()
            );
            let message = std::ffi::CString::new(message).expect("no NUL in the message");
            PyErr::warn(py, &py.get_type::<PyUserWarning>(), &message, 1)?;
            PixelFilter::Box
        };
        let ground_truth = Channel::ALL
            .iter()
            .any(|c| c.traced() && outputs.iter().any(|o| o == c.name()));
        let tone = match tone {
            "aces" => Tone::Aces,
            "clamp" => Tone::Clamp,
            other => {
                return Err(PyValueError::new_err(format!(
                    "tone={other:?}: use \"aces\" or \"clamp\""
                )));
            }
        };
        if !exposure.is_finite() {
            return Err(PyValueError::new_err(format!(
                "exposure={exposure}: give a finite number of stops"
            )));
        }
        let pose = match pose {
            None => self.scene.camera,
            Some(array) => {
                let view = array.as_array();
                if view.shape() != [4, 4] {
                    return Err(PyValueError::new_err(format!(
                        "pose has shape {:?}; give a 4×4 T_scene_camera",
                        view.shape()
                    )));
                }
                let rows: Vec<Vec<f64>> = view
                    .outer_iter()
                    .map(|row| row.iter().copied().collect())
                    .collect();
                let t = fisheye_rt::pose::rigid_from_rows(&rows)
                    .map_err(|e| PyValueError::new_err(format!("pose: {e}")))?;
                camera_from_transform(&t)
            }
        };
        let ctx = context()?;
        let camera = lens.camera;
        let options = RenderOptions {
            filter,
            ..self.options
        };
        let rays = (sampling, ground_truth);
        let spp_map = outputs.iter().any(|o| o == "spp");
        let (output, spp_map) =
            py.detach(|| self.trace(ctx, &camera, (&pose, time), rays, &options, spp_map))?;
        let dict = PyDict::new(py);
        let (h, w) = (camera.size.height as usize, camera.size.width as usize);
        // Only the arrays that read the rays evaluate the f64 lens model at every pixel.
        let reads = |wants: fn(&Channel) -> bool| {
            outputs
                .iter()
                .any(|o| Channel::ALL.iter().any(|c| c.name() == o && wants(c)))
        };
        let camera_rays = if reads(Channel::camera_rays) || reads(Channel::world_rays) {
            camera.directions()
        } else {
            Vec::new()
        };
        let world = if reads(Channel::world_rays) {
            rotated(&camera_rays, &pose)
        } else {
            Vec::new()
        };
        let rays = PixelRays {
            camera: &camera_rays,
            world: &world,
        };
        for name in &outputs {
            let array = match name.as_str() {
                "colour" => PyArray1::from_vec(py, output.colour.concat())
                    .reshape(IxDyn(&[h, w, 4]))?
                    .into_any(),
                "spp" => PyArray1::from_vec(py, spp_map.clone().expect("read when asked for"))
                    .reshape(IxDyn(&[h, w]))?
                    .into_any(),
                "srgb" => {
                    let display = Display { exposure, tone };
                    let image = colour_image_with(output.size, &output.colour, &display);
                    PyArray1::from_vec(py, image.into_raw())
                        .reshape(IxDyn(&[h, w, 4]))?
                        .into_any()
                }
                channel => {
                    let channel = Channel::ALL
                        .into_iter()
                        .find(|c| c.name() == channel)
                        .expect("the names were checked");
                    match output.values(channel, rays) {
                        Values::F32(1, v) => PyArray1::from_vec(py, v)
                            .reshape(IxDyn(&[h, w]))?
                            .into_any(),
                        Values::F32(n, v) => PyArray1::from_vec(py, v)
                            .reshape(IxDyn(&[h, w, n]))?
                            .into_any(),
                        Values::U32(v) => PyArray1::from_vec(py, v)
                            .reshape(IxDyn(&[h, w]))?
                            .into_any(),
                        Values::U8(v) => PyArray1::from_vec(py, v)
                            .reshape(IxDyn(&[h, w]))?
                            .into_any(),
                    }
                }
            };
            dict.set_item(name, array)?;
        }
        Ok(dict)
    }
}

impl Renderer {
    /// Traces one frame (passes per lens and sampling, made at first use; adaptive ones trace
    /// the ground truth of the pixels they interpolate where `ground_truth` says) and reads it
    /// back, with its spp map where `spp_map` asks for it.
    fn trace(
        &self,
        ctx: &GpuContext,
        camera: &LensCamera,
        (pose, time): (&Camera, f64),
        (sampling, ground_truth): (Sampling, bool),
        options: &RenderOptions,
        spp_map: bool,
    ) -> PyResult<(RenderOutput, Option<Vec<u32>>)> {
        let mut state = self
            .state
            .lock()
            .map_err(|_| PyRuntimeError::new_err("an earlier render panicked"))?;
        let State { scene, passes } = &mut *state;
        let (spp, adaptive) = sampling.options(ground_truth);
        let key = (
            format!("{camera:?}"),
            format!("{sampling}+{}", options.filter.name()),
            ground_truth && adaptive.is_some(),
        );
        if !passes.contains_key(&key) {
            let options = RenderOptions {
                spp,
                adaptive,
                ..*options
            };
            let pass = FramePass::new(ctx, camera, scene, &options).map_err(raise)?;
            passes.insert(key.clone(), pass);
        }
        scene
            .place_at(ctx, &self.scene, time, (0.0, 0.0))
            .map_err(raise)?;
        let pass = &passes[&key];
        let output = pass.trace(ctx, scene, pose, "rendering").map_err(raise)?;
        let map = if spp_map {
            Some(pass.rays_map(ctx, &output).map_err(raise)?)
        } else {
            None
        };
        Ok((output, map))
    }
}

/// Lens models, scenes and the GPU tracer of fisheye-rt, with numpy arrays.
#[pymodule]
#[pyo3(name = "fisheye_rt")]
fn fisheye_rt_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Lens>()?;
    m.add_class::<Scene>()?;
    m.add_class::<Renderer>()?;
    m.add_function(wrap_pyfunction!(look_at, m)?)?;
    Ok(())
}

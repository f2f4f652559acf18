//! fisheye-rt in a web page: the library, compiled to wasm32-unknown-unknown, renders on the
//! browser's WebGPU with the same WGSL kernels as natively, and hands the page the 8-bit sRGB
//! image `fisheye render` writes as PNG for the same arguments, or a progressive refinement
//! of it frame by frame. `web/main.js` wraps this in the page's `window.fisheye` (`ready`,
//! `render(opts)`, `open(opts)`); `bash web/build` builds both into `web/dist/`.
//!
//! A page cannot block: the device is requested and the image read back by awaiting
//! WebGPU's promises, never by polling.
#![cfg(target_arch = "wasm32")]

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::Path;
use std::rc::Rc;
use std::sync::{Arc, Mutex};

use fisheye_rt::gpu::{GpuContext, Queries};
use fisheye_rt::input::InputKind;
use fisheye_rt::lens::glass::camera_for;
use fisheye_rt::lens::gpu::LensRays;
use fisheye_rt::lens::twin::TwinCheck;
use fisheye_rt::lens::{ImageSize, LensCamera, calib, parse_spec};
use fisheye_rt::renderer::Renderer;
use fisheye_rt::scene::{self, Scene};
use fisheye_rt::trace::{Display, RenderOptions, Sampling, Tone, auto_exposure, colour_image_with};
use js_sys::{Array, Object, Reflect, Uint8Array};
use wasm_bindgen::prelude::*;

mod read;
use read::{map_read, submit_and_read};

/// The browser's WebGPU device, ready to render.
#[wasm_bindgen]
pub struct Fisheye {
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: String,
    /// Errors WebGPU raised outside any scope (a page cannot wait on error scopes), in order.
    errors: Arc<Mutex<Vec<String>>>,
}

#[wasm_bindgen]
impl Fisheye {
    /// Requests the browser's WebGPU adapter and a device with every limit it offers, or with
    /// `defaults_only` WebGPU's default limits (what a small device, a phone, may offer: the
    /// tracer, adaptive sampling included, works within them); rejects with what is missing
    /// where the adapter is below what the tracer needs.
    pub async fn start(defaults_only: Option<bool>) -> Result<Fisheye, JsError> {
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
        descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
        let instance = wgpu::Instance::new(descriptor);
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            })
            .await
            .map_err(|e| {
                JsError::new(&format!(
                    "this browser gives the page no WebGPU adapter: WebGPU is off or not \
                     supported here ({e})"
                ))
            })?;
        let info = adapter.get_info();
        let adapter_name = match info.driver.is_empty() {
            true => info.name.clone(),
            false => format!("{} ({})", info.name, info.driver),
        };
        let has = adapter.limits();
        let mut short = Vec::new();
        fisheye_rt::renderer::required_limits().check_limits_with_fail_fn(
            &has,
            false,
            |name, need, offers| {
                short.push(format!(
                    "{name}: the tracer needs {need}, it offers {offers}"
                ))
            },
        );
        if !short.is_empty() {
            return Err(JsError::new(&format!(
                "this browser's WebGPU adapter ({adapter_name}) is too small: {}",
                short.join("; ")
            )));
        }
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("fisheye.web"),
                // Timestamps, where the adapter has them, time each frame on the GPU.
                required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
                required_limits: match defaults_only {
                    Some(true) => wgpu::Limits::default(),
                    _ => has,
                },
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| JsError::new(&format!("WebGPU refused a device: {e}")))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            sink.lock().unwrap().push(error.to_string());
        }));
        Ok(Fisheye {
            device,
            queue,
            adapter: adapter_name,
            errors,
        })
    }

    /// Checks the WGSL lens code against the f64 reference at every pixel of `lens` (a spec)
    /// at `size` (`WxH`), on this device: resolves to `{lens, rays, max_error, max_ratio,
    /// max_error_well_conditioned, holds, why}` (radians; `max_ratio` is the largest error
    /// over its pixel's bound, `holds` whether the twin keeps its bounds and `why` not);
    /// rejects where the masks differ or a direction is not finite.
    pub fn lens_twin(&self, lens: String, size: String) -> js_sys::Promise {
        let (device, queue, errors) =
            (self.device.clone(), self.queue.clone(), self.errors.clone());
        wasm_bindgen_futures::future_to_promise(async move {
            lens_twin(&device, &queue, &errors, &lens, &size).await
        })
    }

    /// The storage buffers a shader stage may bind on this device: the tracer needs 8
    /// (adaptive sampling, and so progressive refinement, included).
    #[wasm_bindgen(getter)]
    pub fn storage_buffers(&self) -> u32 {
        self.device.limits().max_storage_buffers_per_shader_stage
    }

    /// The adapter's name (and driver, where the browser says).
    #[wasm_bindgen(getter)]
    pub fn adapter(&self) -> String {
        self.adapter.clone()
    }

    /// Opens a view of what `opts` asks, as `fisheye render` would render it: `{name, lens,
    /// size, spp, camera, calib, calib_name, calib_camera, complete}`: the scene `name`
    /// (`builtin:NAME`, or a file in `files` ending `.obj`, `.gltf`, `.glb` or `.toml`;
    /// `files` maps names to their bytes, the scene's and those it names) through `lens` at
    /// `size` (`WxH`), or through camera `calib_camera` (from 0) of the calibration file whose
    /// bytes are `calib` (a `Uint8Array`) and name `calib_name`, with `spp` (`render --spp`'s
    /// forms, then optionally `+tent` for `render --filter tent`) from `camera` (`render --camera`'s forms; the scene's own if empty). The scene is loaded, its BVH built and uploaded, the kernels made; a
    /// [`View`] renders frames of it. Rejects with an `Error` whose message says what is
    /// wrong. Until `complete`, a scene that names files not in `files` (an OBJ's MTL,
    /// textures, glTF buffers) is refused with an `Error` whose `missing` lists them, even
    /// where it would load without them (the page fetches them and tries again); once
    /// `complete`, those still missing are missing, as they are to `fisheye render`.
    pub fn open(&self, files: js_sys::Map, opts: Object) -> js_sys::Promise {
        let (device, queue, errors) =
            (self.device.clone(), self.queue.clone(), self.errors.clone());
        let mut bytes = HashMap::new();
        files.for_each(&mut |value, key| {
            if let (Some(key), Some(value)) = (key.as_string(), value.dyn_ref::<Uint8Array>()) {
                bytes.insert(key, value.to_vec());
            }
        });
        let text = |key: &str| {
            Reflect::get(&opts, &key.into())
                .ok()
                .and_then(|v| v.as_string())
                .unwrap_or_default()
        };
        let request = Request {
            name: text("name"),
            files: bytes,
            lens: text("lens"),
            size: text("size"),
            spp: text("spp"),
            camera: text("camera"),
            calib: Reflect::get(&opts, &"calib".into())
                .ok()
                .and_then(|v| v.dyn_into::<Uint8Array>().ok())
                .map(|bytes| (text("calib_name"), bytes.to_vec())),
            calib_camera: Reflect::get(&opts, &"calib_camera".into())
                .ok()
                .and_then(|v| v.as_f64())
                .unwrap_or(0.0) as usize,
            complete: Reflect::get(&opts, &"complete".into()).is_ok_and(|v| v.is_truthy()),
        };
        wasm_bindgen_futures::future_to_promise(async move {
            let view = request.open(device, queue, errors)?;
            Ok(JsValue::from(View {
                inner: Rc::new(view),
            }))
        })
    }
}

/// A scene through a lens on the device, ready for frames.
#[wasm_bindgen]
pub struct View {
    inner: Rc<ViewInner>,
}

struct ViewInner {
    device: wgpu::Device,
    queue: wgpu::Queue,
    errors: Arc<Mutex<Vec<String>>>,
    scene: Scene,
    warnings: Vec<String>,
    size: ImageSize,
    renderer: Renderer,
    target: wgpu::Texture,
    /// Where each frame's image is copied to be read: rows of `row` bytes (WebGPU's copy
    /// alignment), made once with the view.
    read_back: wgpu::Buffer,
    row: u32,
    /// Where its ids are (traced frames only).
    ids_read_back: Option<wgpu::Buffer>,
    /// Timestamps around each frame and where they are read, on a device with timestamp
    /// queries.
    timing: Option<(Queries, wgpu::Buffer)>,
    /// The frames a progressive refinement takes at most (1 where it is not progressive).
    steps: u32,
}

#[wasm_bindgen]
impl View {
    /// A frame from `camera` (`render --camera`'s forms; the view's first pose if empty) at
    /// scene `time` (seconds, 0 if not given: where `render --time` places a moving scene):
    /// the whole frame, or with `progressive` the next step of a progressive refinement
    /// (`Renderer::encode_progressive`: with adaptive sampling the first frame at a pose is
    /// the coarse one and each frame after it at the same pose sharpens it, until the whole
    /// frame, bit for bit, after at most [`View::steps`]; a new pose or time starts
    /// again). Resolves to `{width, height, rgba, ids, gpu_ms, timed_by, wall_ms, camera,
    /// warnings}`: the PNG's 8-bit sRGB pixels, the scene triangle at each pixel's centre
    /// (`--outputs id`'s, as a `Uint32Array`; with adaptive sampling only the traced pixels'
    /// are there, the rest `NO_HIT`), the frame's milliseconds on the GPU (`timed_by`
    /// `"timestamps"`: from the start of its first pass to the end of its last, by the GPU's
    /// timestamps, which browsers quantise; or `"wall clock"` where the device has no
    /// timestamp queries, `wall_ms`), the milliseconds from submission to the pixels' arrival
    /// on the CPU (`wall_ms`), the pose (as `camera` takes it) and what loading the scene
    /// warned of. One frame at a time: frames share the view's read-back buffers.
    pub fn frame(&self, camera: String, progressive: bool, time: Option<f64>) -> js_sys::Promise {
        let inner = self.inner.clone();
        wasm_bindgen_futures::future_to_promise(async move {
            let image = inner
                .frame(&camera, progressive, time.unwrap_or(0.0))
                .await?;
            let out = Object::new();
            let set = |key: &str, value: JsValue| Reflect::set(&out, &key.into(), &value);
            set("width", image.size.width.into())?;
            set("height", image.size.height.into())?;
            set("rgba", Uint8Array::from(&image.rgba[..]).into())?;
            set("ids", js_sys::Uint32Array::from(&image.ids[..]).into())?;
            let (gpu_ms, timed_by) = match image.gpu_ms {
                Some(ms) => (ms, "timestamps"),
                None => (image.wall_ms, "wall clock"),
            };
            set("gpu_ms", gpu_ms.into())?;
            set("timed_by", timed_by.into())?;
            set("wall_ms", image.wall_ms.into())?;
            set("camera", image.camera.into())?;
            let warnings: Array = inner.warnings.iter().map(JsValue::from).collect();
            set("warnings", warnings.into())?;
            Ok(out.into())
        })
    }

    /// The frames a progressive refinement takes at most: 2 + the most samples a pixel with
    /// adaptive sampling (the coarse frame, the estimate, then about one ray a pixel a
    /// frame), 1 with uniform sampling (its whole frame at once).
    #[wasm_bindgen(getter)]
    pub fn steps(&self) -> u32 {
        self.inner.steps
    }

    /// The first and last key times (seconds) of a scene that moves (glTF animations,
    /// scene-file keys); `undefined` where nothing moves.
    #[wasm_bindgen(getter)]
    pub fn key_span(&self) -> Option<Vec<f64>> {
        let (first, last) = self.inner.scene.key_span()?;
        Some(vec![first, last])
    }
}

/// What `open` was asked.
struct Request {
    name: String,
    files: HashMap<String, Vec<u8>>,
    lens: String,
    size: String,
    spp: String,
    camera: String,
    /// A calibration file's name and contents, whose camera `calib_camera` (from 0) replaces
    /// `lens` and `size`, as `render --calib FILE --calib-camera N`.
    calib: Option<(String, Vec<u8>)>,
    calib_camera: usize,
    complete: bool,
}

/// A rendered image as the PNG holds it.
struct Image {
    size: ImageSize,
    rgba: Vec<u8>,
    /// The scene triangle at each pixel's centre (`NO_HIT` where none), row-major.
    ids: Vec<u32>,
    /// The frame's time on the GPU by timestamps, where the device has them.
    gpu_ms: Option<f64>,
    /// From submission to the pixels' arrival on the CPU.
    wall_ms: f64,
    /// The pose it was seen from, as `camera` takes it.
    camera: String,
}

/// A JavaScript `Error` with `message`.
fn error(message: impl std::fmt::Display) -> JsValue {
    js_sys::Error::new(&message.to_string()).into()
}

impl Request {
    fn open(
        &self,
        device: wgpu::Device,
        queue: wgpu::Queue,
        errors: Arc<Mutex<Vec<String>>>,
    ) -> Result<ViewInner, JsValue> {
        let (sampling, filter) =
            Sampling::parse_filtered(&self.spp).map_err(|e| error(format!("spp: {e}")))?;
        let camera = self.camera()?;
        let size = camera.size;
        let (mut scene, warnings) = self.scene()?;
        scene.frame_for(&camera);
        if !self.camera.is_empty() {
            // Before the upload, as `fisheye render --camera`: a headlight goes with it.
            let pose = scene.parse_camera(&self.camera).map_err(error)?;
            scene.set_camera(pose);
        }
        let (spp, adaptive) = sampling.options(false);
        let options = RenderOptions {
            spp,
            adaptive,
            filter,
            ..RenderOptions::default()
        };
        let format = wgpu::TextureFormat::Rgba32Float;
        let renderer =
            Renderer::new(&device, &queue, &scene, &camera, &options, format).map_err(error)?;
        let target = renderer.target_texture(&device);
        let read_back = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            })
        };
        let row = (16 * size.width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let image = read_back(
            "fisheye.web.read_back",
            u64::from(row) * u64::from(size.height),
        );
        let ids = renderer
            .outputs()
            .map(|[_, _, ids]| read_back("fisheye.web.ids", ids.size()));
        let ctx = GpuContext::from_device(&device, &queue);
        let timing = Queries::new(&ctx, 1).map(|q| {
            let ticks = read_back("fisheye.web.timestamps", q.resolved().size());
            (q, ticks)
        });
        Ok(ViewInner {
            device,
            queue,
            errors,
            scene,
            warnings,
            size,
            renderer,
            target,
            read_back: image,
            row,
            ids_read_back: ids,
            timing,
            steps: if adaptive.is_some() { 2 + spp } else { 1 },
        })
    }

    /// The camera: the calibration's, else `lens` at `size`.
    fn camera(&self) -> Result<LensCamera, JsValue> {
        let Some((name, bytes)) = &self.calib else {
            let size: ImageSize = self.size.parse().map_err(|e| error(format!("size: {e}")))?;
            return camera_for(&self.lens, size).map_err(|e| error(format!("lens: {e}")));
        };
        let cameras = calib::read_from(Path::new(name), bytes.clone()).map_err(error)?;
        let Some(c) = cameras.get(self.calib_camera) else {
            return Err(error(format!(
                "{name} holds {} camera(s); camera {} is not one",
                cameras.len(),
                self.calib_camera
            )));
        };
        Ok(c.camera())
    }

    /// The scene `name` names, its files read from `files`, and the loader's warnings.
    fn scene(&self) -> Result<(Scene, Vec<String>), JsValue> {
        if self.name.starts_with("builtin:") {
            return scene::load(&self.name)
                .map(|l| (l.scene, l.warnings))
                .map_err(error);
        }
        let missing = RefCell::new(Vec::new());
        let read = |path: &Path, _: InputKind| -> std::io::Result<Vec<u8>> {
            let key = file_key(path);
            self.files.get(&key).cloned().ok_or_else(|| {
                missing.borrow_mut().push(key.clone());
                std::io::Error::new(std::io::ErrorKind::NotFound, format!("{key} was not given"))
            })
        };
        let path = Path::new(&self.name);
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let loaded = match extension.as_deref() {
            Some("obj") => scene::obj::load_obj_from(path, &read),
            Some("gltf" | "glb") => scene::gltf::load_gltf_from(path, &read, None),
            Some("toml") => scene::file::load_scene_file_from(path, &read),
            _ => {
                return Err(error(format!(
                    "{}: expected an OBJ file (.obj), a glTF file (.gltf, .glb), a scene file \
                     (.toml) or builtin:NAME",
                    self.name
                )));
            }
        };
        let missing = missing.take();
        let out = match (loaded, self.complete || missing.is_empty()) {
            (Ok(l), true) => return Ok((l.scene, l.warnings)),
            (Ok(_), false) => error(format!(
                "{} names files that were not given: {}",
                self.name,
                missing.join(", ")
            )),
            (Err(e), _) => error(e),
        };
        let names: Array = missing.into_iter().map(JsValue::from).collect();
        let _ = Reflect::set(&out, &"missing".into(), &names);
        Err(out)
    }
}

impl ViewInner {
    async fn frame(&self, camera: &str, progressive: bool, time: f64) -> Result<Image, JsValue> {
        let pose = match camera {
            "" => self.scene.camera,
            text => self.scene.parse_camera(text).map_err(error)?,
        };
        // Moving instances placed at `time`, as `render --time` places them (a new time
        // starts progressive refinement again; the same time changes nothing).
        if !time.is_finite() {
            return Err(error(format!(
                "time {time}: a time in seconds must be finite"
            )));
        }
        self.renderer.place_at(&self.scene, time).map_err(error)?;
        let (size, row) = (self.size, self.row);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        if let Some((queries, _)) = &self.timing {
            queries.mark(&mut encoder, 0, true);
        }
        let encoded = match progressive {
            true => self
                .renderer
                .encode_progressive(&mut encoder, &pose, &self.target),
            false => self.renderer.encode(&mut encoder, &pose, &self.target),
        };
        encoded.map_err(error)?;
        if let Some((queries, ticks)) = &self.timing {
            queries.mark(&mut encoder, 0, false);
            queries.resolve(&mut encoder);
            let resolved = queries.resolved();
            encoder.copy_buffer_to_buffer(resolved, 0, ticks, 0, resolved.size());
        }
        encoder.copy_texture_to_buffer(
            self.target.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.read_back,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(size.height),
                },
            },
            self.target.size(),
        );
        // The scene triangle at each pixel's centre, as `--outputs id` (traced frames only).
        if let (Some([_, _, ids]), Some(staging)) = (self.renderer.outputs(), &self.ids_read_back) {
            encoder.copy_buffer_to_buffer(ids, 0, staging, 0, ids.size());
        }
        let started = js_sys::Date::now();
        let data = submit_and_read(&self.queue, encoder, &self.read_back, &self.errors).await?;
        let wall_ms = js_sys::Date::now() - started;
        let gpu_ms = match &self.timing {
            Some((queries, ticks)) => {
                let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&map_read(ticks).await?);
                Some(queries.durations_ns(&ticks)[0] * 1e-6)
            }
            None => None,
        };
        let ids = match &self.ids_read_back {
            Some(staging) => bytemuck::pod_collect_to_vec::<u8, u32>(&map_read(staging).await?),
            None => Vec::new(),
        };
        let mut colour = Vec::with_capacity(size.pixels());
        for r in data.chunks(row as usize) {
            colour.extend(bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(
                &r[..16 * size.width as usize],
            ));
        }
        // As `fisheye render`'s PNG: bare meshes, lit by the headlight and sun it adds, at the
        // exposure that maps their log-average luminance to middle grey; the ACES curve.
        let exposure = match self.scene.headlight {
            Some(_) => auto_exposure(&colour),
            None => 0.0,
        };
        let display = Display {
            exposure,
            tone: Tone::Aces,
        };
        Ok(Image {
            size,
            rgba: colour_image_with(size, &colour, &display).into_raw(),
            ids,
            gpu_ms,
            wall_ms,
            camera: format!(
                "{},{},{}:{},{},{}",
                pose.position.x,
                pose.position.y,
                pose.position.z,
                pose.look_at.x,
                pose.look_at.y,
                pose.look_at.z
            ),
        })
    }
}

/// A path the loaders ask for, as the page names its files: `/`-separated, no `./`.
fn file_key(path: &Path) -> String {
    let parts: Vec<String> = path
        .components()
        .filter(|c| !matches!(c, std::path::Component::CurDir))
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    parts.join("/")
}

/// The WGSL lens twin against the f64 reference in the page: every pixel's direction of
/// `lens` (a spec) at `size` (`WxH`), computed by the lens kernel on this device and read
/// back, compared with the library's f64 reference, compiled to wasm, by
/// `fisheye_rt::lens::twin` (as `tests/lens_gpu.rs` compares them natively).
async fn lens_twin(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    errors: &Mutex<Vec<String>>,
    lens: &str,
    size: &str,
) -> Result<JsValue, JsValue> {
    let size: ImageSize = size.parse().map_err(|e| error(format!("size: {e}")))?;
    let spec = parse_spec(lens).map_err(|e| error(format!("lens: {e}")))?;
    let camera = LensCamera::new(spec, size);
    let ctx = GpuContext::from_device(device, queue);
    let rays = LensRays::new(&ctx, &camera).map_err(error)?;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fisheye.web.directions"),
        size: rays.directions.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    rays.encode(&mut encoder, None);
    encoder.copy_buffer_to_buffer(&rays.directions, 0, &staging, 0, staging.size());
    let bytes = submit_and_read(queue, encoder, &staging, errors).await?;
    let gpu = LensRays::decode(&bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(&bytes));
    let check = TwinCheck::new(&camera, &gpu).map_err(error)?;
    let out = Object::new();
    let set = |key: &str, value: JsValue| Reflect::set(&out, &key.into(), &value);
    set("lens", camera.lens.to_string().into())?;
    set("rays", (check.valid as u32).into())?;
    set("max_error", check.max_error.into())?;
    set("max_ratio", check.max_ratio.into())?;
    set(
        "max_error_well_conditioned",
        check.max_error_well_conditioned.into(),
    )?;
    let verdict = check.holds();
    set("holds", verdict.is_ok().into())?;
    set("why", verdict.err().unwrap_or_default().into())?;
    Ok(out.into())
}

/// Lens specs to start from, each with what it is: the presets (real lenses), each classic
/// model over 180° (rectilinear narrower), and an example of each calibrated model (its
/// numbers for a 512×512 image).
#[wasm_bindgen]
pub fn lenses() -> Array {
    use fisheye_rt::lens::{CalibratedModel, PRESETS};
    let mut out: Vec<(String, String)> = PRESETS
        .iter()
        .map(|p| (p.name.to_string(), p.description.to_string()))
        .collect();
    for model in ["equidistant", "equisolid", "stereographic", "orthographic"] {
        out.push((
            format!("{model}:f=0.5,fov=180"),
            format!("{model} model, 180°"),
        ));
    }
    out.push((
        "rectilinear:f=0.5".into(),
        "rectilinear (pinhole) model".into(),
    ));
    for ((name, keys), example) in CalibratedModel::NAMES.iter().zip(CalibratedModel::EXAMPLES) {
        out.push((
            example.to_string(),
            format!("{name} calibration ({keys}), 512×512"),
        ));
    }
    out.into_iter()
        .map(|(spec, about)| JsValue::from(Array::of2(&spec.into(), &about.into())))
        .collect()
}

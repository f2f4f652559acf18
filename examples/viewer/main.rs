//! An interactive fisheye viewer, built on the library's embedding API (`renderer::Renderer`)
//! and winit: the window's device renders each frame into a texture the viewer then draws.
//!
//! ```sh
//! cargo run --release --example viewer -- [SCENE] [--lens SPEC] [--method NAME] [--spp N]
//!     [--size WxH] [--time T]
//! ```
//!
//! Keys: W A S D (or the arrows) move, Q and E go down and up, dragging with the left button
//! looks around; L switches lens, M switches method (rt, rq, cube-rt, cube-forward,
//! cube-deferred, cube-single: those the adapter has), P switches the sampling of the traced
//! methods (adaptive `auto` first, then 1, 4 and 16 rays per pixel, then `auto:0.1:1`, then
//! `1+tent` and `auto:0.1:1+tent`: one ray a pixel at most through the tent filter), R goes
//! back to the scene's camera, Esc quits. The title shows the lens, the method and the frame
//! time.
//!
//! A scene that moves (glTF animations, scene-file keys) plays, looping over its keys'
//! span, with the scene time in the title; Space pauses and resumes it, and `--time T` starts
//! it paused at T seconds. Ray queries and rasterized cube maps draw it as loaded (a note
//! says so): they take the scene flattened once.
//!
//! Frames are progressive (`Renderer::encode_progressive`): with adaptive sampling, a moving
//! camera sees the frame below one ray per pixel, and a still one sees it sharpen frame by
//! frame (about one ray per pixel each) into the whole adaptive frame; other samplings draw
//! their whole frame when the camera moves. For tests: `--frames N --screenshot FILE` renders
//! N frames from the scene's camera, saves the window's last frame as a PNG and exits.
//!
//! `--lens prescription:FILE[,...]` renders through a lens's glass (see the book's Lenses
//! page), which is traced with uniform sampling: an adaptive choice takes its most rays a
//! pixel, every pixel.

use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use fisheye_rt::cube::CubeSettings;
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::ImageSize;
use fisheye_rt::lens::glass::camera_for;
use fisheye_rt::renderer::{Method, Renderer};
use fisheye_rt::scene::{Camera, Scene};
use fisheye_rt::trace::{RenderOptions, Sampling};
use glam::DVec3;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{DeviceEvent, ElementState, KeyEvent, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

mod clock;
use clock::Clock;

/// The lenses L cycles through (after the one given with `--lens`).
const LENSES: [&str; 5] = [
    "canon-8-15mm@8mm",
    "samyang-7.5mm",
    "equidistant:f=0.3,fov=220",
    "stereographic:f=0.45",
    "rectilinear:f=1",
];

/// The samplings P steps through: adaptive sampling (below one ray a pixel where the image is
/// smooth, up to 16 where it is not), uniform rays per pixel, adaptive sampling that stops at
/// one ray a pixel, then those at one ray through the tent filter (`+tent`, as `compare`
/// labels them).
const SPP: [&str; 7] = [
    "auto",
    "1",
    "4",
    "16",
    "auto:0.1:1",
    "1+tent",
    "auto:0.1:1+tent",
];

struct Args {
    scene: String,
    lenses: Vec<String>,
    method: usize,
    spp: usize,
    size: PhysicalSize<u32>,
    frames: Option<u32>,
    screenshot: Option<PathBuf>,
    time: Option<f64>,
}

fn args() -> Result<Args, String> {
    let mut out = Args {
        scene: "builtin:default".into(),
        lenses: LENSES.iter().map(|s| s.to_string()).collect(),
        method: 0,
        spp: 0,
        size: PhysicalSize::new(960, 720),
        frames: None,
        screenshot: None,
        time: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--lens" => out.lenses.insert(0, value("--lens")?),
            "--method" => {
                let name = value("--method")?;
                out.method = Method::ALL
                    .iter()
                    .position(|m| m.name() == name)
                    .ok_or(format!("unknown method {name:?}"))?;
            }
            "--spp" => {
                let text = value("--spp")?;
                out.spp = SPP
                    .iter()
                    .position(|s| *s == text)
                    .ok_or(format!("--spp {text}: one of {SPP:?}"))?;
            }
            "--size" => {
                let size: ImageSize = value("--size")?
                    .parse()
                    .map_err(|e: fisheye_rt::LensError| e.to_string())?;
                out.size = PhysicalSize::new(size.width, size.height);
            }
            "--frames" => {
                let text = value("--frames")?;
                out.frames = Some(text.parse().map_err(|_| format!("--frames {text:?}"))?);
            }
            "--screenshot" => out.screenshot = Some(value("--screenshot")?.into()),
            "--time" => {
                let text = value("--time")?;
                let t: f64 = text.parse().map_err(|_| format!("--time {text:?}"))?;
                if !t.is_finite() {
                    return Err(format!("--time {text}: a time in seconds must be finite"));
                }
                out.time = Some(t);
            }
            flag if flag.starts_with("--") => return Err(format!("unknown option {flag}")),
            scene => out.scene = scene.into(),
        }
    }
    Ok(out)
}

/// The window, its device and surface, and what is drawn.
struct State {
    window: Arc<Window>,
    ctx: GpuContext,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    blit: wgpu::RenderPipeline,
    scene: Scene,
    view: Option<View>,
    pose: Camera,
    lens: usize,
    method: usize,
    spp: usize,
    keys: HashSet<KeyCode>,
    dragging: bool,
    last_frame: Instant,
    frame_ms: f64,
    frames: u32,
    /// The scene's time, where it moves.
    clock: Option<Clock>,
}

/// A renderer for the current lens, method and window size, and its texture.
struct View {
    renderer: Renderer,
    target: wgpu::Texture,
    blit_group: wgpu::BindGroup,
    lens: String,
}

impl State {
    fn new(window: Arc<Window>, scene: Scene, time: Option<f64>) -> Result<Self, String> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| format!("no surface for the window: {e}"))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| format!("no adapter for the window: {e}"))?;
        // The device the library would make: every optional feature the adapter has (ray
        // queries, multiview), with the adapter's limits.
        let ctx = GpuContext::with_adapter(adapter.clone()).map_err(|e| e.to_string())?;
        let caps = surface.get_capabilities(&adapter);
        let format = caps.formats[0];
        let size = window.inner_size();
        let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        if caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
            usage |= wgpu::TextureUsages::COPY_SRC; // for --screenshot
        }
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: Vec::new(),
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&ctx.device, &config);
        let blit = blit_pipeline(&ctx.device, format);
        let pose = scene.camera;
        let clock = scene.key_span().map(|span| Clock::new(span, time));
        Ok(Self {
            window,
            ctx,
            surface,
            config,
            blit,
            scene,
            view: None,
            pose,
            lens: 0,
            method: 0,
            spp: 0,
            keys: HashSet::new(),
            dragging: false,
            last_frame: Instant::now(),
            frame_ms: 0.0,
            frames: 0,
            clock,
        })
    }

    /// Makes the renderer for the current lens, method and size if it is not there; a method
    /// the adapter lacks is skipped with a note.
    fn ensure_view(&mut self, lenses: &[String]) -> Result<(), String> {
        for _ in 0..Method::ALL.len() {
            if self.view.is_some() {
                return Ok(());
            }
            match self.make_view(&lenses[self.lens]) {
                Ok(view) => {
                    self.view = Some(view);
                    if let Some(clock) = &mut self.clock {
                        clock.fixed = false;
                    }
                }
                Err(e) => {
                    eprintln!("{}: {e}", Method::ALL[self.method].name());
                    self.method = (self.method + 1) % Method::ALL.len();
                }
            }
        }
        self.view
            .as_ref()
            .map(|_| ())
            .ok_or_else(|| "no method renders on this adapter".into())
    }

    fn make_view(&self, lens: &str) -> Result<View, String> {
        let size =
            ImageSize::new(self.config.width, self.config.height).map_err(|e| e.to_string())?;
        let camera = camera_for(lens, size).map_err(|e| e.to_string())?;
        // An sRGB surface encodes what the blit writes, so the renderer hands over radiance;
        // a plain one shows the values as they are, so the renderer encodes them.
        let format = if self.config.format.is_srgb() {
            wgpu::TextureFormat::Rgba16Float
        } else {
            wgpu::TextureFormat::Rgba8Unorm
        };
        let method = Method::ALL[self.method];
        let (sampling, filter) =
            Sampling::parse_filtered(SPP[self.spp]).map_err(|e| e.to_string())?;
        let (spp, adaptive) = sampling.options(false);
        let options = RenderOptions {
            traversal: method.traversal(),
            spp,
            adaptive,
            filter,
            ..RenderOptions::default()
        };
        let (device, queue) = (&self.ctx.device, &self.ctx.queue);
        let renderer = match method {
            Method::Cube(m) => {
                let cube = CubeSettings::new(size.width.max(size.height) / 2, m);
                Renderer::through_cube(device, queue, &self.scene, &camera, &options, &cube, format)
            }
            _ => Renderer::new(device, queue, &self.scene, &camera, &options, format),
        }
        .map_err(|e| e.to_string())?;
        let target = renderer.target_texture(device);
        let view = target.create_view(&Default::default());
        let blit_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("viewer.blit"),
            layout: &self.blit.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            }],
        });
        Ok(View {
            renderer,
            target,
            blit_group,
            lens: lens.to_string(),
        })
    }

    /// Moves the camera by the keys held, `seconds` after the last frame.
    fn fly(&mut self, seconds: f64) {
        let (lo, hi) = self.scene.bounds().unwrap_or((DVec3::ZERO, DVec3::ONE));
        let step = 0.25 * (hi - lo).length() * seconds;
        let forward = (self.pose.look_at - self.pose.position).normalize();
        let right = forward.cross(self.pose.up).normalize_or_zero();
        let mut motion = DVec3::ZERO;
        for (keys, direction) in [
            ([KeyCode::KeyW, KeyCode::ArrowUp], forward),
            ([KeyCode::KeyS, KeyCode::ArrowDown], -forward),
            ([KeyCode::KeyD, KeyCode::ArrowRight], right),
            ([KeyCode::KeyA, KeyCode::ArrowLeft], -right),
            ([KeyCode::KeyE, KeyCode::PageUp], self.pose.up),
            ([KeyCode::KeyQ, KeyCode::PageDown], -self.pose.up),
        ] {
            if keys.iter().any(|k| self.keys.contains(k)) {
                motion += direction;
            }
        }
        if motion != DVec3::ZERO {
            let d = motion.normalize() * step;
            self.pose.position += d;
            self.pose.look_at += d;
        }
    }

    /// Turns the view by a mouse movement of `dx, dy` pixels.
    fn look(&mut self, dx: f64, dy: f64) {
        let radians = 0.004;
        let forward = (self.pose.look_at - self.pose.position).normalize();
        let up = self.pose.up.normalize();
        let turned = glam::DQuat::from_axis_angle(up, -dx * radians) * forward;
        let right = turned.cross(up).normalize_or_zero();
        let mut pitched = glam::DQuat::from_axis_angle(right, -dy * radians) * turned;
        if pitched.dot(up).abs() > 0.99 {
            pitched = turned; // no turning over the pole
        }
        self.pose.look_at = self.pose.position + pitched;
    }

    /// Renders and shows one frame; with `screenshot`, also reads it back as RGBA.
    fn frame(
        &mut self,
        lenses: &[String],
        screenshot: bool,
    ) -> Result<Option<image::RgbaImage>, String> {
        let now = Instant::now();
        let seconds = now.duration_since(self.last_frame).as_secs_f64();
        self.last_frame = now;
        self.frame_ms = 0.9 * self.frame_ms + 0.1 * seconds * 1e3;
        self.fly(seconds.min(0.1));
        self.ensure_view(lenses)?;
        let view = self.view.as_ref().expect("made above");
        // The renderer places the scene only when the time changes (a paused clock's frames
        // go on refining).
        if let Some(clock) = self.clock.as_mut().filter(|c| !c.fixed)
            && let Err(e) = view.renderer.place_at(&self.scene, clock.now())
        {
            let method = Method::ALL[self.method].name();
            eprintln!("note: {method} does not play the scene's motion: {e}");
            clock.fixed = true;
        }
        let surface = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.ctx.device, &self.config);
                return Ok(None);
            }
            _ => return Ok(None),
        };
        let device = &self.ctx.device;
        let mut encoder = device.create_command_encoder(&Default::default());
        view.renderer
            .encode_progressive(&mut encoder, &self.pose, &view.target)
            .map_err(|e| e.to_string())?;
        let output = surface.texture.create_view(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("viewer.blit"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &output,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            pass.set_pipeline(&self.blit);
            pass.set_bind_group(0, &view.blit_group, &[]);
            pass.draw(0..3, 0..1);
        }
        self.ctx.queue.submit([encoder.finish()]);
        let shot = if screenshot {
            let texture = if self.config.usage.contains(wgpu::TextureUsages::COPY_SRC) {
                &surface.texture
            } else {
                return Err("the surface cannot be copied from on this adapter".into());
            };
            let bytes = self
                .ctx
                .read_texture_bytes(texture)
                .map_err(|e| e.to_string())?;
            let bgra = matches!(
                self.config.format,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
            );
            let rgba: Vec<u8> = bytes
                .chunks_exact(4)
                .flat_map(|p| {
                    if bgra {
                        [p[2], p[1], p[0], 255]
                    } else {
                        [p[0], p[1], p[2], 255]
                    }
                })
                .collect();
            image::RgbaImage::from_raw(self.config.width, self.config.height, rgba)
        } else {
            None
        };
        self.ctx.queue.present(surface);
        let time = match &self.clock {
            None => String::new(),
            Some(Clock { fixed: true, .. }) => ", the scene as loaded".into(),
            Some(clock) => format!(
                ", scene time {:.2} s{}",
                clock.now(),
                if clock.paused.is_some() {
                    " (paused)"
                } else {
                    ""
                }
            ),
        };
        self.window.set_title(&format!(
            "fisheye-rt: {} triangles through {}, {}{}{time} ({:.1} ms a frame)",
            self.scene.len(),
            view.lens,
            Method::ALL[self.method].name(),
            match Method::ALL[self.method] {
                Method::Cube(_) => String::new(),
                _ => format!(" at --spp {}", SPP[self.spp]),
            },
            self.frame_ms
        ));
        self.frames += 1;
        Ok(shot)
    }
}

/// The pipeline that draws the renderer's image onto the window.
fn blit_pipeline(device: &wgpu::Device, format: wgpu::TextureFormat) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("viewer.blit"),
        source: wgpu::ShaderSource::Wgsl(include_str!("viewer.wgsl").into()),
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("viewer.blit"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    })
}

struct App {
    args: Args,
    scene: Option<Scene>,
    state: Option<State>,
    error: Option<String>,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: String) {
        self.error = Some(error);
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title("fisheye-rt")
            .with_inner_size(self.args.size);
        let window = match event_loop.create_window(attributes) {
            Ok(w) => Arc::new(w),
            Err(e) => return self.fail(event_loop, format!("no window: {e}")),
        };
        let scene = self
            .scene
            .take()
            .expect("the scene, loaded before the window");
        match State::new(window, scene, self.args.time) {
            Ok(mut state) => {
                state.method = self.args.method;
                state.spp = self.args.spp;
                state.window.request_redraw();
                self.state = Some(state);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(state) = self.state.as_mut() else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) if size.width > 0 && size.height > 0 => {
                state.config.width = size.width;
                state.config.height = size.height;
                state.surface.configure(&state.ctx.device, &state.config);
                state.view = None;
            }
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        physical_key: PhysicalKey::Code(key),
                        state: pressed,
                        repeat: false,
                        ..
                    },
                ..
            } => {
                if pressed == ElementState::Released {
                    state.keys.remove(&key);
                    return;
                }
                state.keys.insert(key);
                match key {
                    KeyCode::Escape => event_loop.exit(),
                    KeyCode::KeyL => {
                        state.lens = (state.lens + 1) % self.args.lenses.len();
                        state.view = None;
                    }
                    KeyCode::KeyM => {
                        state.method = (state.method + 1) % Method::ALL.len();
                        state.view = None;
                    }
                    KeyCode::KeyP => {
                        state.spp = (state.spp + 1) % SPP.len();
                        state.view = None;
                    }
                    KeyCode::KeyR => state.pose = state.scene.camera,
                    KeyCode::Space => {
                        if let Some(clock) = &mut state.clock {
                            clock.toggle();
                        }
                    }
                    _ => {}
                }
            }
            WindowEvent::MouseInput {
                button: MouseButton::Left,
                state: pressed,
                ..
            } => state.dragging = pressed == ElementState::Pressed,
            WindowEvent::RedrawRequested => {
                let last = self.args.frames.is_some_and(|n| state.frames + 1 >= n);
                let shot = last && self.args.screenshot.is_some();
                match state.frame(&self.args.lenses, shot) {
                    Ok(image) => {
                        if let (Some(image), Some(path)) = (image, &self.args.screenshot)
                            && let Err(e) = image.save(path)
                        {
                            return self.fail(event_loop, format!("{}: {e}", path.display()));
                        }
                        if last {
                            event_loop.exit();
                        } else {
                            state.window.request_redraw();
                        }
                    }
                    Err(e) => self.fail(event_loop, e),
                }
            }
            _ => {}
        }
    }

    fn device_event(&mut self, _: &ActiveEventLoop, _: winit::event::DeviceId, event: DeviceEvent) {
        if let (Some(state), DeviceEvent::MouseMotion { delta }) = (self.state.as_mut(), event)
            && state.dragging
        {
            state.look(delta.0, delta.1);
        }
    }
}

fn main() {
    let args = match args() {
        Ok(args) => args,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    let scene = match fisheye_rt::scene::load(&args.scene) {
        Ok(loaded) => {
            for w in &loaded.warnings {
                eprintln!("warning: {w}");
            }
            if args.time.is_some() && !loaded.scene.moves() {
                eprintln!(
                    "note: nothing in {} moves, so --time changes nothing",
                    args.scene
                );
            }
            loaded.scene
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let event_loop = match EventLoop::new() {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: no display to open a window on ({e}); try xvfb-run");
            std::process::exit(1);
        }
    };
    let mut app = App {
        args,
        scene: Some(scene),
        state: None,
        error: None,
    };
    if let Err(e) = event_loop.run_app(&mut app) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    if let Some(e) = app.error {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

//! `fisheye`: the command-line tool. See `fisheye --help` and the README.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use fisheye_rt::bench::{self, PathKind, SceneSet, Setup};
use fisheye_rt::bvh::BvhQuality;
use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings, FACES};
use fisheye_rt::demo::LensDemo;
use fisheye_rt::gpu::{GpuContext, Queries};
use fisheye_rt::lens::calib::{self, CalibFormat, Calibration};
use fisheye_rt::lens::gpu::{DirectionSource, LensPoints};
use fisheye_rt::lens::{
    CalibratedModel, DirectionFormula, ImageSize, LensCamera, LensModel, PRESET_FOV_DEGREES,
    PRESETS, parse_spec,
};
use fisheye_rt::raster::RasterMethod;
use fisheye_rt::report::{self, LensRun, Progress, Study};
use fisheye_rt::scene::{Scene, builtin};
use fisheye_rt::trace::{
    Channel, GpuScene, RenderOptions, TracePass, Traversal, colour_image, save_png,
    world_directions,
};
use fisheye_rt::validate;
use glam::{DVec2, DVec3};

#[derive(Parser)]
#[command(
    name = "fisheye",
    version,
    about = "Fisheye lens rendering by ray tracing in wgpu compute shaders"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene through a lens by ray tracing; with no arguments, the built-in default
    /// scene through a 180° fisheye to fisheye.png.
    Render(RenderArgs),
    /// Time every method (direct RT, ray queries, cube maps at several face sizes) along a
    /// camera path, fisheye and pinhole: fps statistics and per-pass GPU times, as JSON, a
    /// Markdown table and a PNG of fps along the path, in the --out folder.
    Bench(BenchArgs),
    /// Measure every method's error against direct ray tracing and a supersampled reference,
    /// with its time per frame: JSON, a Markdown table, error maps and a time-against-error
    /// PNG with the Pareto front, in the --out folder.
    Compare(CompareArgs),
    /// Check lens models against rendered images: render the built-in `grid` checkerboard
    /// through each lens, find its corners in the image to a fraction of a pixel without the
    /// lens model, and compare them with where the model projects them. Writes a Markdown
    /// table, JSON, an overlay per lens and an error plot into the --out folder; exits
    /// non-zero if a lens misses the bound.
    Validate(ValidateArgs),
    /// List the built-in scenes.
    Scenes,
    /// Show the GPU adapter, its optional features and limits, and measure the precision of
    /// WGSL's trigonometric builtins against this project's replacements on it.
    Info,
    /// Lens models: list them, map pixels and directions, draw what they do.
    Lens {
        #[command(subcommand)]
        command: LensCommand,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene: `builtin:NAME` (see `fisheye scenes`), a scene file (`.toml`, see
    /// `scenes/`), or an OBJ file, framed from the front with a headlight and a sun.
    #[arg(default_value = "builtin:default")]
    scene: String,
    /// Lens spec (see `fisheye lens list`).
    #[arg(long, default_value = "canon-8-15mm@8mm")]
    lens: String,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    size: ImageSize,
    #[command(flatten)]
    calib: CalibArgs,
    /// Camera pose instead of the scene's: `X,Y,Z:LX,LY,LZ` (eye and look-at point, y up),
    /// or `path:S` for the point S ∈ [0, 1] along the scene file's camera path.
    #[arg(long)]
    camera: Option<String>,
    /// How to make the image: `rt` traces the lens's rays directly, `rq` does too with the
    /// adapter's hardware ray queries in place of the software BVH traversal (same lens and
    /// shading code; an error where the adapter lacks them); the `cube-*` methods render
    /// the faces of a cube map (those the lens reaches, and of them only the parts it reaches)
    /// and resample it: `cube-rt` traces them; `cube-forward` (a render pass per face),
    /// `cube-deferred` (G-buffer, then lighting in a compute pass) and `cube-single` (one
    /// multiview pass) rasterize them, with shadow maps and no reflection or refraction.
    #[arg(long, value_enum, default_value = "rt")]
    method: Method,
    /// Face size of the cube map in texels (`cube-*` methods).
    #[arg(long, default_value_t = 1024)]
    cube_size: u32,
    #[command(flatten)]
    shading: ShadingArgs,
    /// Primary ray directions: evaluated per pixel, or read from a table made once.
    #[arg(long, value_enum, default_value = "computed")]
    directions: Directions,
    /// The colour image (PNG; alpha is the validity mask).
    #[arg(long, short, default_value = "fisheye.png")]
    out: PathBuf,
    /// Ground-truth arrays to write beside the image as OUT_STEM.NAME.npy (or .exr): range
    /// (distance to the primary hit), normal, id (triangle), direction (world-space ray), mask.
    #[arg(long, value_enum, value_delimiter = ',')]
    outputs: Vec<Output>,
    /// File format of the ground-truth arrays.
    #[arg(long, value_enum, default_value = "npy")]
    format: ArrayFormat,
}

/// How the scene is built and shaded, for `render`, `bench` and `compare`.
#[derive(clap::Args)]
struct ShadingArgs {
    /// Shadow-map size in texels per side and layer (rasterized `cube-*` methods).
    #[arg(long, default_value_t = 2048)]
    shadow_size: u32,
    /// Deepest reflection/refraction bounce.
    #[arg(long, default_value_t = 5)]
    max_depth: u32,
    /// BVH build preset.
    #[arg(long, value_enum, default_value = "fast")]
    bvh: Quality,
}

/// The scene, lenses, setups and outputs `bench` and `compare` share with `render`.
#[derive(clap::Args)]
struct StudyArgs {
    /// The scene, as for `render`.
    #[arg(default_value = "builtin:default")]
    scene: String,
    /// Lens specs to measure (repeatable); or give --calib.
    #[arg(long, default_value = "canon-8-15mm@8mm")]
    lens: Vec<String>,
    /// The pinhole baseline measured beside the lenses, at the same image size.
    #[arg(long, default_value = "rectilinear:f=1")]
    pinhole: String,
    /// Leave the pinhole baseline out.
    #[arg(long)]
    no_pinhole: bool,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    size: ImageSize,
    #[command(flatten)]
    calib: CalibArgs,
    /// Camera pose instead of the scene's (as for `render`); the orbit path circles its
    /// look-at point.
    #[arg(long)]
    camera: Option<String>,
    /// Methods to measure (comma-separated); by default every one the adapter has.
    #[arg(long, value_enum, value_delimiter = ',')]
    method: Vec<Method>,
    /// Cube face sizes to measure the cube-map methods at (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "512,1024,1920")]
    cube_size: Vec<u32>,
    #[command(flatten)]
    shading: ShadingArgs,
    /// Folder for the results; by default a new folder `fisheye-COMMAND-N` here.
    #[arg(long, short)]
    out: Option<PathBuf>,
}

#[derive(clap::Args)]
struct BenchArgs {
    #[command(flatten)]
    study: StudyArgs,
    /// Timed frames per setup along the path.
    #[arg(long, default_value_t = 60)]
    frames: usize,
    /// Untimed frames first, per setup.
    #[arg(long, default_value_t = 3)]
    warmup: usize,
    /// Camera path: `walk` (the scene's keyframes; every built-in scene but `grid` has them)
    /// or `orbit` (a circle around the camera's look-at point, for open scenes). Default:
    /// walk where the scene has keyframes.
    #[arg(long, value_enum)]
    path: Option<PathArg>,
}

#[derive(clap::Args)]
struct CompareArgs {
    #[command(flatten)]
    study: StudyArgs,
    /// Timed frames per setup at the pose (the median is reported), after one untimed.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Rays per pixel side of the supersampled reference (1 to 8); by default the most, up to
    /// 4, whose image fits one storage binding.
    #[arg(long)]
    supersample: Option<u32>,
}

#[derive(clap::Args)]
struct ValidateArgs {
    /// Lens specs to validate (repeatable); by default every preset (at 512x512) and each
    /// calibrated model's example (at the size it is calibrated for), as `fisheye lens list`
    /// shows them.
    #[arg(long)]
    lens: Vec<String>,
    /// Image size for --lens, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512")]
    size: ImageSize,
    #[command(flatten)]
    calib: CalibArgs,
    /// Rays per pixel side of the rendered images (1 to 8); by default the most, up to 4,
    /// whose image fits one storage binding.
    #[arg(long)]
    supersample: Option<u32>,
    /// Folder for the results; by default a new folder `fisheye-validate-N` here.
    #[arg(long, short)]
    out: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum PathArg {
    Walk,
    Orbit,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Method {
    Rt,
    Rq,
    CubeRt,
    CubeForward,
    CubeDeferred,
    CubeSingle,
}

impl Method {
    /// The library's method.
    fn method(self) -> bench::Method {
        let raster = |m| bench::Method::Cube(CubeMethod::Raster(m));
        match self {
            Self::Rt => bench::Method::Rt,
            Self::Rq => bench::Method::Rq,
            Self::CubeRt => bench::Method::Cube(CubeMethod::Traced),
            Self::CubeForward => raster(RasterMethod::Forward),
            Self::CubeDeferred => raster(RasterMethod::Deferred),
            Self::CubeSingle => raster(RasterMethod::SinglePass),
        }
    }

    /// The cube-map method, `None` for direct ray tracing.
    fn cube(self) -> Option<CubeMethod> {
        match self.method() {
            bench::Method::Cube(m) => Some(m),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ArrayFormat {
    Npy,
    Exr,
}

/// Parses `--camera`: `X,Y,Z:LX,LY,LZ` or `path:S`.
fn parse_camera(text: &str, scene: &Scene) -> Result<fisheye_rt::scene::Camera> {
    if let Some(s) = text.strip_prefix("path:") {
        let s: f64 = s
            .parse()
            .ok()
            .filter(|s: &f64| (0.0..=1.0).contains(s))
            .with_context(|| format!("--camera {text:?}: S must be a number in [0, 1]"))?;
        if scene.camera_path.is_empty() {
            bail!("--camera {text:?}: this scene has no camera path");
        }
        return Ok(scene.camera_on_path(s));
    }
    let triple = |t: &str| -> Option<DVec3> {
        let v: Vec<f64> = t
            .split(',')
            .map(|x| x.trim().parse().ok())
            .collect::<Option<_>>()?;
        (v.len() == 3 && v.iter().all(|x| x.is_finite())).then(|| DVec3::new(v[0], v[1], v[2]))
    };
    let pose = text
        .split_once(':')
        .and_then(|(p, l)| Some((triple(p)?, triple(l)?)))
        .filter(|(p, l)| p != l)
        .with_context(|| {
            format!(
                "--camera {text:?}: expected X,Y,Z:LX,LY,LZ (two different finite points) or path:S"
            )
        })?;
    Ok(fisheye_rt::scene::Camera {
        position: pose.0,
        look_at: pose.1,
        up: DVec3::Y,
    })
}

#[derive(Clone, Copy, ValueEnum)]
enum Formula {
    Stable,
    Thesis,
}

impl From<Formula> for DirectionFormula {
    fn from(f: Formula) -> Self {
        match f {
            Formula::Stable => DirectionFormula::Stable,
            Formula::Thesis => DirectionFormula::Thesis,
        }
    }
}

/// A calibration file in place of `--lens` and `--size`.
#[derive(clap::Args)]
struct CalibArgs {
    /// Calibration file (OpenCV YAML/XML, Kalibr camchain YAML or Basalt JSON): render
    /// through that camera at its resolution, instead of --lens and --size.
    #[arg(long, conflicts_with_all = ["lens", "size"])]
    calib: Option<PathBuf>,
    /// Which camera of a multi-camera calibration file (0 is the first).
    #[arg(long, default_value_t = 0, requires = "calib")]
    calib_camera: usize,
}

impl CalibArgs {
    /// How reports name the camera of `--calib`: the file, and the camera if not the first.
    fn describe(&self) -> String {
        let path = self
            .calib
            .as_deref()
            .map_or(String::new(), |p| p.display().to_string());
        match self.calib_camera {
            0 => path,
            n => format!("{path}#{n}"),
        }
    }

    /// The camera of `--calib`, or else `--lens` (required then) at `size`; warns when the
    /// lens's field of view is clipped where its mapping turns.
    fn camera(&self, lens: Option<&str>, size: ImageSize) -> Result<LensCamera> {
        let camera = match &self.calib {
            Some(path) => {
                let cameras = calib::read(path)?;
                let Some(c) = cameras.get(self.calib_camera) else {
                    bail!(
                        "{} holds {} camera(s); --calib-camera {} is not one",
                        path.display(),
                        cameras.len(),
                        self.calib_camera
                    );
                };
                LensCamera::new(c.lens, c.size)
            }
            None => {
                let Some(spec) = lens else {
                    bail!("give a lens: --lens SPEC or --calib FILE");
                };
                LensCamera::new(parse_spec(spec)?, size)
            }
        };
        if let Some(turn) = camera.lens.calibrated().and_then(|l| l.turns_at()) {
            eprintln!(
                "warning: {}: the mapping stops increasing at θ = {:.2}°, so the field of view \
                 is clipped to {:.2}° (pixels beyond have no ray)",
                camera.lens.name(),
                turn.to_degrees(),
                2.0 * turn.to_degrees()
            );
        }
        Ok(camera)
    }
}

#[derive(clap::Args)]
struct CameraArgs {
    /// Lens spec: a model with parameters (`equisolid:f=0.93`, `general:f=1,k1=0.5,k2=0.5`,
    /// `equidistant:f=0.42,fov=180`, `kb:fx=190,cx=255,cy=255,k1=0.003`), or a preset
    /// (`samyang-7.5mm`); see `fisheye lens list`. Or give --calib.
    #[arg(long)]
    lens: Option<String>,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    size: ImageSize,
    #[command(flatten)]
    calib: CalibArgs,
    /// How directions are built from θ: the stable default, or the thesis's formula.
    #[arg(long, value_enum, default_value = "stable")]
    formula: Formula,
    /// Run the WGSL (f32) lens code on the GPU instead of the f64 reference.
    #[arg(long)]
    gpu: bool,
}

impl CameraArgs {
    fn camera(&self) -> Result<LensCamera> {
        let camera = self.calib.camera(self.lens.as_deref(), self.size)?;
        Ok(camera.with_formula(self.formula.into()))
    }
}

#[derive(Subcommand)]
enum LensCommand {
    /// List the lens models and the presets.
    List,
    /// Read `px py` lines on stdin (continuous pixel coordinates, origin at the top-left
    /// corner of the image) and write the unit direction `dx dy dz` (x right, y down, z
    /// forward) or `none` for each.
    Unproject(CameraArgs),
    /// Read `dx dy dz` lines on stdin and write the pixel `px py` each lands on, or `none`.
    Project(CameraArgs),
    /// Fit the thesis's classic mappings (equidistant, equisolid, orthographic,
    /// stereographic) to a calibrated lens over the angles its image shows, and print each
    /// one's focal length and radial residual in pixels, best first.
    Fit(CameraArgs),
    /// Write a lens (--lens SPEC at --size, or --calib FILE) as a calibration file: OpenCV
    /// YAML or XML, a Kalibr camchain or Basalt JSON.
    Convert {
        #[command(flatten)]
        camera: CameraArgs,
        /// The output format.
        #[arg(long, value_enum)]
        format: Format,
        /// The file to write.
        #[arg(long, short)]
        out: PathBuf,
    },
    /// Draw what lenses do to the sphere of directions (10° grid, rings every 30° off the
    /// axis), one PNG per lens.
    Demo {
        /// Lens specs to draw (repeatable); by default one of each model and every preset.
        #[arg(long)]
        lens: Vec<String>,
        /// Image size in pixels, WIDTHxHEIGHT.
        #[arg(long, default_value = "1024x768")]
        size: ImageSize,
        /// Folder to write the PNGs into.
        #[arg(long, short, default_value = "fisheye-demo")]
        out: PathBuf,
    },
}

fn main() {
    if let Err(error) = run(Cli::parse()) {
        eprintln!("error: {error:#}");
        std::process::exit(1);
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum Quality {
    Fastest,
    VeryFast,
    Fast,
    Medium,
    Slow,
}

impl From<Quality> for BvhQuality {
    fn from(q: Quality) -> Self {
        match q {
            Quality::Fastest => BvhQuality::Fastest,
            Quality::VeryFast => BvhQuality::VeryFast,
            Quality::Fast => BvhQuality::Fast,
            Quality::Medium => BvhQuality::Medium,
            Quality::Slow => BvhQuality::Slow,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum Output {
    Range,
    Normal,
    Id,
    Direction,
    Mask,
}

impl From<Output> for Channel {
    fn from(o: Output) -> Self {
        match o {
            Output::Range => Channel::Range,
            Output::Normal => Channel::Normal,
            Output::Id => Channel::Id,
            Output::Direction => Channel::Direction,
            Output::Mask => Channel::Mask,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum Directions {
    Computed,
    Table,
}

impl From<Directions> for DirectionSource {
    fn from(d: Directions) -> Self {
        match d {
            Directions::Computed => DirectionSource::Computed,
            Directions::Table => DirectionSource::Table,
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render(&args),
        Command::Bench(args) => run_bench(&args),
        Command::Compare(args) => run_compare(&args),
        Command::Validate(args) => run_validate(&args),
        Command::Scenes => {
            for (name, what) in builtin::SCENES {
                println!("builtin:{name:<14} {what}");
            }
            Ok(())
        }
        Command::Info => info(),
        Command::Lens { command } => match command {
            LensCommand::List => {
                list();
                Ok(())
            }
            LensCommand::Unproject(args) => unproject(&args),
            LensCommand::Project(args) => project(&args),
            LensCommand::Fit(args) => fit(&args),
            LensCommand::Convert {
                camera,
                format,
                out,
            } => convert(&camera, format.into(), &out),
            LensCommand::Demo { lens, size, out } => demo(lens, size, out),
        },
    }
}

/// A scene from `builtin:NAME`, a scene file or an OBJ file; warnings go to stderr.
fn load_scene(spec: &str) -> Result<Scene> {
    let loaded = fisheye_rt::scene::load(spec)?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(loaded.scene)
}

fn render(args: &RenderArgs) -> Result<()> {
    let started = Instant::now();
    let options = RenderOptions {
        max_depth: args.shading.max_depth,
        bvh: args.shading.bvh.into(),
        directions: args.directions.into(),
        traversal: if args.method == Method::Rq {
            Traversal::RayQuery
        } else {
            Traversal::Software
        },
    };
    let camera = args.calib.camera(Some(&args.lens), args.size)?;
    let (size, out) = (camera.size, &args.out);
    let scene_spec = &args.scene;
    let mut scene = load_scene(scene_spec)?;
    if let Some(text) = &args.camera {
        scene.camera = parse_camera(text, &scene)?;
    }
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let gpu_scene = GpuScene::new(&ctx, &scene, &options)?;
    println!(
        "scene: {scene_spec}, {} triangles; BVH ({}) {} nodes, depth {}, built in {:.1} ms",
        scene.len(),
        options.bvh.name(),
        gpu_scene.bvh_nodes,
        gpu_scene.bvh_depth,
        gpu_scene.bvh_build_time.as_secs_f64() * 1e3
    );
    if let Some(rq) = &gpu_scene.ray_query {
        println!(
            "ray queries: acceleration structure built by the driver in {:.1} ms",
            rq.build_time.as_secs_f64() * 1e3
        );
    }
    println!(
        "lens: {} at {size}; compiling the trace kernel...",
        camera.lens
    );
    if let Some(method) = args.method.cube() {
        if !args.outputs.is_empty() {
            bail!("--outputs come from the direct tracer; use --method rt for ground-truth arrays");
        }
        let settings = CubeSettings {
            shadow_size: args.shading.shadow_size,
            ..CubeSettings::new(args.cube_size, method)
        };
        let cube = CubeMap::new(&ctx, &camera, &gpu_scene, &settings)?;
        let regions = cube.regions();
        let faces: Vec<&str> = FACES
            .iter()
            .zip(regions)
            .filter_map(|(f, r)| r.map(|_| f.name))
            .collect();
        let rendered: u64 = regions.iter().flatten().map(|r| r.texels()).sum();
        let side = u64::from(args.cube_size + 2);
        println!(
            "cube map ({}): {} faces of {}² texels ({}); rendered {:.0}% of their texels (the \
             parts the lens reaches), then resampled",
            method.name(),
            faces.len(),
            args.cube_size,
            faces.join(" "),
            100.0 * rendered as f64 / (faces.len() as u64 * side * side) as f64
        );
        if let Some(maps) = cube.shadow_maps() {
            println!(
                "shadow maps: {} layers of {}² for {} lights",
                maps.views().len(),
                maps.size(),
                scene.lights.len()
            );
        }
        let colour = cube.render(&ctx, &gpu_scene, &scene.camera)?;
        save_png(&colour_image(size, &colour), out)?;
        println!(
            "wrote {} ({:.1} s in all)",
            out.display(),
            started.elapsed().as_secs_f64()
        );
        return Ok(());
    }
    let pass = TracePass::new(&ctx, &camera, &gpu_scene, options.directions)?;
    let queries = Queries::new(&ctx, 1);
    ctx.checked("tracing", || {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        pass.encode(
            &mut encoder,
            &gpu_scene,
            queries.as_ref().map(|q| q.writes(0)),
        );
        if let Some(q) = &queries {
            q.resolve(&mut encoder);
        }
        ctx.queue.submit([encoder.finish()]);
    })?;
    let output = pass.read(&ctx)?;
    let (rays, hits) = output.counts();
    match &queries {
        Some(q) => {
            let ms = q.read_ns(&ctx)?[0] * 1e-6;
            println!(
                "trace: {ms:.1} ms on the GPU, {rays} primary rays ({hits} hit), {:.2} M primary rays/s",
                rays as f64 / ms * 1e-3
            );
        }
        None => {
            println!("trace: {rays} primary rays ({hits} hit); no GPU timestamps on this adapter")
        }
    }
    save_png(&output.to_image(), out)?;
    if !args.outputs.is_empty() {
        let directions = world_directions(&camera, &scene.camera);
        for channel in args.outputs.iter().map(|&o| Channel::from(o)) {
            let path = match args.format {
                ArrayFormat::Npy => {
                    let path = out.with_extension(format!("{}.npy", channel.name()));
                    output.write_npy(channel, &directions, &path)?;
                    path
                }
                ArrayFormat::Exr => {
                    let path = out.with_extension(format!("{}.exr", channel.name()));
                    output.write_exr(channel, &directions, &path)?;
                    path
                }
            };
            println!("wrote {}", path.display());
        }
    }
    println!(
        "wrote {} ({:.1} s in all)",
        out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

fn info() -> Result<()> {
    let ctx = GpuContext::new()?;
    print!("{}", ctx.report());
    println!("trigonometry, max |error| against f64 (WGSL builtin / fisheye-rt math.wgsl):");
    for t in fisheye_rt::precision::measure_trig(&ctx)? {
        println!(
            "  {:<5} on {:<7} builtin {:9.2e}   ours {:9.2e}",
            t.function, t.domain, t.builtin, t.ours
        );
    }
    Ok(())
}

fn list() {
    println!("models (spec: NAME:f=F[,fov=DEGREES]; general also takes k1, k2):");
    let general = LensModel::General { k1: 1.0, k2: 1.0 };
    for model in [
        LensModel::Rectilinear,
        LensModel::Stereographic,
        LensModel::Equidistant,
        LensModel::Equisolid,
        LensModel::Orthographic,
        general,
    ] {
        println!("  {:<14} {}", model.name(), model.formula());
    }
    println!(
        "\ncalibrated models (spec: NAME:fx=FX,fy=FY,cx=CX,cy=CY,...[,fov=DEGREES], pixels, \
         OpenCV's centre convention):"
    );
    for ((name, keys), example) in CalibratedModel::NAMES.iter().zip(CalibratedModel::EXAMPLES) {
        println!("  {name:<14} {keys}\n  {:<14} e.g. {example}", "");
    }
    println!("\npresets (limited to {PRESET_FOV_DEGREES}°; spec: NAME[:f=F,fov=DEGREES]):");
    for p in PRESETS {
        println!(
            "  {:<24} {:<13} f={:<6} {}",
            p.name,
            p.model.name(),
            p.f,
            p.description
        );
    }
}

/// Parses stdin: one point per non-empty line, `N` numbers each; `#` starts a comment.
fn read_points<const N: usize>() -> Result<Vec<[f64; N]>> {
    let mut points = Vec::new();
    for (number, line) in std::io::stdin().lock().lines().enumerate() {
        let line = line.context("reading stdin")?;
        let text = line.split('#').next().unwrap_or("").trim();
        if text.is_empty() {
            continue;
        }
        let values: Vec<f64> = text
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .with_context(|| format!("stdin line {}: {text:?} is not numbers", number + 1))?;
        let Ok(point) = <[f64; N]>::try_from(values) else {
            bail!(
                "stdin line {}: expected {N} numbers, got {text:?}",
                number + 1
            );
        };
        points.push(point);
    }
    Ok(points)
}

fn write_lines(lines: impl Iterator<Item = String>) -> Result<()> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for line in lines {
        writeln!(out, "{line}")?;
    }
    Ok(out.flush()?)
}

fn unproject(args: &CameraArgs) -> Result<()> {
    let camera = args.camera()?;
    let pixels: Vec<DVec2> = read_points::<2>()?.into_iter().map(DVec2::from).collect();
    let dirs: Vec<Option<DVec3>> = if args.gpu {
        let ctx = GpuContext::new()?;
        LensPoints::new(&ctx, &camera)?
            .unproject(&ctx, &pixels)?
            .into_iter()
            .map(|d| d.map(|d| d.as_dvec3()))
            .collect()
    } else {
        pixels.iter().map(|&p| camera.unproject(p)).collect()
    };
    write_lines(dirs.into_iter().map(|d| match d {
        Some(d) => format!("{:.9} {:.9} {:.9}", d.x, d.y, d.z),
        None => "none".into(),
    }))
}

fn project(args: &CameraArgs) -> Result<()> {
    let camera = args.camera()?;
    let dirs: Vec<DVec3> = read_points::<3>()?.into_iter().map(DVec3::from).collect();
    let pixels: Vec<Option<DVec2>> = if args.gpu {
        let ctx = GpuContext::new()?;
        LensPoints::new(&ctx, &camera)?
            .project(&ctx, &dirs)?
            .into_iter()
            .map(|p| p.map(|p| p.as_dvec2()))
            .collect()
    } else {
        dirs.iter().map(|&d| camera.project(d)).collect()
    };
    write_lines(pixels.into_iter().map(|p| match p {
        Some(p) => format!("{:.6} {:.6}", p.x, p.y),
        None => "none".into(),
    }))
}

/// Calibration file formats, for `lens convert`.
#[derive(Clone, Copy, ValueEnum)]
enum Format {
    OpencvYaml,
    OpencvXml,
    Kalibr,
    Basalt,
}

impl From<Format> for CalibFormat {
    fn from(f: Format) -> Self {
        match f {
            Format::OpencvYaml => CalibFormat::OpenCvYaml,
            Format::OpencvXml => CalibFormat::OpenCvXml,
            Format::Kalibr => CalibFormat::Kalibr,
            Format::Basalt => CalibFormat::Basalt,
        }
    }
}

fn fit(args: &CameraArgs) -> Result<()> {
    let camera = args.camera()?;
    let Some(lens) = camera.lens.calibrated() else {
        bail!(
            "{} is already a classic lens; fit takes a calibrated one",
            camera.lens
        );
    };
    let angles = fisheye_rt::lens::fit::fitted_angles(lens, camera.size);
    let widest = angles.last().copied().unwrap_or(0.0).to_degrees();
    println!(
        "{} at {}: classic mappings fitted over θ ≤ {widest:.1}° (a {:.1}° field)",
        lens.model().name(),
        camera.size,
        2.0 * widest
    );
    println!(
        "{:<14} {:>10} {:>10} {:>12} {:>12}",
        "model", "f (px)", "f (norm.)", "rms (px)", "max (px)"
    );
    for f in fisheye_rt::lens::fit::fit_classic(lens, camera.size) {
        println!(
            "{:<14} {:>10.3} {:>10.4} {:>12.4} {:>12.4}",
            f.model.name(),
            f.f_pixels,
            f.f_pixels * 2.0 / f64::from(camera.size.width),
            f.rms,
            f.max
        );
    }
    Ok(())
}

fn convert(args: &CameraArgs, format: CalibFormat, out: &Path) -> Result<()> {
    let camera = args.camera()?;
    let Some(lens) = camera.lens.calibrated() else {
        bail!(
            "{} is a classic lens; calibration files hold calibrated models (see `fisheye lens \
             list`)",
            camera.lens
        );
    };
    let text = calib::write(
        &Calibration {
            lens: *lens,
            size: camera.size,
        },
        format,
    )?;
    std::fs::write(out, text).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {} ({})", out.display(), format.name());
    Ok(())
}

/// One representative lens per model, then every preset.
fn default_demo_lenses() -> Vec<String> {
    let mut specs: Vec<String> = [
        "rectilinear:f=0.5",
        "stereographic:f=0.35",
        "equidistant:f=0.3",
        "equisolid:f=0.45",
        "orthographic:f=0.66",
        "general:f=0.4,k1=0.7,k2=0.7",
    ]
    .map(String::from)
    .to_vec();
    specs.extend(PRESETS.iter().map(|p| p.name.to_string()));
    specs
}

fn demo(lenses: Vec<String>, size: ImageSize, out: PathBuf) -> Result<()> {
    let lenses = if lenses.is_empty() {
        default_demo_lenses()
    } else {
        lenses
    };
    // Check every spec before starting the GPU.
    let cameras = lenses
        .iter()
        .map(|spec| Ok((spec, LensCamera::new(parse_spec(spec)?, size))))
        .collect::<Result<Vec<_>>>()?;
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let queries = Queries::new(&ctx, 1);
    for (spec, camera) in cameras {
        let started = Instant::now();
        let demo = LensDemo::new(&ctx, &camera, DirectionSource::Computed)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        demo.encode(&mut encoder, queries.as_ref().map(|q| q.writes(0)));
        if let Some(q) = &queries {
            q.resolve(&mut encoder);
        }
        ctx.queue.submit([encoder.finish()]);
        let gpu_ms = match &queries {
            Some(q) => format!("{:.2} ms on the GPU", q.read_ns(&ctx)?[0] * 1e-6),
            None => "no timestamps".into(),
        };
        let image = demo.render(&ctx)?;
        let path = out.join(format!("{}.png", report::file_stem(spec)));
        save_png(&image, &path)?;
        println!(
            "{:<36} -> {} ({gpu_ms}, {:.0} ms in all)",
            camera.lens.to_string(),
            path.display(),
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}

/// What `bench` and `compare` set up from their shared arguments.
struct Prepared {
    ctx: GpuContext,
    scene: Scene,
    scenes: SceneSet,
    lenses: Vec<LensRun>,
    setups: Vec<Setup>,
    out: PathBuf,
}

impl Prepared {
    fn study(&self, args: &StudyArgs) -> Study<'_> {
        Study {
            ctx: &self.ctx,
            scene: &self.scene,
            scene_name: args.scene.clone(),
            scenes: &self.scenes,
            lenses: &self.lenses,
            setups: &self.setups,
            shadow_size: args.shading.shadow_size,
        }
    }
}

/// Checks the arguments, loads the scene, makes the output folder and uploads the scene.
fn prepare(args: &StudyArgs, command: &str) -> Result<Prepared> {
    let mut lenses = match &args.calib.calib {
        Some(_) => vec![LensRun {
            name: args.calib.describe(),
            camera: args.calib.camera(None, args.size)?,
        }],
        None => args
            .lens
            .iter()
            .map(|spec| {
                Ok(LensRun {
                    name: spec.clone(),
                    camera: LensCamera::new(parse_spec(spec)?, args.size),
                })
            })
            .collect::<Result<Vec<_>>>()?,
    };
    // The calibration's resolution, or --size.
    let size = lenses.first().map_or(args.size, |l| l.camera.size);
    if !args.no_pinhole {
        lenses.push(LensRun {
            name: args.pinhole.clone(),
            camera: LensCamera::new(parse_spec(&args.pinhole)?, size),
        });
    }
    if let Some(&bad) = args.cube_size.iter().find(|&&s| s == 0) {
        bail!("--cube-size {bad}: face sizes must be at least 1");
    }
    let methods: Vec<bench::Method> = if args.method.is_empty() {
        bench::Method::ALL.to_vec()
    } else {
        args.method.iter().map(|m| m.method()).collect()
    };
    let setups = Setup::all(&methods, &args.cube_size);
    let mut scene = load_scene(&args.scene)?;
    if let Some(text) = &args.camera {
        scene.camera = parse_camera(text, &scene)?;
    }
    let out = out_folder(args.out.as_deref(), command)?;
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let options = RenderOptions {
        max_depth: args.shading.max_depth,
        bvh: args.shading.bvh.into(),
        ..RenderOptions::default()
    };
    let scenes = SceneSet::new(&ctx, &scene, &options, &setups)?;
    println!(
        "scene: {}, {} triangles; {} setups on {} lenses at {}",
        args.scene,
        scene.len(),
        setups.len(),
        lenses.len(),
        size
    );
    Ok(Prepared {
        ctx,
        scene,
        scenes,
        lenses,
        setups,
        out,
    })
}

/// `out`, or else a new folder `fisheye-COMMAND-N` here; created.
fn out_folder(out: Option<&std::path::Path>, command: &str) -> Result<PathBuf> {
    let out = match out {
        Some(out) => out.to_path_buf(),
        None => (1..)
            .map(|n| PathBuf::from(format!("fisheye-{command}-{n}")))
            .find(|p| !p.exists())
            .expect("a free folder name"),
    };
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    Ok(out)
}

/// A progress bar on stderr when it is a terminal, else a line per new setup.
fn progress_bar() -> impl FnMut(Progress<'_>) {
    use std::io::IsTerminal;
    let terminal = std::io::stderr().is_terminal();
    let mut last = String::new();
    move |p: Progress<'_>| {
        if terminal {
            let width = 30;
            let filled = (width * p.done / p.total.max(1)).min(width);
            eprint!(
                "\r[{}{}] {:>5}/{} frames  {:<40}",
                "#".repeat(filled),
                ".".repeat(width - filled),
                p.done,
                p.total,
                p.what
            );
            if p.done == p.total {
                eprintln!();
            }
        } else if p.what != last {
            eprintln!("[{}/{} frames] {}", p.done, p.total, p.what);
        }
        last = p.what.to_string();
    }
}

/// Prints the table lines of a report's Markdown and where the files went.
fn finish(markdown: &str, out: &std::path::Path, plot_warning: Option<String>) {
    println!();
    for line in markdown.lines().filter(|l| !l.starts_with('#')) {
        println!("{line}");
    }
    if let Some(why) = plot_warning {
        eprintln!("warning: no plots: {why}");
    }
    println!("\nwrote {}", out.display());
}

fn run_bench(args: &BenchArgs) -> Result<()> {
    let p = prepare(&args.study, "bench")?;
    let path = match args.path {
        Some(PathArg::Walk) => PathKind::Walk,
        Some(PathArg::Orbit) => PathKind::Orbit,
        None if p.scene.camera_path.is_empty() => PathKind::Orbit,
        None => PathKind::Walk,
    };
    let study = p.study(&args.study);
    let report = report::bench(&study, path, args.frames, args.warmup, &mut progress_bar())?;
    let warning = report.write(&p.out)?;
    finish(&report.markdown(), &p.out, warning);
    Ok(())
}

fn run_compare(args: &CompareArgs) -> Result<()> {
    if let Some(s) = args.supersample.filter(|s| !(1..=8).contains(s)) {
        bail!("--supersample {s}: must be 1 to 8");
    }
    let p = prepare(&args.study, "compare")?;
    let supersample = args.supersample.unwrap_or_else(|| {
        fisheye_rt::compare::supersample_factor(&p.ctx, p.lenses[0].camera.size)
    });
    let study = p.study(&args.study);
    let pose = p.scene.camera;
    let report = report::compare(
        &study,
        &pose,
        args.frames,
        supersample,
        &p.out,
        &mut progress_bar(),
    )?;
    let warning = report.write(&p.out)?;
    finish(&report.markdown(), &p.out, warning);
    Ok(())
}

fn run_validate(args: &ValidateArgs) -> Result<()> {
    if let Some(s) = args.supersample.filter(|s| !(1..=8).contains(s)) {
        bail!("--supersample {s}: must be 1 to 8");
    }
    let lenses = if args.calib.calib.is_some() {
        vec![validate::LensToValidate {
            name: args.calib.describe(),
            camera: args.calib.camera(None, args.size)?,
        }]
    } else if args.lens.is_empty() {
        validate::default_lenses()?
    } else {
        args.lens
            .iter()
            .map(|spec| {
                Ok(validate::LensToValidate {
                    name: spec.clone(),
                    camera: args.calib.camera(Some(spec), args.size)?,
                })
            })
            .collect::<Result<Vec<_>>>()?
    };
    let out = out_folder(args.out.as_deref(), "validate")?;
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let count = lenses.len();
    let report = validate::run(&ctx, &lenses, args.supersample, &mut |k, name| {
        eprintln!("[{}/{count}] {name}", k + 1);
    })?;
    let warning = report.write(&out)?;
    finish(&report.markdown(), &out, warning);
    let failed: Vec<&str> = report
        .lenses
        .iter()
        .filter(|l| !l.passed)
        .map(|l| l.lens.as_str())
        .collect();
    if !failed.is_empty() {
        bail!(
            "{} of {count} lens(es) failed validation: {}",
            failed.len(),
            failed.join(", ")
        );
    }
    Ok(())
}

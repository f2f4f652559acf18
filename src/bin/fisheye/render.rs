//! `fisheye render`: one image, and its ground truth, through a lens.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Result, bail};
use fisheye_rt::bvh::BvhQuality;
use fisheye_rt::cube::{CubeMap, FACES, bordered};
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::ImageSize;
use fisheye_rt::lens::gpu::DirectionSource;
use fisheye_rt::renderer::{Offscreen, Pass, SceneSet, Setup};
use fisheye_rt::scene::{FRAME_FILL, Scene};
use fisheye_rt::trace::{
    Channel, ColourFile, Display, GpuScene, KEY, PixelFilter, PixelRays, RenderOptions, Sampling,
    Tone, auto_exposure, check_writable, rotated, save_png, spp_key, spp_picture, write_colour,
    write_rays_map,
};

use crate::args::{
    ArrayFormat, CalibArgs, Directions, Exposure, Method, Output, ShadingArgs, ToneArg, filter_for,
    load_scene_with, parse_camera,
};

#[derive(clap::Args)]
pub(crate) struct RenderArgs {
    /// The scene: `builtin:NAME` (see `fisheye scenes`), a scene file (`.toml`, see
    /// `scenes/`), an OBJ file, framed from the front for the lens (its bounding sphere fills
    /// 80% of the picture) with a headlight and a sun, or a glTF file (`.gltf`, `.glb`: its
    /// camera and lights where it has them, else framed and lit as an OBJ).
    #[arg(default_value = "builtin:default")]
    pub(crate) scene: String,
    /// Lens spec (see `fisheye lens list`).
    #[arg(long, default_value = "canon-8-15mm@8mm")]
    pub(crate) lens: String,
    /// Image size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    pub(crate) size: ImageSize,
    #[command(flatten)]
    pub(crate) calib: CalibArgs,
    /// Which scene of a glTF file (from 0); its default scene if not given.
    #[arg(long)]
    pub(crate) gltf_scene: Option<usize>,
    /// Camera pose instead of the scene's: `X,Y,Z:LX,LY,LZ` (eye and look-at point, y up),
    /// `path:S` for the point S ∈ [0, 1] along the scene file's camera path, or `gltf:N` for a
    /// glTF file's camera N (from 0). Coordinates may be negative (`--camera
    /// -16,-11.5,0:0,-9,0`).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) camera: Option<String>,
    /// Scene time in seconds: animated glTF nodes and keyed scene-file instances are placed
    /// where their keys put them then (before their first key, at it; after their last, at
    /// it).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub(crate) time: f64,
    /// How to make the image: `rt` traces the lens's rays directly, `rq` does too with the
    /// adapter's hardware ray queries in place of the software BVH traversal (same lens and
    /// shading code; an error where the adapter lacks them); the `cube-*` methods render
    /// the faces of a cube map (those the lens reaches, and of them only the parts it reaches)
    /// and resample it: `cube-rt` traces them; `cube-forward` (a render pass per face),
    /// `cube-deferred` (G-buffer, then lighting in a compute pass) and `cube-single` (one
    /// multiview pass) rasterize them, with shadow maps and no reflection or refraction.
    #[arg(long, value_enum, default_value = "rt")]
    pub(crate) method: Method,
    /// Face size of the cube map in texels (`cube-*` methods; 1024 unless given).
    #[arg(long)]
    pub(crate) cube_size: Option<u32>,
    /// Rays per pixel (direct methods): N, a square from 1 to 256, for N rays in every pixel
    /// (on a rotated grid: one in each row and column of N × N cells), their mean its colour
    /// (a box filter) and alpha the share of the pixel the lens covers; or auto,
    /// auto:THRESHOLD, auto:THRESHOLD:MAX or auto:THRESHOLD:MAX:LEAST for adaptive sampling:
    /// one ray per 4×4 pixels first, then rays where neighbours see different surfaces or
    /// their displayed colours bend by THRESHOLD or more (default 0.02 of full scale), then
    /// 2×2 samples where a pixel's colour still bends, and all MAX (default 16) where those
    /// disagree; the rest interpolated. LEAST 1 traces every pixel's centre first instead
    /// (fewer passes for more rays: faster where a pass costs a ray's latency, as on a large
    /// GPU; LEAST 1/16 is the default). Ground-truth arrays stay the one ray
    /// through each pixel's centre. The default, 16, chosen by measurement: on the default
    /// scene it gives 52 dB against 64 rays, where adaptive sampling stops near 49 dB (see
    /// the book's "Adaptive sampling").
    #[arg(long)]
    pub(crate) spp: Option<Sampling>,
    /// How a pixel's colour is made from its rays (direct methods): `box`, the mean of its
    /// own rays; or `tent`, in a frame of one ray a pixel at most (--spp 1, or auto:T:1), the
    /// mean over the pixel's square of the bilinear interpolation through it and its eight
    /// neighbours (weights 3/4 and 1/8 along each axis, in linear radiance): a little blur
    /// for far less aliasing (see the book's "Adaptive sampling"). With more rays a pixel,
    /// the box.
    #[arg(long, default_value = "box")]
    pub(crate) filter: PixelFilter,
    #[command(flatten)]
    pub(crate) shading: ShadingArgs,
    /// Primary ray directions: evaluated per pixel, or read from a table made once.
    #[arg(long, value_enum, default_value = "computed")]
    pub(crate) directions: Directions,
    /// The colour image, by its extension: `.png` (sRGB through the exposure and tone curve)
    /// or `.exr` (linear radiance times 2^EXPOSURE, no tone curve); alpha is the share of
    /// the pixel the lens covers. Written to a temporary file and renamed into place.
    #[arg(long, short, default_value = "fisheye.png")]
    pub(crate) out: PathBuf,
    /// Bits a channel of the colour image: 8 (PNG's default) or 16 for PNG; 16 (half float,
    /// EXR's default) or 32 (float) for EXR.
    #[arg(long)]
    pub(crate) bits: Option<u32>,
    /// Exposure in stops (EV): the radiance is scaled by 2^EXPOSURE before the tone curve;
    /// `auto` maps the image's log-average luminance to middle grey (Reinhard et al. 2002).
    /// Default: `auto` for a PNG of a bare OBJ or glTF file lit by the headlight and sun this
    /// tool adds (their brightness has no meaning in the file's units), else 0.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) exposure: Option<Exposure>,
    /// Tone curve from exposed radiance to the PNG's [0, 1]: `aces` (Narkowicz's 2015 fit of
    /// the ACES filmic curve: highlights roll off instead of clipping) or `clamp` (linear,
    /// clipped at 1: what `compare` and `validate` measure).
    #[arg(long, value_enum, default_value = "aces")]
    pub(crate) tone: ToneArg,
    /// Ground-truth arrays to write beside the image as OUT_STEM.NAME.npy (or .exr): range
    /// (distance to the primary hit), normal, id (triangle), direction (world-space ray), mask,
    /// depth (the hit's z in the camera's frame), point (the hit in the camera's frame); and
    /// spp, a picture of the rays each pixel took (OUT_STEM.spp.png: dark where a pixel
    /// was interpolated, brighter with more rays; transparent where the lens masks it) and
    /// their counts (OUT_STEM.spp.npy, uint32, or .exr).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub(crate) outputs: Vec<Output>,
    /// File format of the ground-truth arrays.
    #[arg(long, value_enum, default_value = "npy")]
    pub(crate) format: ArrayFormat,
}

/// `render`'s rays per pixel unless `--spp` is given (chosen by measurement: see `--spp`).
const DEFAULT_SPP: u32 = 16;
/// `render`'s cube faces' size in texels unless `--cube-size` is given.
const DEFAULT_CUBE_SIZE: u32 = 1024;

pub(crate) fn render(args: &RenderArgs) -> Result<()> {
    let started = Instant::now();
    // Everything about the files first: a refused name costs no rendering.
    let file = ColourFile::for_path(&args.out, args.bits)?;
    let array_path = |name: &str| {
        let extension = match args.format {
            ArrayFormat::Npy => "npy",
            ArrayFormat::Exr => "exr",
        };
        args.out.with_extension(format!("{name}.{extension}"))
    };
    if let Some(b) = args.outputs.iter().find_map(|o| o.between()) {
        anyhow::bail!(
            "--outputs {}: it needs the frames before and after; `fisheye dataset render \
             --outputs {}` writes it along a trajectory",
            b.name(),
            b.name()
        );
    }
    if let Some(l) = args.outputs.iter().find_map(|o| o.label()) {
        anyhow::bail!(
            "--outputs {}: `fisheye dataset render --outputs {}` writes it, with its label map",
            l.name(),
            l.name()
        );
    }
    let channels: Vec<Channel> = args.outputs.iter().filter_map(|o| o.channel()).collect();
    // The spp map: its picture, and its counts as an array beside the others.
    let spp_map = args
        .outputs
        .iter()
        .any(|o| matches!(o, Output::Spp))
        .then(|| (args.out.with_extension("spp.png"), array_path("spp")));
    check_writable(&args.out)?;
    for &channel in &channels {
        check_writable(&array_path(channel.name()))?;
    }
    if let Some((picture, counts)) = &spp_map {
        check_writable(picture)?;
        check_writable(counts)?;
    }
    let method = args.method.method();
    // A cube map's resampler takes one bilinear sample a pixel; --spp is direct tracing's,
    // and --cube-size the cube maps': each is refused with the other family, not ignored.
    let cube = method.cube().is_some();
    if args.filter != PixelFilter::Box && cube {
        bail!("--filter applies to direct tracing (--method rt or rq)");
    }
    if let (true, Some(spp)) = (cube, args.spp) {
        bail!(
            "--spp {spp} applies to direct tracing (--method rt or rq): a cube map's detail is \
             its --cube-size"
        );
    }
    if let (false, Some(size)) = (cube, args.cube_size) {
        bail!(
            "--cube-size {size} applies to the cube-map methods (--method cube-rt, \
             cube-forward, cube-deferred or cube-single)"
        );
    }
    let sampling = args.spp.unwrap_or(Sampling::Uniform(DEFAULT_SPP));
    let filter = filter_for(args.filter, sampling);
    let setup = match method.cube() {
        Some(_) => Setup::cube(method, args.cube_size.unwrap_or(DEFAULT_CUBE_SIZE)),
        None => Setup::sampled(method, sampling).filtered(filter),
    };
    // Adaptive sampling traces the hits of the pixels it interpolates only when arrays of
    // them are written.
    let ground_truth = channels.iter().any(Channel::traced);
    let (spp, adaptive) = sampling.options(ground_truth);
    let directions = DirectionSource::from(args.directions);
    if setup.method.cube().is_some() && directions == DirectionSource::Table {
        bail!("--directions table applies to direct tracing (--method rt or rq)");
    }
    let options = RenderOptions {
        max_depth: args.shading.max_depth,
        bvh: args.shading.bvh.into(),
        directions,
        traversal: setup.method.traversal(),
        spp,
        adaptive,
        filter,
    };
    if !args.outputs.is_empty() && setup.method.cube().is_some() {
        bail!("--outputs come from direct tracing; use --method rt or rq for ground-truth arrays");
    }
    let camera = args.calib.camera(Some(&args.lens), args.size)?;
    let out = &args.out;
    let scene_spec = &args.scene;
    let mut scene = load_scene_with(scene_spec, args.gltf_scene)?;
    if !args.time.is_finite() {
        bail!("--time {}: a time in seconds must be finite", args.time);
    }
    if let Some((first, last)) = scene.key_span() {
        let moving = scene
            .instances
            .iter()
            .filter(|i| i.animation.is_some())
            .count();
        println!(
            "scene time {} s: {moving} moving instances placed (their keys span {first} s to \
             {last} s)",
            args.time
        );
        scene = scene.at(args.time);
    } else if args.time != 0.0 {
        println!("note: nothing in {scene_spec} moves, so --time changes nothing");
    }
    if let Some(angle) = scene.frame_for(&camera) {
        println!(
            "framed for the lens: the scene's bounding sphere seen under ±{:.1}°, {:.0}% of the \
             picture",
            angle.to_degrees(),
            100.0 * FRAME_FILL
        );
    }
    if let Some(text) = &args.camera {
        let pose = parse_camera(text, &scene)?;
        scene.set_camera(pose);
    }
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let scenes = SceneSet::new(&ctx, &scene, &options, &[setup])?;
    let gpu_scene = scenes.for_method(setup.method);
    print!(
        "{}",
        scene_report(scene_spec, &scene, gpu_scene, options.bvh)
    );
    if let Some(rq) = &gpu_scene.ray_query {
        println!(
            "ray queries: acceleration structure built by the driver in {:.1} ms",
            rq.build_time.as_secs_f64() * 1e3
        );
    }
    println!(
        "lens: {} at {}; compiling the kernels...",
        camera.lens, camera.size
    );
    if let Some(glass) = &camera.glass {
        println!(
            "glass: each sample traced through the prescription's {} surfaces from its place on \
             the film (vignetting, depth of field); the mask, projection and ground truth \
             follow the fitted chief rays above",
            glass.counts[0]
        );
        if sampling.options(false).0 < 16 {
            eprintln!(
                "warning: through glass each sample sees one point of the exit pupil: give \
                 --spp 16 or more for a smooth picture where it is out of focus"
            );
        }
    }
    let renderer = Offscreen::with_directions(
        &ctx,
        &camera,
        &scenes,
        setup,
        args.shading.shadow_size,
        options.directions,
        ground_truth,
    )?;
    if let Some(cube) = renderer.cube() {
        describe_cube(cube, setup, scene.lights.len());
    }
    let compile_ms = renderer.warm_up(&ctx, &scenes, &scene.camera)?;
    println!("kernels compiled and first dispatch: {compile_ms:.1} ms (wall clock)");
    let time = renderer.frame(&ctx, &scenes, &scene.camera)?;
    let output = renderer.output(&ctx)?;
    let (rays, hits) = output.counts();
    let adaptive_rays = renderer.rays_per_pixel(&ctx)?;
    // Pixels with a ray at their centre, and rays traced from the camera for the colour.
    let (primary, what) = match (renderer.cube(), &adaptive_rays) {
        (Some(_), _) => (0, format!("{} (faces and resampling)", setup.label())),
        (None, Some(map)) => {
            let traced: u64 = map.iter().map(|&n| u64::from(n)).sum();
            let per_pixel = traced as f64 / rays.max(1) as f64;
            let rays_of = |k: usize| time.passes_rays.as_ref().map_or(0, |r| r[k]);
            let passes: Vec<String> = renderer
                .passes()
                .iter()
                .zip(time.passes_ms.iter().flatten())
                .enumerate()
                .map(|(k, (pass, ms))| match rays_of(k) {
                    0 => format!("{} {ms:.2}", pass.name()),
                    rays => format!("{} {ms:.2} ({rays} rays)", pass.name()),
                })
                .collect();
            let listing = time
                .passes_ms
                .as_ref()
                .and_then(|ms| Pass::bookkeeping(renderer.passes(), ms))
                .map_or(String::new(), |(spent, share)| {
                    format!(
                        "; the listing passes {spent:.2} ms together ({:.0} %)",
                        100.0 * share
                    )
                });
            let what = format!(
                "trace ({}): {rays} pixels, {traced} rays for their colour ({per_pixel:.2} a \
                 pixel on average, at most {spp}){}{listing}",
                setup.label(),
                match passes.is_empty() {
                    true => String::new(),
                    false => format!("; ms per pass: {}", passes.join(", ")),
                }
            );
            (traced as usize, what)
        }
        (None, None) => {
            let filter = renderer.passes().iter().position(|&p| p == Pass::Filter);
            let filter_ms = filter.and_then(|k| time.passes_ms.as_ref().map(|ms| ms[k]));
            (
                rays * spp as usize,
                format!(
                    "trace: {rays} pixels ({hits} hit at their centre) × {spp} rays{}",
                    filter_ms.map_or(String::new(), |ms| format!(" (tent filter {ms:.2} ms)"))
                ),
            )
        }
    };
    match time.gpu_ms() {
        Some(ms) => println!(
            "{what}, {ms:.1} ms on the GPU (after compilation), {:.2} M primary rays/s",
            primary as f64 / ms * 1e-3
        ),
        None => println!("{what}; no GPU timestamps on this adapter"),
    }
    // Bare meshes are lit by lights this tool made up: expose what they show (PNG only; an
    // EXR keeps the radiance unless asked).
    let png = matches!(file, ColourFile::Png8 | ColourFile::Png16);
    let exposure = match args.exposure {
        Some(Exposure::Stops(stops)) => stops,
        Some(Exposure::Auto) => auto(&output.colour),
        None if png && scene.headlight.is_some() => auto(&output.colour),
        None => 0.0,
    };
    let display = Display {
        exposure,
        tone: args.tone.into(),
    };
    write_colour(out, output.size, &output.colour, &display, file)?;
    if !channels.is_empty() {
        let camera_rays = camera.directions();
        let world = rotated(&camera_rays, &scene.camera);
        let rays = PixelRays {
            camera: &camera_rays,
            world: &world,
        };
        for &channel in &channels {
            let path = array_path(channel.name());
            match args.format {
                ArrayFormat::Npy => output.write_npy(channel, rays, &path)?,
                ArrayFormat::Exr => output.write_exr(channel, rays, &path)?,
            }
            println!("wrote {}", path.display());
        }
    }
    if let Some((picture, counts)) = &spp_map {
        let map = adaptive_rays.unwrap_or_else(|| output.uniform_rays(spp));
        save_png(
            &spp_picture(output.size, &map, &output.colour, spp + 1),
            picture,
        )?;
        println!("wrote {} ({})", picture.display(), spp_key(spp + 1));
        write_rays_map(counts, output.size, &map)?;
        println!(
            "wrote {} (the rays each pixel's colour took)",
            counts.display()
        );
    }
    println!(
        "wrote {} ({}; {:.1} s in all)",
        out.display(),
        describe_file(file, &display),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The exposure that maps `colour`'s log-average luminance to middle grey, said.
fn auto(colour: &[[f32; 4]]) -> f32 {
    let stops = auto_exposure(colour);
    println!(
        "exposure: auto, {stops:+.2} EV (log-average luminance to {KEY}, Reinhard et al. 2002)"
    );
    stops
}

/// The colour file's format and how it shows radiance, in words.
fn describe_file(file: ColourFile, display: &Display) -> String {
    let exposure = format!("exposure {:+.2} EV", display.exposure);
    match file {
        ColourFile::Png8 | ColourFile::Png16 => {
            let bits = if file == ColourFile::Png8 { 8 } else { 16 };
            let tone = match display.tone {
                Tone::Aces => "ACES tone curve",
                Tone::Clamp => "clamped",
            };
            format!("{bits}-bit sRGB PNG, {exposure}, {tone}")
        }
        ColourFile::ExrHalf => format!("half-float linear OpenEXR, {exposure}"),
        ColourFile::ExrFloat => format!("float linear OpenEXR, {exposure}"),
    }
}

/// Which faces of the cube are rendered, how much of them, and the shadow maps.
fn describe_cube(cube: &CubeMap, setup: Setup, lights: usize) {
    let regions = cube.regions();
    let faces: Vec<&str> = FACES
        .iter()
        .zip(regions)
        .filter_map(|(f, r)| r.map(|_| f.name))
        .collect();
    let rendered: u64 = regions.iter().flatten().map(|r| r.texels()).sum();
    let side = u64::from(bordered(setup.cube_size));
    println!(
        "cube map ({}): {} faces of {}² texels ({}); rendered {:.0}% of their texels (the parts \
         the lens reaches), then resampled",
        setup.method.name(),
        faces.len(),
        setup.cube_size,
        faces.join(" "),
        100.0 * rendered as f64 / (faces.len() as u64 * side * side) as f64
    );
    if let Some(maps) = cube.shadow_maps() {
        println!(
            "shadow maps: {} layers of {}² for {lights} lights",
            maps.views().len(),
            maps.size(),
        );
    }
}

/// What `render` and `info --scene` say of a scene on the device: its triangles, BVH and
/// bytes, by what they hold and per stored triangle, and the storage bindings it is split
/// across where one each does not hold it.
pub(crate) fn scene_report(spec: &str, scene: &Scene, gpu: &GpuScene, bvh: BvhQuality) -> String {
    let stored = if scene.is_instanced() {
        format!(
            " ({} stored, {} instances)",
            scene.triangles.len(),
            scene.instances.len()
        )
    } else {
        String::new()
    };
    let mut out = format!(
        "scene: {spec}, {} triangles{stored}; BVH ({}) {} nodes, depth {}, built in {:.1} ms\n",
        scene.len(),
        bvh.name(),
        gpu.bvh_nodes,
        gpu.bvh_depth,
        gpu.bvh_build_time.as_secs_f64() * 1e3
    );
    let found = gpu.unshadowed;
    let unsearched = match found.unsearched {
        0 => String::new(),
        n => format!(
            "{n} light{} left out ({} triangles a light would take the search past its {} \
             pairs), whose shadow rays are all traced",
            if n == 1 { "" } else { "s" },
            scene.world_triangles,
            fisheye_rt::bvh::unshadowed::SEARCH_PAIRS,
        ),
    };
    if found.pairs > 0 {
        out += &format!(
            "shadows: the lights reach every point of {:.0}% of (triangle, light) pairs, whose \
             shadow rays are skipped; found in {:.0} ms{}\n",
            100.0 * found.open as f64 / found.pairs as f64,
            found.time.as_secs_f64() * 1e3,
            if unsearched.is_empty() {
                String::new()
            } else {
                format!("; {unsearched}")
            }
        );
    } else if !unsearched.is_empty() {
        out += &format!("shadows: {unsearched}\n");
    }
    let bytes = gpu.bytes;
    let per = |b: u64| b as f64 / f64::from(gpu.triangles.max(1));
    let mib = |b: u64| b as f64 / f64::from(1 << 20);
    out += &format!(
        "on the device: {:.1} MiB, {:.0} bytes a stored triangle (geometry {:.0}, BVH {:.1}, \
         shading {:.1}), textures {:.1} MiB\n",
        mib(bytes.geometry + bytes.bvh + bytes.shading),
        bytes.per_triangle(gpu.triangles),
        per(bytes.geometry),
        per(bytes.bvh),
        per(bytes.shading),
        mib(bytes.textures)
    );
    let arrays = gpu.arrays;
    if arrays.is_split() {
        out += &format!(
            "split across storage bindings: nodes {}, triangles {}, shading data {}\n",
            arrays.nodes.chunks, arrays.triangles.chunks, arrays.vertices.chunks
        );
    }
    out
}

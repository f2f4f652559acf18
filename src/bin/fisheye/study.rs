//! `fisheye bench` and `fisheye compare`: every method measured, into a report folder.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use fisheye_rt::bench::PathKind;
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::glass::camera_for;
use fisheye_rt::renderer::{self, SceneSet, Setup};
use fisheye_rt::report::{self, LensRun, Study};
use fisheye_rt::scene::Scene;
use fisheye_rt::trace::RenderOptions;
use fisheye_rt::trace::sampling::samples_per_side;

use crate::args::{PathArg, StudyArgs, load_scene_with, parse_camera};

#[derive(clap::Args)]
pub(crate) struct BenchArgs {
    #[command(flatten)]
    pub(crate) study: StudyArgs,
    /// Timed frames per setup along the path.
    #[arg(long, default_value_t = 60, value_parser = at_least_one)]
    pub(crate) frames: usize,
    /// Untimed frames first, per setup.
    #[arg(long, default_value_t = 3)]
    pub(crate) warmup: usize,
    /// Camera path: `walk` (the scene's keyframes; every built-in scene but `grid` has them)
    /// or `orbit` (a circle around the camera's look-at point, for open scenes). Default:
    /// walk where the scene has keyframes.
    #[arg(long, value_enum)]
    pub(crate) path: Option<PathArg>,
}

#[derive(clap::Args)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    pub(crate) study: StudyArgs,
    /// Timed frames per setup at the pose (the median is reported), in rounds of a frame of
    /// each setup in turn, after a quarter of a second of untimed rounds.
    #[arg(long, default_value_t = 5, value_parser = at_least_one)]
    pub(crate) frames: usize,
    /// Rays per pixel of the reference (direct tracing, the same box filter as the RT
    /// setups; a square up to 256): 16 times the most the setups use leaves it about a
    /// sixteenth of their error.
    #[arg(long, default_value_t = 256)]
    pub(crate) reference_spp: u32,
}

/// Reads `--frames`: a whole number of at least one (a median of no frames is no time).
fn at_least_one(text: &str) -> std::result::Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("a median needs at least one timed frame".into()),
        Ok(n) => Ok(n),
        Err(_) => Err("not a whole number of frames".into()),
    }
}

/// What `bench` and `compare` set up from their shared arguments.
pub(crate) struct Prepared {
    pub(crate) ctx: GpuContext,
    pub(crate) scene: Scene,
    pub(crate) scenes: SceneSet,
    pub(crate) lenses: Vec<LensRun>,
    pub(crate) setups: Vec<Setup>,
    pub(crate) out: PathBuf,
}

impl Prepared {
    pub(crate) fn study(&self, args: &StudyArgs) -> Study<'_> {
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
pub(crate) fn prepare(args: &StudyArgs, command: &str) -> Result<Prepared> {
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
                    camera: camera_for(spec, args.size)?,
                })
            })
            .collect::<Result<Vec<_>>>()?,
    };
    // The calibration's resolution, or --size.
    let size = lenses.first().map_or(args.size, |l| l.camera.size);
    if !args.no_pinhole {
        lenses.push(LensRun {
            name: args.pinhole.clone(),
            camera: camera_for(&args.pinhole, size)?,
        });
    }
    if let Some(&bad) = args.cube_size.iter().find(|&&s| s == 0) {
        bail!("--cube-size {bad}: face sizes must be at least 1");
    }
    let mut methods: Vec<renderer::Method> = if args.method.is_empty() {
        renderer::Method::ALL.to_vec()
    } else {
        args.method.iter().map(|m| m.method()).collect()
    };
    let mut scene = load_scene_with(&args.scene, args.gltf_scene)?;
    if let Some(text) = &args.camera {
        let pose = parse_camera(text, &scene)?;
        scene.set_camera(pose);
    }
    let out = out_folder(args.out.as_deref(), command)?;
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    // Without --method, every method the adapter can run; a method named is an error there.
    if args.method.is_empty() {
        methods.retain(|m| match m.missing_feature(&ctx) {
            Some(feature) => {
                println!("left out: {} (the adapter has no {feature})", m.name());
                false
            }
            None => true,
        });
    }
    let setups = Setup::all(&methods, &args.cube_size, &args.spp, &args.filter);
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
pub(crate) fn out_folder(out: Option<&std::path::Path>, command: &str) -> Result<PathBuf> {
    let out = match out {
        Some(out) => out.to_path_buf(),
        None => (1..)
            .map(|n| PathBuf::from(format!("fisheye-{command}-{n}")))
            .find(|p| !p.exists())
            .expect("a free folder name"),
    };
    fisheye_rt::trace::check_writable_folder(&out)?;
    Ok(out)
}

/// Prints the table lines of a report's Markdown and where the files went.
pub(crate) fn finish(markdown: &str, out: &std::path::Path, plot_warning: Option<String>) {
    println!();
    for line in markdown.lines().filter(|l| !l.starts_with('#')) {
        println!("{line}");
    }
    if let Some(why) = plot_warning {
        eprintln!("warning: no plots: {why}");
    }
    println!("\nwrote {}", out.display());
}

pub(crate) fn run_bench(args: &BenchArgs) -> Result<()> {
    let p = prepare(&args.study, "bench")?;
    let path = match args.path {
        Some(PathArg::Walk) => PathKind::Walk,
        Some(PathArg::Orbit) => PathKind::Orbit,
        None if p.scene.camera_path.is_empty() => PathKind::Orbit,
        None => PathKind::Walk,
    };
    let study = p.study(&args.study);
    let report = report::bench(
        &study,
        path,
        args.frames,
        args.warmup,
        &mut crate::progress::frames(),
    )?;
    let warning = report.write(&p.out)?;
    finish(&report.markdown(), &p.out, warning);
    Ok(())
}

pub(crate) fn run_compare(args: &CompareArgs) -> Result<()> {
    let spp = args.reference_spp;
    samples_per_side(spp).with_context(|| format!("--reference-spp {spp}"))?;
    let p = prepare(&args.study, "compare")?;
    let study = p.study(&args.study);
    let pose = p.scene.camera;
    let report = report::compare(
        &study,
        &pose,
        args.frames,
        spp,
        &p.out,
        &mut crate::progress::frames(),
    )?;
    let warning = report.write(&p.out)?;
    finish(&report.markdown(), &p.out, warning);
    Ok(())
}

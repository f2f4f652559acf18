//! `fisheye dataset`: a rig of cameras along a trajectory, every camera at every pose with its
//! ground truth, in shards that resume; and the merge that writes the manifest.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Result, bail};
use clap::{Subcommand, ValueEnum};
use fisheye_rt::dataset::imu::{Imu, ImuNoise};
use fisheye_rt::dataset::labels::Label;
use fisheye_rt::dataset::smooth::Spline;
use fisheye_rt::dataset::trajectory::{self, TrajectoryFormat};
use fisheye_rt::dataset::{ArrayFile, Between, Dataset, FlowFile, Shard, Submission};
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::calib;
use fisheye_rt::lens::glass::camera_for;
use fisheye_rt::lens::{ImageSize, LensCamera, Readout, Shutter};
use fisheye_rt::pose::parse_transform;
use fisheye_rt::trace::{Channel, ColourFile, Display, PixelFilter, RenderOptions, Sampling};
use glam::DAffine3;

use crate::args::{ArrayFormat, Output, Quality, ToneArg, filter_for, load_scene_with};
use crate::progress::Progress;

#[derive(Subcommand)]
pub(crate) enum DatasetCommand {
    /// Render every camera of a rig at every pose of a trajectory (or the poses of one
    /// shard) into a folder: per camera, images and ground truth named by frame index and
    /// time stamp, and a plan.json listing them. Poses whose files all exist are skipped, so
    /// a killed run finishes when run again. Without --shard, ends with the merge.
    Render(Box<RenderArgs>),
    /// Check that every file of a dataset's plan exists (every shard finished) and write its
    /// manifest.json.
    Merge {
        /// The dataset's folder.
        folder: PathBuf,
    },
}

#[derive(clap::Args)]
pub(crate) struct RenderArgs {
    /// The scene, as for `render`.
    #[arg(default_value = "builtin:default")]
    scene: String,
    /// Which scene of a glTF file (from 0); its default scene if not given.
    #[arg(long)]
    gltf_scene: Option<usize>,
    /// The trajectory: poses T_world_body in TUM (`t tx ty tz qx qy qz qw`), KITTI (3×4
    /// matrices) or EuRoC CSV (`t_ns, px, py, pz, qw, qx, qy, qz, ...`), detected from the
    /// text unless --trajectory-format says. Every pose is rendered as written, unless
    /// --frame-rate asks for frames at other times.
    #[arg(long)]
    trajectory: PathBuf,
    /// Render frames at this rate (Hz) from the trajectory's first stamp to its last, the poses
    /// between stamps interpolated (translation linearly, rotation by slerp), never past the
    /// last stamp; by default one frame a pose of the file.
    #[arg(long)]
    frame_rate: Option<f64>,
    /// A rolling shutter: seconds between two lines' readouts (Kalibr's line_delay: line v at
    /// the frame's stamp + v·line_delay), for every camera, over any line_delay of the rig's
    /// camchain; every primary ray, and the ground truth, takes its line's pose. Frames whose
    /// readout reaches past the trajectory's last stamp are skipped, with a warning, and the
    /// plan says so.
    #[arg(long)]
    line_delay: Option<f64>,
    /// Motion blur: seconds each line is exposed, centred on its time; a pixel's samples are
    /// spread over it (stratified with their positions). 0: an instant.
    #[arg(long, default_value_t = 0.0)]
    exposure_time: f64,
    /// The order a rolling shutter reads lines in.
    #[arg(long, default_value = "top-to-bottom")]
    readout: Readout,
    /// A synthetic IMU on the body at this rate (Hz): angular rate and specific force from a
    /// smooth spline through the trajectory, which the frames' poses then follow too, written
    /// as EuRoC's imu0/data.csv (and data_noise_free.csv), with the rig as a Kalibr camchain
    /// on the IMU. The rate defaults to --imu-noise's update_rate.
    #[arg(long)]
    imu: Option<f64>,
    /// The IMU's noise: a Kalibr imu.yaml (accelerometer and gyroscope noise densities and
    /// random walks, update_rate); without it the readings are noise-free.
    #[arg(long)]
    imu_noise: Option<PathBuf>,
    /// The seed of the IMU's noise.
    #[arg(long, default_value_t = 0)]
    imu_seed: u64,
    /// Gravity in the trajectory's world, m/s² (EuRoC's and TUM's worlds have z up).
    #[arg(long, default_value = "0,0,-9.81", allow_hyphen_values = true)]
    gravity: String,
    /// Seconds between the IMU spline's control poses (the trajectory sampled by slerp):
    /// longer smooths more.
    #[arg(long, default_value_t = 0.05)]
    spline_step: f64,
    /// The trajectory's format, if detection from its text is not wanted.
    #[arg(long, value_enum)]
    trajectory_format: Option<FormatArg>,
    /// Frames a second of a KITTI trajectory (which has no time stamps): pose i is at i/fps s.
    #[arg(long, default_value_t = 10.0)]
    fps: f64,
    /// The rig: a calibration file with every camera and its extrinsics (a Kalibr camchain
    /// with T_cn_cnm1 or T_cam_imu, a Basalt calibration with T_imu_cam), or one camera of
    /// OpenCV's. Instead of --lens and --size.
    #[arg(long, conflicts_with_all = ["lens", "size"])]
    rig: Option<PathBuf>,
    /// One camera's lens spec (see `fisheye lens list`), at the body's origin.
    #[arg(long)]
    lens: Option<String>,
    /// Image size of --lens, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    size: ImageSize,
    /// T_body_rig, where the rig sits on the trajectory's body: `tx,ty,tz,qx,qy,qz,qw`.
    #[arg(long, default_value = "identity", allow_hyphen_values = true)]
    t_body_rig: String,
    /// T_scene_world, how the trajectory's world sits in the scene: `identity`, `z-up` (a
    /// world whose z axis points up, into a y-up scene) or `tx,ty,tz,qx,qy,qz,qw`.
    #[arg(long, default_value = "identity", allow_hyphen_values = true)]
    t_scene_world: String,
    /// Rays per pixel, as `render --spp` takes them: N (a square, 1 to 256, box-filtered) or
    /// auto, auto:THRESHOLD, auto:THRESHOLD:MAX or auto:THRESHOLD:MAX:LEAST (adaptive
    /// sampling); ground truth is the
    /// centre ray's.
    #[arg(long, default_value = "16")]
    spp: Sampling,
    /// How a pixel's colour is made from its rays, as `render --filter` takes it: `box` or
    /// `tent` (at one ray a pixel at most, each pixel blended with its neighbours; ground
    /// truth unchanged).
    #[arg(long, default_value = "box")]
    filter: PixelFilter,
    /// Deepest reflection/refraction bounce (0 to 8).
    #[arg(long, default_value_t = 5,
          value_parser = clap::value_parser!(u32).range(0..=i64::from(fisheye_rt::shared::MAX_DEPTH_LIMIT)))]
    max_depth: u32,
    /// BVH build preset.
    #[arg(long, value_enum, default_value = "fast")]
    bvh: Quality,
    /// The colour images' format: `png` (sRGB through exposure and tone curve) or `exr`
    /// (linear).
    #[arg(long, value_enum, default_value = "png")]
    colour: ColourArg,
    /// Bits a channel of the colour images: 8 or 16 for PNG, 16 or 32 for EXR.
    #[arg(long)]
    bits: Option<u32>,
    /// Exposure in stops (EV).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Tone curve of PNG images (see `render --tone`).
    #[arg(long, value_enum, default_value = "aces")]
    tone: ToneArg,
    /// Ground truth written beside each image: range, normal, id, direction, mask, depth
    /// (the hit's z in the camera's frame), point (the hit in the camera's frame); instance
    /// and semantic (each pixel's object and class, named in labels.json); spp (the rays each
    /// pixel's colour took: 0 where adaptive sampling interpolated it); and between frames,
    /// through the lens (and rolling shutter): flow (to the next frame, with flow_valid where
    /// it sees the point), flow-backward (from the previous), scene-flow.
    #[arg(long, value_enum, value_delimiter = ',')]
    outputs: Vec<Output>,
    /// Optical flow's files: the arrays' --format (npy: H×W×2 float32), flo (Middlebury's,
    /// as cv2.readOpticalFlow reads) or kitti (16-bit PNG: u·64 + 2^15, blue = valid).
    #[arg(long, value_enum, default_value = "arrays")]
    flow_format: FlowFormatArg,
    /// File format of the ground-truth arrays.
    #[arg(long, value_enum, default_value = "npy")]
    format: ArrayFormat,
    /// Render only shard I of N (`I/N`, I from 0): a contiguous share of the poses, the same
    /// on every machine, e.g. `$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`.
    #[arg(long, default_value = "0/1")]
    shard: Shard,
    /// Finish a dataset begun earlier: refuse a folder that holds none (every run skips the
    /// poses already complete; this guards against a mistyped folder).
    #[arg(long)]
    resume: bool,
    /// Submit every camera of a pose at once (`pose`), or each alone (`camera`, to measure
    /// what sharing a submission saves).
    #[arg(long, value_enum, default_value = "pose")]
    submission: SubmissionArg,
    /// The dataset's folder.
    #[arg(long, short)]
    out: PathBuf,
}

#[derive(Clone, Copy, ValueEnum)]
enum FormatArg {
    Tum,
    Kitti,
    Euroc,
}

#[derive(Clone, Copy, ValueEnum)]
enum FlowFormatArg {
    Arrays,
    Flo,
    Kitti,
}

#[derive(Clone, Copy, ValueEnum)]
enum ColourArg {
    Png,
    Exr,
}

#[derive(Clone, Copy, ValueEnum)]
enum SubmissionArg {
    Pose,
    Camera,
}

pub(crate) fn run(command: &DatasetCommand) -> Result<()> {
    match command {
        DatasetCommand::Render(args) => render(args),
        DatasetCommand::Merge { folder } => {
            let path = fisheye_rt::dataset::merge(folder)?;
            println!("every frame is complete; wrote {}", path.display());
            Ok(())
        }
    }
}

fn render(args: &RenderArgs) -> Result<()> {
    let started = Instant::now();
    if args.resume && !args.out.join("plan.json").is_file() {
        bail!(
            "--resume: {} holds no dataset (no plan.json); leave --resume out to begin one",
            args.out.display()
        );
    }
    fisheye_rt::trace::check_writable_folder(&args.out)?;
    let probe = match args.colour {
        ColourArg::Png => "frame.png",
        ColourArg::Exr => "frame.exr",
    };
    let file = ColourFile::for_path(std::path::Path::new(probe), args.bits)
        .map_err(|e| anyhow::anyhow!("--bits: {}", e.to_string().replace("frame.", ".")))?;
    if !args.exposure.is_finite() {
        bail!(
            "--exposure {}: give a finite number of stops",
            args.exposure
        );
    }
    let body_from_rig =
        parse_transform(&args.t_body_rig).map_err(|e| anyhow::anyhow!("--t-body-rig {e}"))?;
    let scene_from_world =
        parse_transform(&args.t_scene_world).map_err(|e| anyhow::anyhow!("--t-scene-world {e}"))?;
    let cameras: Vec<(LensCamera, DAffine3)> = match (&args.rig, &args.lens) {
        (Some(path), _) => calib::read_rig(path)?
            .into_iter()
            .map(|c| (c.calibration.camera(), c.body_from_camera))
            .collect(),
        (None, Some(spec)) => vec![(camera_for(spec, args.size)?, DAffine3::IDENTITY)],
        (None, None) => bail!("give the cameras: --rig CALIBRATION or --lens SPEC"),
    };
    // --line-delay overrides a camchain's line_delay; the exposure and readout are the same
    // for every camera.
    let cameras: Vec<(LensCamera, DAffine3)> = cameras
        .into_iter()
        .map(|(camera, pose)| {
            let line_delay = args.line_delay.unwrap_or(camera.shutter.line_delay);
            let shutter = Shutter::new(line_delay, args.exposure_time, args.readout)
                .map_err(|e| anyhow::anyhow!("--line-delay/--exposure-time: {e}"))?;
            Ok((camera.with_shutter(shutter), pose))
        })
        .collect::<Result<_>>()?;
    let format = args.trajectory_format.map(|f| match f {
        FormatArg::Tum => TrajectoryFormat::Tum,
        FormatArg::Kitti => TrajectoryFormat::Kitti,
        FormatArg::Euroc => TrajectoryFormat::Euroc,
    });
    let (detected, stamps) = trajectory::read(&args.trajectory, format, args.fps)?;
    let mut poses = match args.frame_rate {
        Some(hz) => trajectory::resample(&stamps, detected, hz)
            .map_err(|e| anyhow::anyhow!("--frame-rate: {e}"))?,
        None => stamps.clone(),
    };
    let imu = imu(args, &stamps)?;
    if let Some(imu) = &imu {
        // The frames follow the IMU's spline (those outside it are skipped).
        for pose in &mut poses {
            if let Some(m) = imu.spline.at(pose.seconds) {
                pose.world_from_body = m.pose;
            }
        }
    }
    let scene = load_scene_with(&args.scene, args.gltf_scene)?;
    let channels: Vec<Channel> = args.outputs.iter().filter_map(|o| o.channel()).collect();
    let mut between: Vec<Between> = Vec::new();
    for b in args.outputs.iter().filter_map(|o| o.between()) {
        if !between.contains(&b) {
            between.push(b);
        }
    }
    let mut labels: Vec<Label> = Vec::new();
    for l in args.outputs.iter().filter_map(|o| o.label()) {
        if !labels.contains(&l) {
            labels.push(l);
        }
    }
    // Adaptive sampling traces the hits of the pixels it interpolates where arrays of them
    // (or flow and labels, made from them) are written.
    let traced = channels.iter().any(Channel::traced) || !between.is_empty() || !labels.is_empty();
    let (spp, adaptive) = args.spp.options(traced);
    // The plan records the filter that made the images.
    let filter = filter_for(args.filter, args.spp);
    let dataset = Dataset {
        // The plan records the scene by this name: a glTF file's other scene is another.
        scene_name: match args.gltf_scene {
            Some(n) => format!("{} (glTF scene {n})", args.scene),
            None => args.scene.clone(),
        },
        scene,
        trajectory: (args.trajectory.clone(), detected, args.frame_rate),
        poses,
        stamps,
        imu,
        labels,
        spp_map: args.outputs.iter().any(|o| matches!(o, Output::Spp)),
        cameras,
        scene_from_world,
        body_from_rig,
        options: RenderOptions {
            max_depth: args.max_depth,
            bvh: args.bvh.into(),
            spp,
            adaptive,
            filter,
            ..RenderOptions::default()
        },
        colour: (
            file,
            Display {
                exposure: args.exposure,
                tone: args.tone.into(),
            },
        ),
        between: (
            between,
            match args.flow_format {
                FlowFormatArg::Arrays => FlowFile::Arrays,
                FlowFormatArg::Flo => FlowFile::Flo,
                FlowFormatArg::Kitti => FlowFile::Kitti,
            },
        ),
        outputs: (
            channels,
            match args.format {
                ArrayFormat::Npy => ArrayFile::Npy,
                ArrayFormat::Exr => ArrayFile::Exr,
            },
        ),
    };
    let range = args.shard.poses(dataset.poses.len());
    let rate = args
        .frame_rate
        .map_or(String::new(), |hz| format!(" at {hz} Hz"));
    println!(
        "dataset: {} poses ({} trajectory {}{rate}), {} camera(s); shard {}/{}: poses {}..{}",
        dataset.poses.len(),
        detected.name(),
        args.trajectory.display(),
        dataset.cameras.len(),
        args.shard.index,
        args.shard.count,
        range.start,
        range.end
    );
    for (p, why) in dataset.skipped()?.iter().enumerate() {
        if let Some(why) = why.as_ref().filter(|_| range.contains(&p)) {
            let stem = fisheye_rt::dataset::frame_stem(p, &dataset.poses[p].stamp);
            eprintln!("warning: frame {stem} is skipped: {why}");
        }
    }
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let loaded = started.elapsed().as_secs_f64();
    let mut progress = Progress::new(range.len(), "poses");
    let submission = match args.submission {
        SubmissionArg::Pose => Submission::Pose,
        SubmissionArg::Camera => Submission::Camera,
    };
    let report = dataset.render(&ctx, &args.out, args.shard, submission, &mut |p| {
        let what = if p.skipped > 0 {
            format!("{} already complete", p.skipped)
        } else {
            String::new()
        };
        progress.update(p.done, &what);
    })?;
    if report.rendered > 0 {
        println!(
            "once: scene, trajectory and device {:.2} s; BVH and upload {:.2} s; kernels \
             compiled and first dispatch {:.0} ms",
            loaded,
            report.upload_seconds,
            report.compile_seconds * 1e3
        );
        let per = |s: f64| 1e3 * s / report.rendered as f64;
        println!(
            "rendered {} poses ({} images, {} skipped as complete) in {:.2} s: {:.2} poses/s, \
             {:.2} M primary rays/s; per pose: trace {:.1} ms, read back {:.1} ms, files \
             {:.1} ms (written while the next pose renders)",
            report.rendered,
            report.images,
            report.skipped,
            report.seconds,
            report.poses_per_second(),
            report.rays_per_second() * 1e-6,
            per(report.trace_seconds),
            per(report.readback_seconds),
            per(report.write_seconds)
        );
    } else {
        println!(
            "all {} poses of the shard were already complete",
            report.poses
        );
    }
    if report.outside > 0 {
        println!(
            "{} frames skipped: they reach past the trajectory's poses (plan.json's \
             skipped_frames, and each frame's skipped, say why)",
            report.outside
        );
    }
    if args.shard == Shard::ALL {
        println!("wrote {}", args.out.join("manifest.json").display());
    } else {
        println!(
            "shard {}/{} done; once every shard is, `fisheye dataset merge {}` writes the \
             manifest",
            args.shard.index,
            args.shard.count,
            args.out.display()
        );
    }
    Ok(())
}

/// The IMU `args` ask for, on `stamps`' spline.
fn imu(args: &RenderArgs, stamps: &[trajectory::Pose]) -> Result<Option<Imu>> {
    let noise = args.imu_noise.as_deref().map(ImuNoise::read).transpose()?;
    let rate = match (args.imu, noise) {
        (None, None) => return Ok(None),
        (Some(rate), Some(n)) if rate != n.update_rate => bail!(
            "--imu {rate} Hz: --imu-noise's update_rate is {} Hz; the noise is discretised at \
             the rate the IMU samples, so give one rate",
            n.update_rate
        ),
        (Some(rate), _) => rate,
        (None, Some(n)) => n.update_rate,
    };
    if !(rate.is_finite() && rate > 0.0) {
        bail!("--imu {rate}: give the IMU's rate in Hz, a positive number");
    }
    if !(args.spline_step.is_finite() && args.spline_step > 0.0) {
        bail!(
            "--spline-step {}: give a positive number of seconds",
            args.spline_step
        );
    }
    let gravity: Vec<f64> = args
        .gravity
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()
        .filter(|g: &Vec<f64>| g.len() == 3 && g.iter().all(|v| v.is_finite()))
        .ok_or_else(|| anyhow::anyhow!("--gravity {}: give X,Y,Z in m/s²", args.gravity))?;
    let Some(spline) = Spline::new(stamps, args.spline_step) else {
        bail!(
            "--imu: the trajectory spans fewer than four control poses {} s apart \
             (--spline-step); a cubic spline needs four",
            args.spline_step
        );
    };
    Ok(Some(Imu {
        spline,
        rate,
        noise,
        seed: args.imu_seed,
        gravity: glam::DVec3::from_slice(&gravity),
    }))
}

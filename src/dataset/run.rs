//! Rendering a dataset: the plan (`plan.json`, what every frame is) and the frames of a shard
//! (all cameras of a pose in one submission, files written by a second thread while the next
//! pose renders); the folder's files and the merge are `files`'.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

use glam::{DAffine3, DVec3};
use serde_json::{Value, json};

use super::files::{LAYOUT, check_plan, merge, remove_leftovers};
use super::readout::{Unrenderable, frame_motion};
use super::trajectory::{Pose, TrajectoryFormat};
use super::{Shard, camera_from_transform, frame_stem};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::lens::gpu::DirectionSource;
use crate::lens::{CalibratedModel, Lens, LensCamera};
use crate::pose::rows;
use crate::scene::Scene;
use crate::trace::{
    Channel, ColourFile, Display, FramePass, GpuScene, Motion, RenderOptions, RenderOutput, Tone,
    moving_directions, rotated, write_colour, write_file,
};

/// The file format of the ground-truth arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArrayFile {
    /// NumPy `.npy`.
    Npy,
    /// OpenEXR `.exr`.
    Exr,
}

impl ArrayFile {
    fn extension(self) -> &'static str {
        match self {
            Self::Npy => "npy",
            Self::Exr => "exr",
        }
    }
}

/// How a pose's cameras are submitted to the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Submission {
    /// Every camera of a pose in one submission, then one wait (the default).
    Pose,
    /// One submission and wait per camera (to measure what sharing saves).
    Camera,
}

/// Everything that defines a dataset: the scene, the poses, the rig and how frames are made.
pub struct Dataset {
    /// The scene as the user named it (recorded in the plan).
    pub scene_name: String,
    /// The scene.
    pub scene: Scene,
    /// The trajectory file as given, its format, and the frame rate its poses were resampled
    /// at (`None`: the file's own stamps; see [`super::trajectory::resample`]).
    pub trajectory: (PathBuf, TrajectoryFormat, Option<f64>),
    /// The poses `T_world_body`, one a frame.
    pub poses: Vec<Pose>,
    /// The trajectory's poses as its file gives them: where a camera's shutter spreads a
    /// frame's rays over time, its motion is interpolated between them
    /// ([`super::readout::frame_motion`]).
    pub stamps: Vec<Pose>,
    /// The rig's cameras, named `cam0`, `cam1`, ... in order, each with `T_rig_camera`.
    pub cameras: Vec<(LensCamera, DAffine3)>,
    /// `T_scene_world`.
    pub scene_from_world: DAffine3,
    /// `T_body_rig`.
    pub body_from_rig: DAffine3,
    /// Bounces, BVH preset and rays per pixel (directions computed, software traversal).
    pub options: RenderOptions,
    /// The colour images' format and display.
    pub colour: (ColourFile, Display),
    /// The ground truth written beside each image, and in what format.
    pub outputs: (Vec<Channel>, ArrayFile),
}

/// Progress of a run: frames (poses) done of the shard's, and how many were already complete.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Poses finished (rendered or skipped) in this run.
    pub done: usize,
    /// Poses in the shard.
    pub total: usize,
    /// Of them, already complete before this run.
    pub skipped: usize,
}

/// What a run did and how fast.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RunReport {
    /// The shard, `I/N`.
    pub shard: String,
    /// Poses of the shard.
    pub poses: usize,
    /// Poses already complete, skipped.
    pub skipped: usize,
    /// Poses skipped because a camera's readout or exposure reaches past the trajectory's
    /// stamps (the plan says which and why).
    pub outside: usize,
    /// Poses rendered (every camera).
    pub rendered: usize,
    /// Images written (poses rendered × cameras).
    pub images: usize,
    /// Primary rays traced (pixels with a ray × rays per pixel, over every image).
    pub rays: u64,
    /// Seconds building the BVH and uploading the scene, once.
    pub upload_seconds: f64,
    /// Seconds compiling the kernels (a one-pixel dispatch of each camera's), once.
    pub compile_seconds: f64,
    /// Wall seconds from the first pose to the last file, after upload and compilation.
    pub seconds: f64,
    /// Seconds in GPU submissions and waits (the trace).
    pub trace_seconds: f64,
    /// Seconds reading outputs back.
    pub readback_seconds: f64,
    /// Seconds writing files (on the writer thread, overlapping the next pose's trace).
    pub write_seconds: f64,
}

impl RunReport {
    /// Poses a second.
    pub fn poses_per_second(&self) -> f64 {
        self.rendered as f64 / self.seconds.max(1e-9)
    }

    /// Primary rays a second.
    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / self.seconds.max(1e-9)
    }
}

/// One camera's render of one pose, on its way to the writer thread.
struct Written {
    index: usize,
    camera: usize,
    pose: crate::scene::Camera,
    /// The camera's motion over the frame, where its shutter spreads the rays over time.
    motion: Option<Motion>,
    output: RenderOutput,
}

impl Dataset {
    /// The cameras' names and folders.
    fn camera_name(i: usize) -> String {
        format!("cam{i}")
    }

    /// `T_scene_camera` of camera `c` at pose `p`.
    pub fn scene_from_camera(&self, p: usize, c: usize) -> DAffine3 {
        self.scene_from_world
            * self.poses[p].world_from_body
            * self.body_from_rig
            * self.cameras[c].1
    }

    fn lens_camera(&self, c: usize) -> LensCamera {
        self.cameras[c].0
    }

    /// Camera `c`'s motion over frame `p` (see [`frame_motion`]).
    fn motion(&self, p: usize, c: usize) -> std::result::Result<Motion, Unrenderable> {
        frame_motion(
            &self.stamps,
            self.poses[p].seconds,
            &self.cameras[c].0,
            &self.scene_from_world,
            self.body_from_rig * self.cameras[c].1,
        )
    }

    /// Why each frame is skipped, `None` for those rendered: a frame where some camera's
    /// readout and exposure reach past the trajectory's ends. Errors where one spans more
    /// poses than a frame holds.
    pub fn skipped(&self) -> Result<Vec<Option<String>>> {
        (0..self.poses.len())
            .map(|p| {
                for c in 0..self.cameras.len() {
                    if !self.cameras[c].0.shutter.moves() {
                        continue;
                    }
                    match self.motion(p, c) {
                        Ok(_) => {}
                        Err(Unrenderable::Outside(why)) => {
                            return Ok(Some(format!("{}: {why}", Self::camera_name(c))));
                        }
                        Err(Unrenderable::Crowded(why)) => {
                            return Err(Error::Dataset {
                                path: self.trajectory.0.clone(),
                                message: format!(
                                    "frame {p} ({}), {}: {why}",
                                    self.poses[p].stamp,
                                    Self::camera_name(c)
                                ),
                            });
                        }
                    }
                }
                Ok(None)
            })
            .collect()
    }

    /// The files of camera `c` at pose `p`, relative to the dataset's folder: the colour
    /// image, then each array.
    fn files(&self, p: usize, c: usize) -> Vec<(String, String)> {
        let stem = format!(
            "{}/{}",
            Self::camera_name(c),
            frame_stem(p, &self.poses[p].stamp)
        );
        let colour = match self.colour.0 {
            ColourFile::Png8 | ColourFile::Png16 => "png",
            ColourFile::ExrHalf | ColourFile::ExrFloat => "exr",
        };
        let mut files = vec![("colour".to_string(), format!("{stem}.{colour}"))];
        let ext = self.outputs.1.extension();
        files.extend(
            self.outputs
                .0
                .iter()
                .map(|ch| (ch.name().to_string(), format!("{stem}.{}.{ext}", ch.name()))),
        );
        files
    }

    /// The plan: everything the dataset is, frame by frame, as JSON (deterministic bytes).
    pub fn plan(&self) -> Result<String> {
        let cameras: Vec<Value> = (0..self.cameras.len())
            .map(|c| self.camera_json(c))
            .collect::<Result<_>>()?;
        let skipped = self.skipped()?;
        let frames: Vec<Value> = (0..self.poses.len())
            .map(|p| {
                let pose = &self.poses[p];
                let views: Vec<Value> = (0..self.cameras.len())
                    .map(|c| {
                        let files: serde_json::Map<String, Value> = self
                            .files(p, c)
                            .into_iter()
                            .filter(|_| skipped[p].is_none())
                            .map(|(what, file)| (what, Value::String(file)))
                            .collect();
                        json!({
                            "camera": Self::camera_name(c),
                            "T_scene_camera": rows(&self.scene_from_camera(p, c)),
                            "files": files,
                        })
                    })
                    .collect();
                let mut frame = json!({
                    "index": p,
                    "stamp": pose.stamp,
                    "seconds": pose.seconds,
                    "T_world_body": rows(&pose.world_from_body),
                    "views": views,
                });
                if let Some(why) = &skipped[p] {
                    frame["skipped"] = json!(why);
                }
                frame
            })
            .collect();
        let skipped_frames: Vec<usize> = (0..self.poses.len())
            .filter(|&p| skipped[p].is_some())
            .collect();
        let (file, display) = self.colour;
        let plan = json!({
            "layout": LAYOUT,
            "tool": format!("fisheye-rt {}", env!("CARGO_PKG_VERSION")),
            "scene": self.scene_name,
            "trajectory": {
                "file": self.trajectory.0.display().to_string(),
                "format": self.trajectory.1.name(),
                "frame_rate": self.trajectory.2,
                "poses": self.poses.len(),
            },
            "conventions": {
                "transforms": "T_a_b maps coordinates in frame b to frame a, as 4x4 row-major \
                               matrices; T_scene_camera = T_scene_world T_world_body T_body_rig \
                               T_rig_camera",
                "camera": "OpenCV: x right, y down, z forward",
                "pixels": "intrinsics put the top-left pixel's corner at (0, 0) (this \
                           project's convention); opencv.camera_matrix puts its centre there",
                "arrays": "range: metres to the first hit along the pixel centre's ray (0 where \
                           none); normal: world unit normal; id: scene triangle (4294967295 for \
                           none); direction: world unit ray; mask: 1 where the lens has a ray",
            },
            "T_scene_world": rows(&self.scene_from_world),
            "T_body_rig": rows(&self.body_from_rig),
            "render": {
                "method": "rt",
                "spp": self.options.spp,
                "sampling": self.options.sampling().to_string(),
                "max_depth": self.options.max_depth,
                "bvh": self.options.bvh.name(),
                "colour": match file {
                    ColourFile::Png8 => "8-bit sRGB PNG",
                    ColourFile::Png16 => "16-bit sRGB PNG",
                    ColourFile::ExrHalf => "half-float linear OpenEXR",
                    ColourFile::ExrFloat => "float linear OpenEXR",
                },
                "exposure": display.exposure,
                "tone": match display.tone {
                    Tone::Aces => "aces",
                    Tone::Clamp => "clamp",
                },
                "outputs": self.outputs.0.iter().map(|c| c.name()).collect::<Vec<_>>(),
                "arrays": self.outputs.1.extension(),
            },
            "cameras": cameras,
            "skipped_frames": skipped_frames,
            "frames": frames,
        });
        Ok(serde_json::to_string_pretty(&plan).expect("JSON values serialise") + "\n")
    }

    /// A camera's calibration in the project's and OpenCV's conventions, and its rig pose.
    fn camera_json(&self, c: usize) -> Result<Value> {
        let camera = self.lens_camera(c);
        let (lens, equivalent) = match camera.lens {
            Lens::Calibrated(lens) => (lens, Value::Null),
            Lens::Classic(_) => {
                let e = crate::lens::fit::calibrated_equivalent(&camera)?;
                let note = json!({
                    "lens": camera.lens.to_string(),
                    "exact": e.exact,
                    "residual_px": e.residual_px,
                });
                (e.lens, note)
            }
        };
        let i = lens.intrinsics();
        let model = lens.model();
        let parameters: serde_json::Map<String, Value> = model
            .parameters()
            .into_iter()
            .map(|(k, v)| (k.to_string(), json!(v)))
            .collect();
        let (cv_model, distortion) = match model {
            CalibratedModel::KannalaBrandt { k } => (json!("cv::fisheye"), json!(k)),
            CalibratedModel::RadTan { k, p } => (
                json!("cv::calibrateCamera"),
                json!([k[0], k[1], p[0], p[1], k[2]]),
            ),
            _ => (Value::Null, Value::Null),
        };
        let (cx, cy) = (i.cx - 0.5, i.cy - 0.5);
        Ok(json!({
            "name": Self::camera_name(c),
            "width": camera.size.width,
            "height": camera.size.height,
            "lens": camera.lens.to_string(),
            "model": model.name(),
            "intrinsics": {"fx": i.fx, "fy": i.fy, "cx": i.cx, "cy": i.cy},
            "parameters": parameters,
            "max_fov_degrees": lens.max_fov().map(f64::to_degrees),
            "calibrated_equivalent_of": equivalent,
            "opencv": {
                "model": cv_model,
                "camera_matrix": [[i.fx, 0.0, cx], [0.0, i.fy, cy], [0.0, 0.0, 1.0]],
                "distortion_coefficients": distortion,
            },
            "T_rig_camera": rows(&self.cameras[c].1),
            "shutter": {
                "line_delay": camera.shutter.line_delay,
                "exposure_time": camera.shutter.exposure,
                "readout": camera.shutter.readout.name(),
            },
        }))
    }

    /// Renders the poses of `shard` into `folder`: writes (or checks) the plan, skips the
    /// poses whose files all exist, removes what killed runs of this shard left half-written,
    /// and renders the rest. With [`Shard::ALL`], also writes the manifest.
    pub fn render(
        &self,
        ctx: &GpuContext,
        folder: &Path,
        shard: Shard,
        submission: Submission,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<RunReport> {
        let plan = self.plan()?;
        check_plan(folder, &plan)?;
        let range = shard.poses(self.poses.len());
        let skipped = self.skipped()?;
        let complete = |p: usize| {
            skipped[p].is_some()
                || (0..self.cameras.len())
                    .flat_map(|c| self.files(p, c))
                    .all(|(_, file)| folder.join(file).is_file())
        };
        for c in 0..self.cameras.len() {
            remove_leftovers(&folder.join(Self::camera_name(c)), &range)?;
        }
        let todo: Vec<usize> = range.clone().filter(|&p| !complete(p)).collect();
        let outside = range.clone().filter(|&p| skipped[p].is_some()).count();
        let skipped = range.len() - todo.len();
        let mut report = RunReport {
            shard: format!("{}/{}", shard.index, shard.count),
            poses: range.len(),
            skipped: skipped - outside,
            outside,
            rendered: 0,
            images: 0,
            rays: 0,
            upload_seconds: 0.0,
            compile_seconds: 0.0,
            seconds: 0.0,
            trace_seconds: 0.0,
            readback_seconds: 0.0,
            write_seconds: 0.0,
        };
        progress(Progress {
            done: skipped,
            total: range.len(),
            skipped,
        });
        if !todo.is_empty() {
            self.render_poses(ctx, folder, &todo, submission, &mut report, &mut |done| {
                progress(Progress {
                    done: skipped + done,
                    total: range.len(),
                    skipped,
                })
            })?;
        }
        let record = serde_json::to_string_pretty(&report).expect("a report serialises") + "\n";
        let name = format!("shards/{}-of-{}.json", shard.index, shard.count);
        write_file(&folder.join(name), record.as_bytes())?;
        if shard == Shard::ALL {
            merge(folder)?;
        }
        Ok(report)
    }

    /// Renders `todo`'s poses: the scene uploaded once (relative to the trajectory's first
    /// camera, the same for every shard, so that shards write the same bytes), a trace pass
    /// per camera, files written on a second thread.
    fn render_poses(
        &self,
        ctx: &GpuContext,
        folder: &Path,
        todo: &[usize],
        submission: Submission,
        report: &mut RunReport,
        progress: &mut dyn FnMut(usize),
    ) -> Result<()> {
        let t = Instant::now();
        let mut scene = self.scene.clone();
        scene.set_camera(camera_from_transform(&self.scene_from_camera(0, 0)));
        let gpu_scene = GpuScene::new(ctx, &scene, &self.options)?;
        report.upload_seconds = t.elapsed().as_secs_f64();
        let lens_cameras: Vec<LensCamera> = (0..self.cameras.len())
            .map(|c| self.lens_camera(c))
            .collect();
        let options = RenderOptions {
            directions: DirectionSource::Computed,
            ..self.options
        };
        let passes: Vec<FramePass> = lens_cameras
            .iter()
            .map(|camera| FramePass::new(ctx, camera, &gpu_scene, &options))
            .collect::<Result<_>>()?;
        // Drivers compile a pipeline at its first dispatch (lavapipe does): one pixel of each
        // camera's (an adaptive frame's passes: a whole frame), so that the poses' times are
        // rendering alone.
        let t = Instant::now();
        ctx.checked("compiling the kernels", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            let one = crate::lens::ImageSize::new(1, 1).expect("1x1 is a size");
            for pass in &passes {
                match pass {
                    FramePass::Uniform(pass) => {
                        pass.encode_pose(&ctx.device, &mut encoder, &gpu_scene, &scene.camera);
                        pass.encode_region(&mut encoder, &gpu_scene, 0, one, None);
                    }
                    FramePass::Adaptive(_) => {
                        pass.encode(&ctx.device, &mut encoder, &gpu_scene, &scene.camera)
                    }
                }
            }
            ctx.queue.submit([encoder.finish()]);
        })?;
        ctx.wait()?;
        report.compile_seconds = t.elapsed().as_secs_f64();
        let started = Instant::now();
        let (sender, receiver) = mpsc::sync_channel::<Written>(2 * self.cameras.len());
        std::thread::scope(|scope| -> Result<()> {
            let writer = scope.spawn(|| -> Result<f64> {
                let mut seconds = 0.0;
                let kill_after = injected_kill();
                // The cameras' rays in their own frames, once: each pose only turns them.
                let directions: Vec<Vec<Option<DVec3>>> = if self.outputs.0.is_empty() {
                    Vec::new()
                } else {
                    lens_cameras.iter().map(LensCamera::directions).collect()
                };
                for (written, w) in receiver.into_iter().enumerate() {
                    let t = Instant::now();
                    self.write(folder, &directions, &w)?;
                    seconds += t.elapsed().as_secs_f64();
                    if kill_after == Some(written + 1) {
                        // SAFETY: kill(2) on this process with SIGKILL takes no pointers and
                        // does not return; it is the kill this fault stands for.
                        unsafe {
                            libc::kill(libc::getpid(), libc::SIGKILL);
                        }
                    }
                }
                Ok(seconds)
            });
            let rendered = (|| -> Result<()> {
                for (done, &p) in todo.iter().enumerate() {
                    let poses: Vec<crate::scene::Camera> = (0..self.cameras.len())
                        .map(|c| camera_from_transform(&self.scene_from_camera(p, c)))
                        .collect();
                    let groups: Vec<Vec<usize>> = match submission {
                        Submission::Pose => vec![(0..passes.len()).collect()],
                        Submission::Camera => (0..passes.len()).map(|c| vec![c]).collect(),
                    };
                    // Cameras whose shutters spread their rays over time move over the frame;
                    // `skipped` left out the frames where that reaches past the trajectory.
                    let motions: Vec<Option<Motion>> = (0..self.cameras.len())
                        .map(|c| {
                            let moves = self.cameras[c].0.shutter.moves();
                            moves.then(|| self.motion(p, c).ok()).flatten()
                        })
                        .collect();
                    let mut outputs = Vec::with_capacity(passes.len());
                    for group in groups {
                        let t = Instant::now();
                        ctx.checked("rendering a dataset frame", || -> Result<()> {
                            let mut encoder =
                                ctx.device.create_command_encoder(&Default::default());
                            for &c in &group {
                                let device = &ctx.device;
                                match &motions[c] {
                                    Some(motion) => passes[c].encode_motion(
                                        device,
                                        &mut encoder,
                                        &gpu_scene,
                                        motion,
                                    )?,
                                    None => passes[c].encode(
                                        device,
                                        &mut encoder,
                                        &gpu_scene,
                                        &poses[c],
                                    ),
                                }
                            }
                            ctx.queue.submit([encoder.finish()]);
                            Ok(())
                        })??;
                        ctx.wait()?;
                        report.trace_seconds += t.elapsed().as_secs_f64();
                        let t = Instant::now();
                        for &c in &group {
                            let output = passes[c].trace_pass().read(ctx)?;
                            report.rays += passes[c].rays(ctx, &output)?;
                            outputs.push(output);
                        }
                        report.readback_seconds += t.elapsed().as_secs_f64();
                    }
                    for (c, output) in outputs.into_iter().enumerate() {
                        report.images += 1;
                        let w = Written {
                            index: p,
                            camera: c,
                            pose: poses[c],
                            motion: motions[c].clone(),
                            output,
                        };
                        if sender.send(w).is_err() {
                            // The writer stopped on an error, which its join reports.
                            return Ok(());
                        }
                    }
                    report.rendered += 1;
                    progress(done + 1);
                }
                Ok(())
            })();
            drop(sender);
            let written = writer.join().expect("the writer thread does not panic");
            rendered?;
            report.write_seconds = written?;
            Ok(())
        })?;
        report.seconds = started.elapsed().as_secs_f64();
        Ok(())
    }

    /// Writes one camera's files of one pose (the names [`Dataset::files`] gives), each to a
    /// temporary name renamed into place; `directions` holds each camera's camera-frame rays.
    fn write(&self, folder: &Path, directions: &[Vec<Option<DVec3>>], w: &Written) -> Result<()> {
        let files = self.files(w.index, w.camera);
        let (file, display) = self.colour;
        let out = &w.output;
        write_colour(
            &folder.join(&files[0].1),
            out.size,
            &out.colour,
            &display,
            file,
        )?;
        let (channels, arrays) = &self.outputs;
        if channels.is_empty() {
            return Ok(());
        }
        let directions = match &w.motion {
            Some(motion) => {
                moving_directions(&self.lens_camera(w.camera), &directions[w.camera], motion)
            }
            None => rotated(&directions[w.camera], &w.pose),
        };
        for (&channel, (_, name)) in channels.iter().zip(&files[1..]) {
            let path = folder.join(name);
            match arrays {
                ArrayFile::Npy => out.write_npy(channel, &directions, &path)?,
                ArrayFile::Exr => out.write_exr(channel, &directions, &path)?,
            }
        }
        Ok(())
    }
}

/// The image count after which the run aborts, from `FISHEYE_INJECT_FAULT=kill-after-images:N`
/// (see [`crate::gpu::FAULT_VARIABLE`]): a kill at a known point, for the tests of resuming.
fn injected_kill() -> Option<usize> {
    std::env::var(crate::gpu::FAULT_VARIABLE)
        .ok()?
        .strip_prefix("kill-after-images:")?
        .parse()
        .ok()
}

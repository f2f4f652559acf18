//! Rendering a dataset: the plan (`plan.json`, what every frame is) and the frames of a shard
//! (all cameras of a pose in one submission, files written by a second thread while the next
//! pose renders); the folder's files and the merge are `files`'.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

use glam::{DAffine3, DVec3};

mod plan;

/// The rig as a Kalibr camchain on the IMU, beside a simulated IMU's readings.
const CAMCHAIN: &str = "camchain-imucam.yaml";

use super::between::{Between, FlowFile};
use super::files::{ArrayFile, check_plan, merge, remove_leftovers};
use super::flow::{Movers, Seen};
use super::imu::Imu;
use super::labels::{LABEL_MAP, Label, label_map};
use super::readout::{Track, Unrenderable, frame_motion};
use super::trajectory::{Pose, TrajectoryFormat};
use super::{Shard, camera_from_transform, frame_stem};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::lens::LensCamera;
use crate::lens::gpu::DirectionSource;
use crate::scene::Scene;
use crate::trace::{
    Channel, ColourFile, Display, FramePass, GpuScene, Motion, PixelRays, RenderOptions,
    RenderOutput, moving_directions, rotated, write_colour, write_exr, write_file, write_npy,
    write_rays_map,
};

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
    /// The ground truth between a frame and its neighbours (optical and scene flow), and
    /// the files optical flow is written in.
    pub between: (Vec<Between>, FlowFile),
    /// Segmentation written beside each image (in the arrays' format), with the label map.
    pub labels: Vec<Label>,
    /// Whether each image's spp map is written beside it (`spp`, in the arrays' format): the
    /// rays its pixels' colours took, 0 where adaptive sampling interpolated a pixel or the
    /// lens covers none of it ([`FramePass::rays_map`]).
    pub spp_map: bool,
    /// A synthetic IMU on the body, whose spline the frames' poses follow too (`poses` hold
    /// them).
    pub imu: Option<Imu>,
}

/// Progress of a run: frames (poses) done of the shard's, and how many were already complete.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Poses finished (rendered or skipped) in this run.
    pub done: usize,
    /// Poses in the shard.
    pub total: usize,
    /// Of them, already complete before this run (frames skipped past the trajectory's
    /// ends are done, but not counted here).
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
    /// The rays each pixel took, where the spp map is written.
    rays: Option<Vec<u32>>,
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

    /// The trajectory as a function of time: its spline where an IMU is simulated (the
    /// frames' poses then follow it too), else between its stamps.
    fn track(&self) -> Track<'_> {
        match &self.imu {
            Some(imu) => Track::Smooth(&imu.spline),
            None => Track::Stamps(&self.stamps),
        }
    }

    /// The scene time of frame `p`: seconds from the trajectory's first stamp (where the
    /// scene's animations start).
    pub fn scene_time(&self, p: usize) -> f64 {
        self.poses[p].seconds - self.stamps.first().map_or(0.0, |s| s.seconds)
    }

    /// Camera `c`'s motion over frame `p` (see [`frame_motion`]).
    fn motion(&self, p: usize, c: usize) -> std::result::Result<Motion, Unrenderable> {
        frame_motion(
            self.track(),
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
                let seconds = self.poses[p].seconds;
                if self.imu.is_some() && self.track().pose_at(seconds).is_none() {
                    let (a, b) = self.track().span();
                    return Ok(Some(format!(
                        "its time, {seconds:.6} s, is outside the IMU's spline ({a:.6} s to \
                         {b:.6} s: a spline step in from the trajectory's ends)"
                    )));
                }
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
        files.extend(self.labels.iter().map(|l| {
            let name = l.name().to_string();
            let file = format!("{stem}.{name}.{ext}");
            (name, file)
        }));
        if self.spp_map {
            files.push(("spp".to_string(), format!("{stem}.spp.{ext}")));
        }
        for b in &self.between.0 {
            files.extend(b.files(&stem, self.outputs.1, self.between.1));
        }
        files
    }

    /// The frames to trace for `todo`'s: each, and where flow is written its neighbours
    /// (another shard's, or already complete) that are not skipped, in order, with whether
    /// to write it.
    fn traced(&self, todo: &[usize], skipped: &[Option<String>]) -> Vec<(usize, bool)> {
        let reach = usize::from(!self.between.0.is_empty());
        let mut frames = std::collections::BTreeMap::new();
        for &p in todo {
            let first = p.saturating_sub(reach);
            let around = &skipped[first..=(p + reach).min(self.poses.len() - 1)];
            for (q, why) in (first..).zip(around) {
                if why.is_none() {
                    *frames.entry(q).or_insert(false) |= q == p;
                }
            }
        }
        frames.into_iter().collect()
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
        if let Some(imu) = &self.imu {
            imu.write(folder, self.stamps.first(), self.trajectory.1)?;
            if let Some(camchain) = self.camchain() {
                write_file(&folder.join(CAMCHAIN), camchain.as_bytes())?;
            }
        }
        if !self.labels.is_empty() {
            write_file(&folder.join(LABEL_MAP), label_map(&self.scene).as_bytes())?;
        }
        let range = shard.poses(self.poses.len());
        let reasons = self.skipped()?;
        let complete = |p: usize| {
            reasons[p].is_some()
                || (0..self.cameras.len())
                    .flat_map(|c| self.files(p, c))
                    .all(|(_, file)| folder.join(file).is_file())
        };
        for c in 0..self.cameras.len() {
            remove_leftovers(&folder.join(Self::camera_name(c)), &range)?;
        }
        let todo: Vec<usize> = range.clone().filter(|&p| !complete(p)).collect();
        let outside = range.clone().filter(|&p| reasons[p].is_some()).count();
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
        // Frames past the trajectory's ends count as done, not as already complete.
        progress(Progress {
            done: skipped,
            total: range.len(),
            skipped: skipped - outside,
        });
        if !todo.is_empty() {
            let frames = self.traced(&todo, &reasons);
            self.render_poses(ctx, folder, &frames, submission, &mut report, &mut |done| {
                progress(Progress {
                    done: skipped + done,
                    total: range.len(),
                    skipped: skipped - outside,
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
        frames: &[(usize, bool)],
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
        // Each traced frame's views, and whether to write them (a neighbour traced for flow
        // alone is not).
        let (sender, receiver) = mpsc::sync_channel::<(bool, Vec<Written>)>(2);
        std::thread::scope(|scope| -> Result<()> {
            let writer = scope.spawn(|| -> Result<f64> {
                let mut seconds = 0.0;
                let kill_after = injected_kill();
                // The cameras' rays in their own frames, once: each pose only turns them.
                let directions: Vec<Vec<Option<DVec3>>> =
                    if self.outputs.0.is_empty() && self.between.0.is_empty() {
                        Vec::new()
                    } else {
                        lens_cameras.iter().map(LensCamera::directions).collect()
                    };
                let mut images = 0;
                let mut write = |frames: &[&(bool, Vec<Written>)], k: usize| -> Result<()> {
                    let (wanted, views) = frames[k];
                    if !wanted {
                        return Ok(());
                    }
                    // The neighbours, where they are the frames just before and after.
                    let index = views[0].index;
                    let beside = |j: Option<usize>, at: usize| {
                        j.and_then(|j| frames.get(j)).filter(|f| f.1[0].index == at)
                    };
                    let previous = beside(k.checked_sub(1), index.wrapping_sub(1));
                    let next = beside(Some(k + 1), index + 1);
                    for (c, w) in views.iter().enumerate() {
                        let t = Instant::now();
                        let around = (previous.map(|f| &f.1[c]), next.map(|f| &f.1[c]));
                        self.write(folder, &directions, w, around)?;
                        seconds += t.elapsed().as_secs_f64();
                        images += 1;
                        if kill_after == Some(images) {
                            // SAFETY: kill(2) on this process with SIGKILL takes no pointers
                            // and does not return; it is the kill this fault stands for.
                            unsafe {
                                libc::kill(libc::getpid(), libc::SIGKILL);
                            }
                        }
                    }
                    Ok(())
                };
                // Without flow a frame is written as it comes; with flow once the next has
                // come (or there is none), its neighbours held beside it.
                let mut window: std::collections::VecDeque<(bool, Vec<Written>)> =
                    Default::default();
                for frame in receiver {
                    window.push_back(frame);
                    if self.between.0.is_empty() {
                        write(&[&window[0]], 0)?;
                        window.clear();
                    } else if window.len() >= 2 {
                        let held: Vec<_> = window.iter().collect();
                        write(&held, held.len() - 2)?;
                        if window.len() == 3 {
                            window.pop_front();
                        }
                    }
                }
                if !window.is_empty() {
                    let held: Vec<_> = window.iter().collect();
                    write(&held, held.len() - 1)?;
                }
                Ok(seconds)
            });
            let rendered = (|| -> Result<()> {
                let mut done = 0;
                // Every ray of a frame's cameras is within this of its stamp.
                let window = lens_cameras
                    .iter()
                    .map(LensCamera::exposure_span)
                    .fold((0.0f64, 0.0f64), |(a, b), (lo, hi)| (a.min(lo), b.max(hi)));
                for &(p, wanted) in frames {
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
                    let mut rays = Vec::with_capacity(passes.len());
                    gpu_scene.place_at(ctx, &scene, self.scene_time(p), window)?;
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
                            let map = passes[c].rays_map(ctx, &output)?;
                            report.rays += map.iter().map(|&n| u64::from(n)).sum::<u64>();
                            outputs.push(output);
                            rays.push(self.spp_map.then_some(map));
                        }
                        report.readback_seconds += t.elapsed().as_secs_f64();
                    }
                    let views: Vec<Written> = outputs
                        .into_iter()
                        .zip(rays)
                        .enumerate()
                        .map(|(c, (output, rays))| Written {
                            index: p,
                            camera: c,
                            pose: poses[c],
                            motion: motions[c].clone(),
                            output,
                            rays,
                        })
                        .collect();
                    if sender.send((wanted, views)).is_err() {
                        // The writer stopped on an error, which its join reports.
                        return Ok(());
                    }
                    if wanted {
                        report.images += self.cameras.len();
                        report.rendered += 1;
                        done += 1;
                        progress(done);
                    }
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
    /// temporary name renamed into place; `directions` holds each camera's camera-frame rays,
    /// `around` its views of the previous and next frames where they were traced.
    fn write(
        &self,
        folder: &Path,
        directions: &[Vec<Option<DVec3>>],
        w: &Written,
        around: (Option<&Written>, Option<&Written>),
    ) -> Result<()> {
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
        let camera_rays = directions;
        if !channels.is_empty() {
            let world = match &w.motion {
                Some(motion) => {
                    moving_directions(&self.lens_camera(w.camera), &directions[w.camera], motion)
                }
                None => rotated(&directions[w.camera], &w.pose),
            };
            let rays = PixelRays {
                camera: &directions[w.camera],
                world: &world,
            };
            for (&channel, (_, name)) in channels.iter().zip(&files[1..]) {
                let path = folder.join(name);
                match arrays {
                    ArrayFile::Npy => out.write_npy(channel, rays, &path)?,
                    ArrayFile::Exr => out.write_exr(channel, rays, &path)?,
                }
            }
        }
        let mut rest = &files[1 + channels.len()..];
        for (label, (name, file)) in self.labels.iter().zip(rest) {
            let values = label.values(&self.scene, &out.ids);
            match arrays {
                ArrayFile::Npy => write_npy(&folder.join(file), out.size, values)?,
                ArrayFile::Exr => write_exr(&folder.join(file), out.size, name, values)?,
            }
        }
        rest = &rest[self.labels.len()..];
        if let Some(map) = &w.rays {
            write_rays_map(&folder.join(&rest[0].1), out.size, map)?;
            rest = &rest[1..];
        }
        if self.between.0.is_empty() {
            return Ok(());
        }
        // Flow: each view as it moved over its frame (still where its shutter is global).
        let camera = self.lens_camera(w.camera);
        let motion = |w: &Written| w.motion.clone().unwrap_or_else(|| Motion::still(&w.pose));
        let motions = [Some(w), around.0, around.1].map(|w| w.map(motion));
        let movers = Movers::new(&self.scene);
        fn seen<'a>(
            camera: &'a LensCamera,
            motion: Option<&'a Motion>,
            w: Option<&'a Written>,
            rays: &'a [Vec<Option<DVec3>>],
            (dataset, movers): (&Dataset, Option<&'a Movers<'a>>),
        ) -> Option<Seen<'a>> {
            let w = w?;
            Some(Seen {
                camera,
                motion: motion?,
                output: &w.output,
                directions: &rays[w.camera],
                time: dataset.scene_time(w.index),
                movers,
            })
        }
        let moving = (self, movers.as_ref());
        let seen = |k: usize, w| seen(&camera, motions[k].as_ref(), w, camera_rays, moving);
        let this = seen(0, Some(w));
        let (previous, next) = (seen(1, around.0), seen(2, around.1));
        for b in &self.between.0 {
            let count = b.files("", *arrays, self.between.1).len();
            let this = this.as_ref().expect("the frame itself");
            let neighbours = (previous.as_ref(), next.as_ref());
            b.write(
                folder,
                &rest[..count],
                this,
                neighbours,
                (*arrays, self.between.1),
            )?;
            rest = &rest[count..];
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

//! What `fisheye compare` measures of each setup, and the verdict made of it: direct RT's
//! family against the cube maps' at equal error, in time (and the ceiling on it) and in
//! samples against the traced cube.

use serde::Serialize;

use crate::compare::{Envelope, ImageError};
use crate::cube::CubeMethod;
use crate::renderer::Method;

/// One setup's time and error on one lens.
#[derive(Serialize)]
pub struct CompareEntry {
    /// Lens name.
    pub lens: String,
    /// Setup label.
    pub setup: String,
    /// Method name.
    pub method: &'static str,
    /// Cube face size, `None` for direct methods.
    pub cube_size: Option<u32>,
    /// Rays per pixel of a direct method (the most, for adaptive sampling), `None` for cube
    /// maps.
    pub spp: Option<u32>,
    /// Adaptive sampling's threshold, `None` for uniform sampling and cube maps.
    pub threshold: Option<f32>,
    /// The pixel filter of a direct method (`box` or `tent`), `None` for cube maps.
    pub filter: Option<&'static str>,
    /// The rays the last frame's colour took per pixel the lens covers, on average: adaptive
    /// sampling's measured count; `spp` for uniform sampling; `None` for cube maps.
    pub rays_per_pixel: Option<f64>,
    /// The scene samples the last frame's colour took: a direct setup's primary rays (every
    /// pixel's, as `rays_per_pixel` counts them), a cube map's face texels (traced or
    /// rasterized, over the parts of the faces the lens reaches).
    pub samples: f64,
    /// Median GPU ms per frame, if timestamps exist.
    pub gpu_ms: Option<f64>,
    /// Median wall ms per frame.
    pub wall_ms: f64,
    /// MSE, PSNR and the rest against the reference.
    pub error: ImageError,
    /// Mean ꟻLIP against the reference.
    pub flip: f64,
    /// Whether no other setup on this lens is as fast and as close to the reference in MSE
    /// (errors within [`crate::compare::EQUAL_ERROR`] count as equal).
    pub pareto: bool,
    /// The same in ꟻLIP.
    pub pareto_flip: bool,
}

impl CompareEntry {
    /// GPU time where timed, else wall time.
    pub fn ms(&self) -> f64 {
        self.gpu_ms.unwrap_or(self.wall_ms)
    }

    /// The error `metric` measures.
    pub fn error_in(&self, metric: Metric) -> f64 {
        match metric {
            Metric::Mse => self.error.mse,
            Metric::Flip => self.flip,
        }
    }
}

/// An error measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Metric {
    /// Mean squared error of displayed values.
    #[serde(rename = "MSE")]
    Mse,
    /// Mean ꟻLIP.
    #[serde(rename = "FLIP")]
    Flip,
}

impl Metric {
    /// As tables print it.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Mse => "MSE",
            Metric::Flip => "ꟻLIP",
        }
    }
}

/// Direct RT's time at one cube-map setup's error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Level {
    /// The cube-map setup on its family's envelope.
    pub cube: String,
    /// Its error (the level).
    pub error: f64,
    /// Its ms per frame.
    pub cube_ms: f64,
    /// The ms per frame direct RT needs for that error (its envelope, interpolated), `None`
    /// if RT does not reach it.
    pub rt_ms: Option<f64>,
    /// `cube_ms / rt_ms`: how many times faster RT is (the goal is at least 4).
    pub speedup: Option<f64>,
}

/// Direct RT against the cube maps at equal error on one lens, in one metric: at the error
/// of every cube-map setup on its family's lower envelope, the time RT's family needs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// Lens name.
    pub lens: String,
    /// The error measure.
    pub metric: Metric,
    /// One per cube-map setup on the envelope, fastest first.
    pub levels: Vec<Level>,
    /// The least speed-up over the levels both families reach.
    pub least_speedup: Option<f64>,
    /// When RT reaches less error than any cube map: its least error and that setup.
    pub rt_only: Option<(f64, String)>,
    /// The same comparison in samples against the traced cube (`cube-rt`), whose texels are
    /// rays like RT's: one per `cube-rt` setup on its envelope in texels against error (none
    /// without traced cubes).
    pub rays: Vec<RayLevel>,
    /// The least of `rays`' ratios over the levels both reach.
    pub least_fewer: Option<f64>,
}

/// Direct RT's primary rays at one traced cube setup's error: with a ray costing the same in
/// both (the same kernels shade them), the speed-up RT's sampling allows, whatever the GPU.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayLevel {
    /// The traced cube setup on its envelope in texels against error.
    pub cube: String,
    /// Its error (the level).
    pub error: f64,
    /// The texels its faces trace a frame.
    pub texels: f64,
    /// The primary rays a frame direct RT's family needs for that error (its envelope in rays
    /// against error, interpolated), `None` if RT does not reach it.
    pub rt_rays: Option<f64>,
    /// `texels / rt_rays`: how many times fewer rays RT traces.
    pub fewer: Option<f64>,
}

/// The most direct RT can be faster than the cube maps at the error of their fastest setup,
/// whatever its sampling reaches there: that setup's time over RT's fastest frame, at any
/// error. A verdict's least speed-up cannot exceed it (the cube maps' fastest setup is the
/// first level, and RT needs at least its fastest frame's time for any error), so where it
/// is under 4 only cheaper RT frames, not better sampling, can meet the goal.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ceiling {
    /// Lens name.
    pub lens: String,
    /// The cube maps' fastest setup.
    pub cube: String,
    /// Its ms per frame.
    pub cube_ms: f64,
    /// Direct RT's fastest setup.
    pub rt: String,
    /// Its ms per frame.
    pub rt_ms: f64,
    /// `cube_ms / rt_ms`.
    pub ratio: f64,
}

/// What a setup costs a frame: its time, or its samples.
pub(super) type Cost = fn(&CompareEntry) -> f64;

pub(super) fn time(e: &CompareEntry) -> f64 {
    e.ms()
}

pub(super) fn samples(e: &CompareEntry) -> f64 {
    e.samples
}

/// The lower envelope of the entries `family` picks, in `cost` against `metric`'s error.
pub(super) fn envelope<'a>(
    entries: impl IntoIterator<Item = &'a CompareEntry>,
    metric: Metric,
    family: fn(&CompareEntry) -> bool,
    cost: Cost,
) -> Envelope {
    let points: Vec<(f64, f64)> = entries
        .into_iter()
        .filter(|e| family(e))
        .map(|e| (cost(e), e.error_in(metric)))
        .collect();
    Envelope::of(&points)
}

/// The setup of `family` at a point of its envelope.
fn name_at(
    entries: &[CompareEntry],
    metric: Metric,
    family: fn(&CompareEntry) -> bool,
    cost: Cost,
    (c, e): (f64, f64),
) -> String {
    entries
        .iter()
        .find(|x| family(x) && cost(x) == c && x.error_in(metric) == e)
        .map_or(String::new(), |x| x.setup.clone())
}

/// At each setup on the envelope of the cube setups `cube` picks, in `cost` against error:
/// its name, error and cost, and the cost RT's family needs for that error (`None` where it
/// does not reach it).
fn at_cube_errors(
    entries: &[CompareEntry],
    metric: Metric,
    cube: fn(&CompareEntry) -> bool,
    cost: Cost,
) -> Vec<(String, f64, f64, Option<f64>)> {
    let rt = envelope(entries, metric, is_rt, cost);
    envelope(entries, metric, cube, cost)
        .points
        .iter()
        .map(|&(c, error)| {
            let name = name_at(entries, metric, cube, cost, (c, error));
            (name, error, c, rt.time_to_reach(error))
        })
        .collect()
}

/// Every direct setup (`rt`, `rq`; uniform and adaptive): RT's family in the verdict.
pub(super) fn is_rt(e: &CompareEntry) -> bool {
    e.cube_size.is_none()
}

/// The direct setups that sample every pixel alike, each pixel its own rays' mean.
pub(super) fn is_uniform(e: &CompareEntry) -> bool {
    is_rt(e) && e.threshold.is_none() && e.filter == Some("box")
}

pub(super) fn is_cube(e: &CompareEntry) -> bool {
    e.cube_size.is_some()
}

/// The traced cube, whose texels are rays.
pub(super) fn is_traced_cube(e: &CompareEntry) -> bool {
    e.method == Method::Cube(CubeMethod::Traced).name()
}

/// The least of some ratios, `None` without any.
fn least(ratios: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    ratios.flatten().min_by(f64::total_cmp)
}

/// RT's family against the cube maps' at the errors of the cube setups on their envelope,
/// in time, and against the traced cubes' in samples; `None` without both families.
pub(super) fn verdict(lens: &str, entries: &[CompareEntry], metric: Metric) -> Option<Verdict> {
    let rt_best = envelope(entries, metric, is_rt, time).best()?;
    let cube_best = envelope(entries, metric, is_cube, time).best()?;
    let levels: Vec<Level> = at_cube_errors(entries, metric, is_cube, time)
        .into_iter()
        .map(|(cube, error, cube_ms, rt_ms)| Level {
            cube,
            error,
            cube_ms,
            rt_ms,
            speedup: rt_ms.map(|t| cube_ms / t),
        })
        .collect();
    let rays: Vec<RayLevel> = at_cube_errors(entries, metric, is_traced_cube, samples)
        .into_iter()
        .map(|(cube, error, texels, rt_rays)| RayLevel {
            cube,
            error,
            texels,
            rt_rays,
            fewer: rt_rays.map(|r| texels / r),
        })
        .collect();
    Some(Verdict {
        lens: lens.to_string(),
        metric,
        least_speedup: least(levels.iter().map(|l| l.speedup)),
        least_fewer: least(rays.iter().map(|l| l.fewer)),
        levels,
        rays,
        rt_only: (rt_best.1 < cube_best.1)
            .then(|| (rt_best.1, name_at(entries, metric, is_rt, time, rt_best))),
    })
}

/// The cube maps' fastest frame over direct RT's on one lens (see [`Ceiling`]); `None`
/// without both families.
pub(super) fn ceiling(lens: &str, entries: &[CompareEntry]) -> Option<Ceiling> {
    let fastest = |family: fn(&CompareEntry) -> bool| {
        entries
            .iter()
            .filter(|e| family(e))
            .min_by(|a, b| a.ms().total_cmp(&b.ms()))
    };
    let (cube, rt) = (fastest(is_cube)?, fastest(is_rt)?);
    Some(Ceiling {
        lens: lens.to_string(),
        cube: cube.setup.clone(),
        cube_ms: cube.ms(),
        rt: rt.setup.clone(),
        rt_ms: rt.ms(),
        ratio: cube.ms() / rt.ms(),
    })
}

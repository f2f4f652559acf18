//! The plan of an adaptive frame: its stages, which a frame runs, and what each traces.

use crate::shared::{
    ADAPTIVE_ESTIMATE_SIDE, MODE_CENTRE, MODE_ESTIMATE, MODE_SAMPLES, MODE_TRUTH, NESTED_SIDE,
    WORKGROUP_1D,
};
use crate::trace::options::{Adaptive, SampleLanes};

/// A part of an adaptive frame, each its own compute pass (and its own timestamps).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// One ray per block corner, or per pixel ([`Adaptive::every_pixel`]).
    Coarse,
    /// The blocks whose corners disagree: a ray through each of their edges' midpoints and
    /// their centres (the corners of their half-blocks); the other blocks interpolated.
    Midpoints,
    /// The half-blocks whose corners disagree: one ray per pixel (at one ray a pixel at most,
    /// not those between two corners that agree); the rest interpolated.
    Refine,
    /// The traced pixels whose colour differs from their neighbours': 2 × 2 samples, and
    /// the error estimate that decides which take all of them (more than 4 samples a pixel,
    /// threshold above 0).
    Estimate,
    /// The pixels whose samples still disagree (or, without the estimating stage, whose
    /// colour differs from their neighbours'): every sample.
    Supersample,
    /// The interpolated pixels' first hits, for the ground truth.
    Truth,
}

/// Every stage, in the order a frame runs them.
pub const ALL_STAGES: [Stage; 6] = [
    Stage::Coarse,
    Stage::Midpoints,
    Stage::Refine,
    Stage::Estimate,
    Stage::Supersample,
    Stage::Truth,
];

/// The stages a frame runs with `samples_per_side`² samples at most, in order: the midpoints
/// and refining only after a coarse stage of block corners, supersampling only with more
/// than one sample a pixel, estimating first with more than 4 and a threshold above 0, the
/// ground truth's only when asked for and some pixels may be interpolated.
pub fn stages_for(samples_per_side: u32, options: Adaptive) -> Vec<Stage> {
    let mut stages = vec![Stage::Coarse];
    if !options.every_pixel {
        stages.extend([Stage::Midpoints, Stage::Refine]);
    }
    if samples_per_side > 2 && options.threshold > 0.0 {
        stages.push(Stage::Estimate);
    }
    if samples_per_side > 1 {
        stages.push(Stage::Supersample);
    }
    if options.ground_truth && !options.every_pixel {
        stages.push(Stage::Truth);
    }
    stages
}

/// The samples supersampling takes over from the estimating stage, with `samples_per_side`²
/// at most: the estimate's 2 × 2 where the estimate runs and the pattern is the nested one
/// (whose first samples are the 2 × 2 pattern's, `sampling::sample_offset`, as their points
/// on a prescription's exit pupil are, `pupil_offset` in `wgsl/glass.wgsl`), else none.
pub(super) fn reused_samples(samples_per_side: u32, options: Adaptive) -> u32 {
    let estimates = stages_for(samples_per_side, options).contains(&Stage::Estimate);
    if estimates && samples_per_side == NESTED_SIDE {
        ADAPTIVE_ESTIMATE_SIDE.pow(2)
    } else {
        0
    }
}

/// The rays each pixel listed at `stage` takes, with `samples_per_side`² samples at most: 1 at
/// the stages that trace centres (`trace_list`), 2 × 2 estimating, all of them but those
/// reused from the estimate ([`reused_samples`]) supersampling.
pub(super) fn samples_at(stage: Stage, samples_per_side: u32, options: Adaptive) -> u32 {
    match stage {
        Stage::Estimate => ADAPTIVE_ESTIMATE_SIDE.pow(2),
        Stage::Supersample => samples_per_side.pow(2) - reused_samples(samples_per_side, options),
        Stage::Coarse | Stage::Midpoints | Stage::Refine | Stage::Truth => 1,
    }
}

/// What the kernel tracing `stage`'s list traces of each pixel (`wgsl/adaptive.wgsl`'s
/// MODE_*): its centre's shaded ray, its first hit alone, its estimating samples or all.
pub(super) fn list_mode(stage: Stage) -> u32 {
    match stage {
        Stage::Coarse | Stage::Midpoints | Stage::Refine => MODE_CENTRE,
        Stage::Truth => MODE_TRUTH,
        Stage::Estimate => MODE_ESTIMATE,
        Stage::Supersample => MODE_SAMPLES,
    }
}

/// The lattice points along a side of `n` pixels at `spacing`: every `spacing`-th pixel and
/// the last.
pub(super) fn lattice_points(n: u32, spacing: u32) -> u32 {
    (n - 1).div_ceil(spacing) + 1
}

/// Where the stages that trace a list (all but [`Stage::Coarse`]) keep their kernels in
/// [`AdaptivePass`]'s arrays: in [`ALL_STAGES`] order from 0.
pub(super) fn listed_at(stage: Stage) -> usize {
    debug_assert!(stage != Stage::Coarse, "the coarse stage traces no list");
    stage as usize - 1
}

/// How many invocations of `trace_samples` (wgsl/adaptive_samples.wgsl) trace each pixel
/// listed at `stage` side by side: one for each of its samples, at most a workgroup's, or one.
pub(super) fn sample_lanes(
    stage: Stage,
    samples_per_side: u32,
    options: Adaptive,
    lanes: SampleLanes,
) -> u32 {
    match lanes {
        SampleLanes::PerSample => samples_at(stage, samples_per_side, options).min(WORKGROUP_1D),
        SampleLanes::PerPixel => 1,
    }
}

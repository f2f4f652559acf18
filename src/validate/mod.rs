//! `fisheye validate`: each lens model checked against images it renders, as the thesis checked
//! its models against photographs of a grid.
//!
//! The built-in `grid` scene, a checkerboard on the inside of a cube, is rendered through the
//! lens, supersampled (an area-sampled image, as a sensor records). The checker's corners are
//! found in the image without the lens model ([`Image::corners`]) and compared with the pixels
//! where the model's f64 projection puts the corners' known world positions ([`predict`]). A
//! detected corner away from its prediction means the renderer's rays and the model's
//! projection disagree: a wrong inverse, pixel convention, pose or scene, or a detector bias.
//!
//! The detector weighs the luminance with a Gaussian of [`SIGMA`] pixels around a point and
//! moves the point to where the weighted luminance is stationary (Newton's method on the exact
//! weighted sum, not on a fitted surface). Four cells meeting at a corner, two light and two
//! dark on the diagonals, are symmetric about it under a half turn wherever the image is
//! locally affine, so the weighted luminance's gradient vanishes there: a saddle, the only
//! stationary point within half a cell. Area sampling keeps an edge's sub-pixel position in
//! the pixels it crosses (a box-filtered step is a ramp), so the sum over pixels finds it to a
//! small fraction of a pixel. Lens curvature over the window and the pixel grid's sampling
//! leave the residual that [`BOUND_PX`] bounds.

mod corners;
mod summary;

use glam::DVec2;
use serde::Serialize;

pub use corners::{Detection, Image, MIN_SPACING_PX, SIGMA};
pub use summary::ValidationReport;

use crate::bench::Machine;
use crate::compare::{supersample_factor, supersampled};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::lens::glass::camera_for;
use crate::lens::gpu::DirectionSource;
use crate::lens::{CalibratedModel, ImageSize, LensCamera, PRESETS};
use crate::scene::Camera;
use crate::scene::builtin::{GridCorner, grid_corners};
use crate::trace::{GpuScene, RenderOptions, TracePass};

/// A detected corner must lie within this many pixels of its prediction, and every checked
/// corner must be detected, for a lens to pass.
///
/// What a correct model leaves is the detector's own error: under 0.03 px on exact,
/// area-sampled synthetic corners at any sub-pixel phase, angle and edge sharpness (tested),
/// and up to 0.05 px on the renders of every preset and calibrated example (all 15 in the
/// README), growing as cells shrink towards [`MIN_SPACING_PX`] and their edges get sharper
/// and more numerous in the window; rendering with 8×8 instead of 4×4 rays per pixel does not
/// change it, so it is not the supersampling. The renderer's f32 rays add under 1e-3 px. The
/// bound is twice the worst measured; a focal length off by 0.1 % moves corners 200 px from
/// the centre by 0.2 px, and fails (tested).
pub const BOUND_PX: f64 = 0.1;

/// The sine of the least angle a checked corner's edges may cross at in the image (60°, the
/// narrowest the detector's synthetic test covers).
const MIN_SIN_ANGLE: f64 = 0.866;

/// The pose the grid is validated from: off the cube's centre, turned and rolled, so that the
/// corners land at every sub-pixel phase and no symmetry of the scene hides an error.
pub fn pose() -> Camera {
    let position = glam::DVec3::new(0.4, -0.3, 0.5);
    Camera {
        position,
        look_at: position + glam::DVec3::new(0.35, 0.2, -1.0),
        up: glam::DVec3::new(0.12, 1.0, 0.0),
    }
}

/// Where a lens model puts one grid corner.
#[derive(Clone, Copy, Debug)]
pub struct Prediction {
    /// The corner.
    pub corner: GridCorner,
    /// Its continuous pixel position by the f64 projection.
    pub pixel: DVec2,
    /// Its angle from the optical axis, radians.
    pub theta: f64,
    /// The distance between neighbouring parallel cell edges there, pixels (the smaller of
    /// the two families).
    pub spacing: f64,
    /// Whether it is checked: it is not on a fold of the cube, its neighbours are in the
    /// image, parallel edges are at least [`MIN_SPACING_PX`] apart and cross at 60° or more,
    /// and the detector's window around it is all valid.
    pub checked: bool,
}

/// Every grid corner the lens images, from `pose`, with the detector's view of `image`
/// deciding which are checked.
pub fn predict(camera: &LensCamera, pose: &Camera, image: &Image) -> Vec<Prediction> {
    let to_camera = pose.rotation().transpose();
    let project = |world: glam::DVec3| camera.project(to_camera * (world - pose.position));
    grid_corners()
        .into_iter()
        .filter_map(|corner| {
            let dir = to_camera * (corner.world - pose.position);
            let pixel = project(corner.world)?;
            let theta = dir.x.hypot(dir.y).atan2(dir.z);
            let neighbours = [
                corner.world + corner.step_a,
                corner.world - corner.step_a,
                corner.world + corner.step_b,
                corner.world - corner.step_b,
            ]
            .map(project);
            // The spacing of parallel edges and the sine of the angle they cross at.
            let spacing = match neighbours {
                [Some(a1), Some(a0), Some(b1), Some(b0)] => {
                    // Central differences: pixels per cell along each family.
                    let (pa, pb) = ((a1 - a0) / 2.0, (b1 - b0) / 2.0);
                    let area = pa.perp_dot(pb).abs();
                    (
                        (area / pa.length()).min(area / pb.length()),
                        area / (pa.length() * pb.length()),
                    )
                }
                _ => (0.0, 0.0),
            };
            Some(Prediction {
                corner,
                pixel,
                theta,
                spacing: spacing.0,
                checked: !corner.fold
                    && spacing.0 >= MIN_SPACING_PX
                    && spacing.1 >= MIN_SIN_ANGLE
                    && image.is_interior(pixel),
            })
        })
        .collect()
}

/// One grid corner's outcome.
#[derive(Clone, Copy, Debug)]
pub struct PointResult {
    /// The prediction.
    pub prediction: Prediction,
    /// The detection matched to it: the nearest within a third of the edge spacing.
    pub detected: Option<DVec2>,
}

impl PointResult {
    /// Detected minus predicted position, pixels.
    pub fn error(&self) -> Option<DVec2> {
        self.detected.map(|d| d - self.prediction.pixel)
    }
}

/// One lens's validation.
#[derive(Clone, Debug, Serialize)]
pub struct LensValidation {
    /// The lens as named (spec, preset or calibration file).
    pub lens: String,
    /// Image size.
    pub size: String,
    /// Rays per pixel side of its image.
    pub supersample: u32,
    /// Grid corners in the image.
    pub projected: usize,
    /// Of those, the ones checked (resolvable, away from the mask).
    pub checked: usize,
    /// Checked corners with a detection.
    pub matched: usize,
    /// Detections near checked corners that match none (there should be none).
    pub stray: usize,
    /// Root-mean-square error of the matched corners, pixels.
    pub rms_px: f64,
    /// 95th percentile of the error, pixels.
    pub p95_px: f64,
    /// Largest error, pixels.
    pub max_px: f64,
    /// Mean error vector (a systematic shift shows here), pixels.
    pub mean_px: [f64; 2],
    /// Largest field angle among checked corners, degrees.
    pub max_theta_deg: f64,
    /// Every corner checked was found within [`BOUND_PX`], with no stray detection.
    pub passed: bool,
    /// Per corner.
    #[serde(skip)]
    pub points: Vec<PointResult>,
    /// Where the stray detections are.
    #[serde(skip)]
    pub strays: Vec<DVec2>,
}

/// Matches detections to predictions and summarizes.
pub fn evaluate(
    lens: &str,
    camera: &LensCamera,
    predictions: &[Prediction],
    detections: &[Detection],
) -> LensValidation {
    let near = |p: DVec2, radius: f64| {
        detections
            .iter()
            .map(|d| d.pixel)
            .filter(move |d| d.distance(p) <= radius)
    };
    let points: Vec<PointResult> = predictions
        .iter()
        .map(|&prediction| PointResult {
            prediction,
            detected: prediction
                .checked
                .then(|| {
                    near(prediction.pixel, prediction.spacing / 3.0).min_by(|a, b| {
                        a.distance(prediction.pixel)
                            .total_cmp(&b.distance(prediction.pixel))
                    })
                })
                .flatten(),
        })
        .collect();
    let matched: Vec<DVec2> = points.iter().filter_map(|p| p.detected).collect();
    // A stray detection matches nothing and is nearer to a checked corner than to any
    // unchecked one.
    let strays: Vec<DVec2> = detections
        .iter()
        .map(|d| d.pixel)
        .filter(|d| !matched.contains(d))
        .filter(|d| {
            predictions
                .iter()
                .min_by(|a, b| a.pixel.distance(*d).total_cmp(&b.pixel.distance(*d)))
                .is_some_and(|p| p.checked)
        })
        .collect();
    let mut errors: Vec<f64> = points
        .iter()
        .filter_map(|p| p.error().map(DVec2::length))
        .collect();
    errors.sort_by(f64::total_cmp);
    let n = errors.len();
    let checked = points.iter().filter(|p| p.prediction.checked).count();
    let mean = points
        .iter()
        .filter_map(PointResult::error)
        .fold(DVec2::ZERO, |s, e| s + e)
        / n.max(1) as f64;
    let max_px = errors.last().copied().unwrap_or(0.0);
    LensValidation {
        lens: lens.to_string(),
        size: camera.size.to_string(),
        supersample: 1,
        projected: points.len(),
        checked,
        matched: n,
        stray: strays.len(),
        rms_px: (errors.iter().map(|e| e * e).sum::<f64>() / n.max(1) as f64).sqrt(),
        // Nearest rank.
        p95_px: errors
            .get(((0.95 * n as f64).ceil() as usize).saturating_sub(1))
            .copied()
            .unwrap_or(0.0),
        max_px,
        mean_px: mean.to_array(),
        max_theta_deg: points
            .iter()
            .filter(|p| p.prediction.checked)
            .map(|p| p.prediction.theta.to_degrees())
            .fold(0.0, f64::max),
        passed: checked > 0 && n == checked && strays.is_empty() && max_px <= BOUND_PX,
        points,
        strays,
    }
}

/// Renders the grid scene through `camera` from [`pose`], `supersample²` rays per pixel
/// averaged (linear colours, the mask in `w`).
pub fn render(
    ctx: &GpuContext,
    scene: &GpuScene,
    camera: &LensCamera,
    supersample: u32,
) -> Result<Vec<[f32; 4]>> {
    let pass = TracePass::new(ctx, camera, scene, DirectionSource::Computed)?;
    pass.set_pose(ctx, scene, &pose());
    let centres = pass.trace(ctx, scene, "tracing the grid")?.colour;
    supersampled(ctx, scene, camera, &pose(), supersample, &centres)
}

/// A lens to validate, with the name the report gives it.
pub struct LensToValidate {
    /// Spec, preset name or calibration file.
    pub name: String,
    /// The camera.
    pub camera: LensCamera,
}

/// Image size of the presets in the default validation.
pub const PRESET_SIZE: (u32, u32) = (512, 512);

/// What `fisheye validate` checks by default: every preset at [`PRESET_SIZE`] and each
/// calibrated model's example at the size it is calibrated for.
pub fn default_lenses() -> Result<Vec<LensToValidate>> {
    let presets = PRESETS.iter().map(|p| (p.name, PRESET_SIZE));
    let examples = CalibratedModel::EXAMPLES
        .into_iter()
        .zip(CalibratedModel::EXAMPLE_SIZES);
    presets
        .chain(examples)
        .map(|(spec, (w, h))| {
            Ok(LensToValidate {
                name: spec.to_string(),
                camera: camera_for(spec, ImageSize::new(w, h)?)?,
            })
        })
        .collect()
}

/// Renders, detects and evaluates one lens; returns the evaluation and the rendered colours.
pub fn validate_lens(
    ctx: &GpuContext,
    scene: &GpuScene,
    lens: &LensToValidate,
    supersample: u32,
) -> Result<(LensValidation, Vec<[f32; 4]>)> {
    let colour = render(ctx, scene, &lens.camera, supersample)?;
    let image = Image::from_colour(lens.camera.size.width as usize, &colour);
    let predictions = predict(&lens.camera, &pose(), &image);
    let detections = image.corners();
    let validation = LensValidation {
        supersample,
        ..evaluate(&lens.name, &lens.camera, &predictions, &detections)
    };
    Ok((validation, colour))
}

/// Validates every lens, calling `progress` with the index and name of each before it is
/// rendered. `supersample` rays per pixel side, or by default the most (up to 4) whose image
/// fits one storage binding.
pub fn run(
    ctx: &GpuContext,
    lenses: &[LensToValidate],
    supersample: Option<u32>,
    progress: &mut dyn FnMut(usize, &str),
) -> Result<ValidationReport> {
    let scene = crate::scene::builtin::scene("grid").expect("the grid scene is built in");
    let gpu_scene = GpuScene::new(ctx, &scene, &RenderOptions::default())?;
    let mut report = ValidationReport {
        machine: Machine::describe(ctx),
        sigma_px: SIGMA,
        min_spacing_px: MIN_SPACING_PX,
        bound_px: BOUND_PX,
        lenses: Vec::new(),
        images: Vec::new(),
    };
    for (k, lens) in lenses.iter().enumerate() {
        progress(k, &lens.name);
        let factor = supersample.unwrap_or_else(|| supersample_factor(ctx, lens.camera.size));
        let (validation, colour) = validate_lens(ctx, &gpu_scene, lens, factor)?;
        report.lenses.push(validation);
        report.images.push((lens.camera, colour));
    }
    Ok(report)
}

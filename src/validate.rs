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

use std::fmt::Write as _;
use std::path::Path;

use glam::{DMat2, DVec2};
use serde::Serialize;

use crate::bench::Machine;
use crate::compare::{supersample_factor, supersampled};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::lens::gpu::DirectionSource;
use crate::lens::{CalibratedModel, ImageSize, LensCamera, PRESETS, parse_spec};
use crate::plot;
use crate::report::{file_stem, machine_lines, write_json, write_text};
use crate::scene::Camera;
use crate::scene::builtin::{GridCorner, grid_corners};
use crate::trace::{GpuScene, RenderOptions, TracePass, colour_image, save_png};

/// Standard deviation, in pixels, of the Gaussian the detector weighs luminance with: the
/// wider, the better it averages out the aliasing of area-sampled sharp edges (worst case on
/// synthetic corners: 0.04 px at σ = 1, 0.027 px at 1.5, 0.018 px at 2), the narrower, the
/// closer together corners can be checked ([`MIN_SPACING_PX`]).
pub const SIGMA: f64 = 1.5;

/// Radius of the detector's window in σ: the Gaussian weight left out beyond it is
/// `e^-12.5 ≈ 4e-6` of the centre's.
const WINDOW_SIGMAS: f64 = 5.0;

/// The least distance between neighbouring parallel cell edges in the image (pixels) for a
/// corner between them to be checked: the window's radius, so that the next edges' weight is
/// at most `e^-12.5 ≈ 4e-6` of the centre's and their asymmetry cannot move the saddle.
pub const MIN_SPACING_PX: f64 = WINDOW_SIGMAS * SIGMA;

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

/// How far from its candidate pixel's centre a corner may be found.
const MAX_SHIFT_PX: f64 = 2.0;

/// The least `-σ⁴ det H` of the weighted luminance's Hessian at a corner: a flat cell has
/// none and a lone edge none (its Hessian has rank one), while a corner of contrast Δ whose
/// edges cross at angle φ has about `(Δ sin φ / π)²`: 0.076 square, 0.01 at 22°.
const MIN_SADDLE: f64 = 0.005;

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

/// An image's luminance with its validity mask, as the detector sees it.
pub struct Image {
    width: usize,
    height: usize,
    values: Vec<f64>,
    /// Whether the detector's whole window around each pixel is valid and in the image.
    interior: Vec<bool>,
}

/// A corner found in an image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detection {
    /// Continuous pixel position (pixel `(i, j)` covers `[i, i+1] × [j, j+1]`).
    pub pixel: DVec2,
    /// `-σ⁴ det H` there: how clearly both edges show.
    pub strength: f64,
}

impl Image {
    /// From linear colours whose `w` is the validity mask (as
    /// [`RenderOutput::colour`](crate::trace::RenderOutput::colour)), `width` per row.
    pub fn from_colour(width: usize, colour: &[[f32; 4]]) -> Self {
        let values = colour
            .iter()
            .map(|c| (f64::from(c[0]) + f64::from(c[1]) + f64::from(c[2])) / 3.0)
            .collect();
        let valid: Vec<bool> = colour.iter().map(|c| c[3] == 1.0).collect();
        Self::new(width, values, &valid)
    }

    /// From luminances and their validity, `width` per row.
    pub fn new(width: usize, values: Vec<f64>, valid: &[bool]) -> Self {
        assert_eq!(values.len(), valid.len());
        assert!(width > 0 && values.len().is_multiple_of(width));
        let height = values.len() / width;
        // A pixel is interior when no invalid pixel (or the image border) is within the
        // window's radius plus one: summed-area table of the invalid pixels.
        let reach = (WINDOW_SIGMAS * SIGMA).ceil() as usize + 1;
        let mut table = vec![0u32; (width + 1) * (height + 1)];
        for j in 0..height {
            for i in 0..width {
                table[(j + 1) * (width + 1) + i + 1] = u32::from(!valid[j * width + i])
                    + table[j * (width + 1) + i + 1]
                    + table[(j + 1) * (width + 1) + i]
                    - table[j * (width + 1) + i];
            }
        }
        let invalid_in = |i0: usize, j0: usize, i1: usize, j1: usize| {
            table[j1 * (width + 1) + i1] + table[j0 * (width + 1) + i0]
                - table[j0 * (width + 1) + i1]
                - table[j1 * (width + 1) + i0]
        };
        let interior = (0..values.len())
            .map(|p| {
                let (i, j) = (p % width, p / width);
                i >= reach
                    && j >= reach
                    && i + reach < width
                    && j + reach < height
                    && invalid_in(i - reach, j - reach, i + reach + 1, j + reach + 1) == 0
            })
            .collect();
        Self {
            width,
            height,
            values,
            interior,
        }
    }

    /// Whether the detector can look at a continuous pixel position: its window is all valid.
    pub fn is_interior(&self, pixel: DVec2) -> bool {
        let (i, j) = (pixel.x.floor(), pixel.y.floor());
        i >= 0.0
            && j >= 0.0
            && (i as usize) < self.width
            && (j as usize) < self.height
            && self.interior[j as usize * self.width + i as usize]
    }

    /// The gradient and Hessian in `x` of the weighted mean luminance around `x`: exact sums
    /// over the window's pixel centres `q`, weighted by `w(r²) = e^(-r²/2σ²)·(1 - r²/R²)²`
    /// with `r = |q - x|` and `R` the window's radius. The taper makes the weight and its slope
    /// vanish at `R`, so the gradient is continuous in `x` as pixels enter and leave the
    /// window (a plain truncated Gaussian jumps there, and Newton's method then cycles
    /// between points 1e-5 px apart instead of converging).
    fn weighted(&self, x: DVec2) -> (DVec2, DMat2) {
        let radius = WINDOW_SIGMAS * SIGMA;
        let (s2, r2max) = (SIGMA * SIGMA, radius * radius);
        let (mut grad, mut hess) = (DVec2::ZERO, DMat2::ZERO);
        let i0 = (x.x - radius).floor().max(0.0) as usize;
        let j0 = (x.y - radius).floor().max(0.0) as usize;
        let i1 = ((x.x + radius).ceil() as usize).min(self.width - 1);
        let j1 = ((x.y + radius).ceil() as usize).min(self.height - 1);
        for j in j0..=j1 {
            for i in i0..=i1 {
                let d = DVec2::new(i as f64 + 0.5, j as f64 + 0.5) - x;
                let u = d.length_squared();
                if u >= r2max {
                    continue;
                }
                // w(u) = E·t² with E = e^(-u/2σ²), t = 1 - u/R²; w' and w'' are in u, and
                // u = |q - x|² has ∇ₓu = -2d and ∇ₓ²u = 2I.
                let (e, t) = ((-u / (2.0 * s2)).exp(), 1.0 - u / r2max);
                let w1 = e * t * (-t / (2.0 * s2) - 2.0 / r2max);
                let w2 =
                    e * (t * t / (4.0 * s2 * s2) + 2.0 * t / (s2 * r2max) + 2.0 / (r2max * r2max));
                let v = self.values[j * self.width + i];
                grad += v * -2.0 * w1 * d;
                hess += v
                    * (4.0 * w2 * DMat2::from_cols(d * d.x, d * d.y) + 2.0 * w1 * DMat2::IDENTITY);
            }
        }
        let norm = 1.0 / (2.0 * std::f64::consts::PI * s2);
        (grad * norm, hess * norm)
    }

    /// The luminance blurred by the detector's Gaussian on the pixel grid, for finding
    /// candidates (separable, truncated at 3σ, clamped at the border).
    fn blurred(&self) -> Vec<f64> {
        let reach = (3.0 * SIGMA).ceil() as i64;
        let kernel: Vec<f64> = (-reach..=reach)
            .map(|k| (-(k * k) as f64 / (2.0 * SIGMA * SIGMA)).exp())
            .collect();
        let (w, h) = (self.width as i64, self.height as i64);
        let pass = |src: &[f64], dx: i64, dy: i64| -> Vec<f64> {
            (0..w * h)
                .map(|p| {
                    let (i, j) = (p % w, p / w);
                    kernel
                        .iter()
                        .zip(-reach..=reach)
                        .map(|(g, k)| {
                            let x = (i + k * dx).clamp(0, w - 1);
                            let y = (j + k * dy).clamp(0, h - 1);
                            g * src[(y * w + x) as usize]
                        })
                        .sum()
                })
                .collect()
        };
        pass(&pass(&self.values, 1, 0), 0, 1)
    }

    /// Every checker corner in the interior, to a fraction of a pixel.
    ///
    /// Candidates are the pixels where the blurred luminance is most saddle-shaped (largest
    /// `-det H` by finite differences) in their 5×5 neighbourhood. Each is refined by Newton's
    /// method on the weighted luminance's gradient ([`Self::weighted`]) and kept if it
    /// converges within [`MAX_SHIFT_PX`] to a saddle with `-det H` ≥ [`MIN_SADDLE`] (not an
    /// edge or a flat cell); detections within a pixel of a stronger one are dropped.
    pub fn corners(&self) -> Vec<Detection> {
        let b = self.blurred();
        let (w, h) = (self.width, self.height);
        let mut saddle = vec![0.0; w * h];
        for j in 1..h.saturating_sub(1) {
            for i in 1..w.saturating_sub(1) {
                let p = j * w + i;
                let xx = b[p + 1] - 2.0 * b[p] + b[p - 1];
                let yy = b[p + w] - 2.0 * b[p] + b[p - w];
                let xy = (b[p + w + 1] - b[p + w - 1] - b[p - w + 1] + b[p - w - 1]) / 4.0;
                saddle[p] = xy * xy - xx * yy;
            }
        }
        let mut found: Vec<Detection> = Vec::new();
        for j in 2..h.saturating_sub(2) {
            for i in 2..w.saturating_sub(2) {
                let p = j * w + i;
                if !self.interior[p] || saddle[p] <= 0.0 {
                    continue;
                }
                // The first of equal values wins, so a plateau gives one candidate at most.
                let peak = (j - 2..=j + 2).all(|y| {
                    (i - 2..=i + 2).all(|x| {
                        let q = y * w + x;
                        q == p || saddle[q] < saddle[p] || (saddle[q] == saddle[p] && q > p)
                    })
                });
                if peak {
                    found.extend(self.refine(DVec2::new(i as f64 + 0.5, j as f64 + 0.5)));
                }
            }
        }
        found.sort_by(|a, b| b.strength.total_cmp(&a.strength));
        let mut kept: Vec<Detection> = Vec::new();
        for d in found {
            if kept.iter().all(|k| k.pixel.distance(d.pixel) > 1.0) {
                kept.push(d);
            }
        }
        kept
    }

    /// Newton's method from `start` to where the weighted luminance is stationary, if that is
    /// a corner.
    fn refine(&self, start: DVec2) -> Option<Detection> {
        let mut x = start;
        for _ in 0..50 {
            let (grad, hess) = self.weighted(x);
            let next = x - hess.inverse() * grad;
            if !next.is_finite() || next.distance(start) > MAX_SHIFT_PX || !self.is_interior(next) {
                return None;
            }
            let step = next.distance(x);
            x = next;
            if step < 1e-7 {
                let strength = -self.weighted(x).1.determinant() * SIGMA.powi(4);
                return (strength >= MIN_SADDLE).then_some(Detection { pixel: x, strength });
            }
        }
        None
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
                camera: LensCamera::new(parse_spec(spec)?, ImageSize::new(w, h)?),
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

/// `fisheye validate`'s report.
#[derive(Serialize)]
pub struct ValidationReport {
    /// The machine.
    pub machine: Machine,
    /// The detector's Gaussian, pixels.
    pub sigma_px: f64,
    /// Closest line spacing checked, pixels.
    pub min_spacing_px: f64,
    /// The pass bound, pixels.
    pub bound_px: f64,
    /// Per lens.
    pub lenses: Vec<LensValidation>,
    /// Per lens, its image (for the overlays).
    #[serde(skip)]
    pub images: Vec<(LensCamera, Vec<[f32; 4]>)>,
}

/// Length of an error's arrow in an overlay, per pixel of error: [`BOUND_PX`] draws 12 px.
const ARROW_SCALE: f64 = 12.0 / BOUND_PX;

impl ValidationReport {
    /// Whether every lens passed.
    pub fn passed(&self) -> bool {
        self.lenses.iter().all(|l| l.passed)
    }

    /// The Markdown table: a row per lens.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# fisheye validate: the grid scene through each lens\n\n{}\n\
             The `grid` checkerboard rendered from a fixed off-centre pose, N×N rays per pixel \
             averaged (column SS); corners detected with a σ = {} px Gaussian; checked where \
             parallel cell edges are at least {} px apart and cross at 60° or more, and the \
             detector's window is inside the image's valid pixels. A lens passes when every \
             checked corner is found within {} px of the f64 projection's prediction and \
             nothing else is found among them.\n\n",
            machine_lines(&self.machine),
            self.sigma_px,
            self.min_spacing_px,
            self.bound_px,
        );
        md.push_str(
            "| lens | size | SS | in image | checked | found | stray | rms px | p95 px | max px | mean shift px | max θ checked | pass |\n\
             |---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|:-:|\n",
        );
        for l in &self.lenses {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | ({:+.4}, {:+.4}) | {:.1}° | {} |",
                l.lens,
                l.size,
                l.supersample,
                l.projected,
                l.checked,
                l.matched,
                l.stray,
                l.rms_px,
                l.p95_px,
                l.max_px,
                l.mean_px[0],
                l.mean_px[1],
                l.max_theta_deg,
                if l.passed { "yes" } else { "**no**" }
            );
        }
        let _ = write!(
            md,
            "\nOverlays (`overlay.LENS.png`, the image at twice its size or more): a cross at each \
             checked prediction, green within half the bound, orange within it, red beyond; \
             its error drawn from it {} times magnified; magenta circles: checked corners \
             not found; blue circles: stray detections; grey dots: corners not checked. \
             `points.LENS.csv` lists every corner.\n",
            ARROW_SCALE
        );
        md
    }

    /// Writes `validate.json`, `validate.md`, and per lens `overlay.LENS.png` and
    /// `points.LENS.csv`, then `errors.png` (error against field angle); returns why the plot
    /// is missing, if there is no font for it.
    pub fn write(&self, out: &Path) -> Result<Option<String>> {
        write_json(&out.join("validate.json"), self)?;
        write_text(&out.join("validate.md"), &self.markdown())?;
        for (l, (camera, colour)) in self.lenses.iter().zip(&self.images) {
            let stem = file_stem(&l.lens);
            save_png(
                &overlay(l, camera, colour)?,
                &out.join(format!("overlay.{stem}.png")),
            )?;
            write_text(&out.join(format!("points.{stem}.csv")), &points_csv(l))?;
        }
        if let Err(why) = plot::font() {
            return Ok(Some(why));
        }
        let series: Vec<plot::Series> = self
            .lenses
            .iter()
            .map(|l| plot::Series {
                // The model's name, without a spec's parameters.
                label: l.lens.split(':').next().unwrap_or(&l.lens).to_string(),
                points: l
                    .points
                    .iter()
                    .filter_map(|p| Some((p.prediction.theta.to_degrees(), p.error()?.length())))
                    .collect(),
            })
            .collect();
        plot::error_against_angle(
            &out.join("errors.png"),
            &format!(
                "grid corners: detected − predicted ({})",
                self.machine.adapter
            ),
            &series,
            self.bound_px,
        )?;
        Ok(None)
    }
}

/// Every corner of one lens as CSV.
fn points_csv(l: &LensValidation) -> String {
    let mut csv = String::from(
        "face,a,b,theta_deg,spacing_px,checked,predicted_x,predicted_y,detected_x,detected_y,error_px\n",
    );
    for p in &l.points {
        let q = &p.prediction;
        let (dx, dy, e) = match p.detected {
            Some(d) => (
                d.x.to_string(),
                d.y.to_string(),
                d.distance(q.pixel).to_string(),
            ),
            None => Default::default(),
        };
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{dx},{dy},{e}",
            q.corner.face,
            q.corner.a,
            q.corner.b,
            q.theta.to_degrees(),
            q.spacing,
            q.checked,
            q.pixel.x,
            q.pixel.y
        );
    }
    csv
}

/// The image enlarged to about 1000 px wide (at least 2x) with the predictions and errors
/// drawn over it (see [`ValidationReport::markdown`] for the legend).
fn overlay(
    l: &LensValidation,
    camera: &LensCamera,
    colour: &[[f32; 4]],
) -> Result<image::RgbaImage> {
    use plotters::prelude::*;
    let image = colour_image(camera.size, colour);
    let zoom = (1000 / camera.size.width).clamp(2, 8);
    let (w, h) = (camera.size.width * zoom, camera.size.height * zoom);
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            rgb.extend_from_slice(&image.get_pixel(x / zoom, y / zoom).0[..3]);
        }
    }
    let z = f64::from(zoom);
    let at = |p: DVec2| ((p.x * z).round() as i32, (p.y * z).round() as i32);
    {
        let area = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        let draw = || -> std::result::Result<(), Box<dyn std::error::Error>> {
            let grey = RGBColor(150, 150, 150);
            for p in &l.points {
                let q = &p.prediction;
                if !q.checked {
                    area.draw(&Circle::new(at(q.pixel), 1, grey.filled()))?;
                    continue;
                }
                let Some(e) = p.error() else {
                    area.draw(&Circle::new(at(q.pixel), 5, MAGENTA.stroke_width(2)))?;
                    continue;
                };
                let c = if e.length() <= BOUND_PX / 2.0 {
                    RGBColor(0, 170, 0)
                } else if e.length() <= BOUND_PX {
                    RGBColor(255, 140, 0)
                } else {
                    RED
                };
                area.draw(&Cross::new(at(q.pixel), 3, c.stroke_width(1)))?;
                let tip = q.pixel + e * ARROW_SCALE / z;
                area.draw(&PathElement::new(
                    vec![at(q.pixel), at(tip)],
                    c.stroke_width(2),
                ))?;
            }
            for d in &l.strays {
                area.draw(&Circle::new(at(*d), 5, BLUE.stroke_width(2)))?;
            }
            area.present()?;
            Ok(())
        };
        draw().map_err(|e| crate::error::Error::Plot {
            path: format!("overlay.{}.png", file_stem(&l.lens)).into(),
            message: e.to_string(),
        })?;
    }
    let rgb = image::RgbImage::from_raw(w, h, rgb).expect("a full buffer");
    Ok(image::DynamicImage::ImageRgb8(rgb).to_rgba8())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image of a checker corner at `centre` whose edges run at angles `a` and `b`
    /// (radians from the x axis), each a ramp `ramp` px wide (as the texture's bilinear filter
    /// makes them), between luminances 0.003 and 0.87, area-sampled by 24 × 24 points per
    /// pixel: an exact picture of what the grid scene shows, made without the renderer.
    pub(super) fn synthetic(size: usize, centre: DVec2, a: f64, b: f64, ramp: f64) -> Image {
        let n = 24;
        let normals = [a, b].map(|t| DVec2::new(-t.sin(), t.cos()));
        let side = |s: f64| (s / ramp + 0.5).clamp(0.0, 1.0) * 2.0 - 1.0;
        let luminance = |p: DVec2| {
            let d = p - centre;
            let sign = side(normals[0].dot(d)) * side(normals[1].dot(d));
            0.4365 + 0.4335 * sign
        };
        let mut values = Vec::with_capacity(size * size);
        for j in 0..size {
            for i in 0..size {
                let mut sum = 0.0;
                for v in 0..n {
                    for u in 0..n {
                        let p = DVec2::new(
                            i as f64 + (u as f64 + 0.5) / n as f64,
                            j as f64 + (v as f64 + 0.5) / n as f64,
                        );
                        sum += luminance(p);
                    }
                }
                values.push(sum / (n * n) as f64);
            }
        }
        Image::new(size, values, &vec![true; size * size])
    }

    /// Exact corners at sub-pixel phases across the pixel, edges from square to 60° apart,
    /// and edge ramps from a hundredth of a pixel to two pixels wide are found once each,
    /// within 0.03 px (the worst, 0.027 px, is a sharp edge 12° off the pixel grid's axes:
    /// area sampling aliases it, and the σ = 1.5 px window averages that down).
    #[test]
    fn synthetic_corners_are_found_to_three_hundredths_of_a_pixel() {
        let mut worst: f64 = 0.0;
        for (k, ramp) in [0.01, 0.1, 0.5, 2.0].into_iter().enumerate() {
            for (m, (a, b)) in [(0.0, 90.0), (12.0, 97.0), (-20.0, 40.0), (45.0, 150.0)]
                .into_iter()
                .enumerate()
            {
                let odd = (0.13 + 0.21 * k as f64, 0.71 - 0.17 * m as f64);
                for phase in [(0.0, 0.0), (0.5, 0.5), odd] {
                    let centre = DVec2::new(20.0 + phase.0, 20.0 + phase.1);
                    let (a, b) = (f64::to_radians(a), f64::to_radians(b));
                    let found = synthetic(40, centre, a, b, ramp).corners();
                    assert_eq!(found.len(), 1, "ramp {ramp}, {centre}: {found:?}");
                    let error = found[0].pixel.distance(centre);
                    worst = worst.max(error);
                    assert!(error < 0.03, "ramp {ramp}, {centre}: off by {error} px");
                }
            }
        }
        eprintln!("worst synthetic error {worst:.5} px");
    }

    /// A lone edge, a flat cell and masked pixels in the window give no corner.
    #[test]
    fn edges_flats_and_masks_give_no_corners() {
        let size = 24;
        let centre = DVec2::new(12.3, 11.6);
        // Edges at a and a + π are one straight edge.
        let edge = synthetic(size, centre, 0.3, 0.3 + std::f64::consts::PI, 0.1);
        assert!(edge.corners().is_empty());
        let flat = Image::new(size, vec![0.5; size * size], &vec![true; size * size]);
        assert!(flat.corners().is_empty());
        let corner = synthetic(size, centre, 0.0, 1.5, 0.1);
        assert_eq!(corner.corners().len(), 1);
        let mut valid = vec![true; size * size];
        valid[12 * size + 7] = false;
        let masked = Image::new(size, corner.values.clone(), &valid);
        assert!(masked.corners().is_empty());
        assert!(!masked.is_interior(centre));
        assert!(corner.is_interior(centre));
    }
}

//! How close a calibrated lens is to the classic mappings: the thesis claims most real lenses
//! are close to one of equidistant, equisolid, orthographic and stereographic. We fit each
//! one's focal length to the lens's radial profile and report the residual in pixels. The
//! other way, a classic lens's calibrated equivalent ([`calibrated_equivalent`]): exact where
//! a calibrated model contains the mapping, else a fitted Kannala–Brandt polynomial.

use std::f64::consts::FRAC_PI_2;

use glam::DVec2;

use super::calibrated::{CalibratedLens, CalibratedModel, Intrinsics};
use super::camera::{ImageSize, LensCamera};
use super::model::{Family, LensModel};
use crate::error::LensError;

/// A classic mapping fitted to a calibrated lens.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassicFit {
    /// The classic model.
    pub model: LensModel,
    /// The fitted focal length, pixels.
    pub f_pixels: f64,
    /// Root-mean-square radial residual over the fitted angles, pixels.
    pub rms: f64,
    /// Largest radial residual, pixels.
    pub max: f64,
}

/// A classic mapping as `r/f` of θ.
type Mapping = fn(f64) -> f64;

/// The four classic mappings the thesis fits.
const CLASSIC: [(LensModel, Mapping); 4] = [
    (LensModel::Equidistant, |t| t),
    (LensModel::Equisolid, |t| 2.0 * (0.5 * t).sin()),
    (LensModel::Orthographic, f64::sin),
    (LensModel::Stereographic, |t| 2.0 * (0.5 * t).tan()),
];

/// The angles a fit covers: from the axis to the widest angle the image shows (its farthest
/// corner, or the lens's domain edge), sampled evenly.
pub fn fitted_angles(lens: &CalibratedLens, size: ImageSize) -> Vec<f64> {
    shown_angles(|p| lens.unproject(p), size, lens.theta_max())
}

/// 512 angles from the axis to the widest the image shows: its farthest corner's, or
/// `theta_max` (the domain's edge) where a corner has no ray.
fn shown_angles(
    unproject: impl Fn(DVec2) -> Option<glam::DVec3>,
    size: ImageSize,
    theta_max: f64,
) -> Vec<f64> {
    let (w, h) = (f64::from(size.width), f64::from(size.height));
    let corners: Option<Vec<f64>> = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)]
        .into_iter()
        .map(|(x, y)| unproject(DVec2::new(x, y)).map(|d| d.z.clamp(-1.0, 1.0).acos()))
        .collect();
    let end = corners.map_or(theta_max, |c| {
        c.into_iter().fold(0.0, f64::max).min(theta_max)
    });
    (1..=512).map(|k| end * f64::from(k) / 512.0).collect()
}

/// Fits each classic mapping's focal length to the lens's radial profile over
/// [`fitted_angles`] by least squares (`r = f·g(θ)` is linear in f), in pixels (the mean of
/// fx and fy times the model radius). Orthographic is left out where the angles pass 90°,
/// beyond which it has no image. Best fit first.
pub fn fit_classic(lens: &CalibratedLens, size: ImageSize) -> Vec<ClassicFit> {
    let i = lens.intrinsics();
    let scale = 0.5 * (i.fx + i.fy);
    let samples: Vec<(f64, f64)> = fitted_angles(lens, size)
        .into_iter()
        .filter_map(|t| Some((t, scale * lens.radius(t)?)))
        .collect();
    let widest = samples.last().map_or(0.0, |s| s.0);
    let mut fits: Vec<ClassicFit> = CLASSIC
        .iter()
        .filter(|(model, _)| *model != LensModel::Orthographic || widest <= FRAC_PI_2)
        .map(|&(model, g)| {
            let (num, den) = samples.iter().fold((0.0, 0.0), |(n, d), &(t, r)| {
                (n + r * g(t), d + g(t) * g(t))
            });
            let f = num / den;
            let residuals = samples.iter().map(|&(t, r)| (f * g(t) - r).abs());
            let (sum2, max) = residuals.fold((0.0, 0.0f64), |(s, m), e| (s + e * e, m.max(e)));
            ClassicFit {
                model,
                f_pixels: f,
                rms: (sum2 / samples.len() as f64).sqrt(),
                max,
            }
        })
        .collect();
    fits.sort_by(|a, b| a.rms.total_cmp(&b.rms));
    fits
}

/// A classic lens as a calibrated model, which calibration files can hold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Equivalent {
    /// The calibrated lens, with the classic lens's field of view.
    pub lens: CalibratedLens,
    /// Whether it is the same mapping (to rounding), not a fit.
    pub exact: bool,
    /// The largest radial difference over the angles the image shows, pixels: rounding for
    /// an exact equivalent.
    pub residual_px: f64,
}

/// The calibrated equivalent of a classic lens seen at `camera.size`, principal point at the
/// image's centre and square pixels (a classic lens's radius is in half image widths, so its
/// focal length in pixels is `f W/2`):
/// - equidistant `f θ` is Kannala–Brandt with k1..k4 = 0;
/// - stereographic `2f tan(θ/2)` is the unified model with α = 1/2 (Mei's ξ = 1);
/// - orthographic `f sin θ` is the unified model with α = 1;
/// - equisolid `2f sin(θ/2)` is the double sphere with ξ = 1, α = 1 (the second sphere's
///   distance is 2 cos(θ/2), so r = f sin θ / (2 cos(θ/2)) = f sin(θ/2) with f = 2f_px), up
///   to the 135° where the double sphere's domain ends; wider, it is fitted;
/// - rectilinear `f tan θ` is radial-tangential with no distortion;
/// - the general model's tan and sin families at rate 1 or 1/2 reduce to these; any other
///   rate is fitted: Kannala–Brandt's `θ(1 + k1θ² + … + k4θ⁸)` by linear least squares over
///   the angles the image shows, its focal length the mapping's slope at the axis.
pub fn calibrated_equivalent(camera: &LensCamera) -> Result<Equivalent, LensError> {
    let super::model::Lens::Classic(classic) = camera.lens else {
        return Err(LensError::Spec {
            spec: camera.lens.to_string(),
            reason: "a calibrated lens has no other equivalent here".into(),
        });
    };
    let (family, k1, rate) = classic.model().general_form();
    let (w, h) = (f64::from(camera.size.width), f64::from(camera.size.height));
    // The mapping's radius in pixels is `scale · g(rate θ)`.
    let scale = classic.focal_length() / k1 * w / 2.0;
    let intrinsics = |f: f64| Intrinsics {
        fx: f,
        fy: f,
        cx: w / 2.0,
        cy: h / 2.0,
    };
    let exact = match family {
        Family::Linear => Some((CalibratedModel::KannalaBrandt { k: [0.0; 4] }, scale)),
        Family::Tan if rate == 1.0 => Some((
            CalibratedModel::RadTan {
                k: [0.0; 3],
                p: [0.0; 2],
            },
            scale,
        )),
        Family::Tan if rate == 0.5 => Some((CalibratedModel::Unified { alpha: 0.5 }, scale / 2.0)),
        Family::Sin if rate == 1.0 => Some((CalibratedModel::Unified { alpha: 1.0 }, scale)),
        Family::Sin if rate == 0.5 => Some((
            CalibratedModel::DoubleSphere {
                xi: 1.0,
                alpha: 1.0,
            },
            scale,
        )),
        _ => None,
    };
    let angles = shown_angles(|p| camera.unproject(p), camera.size, classic.theta_max());
    let radius = |t: f64| classic.radius(t).map(|r| r * w / 2.0);
    // The slope at the axis, d/dθ of scale·g(rate θ), is the fit's focal length.
    let fitted = || {
        let f = scale * rate;
        let k = fit_kb(&angles, |t| radius(t).map(|r| r / f));
        (CalibratedModel::KannalaBrandt { k }, f, false)
    };
    // The exact model first; a fit where there is none, or where the exact model's own domain
    // ends before the angles the image shows (the double sphere with ξ = α = 1 stops at
    // 135°, short of an equisolid lens's 180°).
    let candidates = exact
        .map(|(model, f)| (model, f, true))
        .into_iter()
        .chain(std::iter::once_with(fitted));
    let mut short = None;
    for (model, f, exact) in candidates {
        // The classic lens's field of view where it sets one inside the model's own domain
        // (at the domain's edge the model's own end is the same field).
        let whole = CalibratedLens::new(model, intrinsics(f))?;
        let lens = match classic.max_fov() {
            Some(fov) if fov / 2.0 < whole.theta_max() => {
                CalibratedLens::with_fov(model, intrinsics(f), fov)?
            }
            _ => whole,
        };
        match residual(&angles, radius, &lens, f) {
            Ok(residual_px) => {
                return Ok(Equivalent {
                    lens,
                    exact,
                    residual_px,
                });
            }
            Err(t) => short = Some((model.name(), t)),
        }
    }
    let (name, t) = short.expect("a candidate was tried");
    Err(LensError::Spec {
        spec: camera.lens.to_string(),
        reason: format!(
            "its {name} equivalent does not reach {:.1}°, which the image shows",
            t.to_degrees()
        ),
    })
}

/// The largest radial difference between `radius` (pixels) and `lens` (focal length `f`) over
/// `angles`, or the first angle `lens` does not reach.
fn residual(
    angles: &[f64],
    radius: impl Fn(f64) -> Option<f64>,
    lens: &CalibratedLens,
    f: f64,
) -> Result<f64, f64> {
    let mut worst = 0.0f64;
    for &t in angles {
        // At the domain's edge the two may differ by rounding in θ (the unified model with
        // α = 1 stops just short of 90°, where its projection divides by zero).
        let edge = if t > lens.theta_max() && t <= lens.theta_max() + 1e-6 {
            lens.theta_max()
        } else {
            t
        };
        let (Some(want), Some(got)) = (radius(t), lens.radius(edge)) else {
            return Err(t);
        };
        worst = worst.max((want - got * f).abs());
    }
    Ok(worst)
}

/// Kannala–Brandt's k1..k4 for `θd(θ)` (the radius over the focal length) by least squares:
/// `θd/θ - 1 = k1θ² + k2θ⁴ + k3θ⁶ + k4θ⁸` is linear in the k's (normal equations, solved by
/// Gauss–Jordan elimination with partial pivoting).
pub(crate) fn fit_kb(angles: &[f64], theta_d: impl Fn(f64) -> Option<f64>) -> [f64; 4] {
    let mut a = [[0.0f64; 5]; 4];
    for &t in angles {
        let Some(d) = theta_d(t) else { continue };
        let x = [1, 2, 3, 4].map(|p| t.powi(2 * p));
        for (i, row) in a.iter_mut().enumerate() {
            for (j, xj) in x.iter().enumerate() {
                row[j] += x[i] * xj;
            }
            row[4] += x[i] * (d / t - 1.0);
        }
    }
    for col in 0..4 {
        let pivot = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .expect("four rows");
        a.swap(col, pivot);
        let lead = a[col];
        if lead[col] == 0.0 {
            continue;
        }
        for (r, row) in a.iter_mut().enumerate() {
            if r != col {
                let factor = row[col] / lead[col];
                for k in col..5 {
                    row[k] -= factor * lead[k];
                }
            }
        }
    }
    [0, 1, 2, 3].map(|i| {
        if a[i][i] == 0.0 {
            0.0
        } else {
            a[i][4] / a[i][i]
        }
    })
}

//! How close a calibrated lens is to the classic mappings: the thesis claims most real lenses
//! are close to one of equidistant, equisolid, orthographic and stereographic. We fit each
//! one's focal length to the lens's radial profile and report the residual in pixels.

use std::f64::consts::FRAC_PI_2;

use glam::DVec2;

use super::calibrated::CalibratedLens;
use super::camera::ImageSize;
use super::model::LensModel;

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
    let (w, h) = (f64::from(size.width), f64::from(size.height));
    let widest = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)]
        .into_iter()
        .filter_map(|(x, y)| lens.unproject(DVec2::new(x, y)))
        .map(|d| d.z.clamp(-1.0, 1.0).acos())
        .fold(0.0f64, f64::max);
    let end = if widest > 0.0 {
        widest.min(lens.theta_max())
    } else {
        lens.theta_max()
    };
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

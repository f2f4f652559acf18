//! A lens prescription on a camera: the spec
//! `prescription:FILE[,sensor=MM][,fstop=N][,focus=METRES][,rays=glass|fit][,model=kb|ds|equidistant]`
//! and the figures `fisheye lens info` prints for it (see [`super::prescription`] for the
//! glass).
//!
//! `sensor` is the image's width on the film in millimetres (pixels are square); by default
//! the image circle's diameter, so that the circle spans the image's width. `fstop` stops the
//! aperture down to that f-number (not below the lens's own). `focus` is the distance in
//! metres from the front vertex to the plane in focus, where the film sits at the paraxial
//! image of its axial point; by default infinity (the film at the back focal length).
//!
//! `rays` says how direct tracing renders the colour: `glass` (the default) traces every
//! sample through the surfaces from its place on the film ([`super::glass_gpu`]: vignetting,
//! depth of field), `fit` through the chief rays' fitted model, a mapping like any other lens
//! (cheaper; what cube maps use either way). Projection, unprojection and the ground-truth
//! arrays follow the fitted model: the chief rays, fitted as `model` says (Kannala–Brandt by
//! default, the double sphere, or equidistant).

use std::path::Path;

use super::calibrated::{CalibratedLens, CalibratedModel, Intrinsics};
use super::camera::{ImageSize, LensCamera};
use super::glass_gpu::GlassParams;
use super::prescription::Prescription;
use super::spec::parse_spec;
use crate::error::LensError;

/// What a prescription spec starts with.
pub const PREFIX: &str = "prescription:";

/// A prescription with its sensor and stop, as a spec names them.
#[derive(Clone, Debug, PartialEq)]
pub struct GlassLens {
    /// The prescription, stopped down where the spec says.
    pub prescription: Prescription,
    /// The image's width on the film, mm.
    pub sensor_mm: f64,
    /// The film's distance behind the rear vertex, mm: the back focal length (focus at
    /// infinity) unless the spec's `focus` says otherwise.
    pub film_mm: f64,
    /// Half the field of view any ray gets through, radians
    /// ([`Prescription::half_field`], found once: it traces thousands of rays).
    pub half_field: f64,
    /// Whether direct tracing renders through the glass (`rays=glass`, the default) or
    /// through the fitted model (`rays=fit`).
    pub through_glass: bool,
    /// The calibrated model the chief rays are fitted as (`model=`; Kannala–Brandt by
    /// default).
    pub model: FitModel,
}

/// The calibrated models a prescription's chief rays are fitted as: `model=kb|ds|equidistant`
/// in the spec.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitModel {
    /// Kannala–Brandt's `θ(1 + k1θ² + … + k4θ⁸)`, its focal length the mapping's slope at
    /// the axis.
    KannalaBrandt,
    /// Usenko et al.'s double sphere (ξ, α and the focal length by least squares).
    DoubleSphere,
    /// `f θ` (Kannala–Brandt without distortion; f by least squares).
    Equidistant,
}

impl FitModel {
    /// Every model with its spec name.
    pub const ALL: [(&'static str, FitModel); 3] = [
        ("kb", Self::KannalaBrandt),
        ("ds", Self::DoubleSphere),
        ("equidistant", Self::Equidistant),
    ];
}

/// A prescription's chief-ray mapping fitted as a Kannala–Brandt model at an image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fitted {
    /// The camera: Kannala–Brandt, principal point at the image's centre, square pixels, its
    /// field the prescription's.
    pub camera: LensCamera,
    /// The largest radial difference from the traced chief rays over the fitted field,
    /// pixels.
    pub residual_px: f64,
}

impl Fitted {
    /// The full field of view the fitted camera shows, radians: the lens's, or less where the
    /// fitted polynomial turns back before its edge.
    pub fn fov(&self) -> f64 {
        2.0 * self.camera.lens.theta_max()
    }
}

/// The camera of `spec` at `size`: a prescription's fitted chief-ray mapping
/// ([`GlassLens::fitted`]) with its glass unless the spec says `rays=fit`, any other spec's
/// lens ([`parse_spec`]).
pub fn camera_for(spec: &str, size: ImageSize) -> Result<LensCamera, LensError> {
    if GlassLens::is_spec(spec) {
        let glass = GlassLens::parse(spec)?;
        let camera = glass.fitted(size)?.camera;
        if !glass.through_glass {
            return Ok(camera);
        }
        let glass = GlassParams::new(
            &glass.prescription,
            glass.film_mm,
            glass.sensor_mm,
            (size.width, size.height),
        )?;
        Ok(camera.with_glass(glass))
    } else {
        Ok(LensCamera::new(parse_spec(spec)?, size))
    }
}

/// A lens's figures, as `fisheye lens info` prints them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// Effective focal length, mm (paraxial).
    pub efl_mm: f64,
    /// Back focal length from the rear vertex, mm (paraxial).
    pub bfl_mm: f64,
    /// Focal length over the entrance pupil's diameter.
    pub f_number: f64,
    /// The entrance pupil's radius, mm.
    pub pupil_radius_mm: f64,
    /// The entrance pupil's axial place behind the front vertex, mm (paraxial).
    pub pupil_position_mm: f64,
    /// The full field of view any ray gets through, degrees.
    pub fov_deg: f64,
    /// The image circle's diameter on the film, mm: twice the farthest a chief ray lands from
    /// the axis, out to the edge of the field.
    pub image_circle_mm: f64,
}

impl GlassLens {
    /// Whether `spec` names a prescription.
    pub fn is_spec(spec: &str) -> bool {
        spec.trim_start().starts_with(PREFIX)
    }

    /// Reads `prescription:FILE[,sensor=MM][,fstop=N][,focus=METRES][,rays=glass|fit]
    /// [,model=kb|ds|equidistant]`, loading FILE.
    pub fn parse(spec: &str) -> Result<Self, LensError> {
        let err = |reason: String| LensError::Spec {
            spec: spec.to_string(),
            reason,
        };
        let rest = spec
            .trim()
            .strip_prefix(PREFIX)
            .ok_or_else(|| err(format!("a prescription spec starts {PREFIX:?}")))?;
        let mut parts = rest.split(',');
        let file = parts.next().unwrap_or("").trim();
        if file.is_empty() {
            return Err(err("give the prescription's file: prescription:FILE".into()));
        }
        let (mut sensor, mut fstop, mut focus, mut rays, mut model) =
            (None, None, None, None, None);
        for pair in parts.map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| err(format!("{pair:?} is not key=value")))?;
            if key.trim() == "model" {
                let found = FitModel::ALL
                    .iter()
                    .find(|(name, _)| *name == value.trim())
                    .ok_or_else(|| err(format!("model = {value:?}: say kb, ds or equidistant")))?;
                if model.replace(found.1).is_some() {
                    return Err(err("model is given twice".into()));
                }
                continue;
            }
            if key.trim() == "rays" {
                let through = match value.trim() {
                    "glass" => true,
                    "fit" => false,
                    other => return Err(err(format!("rays = {other:?}: say glass or fit"))),
                };
                if rays.replace(through).is_some() {
                    return Err(err("rays is given twice".into()));
                }
                continue;
            }
            let number: f64 = value
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && *v > 0.0)
                .ok_or_else(|| err(format!("{key} = {value:?}: give a number above 0")))?;
            let slot = match key.trim() {
                "sensor" => &mut sensor,
                "fstop" => &mut fstop,
                "focus" => &mut focus,
                other => {
                    return Err(err(format!(
                        "unknown key {other:?}; a prescription takes sensor=MM, fstop=N, \
                         focus=METRES, rays=glass|fit and model=kb|ds|equidistant"
                    )));
                }
            };
            if slot.replace(number).is_some() {
                return Err(err(format!("{} is given twice", key.trim())));
            }
        }
        let mut prescription = Prescription::load(Path::new(file))?;
        if let Some(wanted) = fstop {
            let own = prescription.f_number();
            if wanted < own * (1.0 - 1e-9) {
                return Err(err(format!(
                    "fstop = {wanted}: the lens opens to f/{own:.3} at most"
                )));
            }
            prescription = prescription.with_stop_scaled(own / wanted);
        }
        let film_mm = match focus {
            None => prescription.bfl(),
            Some(metres) => prescription.focus_distance(metres * 1e3).ok_or_else(|| {
                err(format!(
                    "focus = {metres} m: too close for this lens to focus (its image is \
                     virtual)"
                ))
            })?,
        };
        let half_field = prescription.half_field();
        let sensor_mm = match sensor {
            Some(mm) => mm,
            None => image_circle(&prescription, film_mm, half_field).ok_or_else(|| {
                err(
                    "no chief ray reaches the film, so the image circle, the default sensor \
                     width, is unknown: give sensor=MM"
                        .into(),
                )
            })?,
        };
        Ok(Self {
            prescription,
            sensor_mm,
            film_mm,
            half_field,
            through_glass: rays.unwrap_or(true),
            model: model.unwrap_or(FitModel::KannalaBrandt),
        })
    }

    /// The chief-ray mapping at `size` as the spec's model ([`FitModel`]: Kannala–Brandt's
    /// `θ(1 + k1θ² + … + k4θ⁸)` by default), fitted by least squares to the traced chief rays
    /// at 512 angles out to the edge of the field (or of the chief rays, where they end
    /// first); Kannala–Brandt's focal length is the mapping's slope at the axis (the paraxial
    /// one where the film is at the focus for infinity), the others' is fitted: where the
    /// chief ray of a direction lands on the film, read out upright.
    pub fn fitted(&self, size: ImageSize) -> Result<Fitted, LensError> {
        let p = &self.prescription;
        let pitch = self.sensor_mm / f64::from(size.width);
        let edge = self.half_field;
        // The mapping's slope at the axis, from a chief ray 1e-5 rad off it (r = f tan θ
        // there to 1e-10).
        let tiny = 1e-5;
        let slope = p
            .image_height(tiny, self.film_mm)
            .map(|r| r / tiny.tan())
            .ok_or_else(|| LensError::Spec {
                spec: "prescription".into(),
                reason: "no chief ray near the axis reaches the film".into(),
            })?;
        let angles: Vec<f64> = (1..=512).map(|k| edge * f64::from(k) / 512.0).collect();
        let traced: Vec<(f64, f64)> = angles
            .iter()
            .zip(p.image_heights(&angles, self.film_mm))
            .map_while(|(&t, r)| Some((t, r?)))
            .collect();
        let Some(&(widest, _)) = traced.last() else {
            return Err(LensError::Spec {
                spec: "prescription".into(),
                reason: "no chief ray reaches the film".into(),
            });
        };
        let (model, f_mm) = match self.model {
            FitModel::KannalaBrandt => {
                let used: Vec<f64> = traced.iter().map(|s| s.0).collect();
                let k = super::fit::fit_kb(&used, |t| {
                    traced.iter().find(|s| s.0 == t).map(|s| s.1 / slope)
                });
                (CalibratedModel::KannalaBrandt { k }, slope)
            }
            FitModel::Equidistant => {
                let (num, den) = traced
                    .iter()
                    .fold((0.0, 0.0), |(n, d), &(t, r)| (n + r * t, d + t * t));
                (CalibratedModel::KannalaBrandt { k: [0.0; 4] }, num / den)
            }
            FitModel::DoubleSphere => {
                let (xi, alpha, f) = fit_double_sphere(&traced).ok_or_else(|| LensError::Spec {
                    spec: "prescription".into(),
                    reason: "no double sphere holds the chief rays' field".into(),
                })?;
                (CalibratedModel::DoubleSphere { xi, alpha }, f)
            }
        };
        let f = f_mm / pitch;
        let intrinsics = Intrinsics {
            fx: f,
            fy: f,
            cx: f64::from(size.width) / 2.0,
            cy: f64::from(size.height) / 2.0,
        };
        // The lens's field, or less where the fitted model turns back or ends first.
        let whole = CalibratedLens::new(model, intrinsics)?;
        let lens = if widest < whole.theta_max() {
            CalibratedLens::with_fov(model, intrinsics, 2.0 * widest)?
        } else {
            whole
        };
        let mut residual_px = 0.0f64;
        for &(t, r) in traced.iter().filter(|s| s.0 <= lens.theta_max()) {
            let fitted = lens.radius(t).unwrap_or(f64::INFINITY);
            residual_px = residual_px.max((r / pitch - fitted * f).abs());
        }
        Ok(Fitted {
            camera: LensCamera::new(lens, size),
            residual_px,
        })
    }

    /// The lens's figures.
    pub fn figures(&self) -> Figures {
        let p = &self.prescription;
        let (pupil_radius_mm, pupil_position_mm) = p.entrance_pupil();
        Figures {
            efl_mm: p.efl(),
            bfl_mm: p.bfl(),
            f_number: p.f_number(),
            pupil_radius_mm,
            pupil_position_mm,
            fov_deg: 2.0 * self.half_field.to_degrees(),
            image_circle_mm: image_circle(p, self.film_mm, self.half_field).unwrap_or(f64::NAN),
        }
    }
}

/// The image circle's diameter, mm: twice the farthest the chief ray lands from the axis on
/// a film `film` mm behind the rear vertex, over 256 angles out to `edge` (half the field any
/// ray gets through; a chief ray may fail before that edge, reflected inside the glass, where
/// rays off the stop's centre still pass).
fn image_circle(p: &Prescription, film: f64, edge: f64) -> Option<f64> {
    let angles: Vec<f64> = (1..=256).map(|k| edge * f64::from(k) / 256.0).collect();
    p.image_heights(&angles, film)
        .into_iter()
        .flatten()
        .map(f64::abs)
        .reduce(f64::max)
        .map(|r| 2.0 * r)
}

/// The double sphere (ξ, α, f in mm) whose radius `f·sin θ / (α d + (1 − α)(ξ + cos θ))`,
/// `d = √(sin²θ + (ξ + cos θ)²)` (Usenko, Demmel and Cremers, 3DV 2018), fits `traced`'s
/// `(θ, r)` best in least squares: f is linear given (ξ, α), which a grid over their whole
/// ranges (0.05 and 0.025 apart) finds, then three finer grids about the best refine (to about
/// 1e-4). `None` where no (ξ, α) reaches every angle.
fn fit_double_sphere(traced: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    // The squared residual with the best f, and that f.
    let cost = |xi: f64, alpha: f64| -> Option<(f64, f64)> {
        let unit = Intrinsics {
            fx: 1.0,
            fy: 1.0,
            cx: 0.0,
            cy: 0.0,
        };
        let lens = CalibratedLens::new(CalibratedModel::DoubleSphere { xi, alpha }, unit).ok()?;
        let (mut rg, mut gg, mut rr) = (0.0, 0.0, 0.0);
        for &(t, r) in traced {
            let g = lens.radius(t)?;
            (rg, gg, rr) = (rg + r * g, gg + g * g, rr + r * r);
        }
        Some((rr - rg * rg / gg, rg / gg))
    };
    let mut best: Option<(f64, f64, f64, f64)> = None;
    let (mut centre, mut step, mut steps) = ((0.0, 0.5), (0.05, 0.025), 20);
    for _ in 0..4 {
        for i in -steps..=steps {
            for j in -steps..=steps {
                let xi = (centre.0 + f64::from(i) * step.0).clamp(-1.0, 1.0);
                let alpha = (centre.1 + f64::from(j) * step.1).clamp(0.0, 1.0);
                if let Some((c, f)) = cost(xi, alpha)
                    && best.is_none_or(|b| c < b.0)
                {
                    best = Some((c, xi, alpha, f));
                }
            }
        }
        let (_, xi, alpha, _) = best?;
        (centre, step, steps) = ((xi, alpha), (step.0 / 10.0, step.1 / 10.0), 10);
    }
    best.map(|(_, xi, alpha, f)| (xi, alpha, f))
}

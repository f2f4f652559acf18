//! Radial lens mappings `r(θ)` and their inverses, in f64: the reference every GPU path is
//! tested against.
//!
//! `θ` is the angle between a ray and the optical axis; `r` is the distance of its image from
//! the image centre in normalized units (see [`crate::lens::LensCamera`]: the image half-width
//! is 1). The classic mappings follow the fisheye literature (e.g. Bettonvil 2005, *Fisheye
//! lenses*, WGN 33:1, and the 2023 thesis this project starts from):
//!
//! | model          | r(θ)                      | domain of θ                  |
//! |----------------|---------------------------|------------------------------|
//! | rectilinear    | f tan θ                   | [0, π/2) (pole at π/2)       |
//! | stereographic  | 2f tan(θ/2)               | [0, π) (pole at π)           |
//! | equidistant    | f θ                       | [0, 2π] (past 180°, to 360°) |
//! | equisolid      | 2f sin(θ/2)               | [0, π] (r ≤ 2f)              |
//! | orthographic   | f sin θ                   | [0, π/2] (r ≤ f)             |
//! | general, k2>0  | (f/k1) tan(k2 θ)          | [0, π/(2k2)) ∩ [0, 2π]       |
//! | general, k2=0  | f θ                       | [0, 2π]                      |
//! | general, k2<0  | (f/k1) sin(\|k2\| θ)      | [0, π/(2\|k2\|)] ∩ [0, 2π]   |
//!
//! The general form reproduces the others: rectilinear is (k1, k2) = (1, 1), stereographic
//! (1/2, 1/2), equisolid (1/2, -1/2), orthographic (1, -1). For `k2 < 0` the published form is
//! written `sin(k2 θ)`; we take the rate as `|k2|` so that `r ≥ 0` (the sign of k2 only selects
//! the sine family).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::calibrated::CalibratedLens;
use crate::error::LensError;

/// A radial mapping family. Parameters other than the focal length live here.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LensModel {
    /// Pinhole: `r = f tan θ`.
    Rectilinear,
    /// `r = 2f tan(θ/2)`: conformal, keeps small shapes round.
    Stereographic,
    /// `r = f θ`: the "f-theta" lens; valid past 180° up to 360°.
    Equidistant,
    /// `r = 2f sin(θ/2)`: equal-area.
    Equisolid,
    /// `r = f sin θ`: a hemisphere at most.
    Orthographic,
    /// `r = (f/k1) tan(k2 θ)` for `0 < k2 ≤ 1`, `r = f θ` for `k2 = 0`,
    /// `r = (f/k1) sin(|k2| θ)` for `-1 ≤ k2 < 0`.
    General {
        /// Scale of the tan/sin term, `k1 > 0`.
        k1: f64,
        /// Rate and family selector, `-1 ≤ k2 ≤ 1`.
        k2: f64,
    },
}

/// The branch of the general form a parameter set selects; also how the classic models
/// reduce to it (used by the WGSL twin, which implements the three branches once).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Family {
    Tan,
    Linear,
    Sin,
}

impl LensModel {
    /// Every model name `LensModel::parse_name` accepts, in the order `fisheye lens list` prints.
    pub const NAMES: [&'static str; 6] = [
        "rectilinear",
        "stereographic",
        "equidistant",
        "equisolid",
        "orthographic",
        "general",
    ];

    /// The model's name as used in lens specs.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Rectilinear => "rectilinear",
            Self::Stereographic => "stereographic",
            Self::Equidistant => "equidistant",
            Self::Equisolid => "equisolid",
            Self::Orthographic => "orthographic",
            Self::General { .. } => "general",
        }
    }

    /// The mapping formula, for listings.
    pub fn formula(&self) -> &'static str {
        match self {
            Self::Rectilinear => "r = f tan(θ)",
            Self::Stereographic => "r = 2f tan(θ/2)",
            Self::Equidistant => "r = f θ",
            Self::Equisolid => "r = 2f sin(θ/2)",
            Self::Orthographic => "r = f sin(θ)",
            Self::General { .. } => "r = (f/k1) tan(k2 θ) | f θ (k2=0) | (f/k1) sin(|k2| θ)",
        }
    }

    /// The general-form parameters `(family, k1, rate)` with `r = (f/k1)·g(rate·θ)`; for the
    /// linear family `r = f θ` and k1, rate are 1.
    pub(crate) fn general_form(&self) -> (Family, f64, f64) {
        match *self {
            Self::Rectilinear => (Family::Tan, 1.0, 1.0),
            Self::Stereographic => (Family::Tan, 0.5, 0.5),
            Self::Equidistant => (Family::Linear, 1.0, 1.0),
            Self::Equisolid => (Family::Sin, 0.5, 0.5),
            Self::Orthographic => (Family::Sin, 1.0, 1.0),
            Self::General { k1, k2 } if k2 > 0.0 => (Family::Tan, k1, k2),
            Self::General { k1, k2 } if k2 < 0.0 => (Family::Sin, k1, -k2),
            Self::General { .. } => (Family::Linear, 1.0, 1.0),
        }
    }
}

/// A lens: a mapping family, its focal length in normalized units, and an optional maximum
/// field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassicLens {
    model: LensModel,
    f: f64,
    max_fov: Option<f64>,
}

/// Where a model's θ domain ends.
#[derive(Clone, Copy, Debug, PartialEq)]
enum DomainEnd {
    /// θ may reach this value (r stays finite there).
    Closed(f64),
    /// θ stays below this value (r grows without bound towards it).
    Pole(f64),
}

impl ClassicLens {
    /// A lens with focal length `f` (normalized units: the image half-width is 1).
    ///
    /// Errors if `f` is not finite and positive or the model's parameters are out of range.
    pub fn new(model: LensModel, f: f64) -> Result<Self, LensError> {
        if !(f.is_finite() && f > 0.0) {
            return Err(LensError::parameter("f", f, "must be finite and > 0"));
        }
        if let LensModel::General { k1, k2 } = model {
            if !(k1.is_finite() && k1 > 0.0) {
                return Err(LensError::parameter("k1", k1, "must be finite and > 0"));
            }
            if !(k2.is_finite() && (-1.0..=1.0).contains(&k2)) {
                return Err(LensError::parameter("k2", k2, "must be in [-1, 1]"));
            }
        }
        Ok(Self {
            model,
            f,
            max_fov: None,
        })
    }

    /// Limits the full field of view to `fov` radians (a cone of half-angle `fov/2`).
    ///
    /// Errors if `fov` is not in (0, 2π], or is wider than the model reaches: a rectilinear
    /// lens's pole at 90° off axis, where `r` grows without bound, or the end of a sine
    /// family's increasing part (90° for orthographic).
    pub fn with_max_fov(mut self, fov: f64) -> Result<Self, LensError> {
        if !(fov.is_finite() && fov > 0.0 && fov <= TAU * (1.0 + 1e-12)) {
            return Err(LensError::parameter(
                "fov",
                fov.to_degrees(),
                "must be in (0, 360] degrees",
            ));
        }
        let half = (fov / 2.0).min(PI);
        let (end, why) = match self.domain_end() {
            DomainEnd::Pole(p) => (p, (half >= p).then_some("r grows without bound")),
            DomainEnd::Closed(t) => (
                t,
                (half > t * (1.0 + 1e-12)).then_some("its mapping stops increasing"),
            ),
        };
        if let Some(why) = why {
            return Err(LensError::Unreachable {
                model: self.model.name(),
                fov: fov.to_degrees(),
                reach: 2.0 * end.to_degrees(),
                why,
            });
        }
        self.max_fov = Some(fov.min(TAU));
        Ok(self)
    }

    /// The mapping family.
    pub fn model(&self) -> LensModel {
        self.model
    }

    /// Focal length in normalized units.
    pub fn focal_length(&self) -> f64 {
        self.f
    }

    /// The maximum full field of view set on the lens, in radians, if any.
    pub fn max_fov(&self) -> Option<f64> {
        self.max_fov
    }

    fn domain_end(&self) -> DomainEnd {
        let (family, _, rate) = self.model.general_form();
        let end = match family {
            Family::Tan => DomainEnd::Pole(FRAC_PI_2 / rate),
            Family::Linear => DomainEnd::Closed(PI),
            Family::Sin => DomainEnd::Closed(FRAC_PI_2 / rate),
        };
        // θ = π looks straight back: every family stops there, having covered the whole
        // sphere once (past it, a linear mapping would show the sphere a second time).
        match end {
            DomainEnd::Pole(t) | DomainEnd::Closed(t) if t > PI => DomainEnd::Closed(PI),
            e => e,
        }
    }

    /// The largest θ a ray of this lens may have: the model's domain and the field-of-view
    /// limit, whichever is smaller. For a model with a pole and no smaller limit this is the
    /// pole itself, which no ray reaches.
    pub fn theta_max(&self) -> f64 {
        let end = match self.domain_end() {
            DomainEnd::Closed(t) | DomainEnd::Pole(t) => t,
        };
        self.max_fov.map_or(end, |fov| end.min(fov / 2.0))
    }

    /// The image radius of the domain edge: pixels with `r > r_max` have no ray.
    /// Infinite when the mapping has a pole that no field-of-view limit stops short of.
    pub fn r_max(&self) -> f64 {
        let theta = self.theta_max();
        match self.domain_end() {
            DomainEnd::Pole(p) if theta >= p => f64::INFINITY,
            _ => self.radius_unchecked(theta),
        }
    }

    fn radius_unchecked(&self, theta: f64) -> f64 {
        let (family, k1, rate) = self.model.general_form();
        match family {
            Family::Tan => self.f / k1 * (rate * theta).tan(),
            Family::Linear => self.f * theta,
            Family::Sin => self.f / k1 * (rate * theta).sin(),
        }
    }

    /// Forward map θ → r; `None` outside `[0, theta_max]` (or at a pole).
    pub fn radius(&self, theta: f64) -> Option<f64> {
        let inside = match self.domain_end() {
            DomainEnd::Pole(p) => theta < p,
            DomainEnd::Closed(_) => true,
        };
        (theta >= 0.0 && theta <= self.theta_max() && inside).then(|| self.radius_unchecked(theta))
    }

    /// Inverse map r → θ; `None` when `r` is negative, not finite, or beyond `r_max`.
    pub fn theta(&self, r: f64) -> Option<f64> {
        if !(r >= 0.0 && r <= self.r_max() && r.is_finite()) {
            return None;
        }
        let (family, k1, rate) = self.model.general_form();
        let theta = match family {
            Family::Tan => (k1 * r / self.f).atan() / rate,
            Family::Linear => r / self.f,
            // r ≤ r_max keeps the argument in [0, 1] up to rounding.
            Family::Sin => (k1 * r / self.f).min(1.0).asin() / rate,
        };
        Some(theta.min(self.theta_max()))
    }

    /// The sensitivity of the inverse map, `κ(r) = r·dθ/dr`: the angle error (radians) caused by
    /// a relative error of 1 in `r` (or in `f`). Any f32 evaluation of `θ(r)` carries an error
    /// of about `κ·ε` from rounding `r` and `f` alone, whatever the formulas; tests use it to
    /// state their bound.
    pub fn theta_sensitivity(&self, r: f64) -> f64 {
        let (family, k1, rate) = self.model.general_form();
        let u = k1 * r / self.f;
        match family {
            Family::Tan => u / (1.0 + u * u) / rate,
            Family::Linear => r / self.f,
            Family::Sin => {
                let c2 = (1.0 - u * u).max(0.0);
                if c2 == 0.0 {
                    f64::INFINITY
                } else {
                    u / c2.sqrt() / rate
                }
            }
        }
    }
}

impl std::fmt::Display for ClassicLens {
    /// Writes the lens as a spec that [`crate::lens::parse_spec`] reads back.
    fn fmt(&self, out: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(out, "{}:f={}", self.model.name(), self.f)?;
        if let LensModel::General { k1, k2 } = self.model {
            write!(out, ",k1={k1},k2={k2}")?;
        }
        if let Some(fov) = self.max_fov {
            write!(out, ",fov={}", fov.to_degrees())?;
        }
        Ok(())
    }
}

/// Any lens: a classic radial mapping in normalized units, or a calibrated model with pixel
/// intrinsics ([`CalibratedLens`]). Both share the radial profile: `radius(θ)` and `theta(r)`
/// map the angle from the axis to the radius in the lens's own units (normalized
/// coordinates for classic lenses, model coordinates for calibrated ones).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lens {
    /// A classic mapping.
    Classic(ClassicLens),
    /// A calibrated camera model.
    Calibrated(CalibratedLens),
}

impl From<ClassicLens> for Lens {
    fn from(lens: ClassicLens) -> Self {
        Self::Classic(lens)
    }
}

impl From<CalibratedLens> for Lens {
    fn from(lens: CalibratedLens) -> Self {
        Self::Calibrated(lens)
    }
}

impl Lens {
    /// The classic lens, if this is one.
    pub fn classic(&self) -> Option<&ClassicLens> {
        match self {
            Self::Classic(lens) => Some(lens),
            Self::Calibrated(_) => None,
        }
    }

    /// The calibrated lens, if this is one.
    pub fn calibrated(&self) -> Option<&CalibratedLens> {
        match self {
            Self::Calibrated(lens) => Some(lens),
            Self::Classic(_) => None,
        }
    }

    /// The model's name as used in lens specs.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Classic(lens) => lens.model().name(),
            Self::Calibrated(lens) => lens.model().name(),
        }
    }

    /// The largest θ a ray may have.
    pub fn theta_max(&self) -> f64 {
        match self {
            Self::Classic(lens) => lens.theta_max(),
            Self::Calibrated(lens) => lens.theta_max(),
        }
    }

    /// The radius of the domain edge, in the lens's units.
    pub fn r_max(&self) -> f64 {
        match self {
            Self::Classic(lens) => lens.r_max(),
            Self::Calibrated(lens) => lens.r_max(),
        }
    }

    /// Forward map θ → r; `None` outside the domain.
    pub fn radius(&self, theta: f64) -> Option<f64> {
        match self {
            Self::Classic(lens) => lens.radius(theta),
            Self::Calibrated(lens) => lens.radius(theta),
        }
    }

    /// Inverse map r → θ; `None` outside the domain.
    pub fn theta(&self, r: f64) -> Option<f64> {
        match self {
            Self::Classic(lens) => lens.theta(r),
            Self::Calibrated(lens) => lens.theta(r),
        }
    }

    /// `κ(r) = r·dθ/dr` (see [`ClassicLens::theta_sensitivity`]).
    pub fn theta_sensitivity(&self, r: f64) -> f64 {
        match self {
            Self::Classic(lens) => lens.theta_sensitivity(r),
            Self::Calibrated(lens) => lens.theta_sensitivity(r),
        }
    }
}

impl std::fmt::Display for Lens {
    /// Writes the lens as a spec that [`crate::lens::parse_spec`] reads back.
    fn fmt(&self, out: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Classic(lens) => lens.fmt(out),
            Self::Calibrated(lens) => lens.fmt(out),
        }
    }
}

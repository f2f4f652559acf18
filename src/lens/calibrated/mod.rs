//! Calibrated camera models, in f64: the models robotics calibrates real cameras with, each with
//! its projection, unprojection and validity domain.
//!
//! A calibrated lens maps a pixel `p` to *model coordinates* `m = ((u - cx)/fx, (v - cy)/fy)`
//! (y down, as the camera's y), and `m` to a direction in camera space (x right, y down, z
//! forward). Pixel coordinates follow this project's convention (see [`super::LensCamera`]):
//! continuous, origin at the top-left corner of the top-left pixel. Calibration files use
//! OpenCV's, where the centre of the top-left pixel is (0, 0): `cx` here is the file's `cx + 0.5`
//! ([`super::calib`] converts both ways).
//!
//! Every model but radial-tangential is radially symmetric in `m`: a direction at angle θ from
//! the axis lands at radius `r = |m|`, and the model is the pair `r(θ)` (projection) and `θ(r)`
//! (unprojection). The formulas and their published validity domains:
//!
//! | model | r(θ) or θ(r) | domain |
//! |---|---|---|
//! | Kannala–Brandt (2006) | r = θ(1 + k1θ² + k2θ⁴ + k3θ⁶ + k4θ⁸) | θ ≤ π while r(θ) increases |
//! | double sphere (Usenko, Demmel, Cremers 2018) | r = sin θ / (α d₂ + (1-α)(ξ + cos θ)), d₂ = √(sin²θ + (ξ + cos θ)²) | z > -w₂ d₁; α > ½: r² ≤ 1/(2α-1) |
//! | unified, α form (Mei 2007; Usenko 2018) | r = sin θ / (α + (1-α) cos θ) | z > -w d; α > ½: r² ≤ 1/(2α-1) |
//! | extended unified (Khomutenko et al. 2016) | r = sin θ / (α √(β sin²θ + cos²θ) + (1-α) cos θ) | z > -w d; α > ½: r² ≤ 1/(β(2α-1)) |
//! | FOV (Devernay, Faugeras 2001) | r = atan2(2 tan(w/2) sin θ, cos θ) / w | r ≤ π/w |
//! | Scaramuzza (2006) | θ = atan2(ρ, -f(ρ)), f(ρ) = a0 + a1ρ + a2ρ² + a3ρ³ + a4ρ⁴ | θ ≤ fov/2 while θ(ρ) increases |
//! | f-theta | θ = k1 r + k2 r² + k3 r³ + k4 r⁴ + k5 r⁵ | θ ≤ fov/2 while θ(r) increases |
//! | radial-tangential (Brown–Conrady, OpenCV) | m = x(1 + k1ρ² + k2ρ⁴ + k3ρ⁶) + tangential(p1, p2), x = (X/Z, Y/Z) | Z > 0, ρ while ρ(1 + k1ρ² + …) increases |
//!
//! Here `w = α/(1-α)` for α ≤ ½, else `(1-α)/α`, and `w₂ = (w + ξ)/√(2wξ + ξ² + 1)` (Usenko et
//! al. 2018, table 1). The unified model's α form relates to Mei's ξ form by `α = ξ/(1+ξ)`,
//! `f_α = γ/(1+ξ)`. Scaramuzza's model has its own affine stretch: pixel offsets are
//! `[[c, d], [e, 1]]·m`; we use his toolbox's sign convention (a0 < 0) and take the ray as
//! `(m, -f(ρ))` in our camera frame. The toolbox itself indexes (row, column), so its `xc, yc`
//! are our `cy, cx`.
//!
//! Beyond the published conditions, each lens's domain ends where its mapping stops increasing
//! (a non-monotonic calibration folds the image over itself), at θ = π, and at a requested
//! field of view. A requested field of view the model cannot reach is an error; without one,
//! the domain is clipped where the mapping turns and [`CalibratedLens::turns_at`] says so.
//!
//! # Root finding, and its bound
//! Kannala–Brandt's unprojection, the projections of Scaramuzza and f-theta, and θ(r) of
//! radial-tangential solve `h(x) = 0` for the unique root in a bracket `[lo, hi]` with
//! `h(lo) ≤ 0 ≤ h(hi)` (the domain makes the mapping increasing, so the root is unique). The
//! iteration is Newton's, guarded. Each iteration evaluates `h` at the iterate and narrows the
//! bracket to the side holding the root; if that did not halve the bracket, it also evaluates
//! the bracket's midpoint and narrows again. So every iteration at least halves the bracket,
//! whatever `h` does, and after `k` iterations its width is at most `W₀/2ᵏ`. The next iterate
//! is the Newton step from whichever evaluated point has the smaller `|h|`, when it lands
//! strictly inside the bracket, else the midpoint. The iteration stops at a Newton step or a bracket of `tol`, so it takes at most
//! `⌈log₂(W₀/tol)⌉` iterations of one or two evaluations ([`newton_bound`]), and converges
//! quadratically where Newton does (3 to 7 iterations in practice: one-sided convergence
//! costs the midpoint evaluations but never the Newton iterate). The WGSL twin runs the same
//! iteration in f32 with //! `tol = W₀·2⁻²²`.

mod mapping;
mod solve;

use std::f64::consts::PI;

use glam::DVec2;

use solve::increasing_part;
pub use solve::{newton_bound, solve};

use crate::error::LensError;

/// Pinhole intrinsics in pixels, in this project's pixel convention (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels from the image's left edge.
    pub cx: f64,
    /// Principal point y, pixels from the image's top edge.
    pub cy: f64,
}

/// A calibrated model's distortion parameters (the intrinsics are separate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CalibratedModel {
    /// Kannala–Brandt: OpenCV's `cv::fisheye`, Kalibr's `pinhole-equi`, Basalt's `kb4`.
    KannalaBrandt {
        /// k1..k4.
        k: [f64; 4],
    },
    /// Double sphere.
    DoubleSphere {
        /// Offset of the second sphere, ξ ∈ [-1, 1].
        xi: f64,
        /// α ∈ [0, 1].
        alpha: f64,
    },
    /// Unified camera model, α form (α ∈ [0, 1]).
    Unified {
        /// α ∈ [0, 1].
        alpha: f64,
    },
    /// Extended unified camera model.
    ExtendedUnified {
        /// α ∈ [0, 1].
        alpha: f64,
        /// β > 0.
        beta: f64,
    },
    /// Devernay and Faugeras's field-of-view model.
    Fov {
        /// The field-of-view parameter w ∈ (0, π), radians.
        w: f64,
    },
    /// Scaramuzza's polynomial model (OCamCalib).
    Scaramuzza {
        /// a0..a4 of `f(ρ)` (a0 < 0).
        a: [f64; 5],
        /// The affine stretch `[[c, d], [e, 1]]`.
        c: f64,
        /// See `c`.
        d: f64,
        /// See `c`.
        e: f64,
    },
    /// θ as a polynomial of the pixel radius (f-theta).
    FTheta {
        /// k1..k5: θ = k1 r + … + k5 r⁵ (k1 > 0).
        k: [f64; 5],
    },
    /// OpenCV's pinhole radial-tangential (Brown–Conrady) model.
    RadTan {
        /// Radial k1, k2, k3.
        k: [f64; 3],
        /// Tangential p1, p2.
        p: [f64; 2],
    },
}

impl CalibratedModel {
    /// Every calibrated model's spec name, with the keys it takes besides the intrinsics.
    pub const NAMES: [(&'static str, &'static str); 8] = [
        ("kb", "k1, k2, k3, k4"),
        ("ds", "xi, alpha"),
        ("ucm", "alpha"),
        ("eucm", "alpha, beta"),
        ("fov-model", "w (radians)"),
        ("scaramuzza", "a0..a4, c, d, e (needs fov)"),
        ("ftheta", "k1..k5 (needs fov)"),
        ("radtan", "k1, k2, p1, p2, k3"),
    ];

    /// A realistic spec of each model, in [`Self::NAMES`] order: TUM-VI's cam0 Kannala–Brandt
    /// intrinsics (512×512); double-sphere, unified, extended unified and FOV parameters of
    /// the magnitudes Usenko et al. 2018 report for such lenses (ours, not fits of one
    /// camera); Scaramuzza and f-theta lenses of about 190° (polynomials of our own); and the
    /// EuRoC MAV dataset's cam0 radial-tangential intrinsics (752×480).
    pub const EXAMPLES: [&'static str; 8] = [
        "kb:fx=190.978,fy=190.973,cx=254.932,cy=256.897,k1=0.0034824,k2=0.00071503,k3=-0.0020532,k4=0.00020294",
        "ds:fx=158.28,fy=158.24,cx=254.9,cy=256.9,xi=-0.18,alpha=0.59",
        "ucm:fx=249.4,fy=249.3,cx=254.9,cy=256.9,alpha=0.63",
        "eucm:fx=252.6,fy=252.5,cx=254.9,cy=256.9,alpha=0.64,beta=1.09",
        "fov-model:fx=260,fy=259,cx=254.9,cy=256.9,w=0.93",
        "scaramuzza:cx=255.5,cy=256.5,a0=-160,a2=1.6e-3,a3=-1.6e-6,a4=3e-9,c=1.001,d=0.0005,e=-0.0004,fov=190",
        "ftheta:cx=255.5,cy=256.5,k1=0.0055,k2=4e-7,k3=3e-9,fov=195",
        "radtan:fx=458.654,fy=457.296,cx=367.215,cy=248.375,k1=-0.28340811,k2=0.07395907,p1=0.00019359,p2=1.76187114e-05",
    ];

    /// The image size each of [`Self::EXAMPLES`] is calibrated for (width, height).
    pub const EXAMPLE_SIZES: [(u32, u32); 8] = [
        (512, 512),
        (512, 512),
        (512, 512),
        (512, 512),
        (512, 512),
        (512, 512),
        (512, 512),
        (752, 480),
    ];

    /// The model's name in lens specs.
    pub fn name(&self) -> &'static str {
        match self {
            Self::KannalaBrandt { .. } => "kb",
            Self::DoubleSphere { .. } => "ds",
            Self::Unified { .. } => "ucm",
            Self::ExtendedUnified { .. } => "eucm",
            Self::Fov { .. } => "fov-model",
            Self::Scaramuzza { .. } => "scaramuzza",
            Self::FTheta { .. } => "ftheta",
            Self::RadTan { .. } => "radtan",
        }
    }

    /// The parameters as `(spec key, value)` pairs, in spec order.
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        match *self {
            Self::KannalaBrandt { k } => {
                vec![("k1", k[0]), ("k2", k[1]), ("k3", k[2]), ("k4", k[3])]
            }
            Self::DoubleSphere { xi, alpha } => vec![("xi", xi), ("alpha", alpha)],
            Self::Unified { alpha } => vec![("alpha", alpha)],
            Self::ExtendedUnified { alpha, beta } => vec![("alpha", alpha), ("beta", beta)],
            Self::Fov { w } => vec![("w", w)],
            Self::Scaramuzza { a, c, d, e } => vec![
                ("a0", a[0]),
                ("a1", a[1]),
                ("a2", a[2]),
                ("a3", a[3]),
                ("a4", a[4]),
                ("c", c),
                ("d", d),
                ("e", e),
            ],
            Self::FTheta { k } => vec![
                ("k1", k[0]),
                ("k2", k[1]),
                ("k3", k[2]),
                ("k4", k[3]),
                ("k5", k[4]),
            ],
            Self::RadTan { k, p } => vec![
                ("k1", k[0]),
                ("k2", k[1]),
                ("p1", p[0]),
                ("p2", p[1]),
                ("k3", k[2]),
            ],
        }
    }

    /// Whether the model's natural direction is θ(r) (its projection needs a root finder and
    /// a field of view to bound it).
    fn theta_of_r(&self) -> bool {
        matches!(self, Self::Scaramuzza { .. } | Self::FTheta { .. })
    }

    /// `w` of the unified models' domain condition `z > -w d`.
    fn unified_w(alpha: f64) -> f64 {
        if alpha <= 0.5 {
            alpha / (1.0 - alpha)
        } else {
            (1.0 - alpha) / alpha
        }
    }

    /// Checks the parameters' published ranges.
    fn validate(&self) -> Result<(), LensError> {
        let p = LensError::parameter;
        for (name, value) in self.parameters() {
            if !value.is_finite() {
                return Err(p(name, value, "must be finite"));
            }
        }
        match *self {
            Self::DoubleSphere { xi, alpha } => {
                if !(-1.0..=1.0).contains(&xi) {
                    return Err(p("xi", xi, "must be in [-1, 1]"));
                }
                if !(0.0..=1.0).contains(&alpha) {
                    return Err(p("alpha", alpha, "must be in [0, 1]"));
                }
            }
            Self::Unified { alpha } if !(0.0..=1.0).contains(&alpha) => {
                return Err(p("alpha", alpha, "must be in [0, 1]"));
            }
            Self::ExtendedUnified { alpha, beta } => {
                if !(0.0..=1.0).contains(&alpha) {
                    return Err(p("alpha", alpha, "must be in [0, 1]"));
                }
                if beta <= 0.0 {
                    return Err(p("beta", beta, "must be > 0"));
                }
            }
            Self::Fov { w } if !(w > 0.0 && w < PI) => {
                return Err(p("w", w, "must be in (0, π) radians"));
            }
            Self::Scaramuzza { a, c, d, e } => {
                if a[0] >= 0.0 {
                    return Err(p(
                        "a0",
                        a[0],
                        "must be < 0 (the toolbox's convention: -f(0) is the focal length)",
                    ));
                }
                if c - d * e <= 0.0 {
                    return Err(p(
                        "c",
                        c,
                        "the affine [[c, d], [e, 1]] must have c - d·e > 0",
                    ));
                }
            }
            Self::FTheta { k } if k[0] <= 0.0 => {
                return Err(p("k1", k[0], "must be > 0 (θ must grow from the centre)"));
            }
            _ => {}
        }
        Ok(())
    }
}

/// A calibrated lens: a model, its intrinsics, an optional field-of-view limit, and the
/// domain they give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibratedLens {
    model: CalibratedModel,
    intrinsics: Intrinsics,
    max_fov: Option<f64>,
    theta_max: f64,
    /// Radius in model coordinates of the domain edge (for radial-tangential: of the
    /// undistorted `x`); infinite when unbounded.
    r_max: f64,
    turns_at: Option<f64>,
}

impl CalibratedLens {
    /// A lens without a field-of-view limit. Errors on parameters outside their published
    /// ranges; for Scaramuzza and f-theta, which need a field of view, use
    /// [`Self::with_fov`].
    pub fn new(model: CalibratedModel, intrinsics: Intrinsics) -> Result<Self, LensError> {
        Self::build(model, intrinsics, None)
    }

    /// A lens limited to a full field of view of `fov` radians. Errors when the model cannot
    /// reach it (its mapping turns back or its domain ends before `fov/2`).
    pub fn with_fov(
        model: CalibratedModel,
        intrinsics: Intrinsics,
        fov: f64,
    ) -> Result<Self, LensError> {
        if !(fov.is_finite() && fov > 0.0 && fov <= 2.0 * PI * (1.0 + 1e-12)) {
            return Err(LensError::parameter(
                "fov",
                fov.to_degrees(),
                "must be in (0, 360] degrees",
            ));
        }
        Self::build(model, intrinsics, Some(fov.min(2.0 * PI)))
    }

    fn build(
        model: CalibratedModel,
        intrinsics: Intrinsics,
        max_fov: Option<f64>,
    ) -> Result<Self, LensError> {
        let Intrinsics { fx, fy, cx, cy } = intrinsics;
        for (name, value) in [("fx", fx), ("fy", fy)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(LensError::parameter(name, value, "must be finite and > 0"));
            }
        }
        for (name, value) in [("cx", cx), ("cy", cy)] {
            if !value.is_finite() {
                return Err(LensError::parameter(name, value, "must be finite"));
            }
        }
        model.validate()?;
        let mut lens = Self {
            model,
            intrinsics,
            max_fov,
            theta_max: 0.0,
            r_max: 0.0,
            turns_at: None,
        };
        let unreachable = |reach: f64, turned: bool, fov: f64| LensError::Unreachable {
            model: model.name(),
            fov: fov.to_degrees(),
            reach: 2.0 * reach.to_degrees(),
            why: if turned {
                "its mapping stops increasing (the image would fold over itself)"
            } else {
                "its domain ends"
            },
        };
        if model.theta_of_r() {
            let fov = max_fov.ok_or(LensError::Needs {
                model: model.name(),
                what: "a field of view (fov=DEGREES): it bounds the domain of θ(r)",
            })?;
            let target = 0.5 * fov;
            // Grow the radius until θ passes the target; the increasing part must reach it.
            let mut hi = 1.0;
            while lens.theta_raw(hi).is_some_and(|t| t < target) && hi < 1e9 {
                hi *= 2.0;
            }
            let (end, turned) = increasing_part(|r| lens.theta_raw(r), hi);
            let reach = lens.theta_raw(end).unwrap_or(0.0);
            if reach < target {
                return Err(unreachable(reach, turned, fov));
            }
            let (r, _) = solve(
                |r| {
                    let (t, dt) = lens.theta_and_slope(r);
                    (t - target, dt)
                },
                0.0,
                end,
                end * 0.5,
            );
            lens.theta_max = target;
            lens.r_max = r;
        } else {
            let hi = max_fov.map_or(PI, |fov| (0.5 * fov).min(PI));
            let radtan = matches!(model, CalibratedModel::RadTan { .. });
            if let Some(fov) = max_fov
                && radtan
                && hi >= 0.5 * PI
            {
                return Err(unreachable(0.5 * PI, false, fov));
            }
            // Radial-tangential scans the undistorted radius ρ = tan θ (to 1e3: 89.94°).
            let scan_hi = if radtan {
                hi.min(0.5 * PI - 1e-3).tan()
            } else {
                hi
            };
            let (end, turned) = increasing_part(|t| lens.radius_raw(t), scan_hi);
            let end_theta = if radtan { end.atan() } else { end };
            if let Some(fov) = max_fov
                && end < scan_hi * (1.0 - 1e-9)
            {
                return Err(unreachable(end_theta, turned, fov));
            }
            if turned {
                lens.turns_at = Some(end_theta);
            }
            lens.theta_max = end_theta;
            lens.r_max = match model {
                CalibratedModel::RadTan { .. } => end,
                _ => lens
                    .radius_raw(end)
                    .filter(|r| *r < 1e12)
                    .unwrap_or(f64::INFINITY),
            };
        }
        Ok(lens)
    }

    /// The model's distortion parameters.
    pub fn model(&self) -> CalibratedModel {
        self.model
    }

    /// The intrinsics.
    pub fn intrinsics(&self) -> Intrinsics {
        self.intrinsics
    }

    /// The requested full field of view, radians, if any.
    pub fn max_fov(&self) -> Option<f64> {
        self.max_fov
    }

    /// The largest θ a ray may have.
    pub fn theta_max(&self) -> f64 {
        self.theta_max
    }

    /// The model-coordinate radius of the domain edge (radial-tangential: of the undistorted
    /// normalized point `(X/Z, Y/Z)`); infinite when unbounded.
    pub fn r_max(&self) -> f64 {
        self.r_max
    }

    /// Where the mapping stops increasing, when that is what ends the domain (the field of
    /// view is clipped there), as θ in radians.
    pub fn turns_at(&self) -> Option<f64> {
        self.turns_at
    }

    /// The same lens for an image scaled by `sx` along x and `sy` along y (intrinsics scale
    /// with the image; the domain does not change).
    pub fn scaled(&self, sx: f64, sy: f64) -> Self {
        let i = self.intrinsics;
        Self {
            intrinsics: Intrinsics {
                fx: i.fx * sx,
                fy: i.fy * sy,
                cx: i.cx * sx,
                cy: i.cy * sy,
            },
            ..*self
        }
    }

    /// Model coordinates of a continuous pixel position.
    pub fn model_coordinates(&self, pixel: DVec2) -> DVec2 {
        let i = self.intrinsics;
        let q = DVec2::new((pixel.x - i.cx) / i.fx, (pixel.y - i.cy) / i.fy);
        match self.model {
            CalibratedModel::Scaramuzza { c, d, e, .. } => {
                let det = c - d * e;
                DVec2::new((q.x - d * q.y) / det, (c * q.y - e * q.x) / det)
            }
            _ => q,
        }
    }

    /// The pixel position of model coordinates; inverse of [`Self::model_coordinates`].
    pub fn pixel(&self, m: DVec2) -> DVec2 {
        let i = self.intrinsics;
        let q = match self.model {
            CalibratedModel::Scaramuzza { c, d, e, .. } => {
                DVec2::new(c * m.x + d * m.y, e * m.x + m.y)
            }
            _ => m,
        };
        DVec2::new(i.fx * q.x + i.cx, i.fy * q.y + i.cy)
    }
}

impl std::fmt::Display for CalibratedLens {
    /// Writes the lens as a spec that [`crate::lens::parse_spec`] reads back (the principal
    /// point in OpenCV's convention, as specs take it).
    fn fmt(&self, out: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let i = self.intrinsics;
        write!(
            out,
            "{}:fx={},fy={},cx={},cy={}",
            self.model.name(),
            i.fx,
            i.fy,
            i.cx - 0.5,
            i.cy - 0.5
        )?;
        for (key, value) in self.model.parameters() {
            write!(out, ",{key}={value}")?;
        }
        if let Some(fov) = self.max_fov {
            write!(out, ",fov={}", fov.to_degrees())?;
        }
        Ok(())
    }
}

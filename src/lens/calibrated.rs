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

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

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

/// The most iterations [`solve`] takes for a bracket of width `w0` and tolerance `tol`:
/// `⌈log₂(w0/tol)⌉` (see the module docs).
pub fn newton_bound(w0: f64, tol: f64) -> u32 {
    (w0 / tol).log2().ceil().max(0.0) as u32
}

/// Solves `h(x) = 0` in `[lo, hi]`, `h(lo) ≤ 0 ≤ h(hi)`, by the guarded Newton iteration of the
/// module docs; `h` returns the value and the derivative. Returns the root and the number of
/// iterations.
pub fn solve(h: impl Fn(f64) -> (f64, f64), mut lo: f64, mut hi: f64, x0: f64) -> (f64, u32) {
    let tol = 4.0 * f64::EPSILON * hi.abs().max(lo.abs()).max(f64::MIN_POSITIVE);
    let mut x = x0.clamp(lo, hi);
    let mut iterations = 0;
    // Narrows the bracket by the sign of h at `at`; true if `at` is the root.
    let narrow = |at: f64, value: f64, lo: &mut f64, hi: &mut f64| {
        if value < 0.0 {
            *lo = at;
        } else {
            *hi = at;
        }
        value == 0.0
    };
    loop {
        iterations += 1;
        let before = hi - lo;
        let (mut value, mut slope) = h(x);
        if narrow(x, value, &mut lo, &mut hi) {
            return (x, iterations);
        }
        if hi - lo > 0.5 * before {
            let mid = 0.5 * (lo + hi);
            let (mid_value, mid_slope) = h(mid);
            if narrow(mid, mid_value, &mut lo, &mut hi) {
                return (mid, iterations);
            }
            // Newton goes on from whichever point is closer to a root.
            if mid_value.abs() < value.abs() {
                (x, value, slope) = (mid, mid_value, mid_slope);
            }
        }
        let newton = x - value / slope;
        if (newton - x).abs() <= tol {
            return (newton.clamp(lo, hi), iterations);
        }
        let inside = newton > lo && newton < hi;
        if hi - lo <= tol {
            return (0.5 * (lo + hi), iterations);
        }
        x = if inside { newton } else { 0.5 * (lo + hi) };
    }
}

/// The end of the part of `[0, hi]` from 0 on which `f` is defined and increasing: a scan of
/// 4096 samples, refined by bisection to about `hi·1e-9` where `f` turns (to the last bit
/// where it stops being defined). Returns the end and whether `f` turned there (rather than
/// ceasing to be defined, or reaching `hi`).
fn increasing_part(f: impl Fn(f64) -> Option<f64>, hi: f64) -> (f64, bool) {
    const SAMPLES: u32 = 4096;
    let step = hi / f64::from(SAMPLES);
    let delta = step * 1e-6;
    let good = |x: f64| match (f(x), f((x - delta).max(0.0))) {
        (Some(a), Some(b)) => a > b,
        _ => false,
    };
    let Some(mut previous) = f(0.0) else {
        return (0.0, false);
    };
    for i in 1..=SAMPLES {
        let x = step * f64::from(i);
        match f(x) {
            Some(value) if value > previous && good(x) => previous = value,
            _ => {
                let (mut a, mut b) = (x - step, x);
                for _ in 0..80 {
                    let mid = 0.5 * (a + b);
                    if mid <= a || mid >= b {
                        break;
                    }
                    if good(mid) {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                // It turned if f goes on beyond (the next sample), rather than ending there.
                return (a, f(a + step).is_some());
            }
        }
    }
    (hi, false)
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

    /// r(θ) by the model's formula where its published conditions hold, ignoring the domain's
    /// other limits. Radial-tangential: the radial distortion of the undistorted radius
    /// `ρ = tan θ`, here taking `ρ` itself.
    fn radius_raw(&self, theta: f64) -> Option<f64> {
        let (s, c) = theta.sin_cos();
        let r = match self.model {
            CalibratedModel::KannalaBrandt { k } => {
                let t2 = theta * theta;
                theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))))
            }
            CalibratedModel::DoubleSphere { xi, alpha } => {
                let w1 = CalibratedModel::unified_w(alpha);
                let w2 = (w1 + xi) / (2.0 * w1 * xi + xi * xi + 1.0).sqrt();
                if c <= -w2 {
                    return None;
                }
                let d2 = (s * s + (xi + c) * (xi + c)).sqrt();
                s / (alpha * d2 + (1.0 - alpha) * (xi + c))
            }
            CalibratedModel::Unified { alpha } => {
                if c <= -CalibratedModel::unified_w(alpha) {
                    return None;
                }
                s / (alpha + (1.0 - alpha) * c)
            }
            CalibratedModel::ExtendedUnified { alpha, beta } => {
                let d = (beta * s * s + c * c).sqrt();
                if c <= -CalibratedModel::unified_w(alpha) * d {
                    return None;
                }
                s / (alpha * d + (1.0 - alpha) * c)
            }
            CalibratedModel::Fov { w } => (2.0 * (0.5 * w).tan() * s).atan2(c) / w,
            CalibratedModel::RadTan { k, .. } => {
                let r2 = theta * theta;
                theta * (1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[2])))
            }
            CalibratedModel::Scaramuzza { .. } | CalibratedModel::FTheta { .. } => {
                return self.radius_by_solving(theta).map(|(r, _)| r);
            }
        };
        (r.is_finite() && r >= 0.0).then_some(r)
    }

    /// θ(r) by the model's formula where its published conditions hold, ignoring the domain's
    /// other limits (for the models solved by iteration, inside the domain only).
    fn theta_raw(&self, r: f64) -> Option<f64> {
        let r2 = r * r;
        let theta = match self.model {
            CalibratedModel::DoubleSphere { xi, alpha } => {
                if alpha > 0.5 && r2 > 1.0 / (2.0 * alpha - 1.0) {
                    return None;
                }
                let mz = (1.0 - alpha * alpha * r2)
                    / (alpha * (1.0 - (2.0 * alpha - 1.0) * r2).max(0.0).sqrt() + 1.0 - alpha);
                let k = (mz * xi + (mz * mz + (1.0 - xi * xi) * r2).sqrt()) / (mz * mz + r2);
                (k * r).atan2(k * mz - xi)
            }
            CalibratedModel::Unified { alpha } => eucm_theta(alpha, 1.0, r2)?,
            CalibratedModel::ExtendedUnified { alpha, beta } => eucm_theta(alpha, beta, r2)?,
            CalibratedModel::Fov { w } => {
                if w * r > PI {
                    return None;
                }
                let (s, c) = (w * r).sin_cos();
                s.atan2(2.0 * (0.5 * w).tan() * c)
            }
            CalibratedModel::Scaramuzza { a, .. } => r.atan2(-poly(&a, r).0),
            CalibratedModel::FTheta { .. } => self.theta_and_slope(r).0,
            CalibratedModel::KannalaBrandt { .. } | CalibratedModel::RadTan { .. } => {
                return self.theta_by_solving(r).map(|(t, _)| t);
            }
        };
        theta.is_finite().then_some(theta)
    }

    /// θ(r) and dθ/dr of the models whose natural direction is θ(r).
    fn theta_and_slope(&self, r: f64) -> (f64, f64) {
        match self.model {
            CalibratedModel::FTheta { k } => {
                let (t, dt) = poly(&[0.0, k[0], k[1], k[2], k[3], k[4]], r);
                (t, dt)
            }
            CalibratedModel::Scaramuzza { a, .. } => {
                let (f, df) = poly(&a, r);
                // θ = atan2(r, -f): dθ/dr = (-f + r f') / (r² + f²).
                (r.atan2(-f), (-f + r * df) / (r * r + f * f))
            }
            _ => unreachable!("only the θ(r) models"),
        }
    }

    /// Kannala–Brandt and radial-tangential θ(r): solves r(θ) = r (for radial-tangential
    /// ρ(1 + k1ρ² + …) = r, then θ = atan ρ) inside the domain. Returns θ and the iterations.
    fn theta_by_solving(&self, r: f64) -> Option<(f64, u32)> {
        let hi = match self.model {
            CalibratedModel::RadTan { .. } => self.r_max,
            _ => self.theta_max,
        };
        if !(r >= 0.0 && r <= self.radius_raw(hi)?) {
            return None;
        }
        let (x, n) = solve(
            |x| {
                let (value, slope) = match self.model {
                    CalibratedModel::KannalaBrandt { k } => {
                        poly(&[0.0, 1.0, 0.0, k[0], 0.0, k[1], 0.0, k[2], 0.0, k[3]], x)
                    }
                    CalibratedModel::RadTan { k, .. } => {
                        poly(&[0.0, 1.0, 0.0, k[0], 0.0, k[1], 0.0, k[2]], x)
                    }
                    _ => unreachable!("only the r(θ) models solved by iteration"),
                };
                (value - r, slope)
            },
            0.0,
            hi,
            r,
        );
        let theta = match self.model {
            CalibratedModel::RadTan { .. } => x.atan(),
            _ => x,
        };
        Some((theta, n))
    }

    /// Scaramuzza and f-theta r(θ) inside the domain: the root of `θ(r) - θ` (increasing
    /// there). Returns r and the iterations.
    fn radius_by_solving(&self, theta: f64) -> Option<(f64, u32)> {
        if !(theta >= 0.0 && theta <= self.theta_max) {
            return None;
        }
        Some(solve(
            |r| {
                let (t, dt) = self.theta_and_slope(r);
                (t - theta, dt)
            },
            0.0,
            self.r_max,
            self.r_max * theta / self.theta_max,
        ))
    }

    /// Forward map θ → r (model coordinates) inside the domain; `None` outside. For
    /// radial-tangential, the radial part only (`ρ(1 + k1ρ² + k2ρ⁴ + k3ρ⁶)`, `ρ = tan θ`).
    pub fn radius(&self, theta: f64) -> Option<f64> {
        if !(theta >= 0.0 && theta <= self.theta_max) {
            return None;
        }
        match self.model {
            CalibratedModel::RadTan { .. } => self.radius_raw(theta.tan()),
            _ => self.radius_raw(theta),
        }
    }

    /// Inverse map r → θ inside the domain; `None` outside (radial-tangential: of the radial
    /// part, as [`Self::radius`]).
    pub fn theta(&self, r: f64) -> Option<f64> {
        let limit = match self.model {
            CalibratedModel::RadTan { .. } => self.radius_raw(self.r_max)?,
            _ => self.r_max,
        };
        if !(r >= 0.0 && r <= limit) {
            return None;
        }
        self.theta_raw(r).map(|t| t.min(self.theta_max))
    }

    /// The iterations the iterative models take to unproject model radius `r` (or, for
    /// Scaramuzza and f-theta, to project angle `r`); `None` for closed-form models or
    /// outside the domain. For tests of the bound.
    pub fn solver_iterations(&self, x: f64) -> Option<u32> {
        match self.model {
            CalibratedModel::KannalaBrandt { .. } | CalibratedModel::RadTan { .. } => {
                self.theta_by_solving(x).map(|(_, n)| n)
            }
            CalibratedModel::Scaramuzza { .. } | CalibratedModel::FTheta { .. } => {
                self.radius_by_solving(x).map(|(_, n)| n)
            }
            _ => None,
        }
    }

    /// `κ(r) = r·dθ/dr` by a central difference: the angle error a relative error of 1 in r
    /// causes (see [`super::ClassicLens::theta_sensitivity`]).
    pub fn theta_sensitivity(&self, r: f64) -> f64 {
        let h = 1e-6 * r.max(1e-6);
        let lo = self.theta((r - h).max(0.0));
        let hi = self.theta(r + h).or(self.theta(r));
        match (lo, hi) {
            (Some(a), Some(b)) => r * (b - a) / (r + h - (r - h).max(0.0)),
            _ => f64::INFINITY,
        }
    }

    /// The direction through a continuous pixel position; `None` outside the domain.
    pub fn unproject(&self, pixel: DVec2) -> Option<DVec3> {
        let m = self.model_coordinates(pixel);
        if !m.is_finite() {
            return None;
        }
        if let CalibratedModel::RadTan { k, p } = self.model {
            let x = undistort(self, k, p, m)?;
            return (x.length() <= self.r_max).then(|| x.extend(1.0).normalize());
        }
        let r = m.length();
        if r.is_nan() || r > self.r_max {
            return None;
        }
        let theta = self.theta_raw(r)?.min(self.theta_max);
        if r == 0.0 {
            return Some(DVec3::Z);
        }
        let (s, c) = theta.sin_cos();
        Some(DVec3::new(s * m.x / r, s * m.y / r, c))
    }

    /// The continuous pixel position a direction lands on (not checked against the image);
    /// `None` for zero or non-finite directions and outside the domain.
    pub fn project(&self, dir: DVec3) -> Option<DVec2> {
        if !(dir.is_finite() && dir.length_squared() > 0.0) {
            return None;
        }
        let rho = dir.x.hypot(dir.y);
        let theta = rho.atan2(dir.z);
        if let CalibratedModel::RadTan { k, p } = self.model {
            if dir.z.is_nan() || dir.z <= 0.0 {
                return None;
            }
            let x = DVec2::new(dir.x / dir.z, dir.y / dir.z);
            return (x.length() <= self.r_max).then(|| self.pixel(distort(k, p, x).0));
        }
        let r = self.radius(theta)?;
        let m = if rho == 0.0 {
            DVec2::new(r, 0.0)
        } else {
            DVec2::new(r * dir.x / rho, r * dir.y / rho)
        };
        Some(self.pixel(m))
    }
}

/// θ(r) of the extended unified model (β = 1: unified), from Khomutenko et al.'s unprojection
/// `mz = (1 - βα²r²) / (α√(1 - (2α-1)βr²) + 1 - α)`, `θ = atan2(r, mz)`.
fn eucm_theta(alpha: f64, beta: f64, r2: f64) -> Option<f64> {
    if alpha > 0.5 && r2 > 1.0 / (beta * (2.0 * alpha - 1.0)) {
        return None;
    }
    let root = (1.0 - (2.0 * alpha - 1.0) * beta * r2).max(0.0).sqrt();
    let mz = (1.0 - beta * alpha * alpha * r2) / (alpha * root + 1.0 - alpha);
    Some(r2.sqrt().atan2(mz))
}

/// A polynomial `Σ cᵢ xⁱ` and its derivative, by Horner's rule.
fn poly(c: &[f64], x: f64) -> (f64, f64) {
    let mut value = 0.0;
    let mut slope = 0.0;
    for &ci in c.iter().rev() {
        slope = slope * x + value;
        value = value * x + ci;
    }
    (value, slope)
}

/// Radial-tangential distortion of an undistorted normalized point, and its Jacobian
/// (columns ∂/∂x, ∂/∂y).
fn distort(k: [f64; 3], p: [f64; 2], x: DVec2) -> (DVec2, [DVec2; 2]) {
    let r2 = x.length_squared();
    let radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[2]));
    let dradial = k[0] + r2 * (2.0 * k[1] + 3.0 * r2 * k[2]); // d radial / d(r²)
    let xy = x.x * x.y;
    let m = DVec2::new(
        x.x * radial + 2.0 * p[0] * xy + p[1] * (r2 + 2.0 * x.x * x.x),
        x.y * radial + p[0] * (r2 + 2.0 * x.y * x.y) + 2.0 * p[1] * xy,
    );
    let dx = DVec2::new(
        radial + 2.0 * x.x * x.x * dradial + 2.0 * p[0] * x.y + 6.0 * p[1] * x.x,
        2.0 * x.x * x.y * dradial + 2.0 * p[0] * x.x + 2.0 * p[1] * x.y,
    );
    let dy = DVec2::new(
        2.0 * x.x * x.y * dradial + 2.0 * p[0] * x.x + 2.0 * p[1] * x.y,
        radial + 2.0 * x.y * x.y * dradial + 6.0 * p[0] * x.y + 2.0 * p[1] * x.x,
    );
    (m, [dx, dy])
}

/// The undistorted point whose distortion is `m`: Newton's method in 2D, 20 steps at most; `None` unless it converges to a relative residual of 1e-12. No bound is claimed for
/// this 2D iteration: a pixel where it does not converge has no ray.
fn undistort(lens: &CalibratedLens, k: [f64; 3], p: [f64; 2], m: DVec2) -> Option<DVec2> {
    // Start from the radial part's exact inverse: the tangential terms are small corrections.
    let r = m.length();
    let mut x = match lens.theta(r) {
        Some(theta) if r > 0.0 => m * (theta.tan() / r),
        _ => m,
    };
    for _ in 0..20 {
        let (d, [jx, jy]) = distort(k, p, x);
        let residual = d - m;
        if residual.length() <= 1e-12 * (1.0 + m.length()) {
            return Some(x);
        }
        let det = jx.x * jy.y - jy.x * jx.y;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        x -= DVec2::new(
            (jy.y * residual.x - jy.x * residual.y) / det,
            (jx.x * residual.y - jx.y * residual.x) / det,
        );
    }
    None
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

//! A lens on an image: pixel → ray direction and direction → pixel, in f64.
//!
//! # Conventions
//! - Pixel coordinates are continuous, with the origin at the top-left corner of the top-left
//!   pixel: the centre of pixel `(i, j)` is `(i + 0.5, j + 0.5)`.
//! - Normalized image coordinates put the image centre at 0 and the half-width at 1, with square
//!   pixels and y up: `x_n = 2u/W - 1`, `y_n = (H - 2v)/W`. At pixel centres this is the
//!   thesis's `x_n = 2(px + 0.5)/W - 1`, `y_n = (H/W)(1 - 2(py + 0.5)/H)`. Focal lengths are in
//!   these units, so a 180° equidistant lens with `f = 0.42` draws a circle of radius 0.66
//!   half-widths.
//! - Directions are in camera space with x right, y down, z forward (OpenCV's convention).
//!
//! # The pixel mask
//! A pixel centre has a ray iff `r ≤ r_max`. At pixel centres `r² = N / W²` with the integer
//! `N = (2i + 1 - W)² + (H - 2j - 1)²`, so the test is the exact integer comparison
//! `N ≤ N_max` ([`LensCamera::mask_limit`]). The GPU runs the same integer test, so the CPU and
//! GPU masks agree bit for bit, also at the domain edge.
//!
//! Calibrated lenses ([`super::CalibratedLens`]) have pixel intrinsics and a domain that need
//! not be a circle in pixels: a pixel has a ray iff its unprojection's domain test passes, in
//! f64 here and in f32 on the GPU, so the masks can differ for pixels within rounding of the
//! domain edge (none did in the tests).

use glam::{DVec2, DVec3};

use super::glass_gpu::GlassParams;
use super::model::Lens;
use crate::error::LensError;

/// The largest image side we accept: keeps the mask's integer `N` below 2³² (see the module
/// docs) with room to spare, and is at least every adapter's texture limit.
pub const MAX_IMAGE_SIDE: u32 = 32768;

/// Image size in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageSize {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl ImageSize {
    /// Errors if a side is 0 or above [`MAX_IMAGE_SIDE`].
    pub fn new(width: u32, height: u32) -> Result<Self, LensError> {
        for (side, name) in [(width, "width"), (height, "height")] {
            if side == 0 || side > MAX_IMAGE_SIDE {
                return Err(LensError::ImageSize {
                    text: format!("{width}x{height}"),
                    reason: format!("the {name} must be between 1 and {MAX_IMAGE_SIDE} pixels"),
                });
            }
        }
        Ok(Self { width, height })
    }

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

impl std::str::FromStr for ImageSize {
    type Err = LensError;

    /// Parses `WxH`, e.g. `1024x768`.
    fn from_str(text: &str) -> Result<Self, LensError> {
        let bad = |reason: &str| LensError::ImageSize {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let (w, h) = text
            .split_once(['x', 'X'])
            .ok_or_else(|| bad("expected WIDTHxHEIGHT, e.g. 1024x768"))?;
        let w = w
            .trim()
            .parse()
            .map_err(|_| bad("the width is not a whole number"))?;
        let h = h
            .trim()
            .parse()
            .map_err(|_| bad("the height is not a whole number"))?;
        Self::new(w, h)
    }
}

impl std::fmt::Display for ImageSize {
    fn fmt(&self, out: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(out, "{}x{}", self.width, self.height)
    }
}

/// How a direction is built from the angle θ and the pixel's azimuth.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DirectionFormula {
    /// `d = (sin θ · x/r, -sin θ · y/r, cos θ)`, with `sin θ / r` evaluated without
    /// cancellation (see `wgsl/lens.wgsl`). Exact at the centre, valid to θ = 2π.
    #[default]
    Stable,
    /// The thesis's construction in the plane of the axis `v1` and the pinhole ray `v2`:
    /// `d = a' v1 + b' v2`, `b' = sqrt(sin²θ / (1 - (v1·v2)²))`, `a' = cos θ - b' (v1·v2)`.
    /// It is 0/0 at the image centre (we return the axis there, its limit), loses precision
    /// in f32 near the centre, and folds θ > π back (sin²θ loses the sign). Kept to show why
    /// the stable formula is the default.
    Thesis,
}

impl DirectionFormula {
    /// The name used on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Thesis => "thesis",
        }
    }
}

/// A lens on an image of a given size: the camera's projection, without pose.
///
/// ```
/// use fisheye_rt::lens::{parse_spec, ImageSize, LensCamera};
/// let camera = LensCamera::new(parse_spec("equidistant:f=0.5")?, ImageSize::new(640, 480)?);
/// // Pixel (320, 240)'s centre is the image's: straight ahead (x right, y down, z forward).
/// let ahead = camera.pixel_direction(320, 240).expect("the centre has a ray");
/// assert!(ahead.z > 0.99);
/// // f = 0.5 half-widths a radian: 90° off axis at 0.785 half-widths, inside the image.
/// assert!(camera.pixel_direction(320 + 250, 240).is_some_and(|d| d.z.abs() < 0.02));
/// # Ok::<(), fisheye_rt::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensCamera {
    /// The lens mapping.
    pub lens: Lens,
    /// The image size in pixels.
    pub size: ImageSize,
    /// How directions are constructed.
    pub formula: DirectionFormula,
    /// A prescription's glass that direct tracing renders the colour through, sample by
    /// sample ([`super::glass_gpu`]); `lens` is then its chief rays' fitted mapping, which
    /// the mask, projection and ground truth follow.
    pub glass: Option<GlassParams>,
    /// When the pixels see the scene: a global shutter at the frame's stamp by default, or
    /// a rolling shutter and an exposure (see [`super::Shutter`]).
    pub shutter: super::Shutter,
}

impl LensCamera {
    /// A camera with the default (stable) direction formula. A calibrated lens's intrinsics
    /// are in pixels of this image.
    pub fn new(lens: impl Into<Lens>, size: ImageSize) -> Self {
        Self {
            lens: lens.into(),
            size,
            formula: DirectionFormula::Stable,
            glass: None,
            shutter: super::Shutter::GLOBAL,
        }
    }

    /// The same camera rendering its colour through `glass`.
    pub fn with_glass(self, glass: GlassParams) -> Self {
        Self {
            glass: Some(glass),
            ..self
        }
    }

    /// The same camera with `shutter`.
    pub fn with_shutter(self, shutter: super::Shutter) -> Self {
        Self { shutter, ..self }
    }

    /// Pixel `(x, y)`'s line time, seconds from the frame's stamp: its line's number in the
    /// shutter's readout order times the line delay (the f64 twin of `line_time` in
    /// `wgsl/frame.wgsl`).
    pub fn line_time(&self, x: u32, y: u32) -> f64 {
        self.time_at(DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5))
    }

    /// The time, seconds from the frame's stamp, at which the sensor reads a continuous
    /// position (the top-left corner at (0, 0)): Kalibr's `line_delay · v` for the OpenCV row
    /// coordinate v, in readout order; a pixel centre's is its line's
    /// ([`LensCamera::line_time`]).
    pub fn time_at(&self, p: DVec2) -> f64 {
        let (w, h) = (f64::from(self.size.width), f64::from(self.size.height));
        let line = match self.shutter.readout {
            super::Readout::TopToBottom => p.y - 0.5,
            super::Readout::BottomToTop => h - 0.5 - p.y,
            super::Readout::LeftToRight => p.x - 0.5,
            super::Readout::RightToLeft => w - 0.5 - p.x,
        };
        line * self.shutter.line_delay
    }

    /// The earliest and latest times, seconds from the frame's stamp, at which any pixel is
    /// exposed: from the first line's exposure's start to the last's end.
    pub fn exposure_span(&self) -> (f64, f64) {
        let lines = match self.shutter.readout {
            super::Readout::TopToBottom | super::Readout::BottomToTop => self.size.height,
            super::Readout::LeftToRight | super::Readout::RightToLeft => self.size.width,
        };
        let half = 0.5 * self.shutter.exposure;
        (-half, f64::from(lines - 1) * self.shutter.line_delay + half)
    }

    /// The same lens on an image `factor` times larger each way: the same field, with
    /// `factor²` times the pixels (a calibrated lens's intrinsics scale with it) and the
    /// same readout time (a line delay `factor` times shorter).
    pub fn scaled(&self, factor: u32) -> Result<Self, LensError> {
        let size = ImageSize::new(
            self.size.width.saturating_mul(factor),
            self.size.height.saturating_mul(factor),
        )?;
        let lens = match self.lens {
            Lens::Classic(lens) => Lens::Classic(lens),
            Lens::Calibrated(lens) => {
                Lens::Calibrated(lens.scaled(f64::from(factor), f64::from(factor)))
            }
        };
        Ok(Self {
            lens,
            size,
            glass: self.glass.map(|g| g.scaled(factor)),
            // As many lines again in the same readout.
            shutter: super::Shutter {
                line_delay: self.shutter.line_delay / f64::from(factor),
                ..self.shutter
            },
            ..*self
        })
    }

    /// The same camera with another direction formula.
    pub fn with_formula(self, formula: DirectionFormula) -> Self {
        Self { formula, ..self }
    }

    /// Normalized coordinates (y up, half-width 1) of a continuous pixel position.
    pub fn normalized(&self, pixel: DVec2) -> DVec2 {
        let w = f64::from(self.size.width);
        let h = f64::from(self.size.height);
        DVec2::new(2.0 * pixel.x / w - 1.0, (h - 2.0 * pixel.y) / w)
    }

    /// The continuous pixel position of normalized coordinates; inverse of [`Self::normalized`].
    pub fn denormalized(&self, n: DVec2) -> DVec2 {
        let w = f64::from(self.size.width);
        let h = f64::from(self.size.height);
        DVec2::new((n.x + 1.0) * w / 2.0, (h - n.y * w) / 2.0)
    }

    /// The integer `N = (2i + 1 - W)² + (H - 2j - 1)² = (r·W)²` of pixel `(i, j)`'s centre.
    pub fn pixel_radius_units(&self, i: u32, j: u32) -> u64 {
        let nx = 2 * i64::from(i) + 1 - i64::from(self.size.width);
        let ny = i64::from(self.size.height) - 2 * i64::from(j) - 1;
        (nx * nx + ny * ny) as u64
    }

    /// `N_max`: pixel `(i, j)` has a ray iff its [`Self::pixel_radius_units`] is ≤ this. Only
    /// classic lenses have this exact integer mask; a calibrated lens's pixel has a ray iff
    /// its unprojection's domain test passes (0 here).
    pub fn mask_limit(&self) -> u32 {
        if self.lens.calibrated().is_some() {
            return 0;
        }
        let r_max = self.lens.r_max();
        let w = f64::from(self.size.width);
        let inside = |n: u64| (n as f64).sqrt() / w <= r_max;
        let estimate = (r_max * w).powi(2);
        if estimate >= f64::from(u32::MAX) {
            return u32::MAX;
        }
        // `estimate` is within an ulp or two of the true limit; settle it with the exact test.
        let mut n = estimate.floor() as u64;
        while n > 0 && !inside(n) {
            n -= 1;
        }
        while n < u64::from(u32::MAX) && inside(n + 1) {
            n += 1;
        }
        n as u32
    }

    /// The direction of the ray through pixel `(i, j)`'s centre, `None` where it is masked.
    pub fn pixel_direction(&self, i: u32, j: u32) -> Option<DVec3> {
        if let Lens::Calibrated(lens) = &self.lens {
            return lens.unproject(DVec2::new(f64::from(i) + 0.5, f64::from(j) + 0.5));
        }
        if self.pixel_radius_units(i, j) > u64::from(self.mask_limit()) {
            return None;
        }
        let n = self.normalized(DVec2::new(f64::from(i) + 0.5, f64::from(j) + 0.5));
        Some(self.direction_inside(n))
    }

    /// The direction of every pixel centre, row by row; `None` where masked. This is the
    /// thesis's direction table, in f64.
    pub fn directions(&self) -> Vec<Option<DVec3>> {
        if self.lens.calibrated().is_some() {
            let (w, h) = (self.size.width, self.size.height);
            return (0..h)
                .flat_map(|j| (0..w).map(move |i| (i, j)))
                .map(|(i, j)| self.pixel_direction(i, j))
                .collect();
        }
        let limit = u64::from(self.mask_limit());
        let mut out = Vec::with_capacity(self.size.pixels());
        for j in 0..self.size.height {
            for i in 0..self.size.width {
                out.push((self.pixel_radius_units(i, j) <= limit).then(|| {
                    let n = self.normalized(DVec2::new(f64::from(i) + 0.5, f64::from(j) + 0.5));
                    self.direction_inside(n)
                }));
            }
        }
        out
    }

    /// The direction through a continuous pixel position, `None` outside the lens's domain
    /// or field of view (or for non-finite input).
    pub fn unproject(&self, pixel: DVec2) -> Option<DVec3> {
        if let Lens::Calibrated(lens) = &self.lens {
            return lens.unproject(pixel);
        }
        let n = self.normalized(pixel);
        let r = n.length();
        (r.is_finite() && r <= self.lens.r_max()).then(|| self.direction_inside(n))
    }

    /// The change to the direction `d` through image point `pixel` a `step` on along each
    /// axis (x, then y), or from the direction a step back where the lens masks the one ahead
    /// (zero where it masks both): the pixel's footprint as directions, in the camera's frame.
    /// `wgsl/lens.wgsl`'s `lens_steps` is its twin.
    pub fn steps(&self, pixel: DVec2, d: DVec3, step: f64) -> [DVec3; 2] {
        [DVec2::X, DVec2::Y].map(|axis| {
            let s = axis * step;
            match self.unproject(pixel + s) {
                Some(ahead) => ahead - d,
                None => self
                    .unproject(pixel - s)
                    .map_or(DVec3::ZERO, |behind| d - behind),
            }
        })
    }

    /// The direction at normalized coordinates already known to be inside the domain.
    fn direction_inside(&self, n: DVec2) -> DVec3 {
        let r = n.length();
        let theta = self
            .lens
            .theta(r.min(self.lens.r_max()))
            .expect("r is inside the domain");
        let (sin, cos) = theta.sin_cos();
        match self.formula {
            DirectionFormula::Stable if r == 0.0 => DVec3::Z,
            DirectionFormula::Stable => DVec3::new(sin * n.x / r, -sin * n.y / r, cos),
            DirectionFormula::Thesis => {
                let v2 = DVec3::new(n.x, -n.y, 1.0).normalize();
                let c = v2.z; // v1 · v2 with v1 = +z
                if c == 1.0 {
                    return DVec3::Z;
                }
                let b = (sin * sin / (1.0 - c * c)).sqrt();
                let a = cos - b * c;
                DVec3::Z * a + v2 * b
            }
        }
    }

    /// The continuous pixel position where a direction lands, `None` if the direction is zero
    /// or not finite, outside the field of view, or lands outside the image.
    ///
    /// For lenses past 180° a direction has several images; this returns the one with
    /// θ ≤ π (for the direction straight back, the one at azimuth 0).
    pub fn project(&self, dir: DVec3) -> Option<DVec2> {
        let (w, h) = (f64::from(self.size.width), f64::from(self.size.height));
        let inside = |p: DVec2| (0.0..=w).contains(&p.x) && (0.0..=h).contains(&p.y);
        if let Lens::Calibrated(lens) = &self.lens {
            return lens.project(dir).filter(|p| inside(*p));
        }
        let rho = dir.x.hypot(dir.y);
        if !(dir.is_finite() && dir.length_squared() > 0.0) {
            return None;
        }
        let theta = rho.atan2(dir.z);
        let r = self.lens.radius(theta)?;
        let n = if rho == 0.0 {
            DVec2::new(r, 0.0)
        } else {
            DVec2::new(r * dir.x / rho, -r * dir.y / rho)
        };
        Some(self.denormalized(n)).filter(|p| inside(*p))
    }

    /// The half-angle about the optical axis whose image reaches `fraction` (in (0, 1]) of
    /// the way from the axis's image to the edge of the picture (the image circle or the
    /// frame, whichever comes first) along the image's axes, in the tightest of the four
    /// directions: a sphere seen under this half-angle, centred on the axis, fills `fraction`
    /// of the picture. `None` if the axis is outside the picture.
    pub fn fill_angle(&self, fraction: f64) -> Option<f64> {
        let centre = self.project(DVec3::Z)?;
        // Camera space: x right, y down, z forward.
        let towards = |theta: f64, (x, y): (f64, f64)| {
            let (sin, cos) = theta.sin_cos();
            DVec3::new(sin * x, sin * y, cos)
        };
        [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
            .into_iter()
            .map(|axis| {
                let reach = |theta| {
                    self.project(towards(theta, axis))
                        .map(|p| (p - centre).length())
                };
                let edge = last_true(0.0, std::f64::consts::PI, |t| reach(t).is_some());
                let target = fraction * reach(edge).unwrap_or(0.0);
                last_true(0.0, edge, |t| reach(t).is_some_and(|r| r <= target))
            })
            .reduce(f64::min)
    }
}

/// The largest `x` in [`lo`, `hi`] with `holds(x)`, for a `holds` true at `lo` and, past some
/// point, false: bisected to f64 precision.
fn last_true(mut lo: f64, mut hi: f64, holds: impl Fn(f64) -> bool) -> f64 {
    if holds(hi) {
        return hi;
    }
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if holds(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

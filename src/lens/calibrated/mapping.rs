//! A calibrated lens's mappings: r(θ) and θ(r) per model (closed forms, or the guarded Newton
//! of [`super::solve`]), and unprojection and projection of pixels and directions.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::solve::solve;
use super::{CalibratedLens, CalibratedModel};

impl CalibratedLens {
    /// r(θ) by the model's formula where its published conditions hold, ignoring the domain's
    /// other limits. Radial-tangential: the radial distortion of the undistorted radius
    /// `ρ = tan θ`, here taking `ρ` itself.
    pub(super) fn radius_raw(&self, theta: f64) -> Option<f64> {
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
    pub(super) fn theta_raw(&self, r: f64) -> Option<f64> {
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
    pub(super) fn theta_and_slope(&self, r: f64) -> (f64, f64) {
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
    /// causes (see [`crate::lens::ClassicLens::theta_sensitivity`]).
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

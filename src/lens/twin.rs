//! The WGSL lens twin against the f64 reference: the per-pixel directions [`super::gpu::LensRays`]
//! computes, checked against [`LensCamera::directions`] with the error each pixel may have.
//! The native tests (`tests/lens_gpu.rs`) and the web page's (`web/`) both judge by this.
//!
//! The bound for a classic lens. For a pixel at radius r, the f32 code must round the pixel's
//! normalized coordinates, r and f (each within an ulp, relative ε = 2⁻²³), and every f32
//! algorithm pays the error that rounding r causes in θ: `κ·ε` with `κ = r·dθ/dr`
//! ([`Lens::theta_sensitivity`]). The direction's construction adds a few ulp more. So the
//! bound is `4ε(1 + κ)` at every pixel (measured on lavapipe: at most 2.6ε(1 + κ)), and
//! wherever κ ≤ 1 (everywhere but near domain edges that the mapping itself makes
//! ill-conditioned) the error must be below [`WELL_CONDITIONED`].
//!
//! The bound for a calibrated lens at pixel p ([`calibrated_bound`]): the classic `ε(1 + κ)`
//! plus what rounding the pixel does: f32 rounds `u - cx` to an absolute error of about
//! `ε(|u| + |cx|)` pixels, a model-coordinate error of that over `f`, which turns the ray by
//! `g = max(θ'(r), sin θ / r)` per unit (measured on lavapipe: at most 0.67 of it).

use glam::{DVec2, DVec3, Vec3};

use super::{CalibratedLens, Lens, LensCamera};

/// f32's relative rounding error.
pub const EPS: f64 = f32::EPSILON as f64;

/// The angular error (radians) the twin must stay under wherever a classic lens's mapping is
/// well conditioned (κ ≤ 1).
pub const WELL_CONDITIONED: f64 = 1e-6;

/// What comparing a camera's GPU directions with the reference found.
#[derive(Clone, Debug)]
pub struct TwinCheck {
    /// Pixels with a ray in both.
    pub valid: usize,
    /// The largest angular error (radians).
    pub max_error: f64,
    /// The largest error over its pixel's bound: at most 1 where the twin holds.
    pub max_ratio: f64,
    /// The largest angular error where κ ≤ 1 (classic lenses; 0 for calibrated ones).
    pub max_error_well_conditioned: f64,
    /// The angular error at each pixel (0 where masked), row-major.
    pub errors: Vec<f64>,
}

impl TwinCheck {
    /// Compares `gpu` (one direction per pixel, row-major, `None` where masked) with the f64
    /// reference of `camera`; an error names the first pixel whose masks differ or whose GPU
    /// direction is not finite.
    pub fn new(camera: &LensCamera, gpu: &[Option<Vec3>]) -> Result<Self, String> {
        let cpu = LensCamera::new(camera.lens, camera.size).directions();
        if gpu.len() != cpu.len() {
            return Err(format!(
                "{}: {} GPU directions for {} pixels",
                camera.lens,
                gpu.len(),
                cpu.len()
            ));
        }
        let width = camera.size.width as usize;
        let mut c = TwinCheck {
            valid: 0,
            max_error: 0.0,
            max_ratio: 0.0,
            max_error_well_conditioned: 0.0,
            errors: vec![0.0; gpu.len()],
        };
        for (index, (g, r)) in gpu.iter().zip(&cpu).enumerate() {
            let (x, y) = (index % width, index / width);
            let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            match (g, r) {
                (Some(g), Some(r)) => {
                    let g = g.as_dvec3();
                    if !g.is_finite() {
                        return Err(format!("{}: non-finite at ({x}, {y})", camera.lens));
                    }
                    let error = angle(g, *r);
                    let bound = match &camera.lens {
                        Lens::Classic(_) => {
                            let kappa =
                                camera.lens.theta_sensitivity(camera.normalized(p).length());
                            if kappa <= 1.0 {
                                c.max_error_well_conditioned =
                                    c.max_error_well_conditioned.max(error);
                            }
                            4.0 * EPS * (1.0 + kappa)
                        }
                        Lens::Calibrated(lens) => calibrated_bound(lens, p),
                    };
                    c.valid += 1;
                    c.errors[index] = error;
                    c.max_error = c.max_error.max(error);
                    c.max_ratio = c.max_ratio.max(error / bound);
                }
                (None, None) => {}
                _ => {
                    return Err(format!(
                        "{}: masks differ at ({x}, {y}): gpu {g:?}, f64 {r:?}",
                        camera.lens
                    ));
                }
            }
        }
        Ok(c)
    }

    /// Whether the twin holds: every pixel within its bound, and (classic lenses) within
    /// [`WELL_CONDITIONED`] where κ ≤ 1; else what is exceeded.
    pub fn holds(&self) -> Result<(), String> {
        if self.max_ratio > 1.0 {
            return Err(format!("an error {:.2} times its bound", self.max_ratio));
        }
        if self.max_error_well_conditioned > WELL_CONDITIONED {
            return Err(format!(
                "an error of {:.2e} rad where κ ≤ 1",
                self.max_error_well_conditioned
            ));
        }
        Ok(())
    }
}

/// The angle between two directions (radians).
pub fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The error bound of a calibrated lens's twin at pixel `p` (see the module's comment).
pub fn calibrated_bound(lens: &CalibratedLens, p: DVec2) -> f64 {
    let i = lens.intrinsics();
    let r = lens.model_coordinates(p).length();
    let kappa = lens.theta_sensitivity(r).min(1e6);
    let g = if r > 1e-9 {
        let theta = lens.theta(r).unwrap_or(lens.theta_max());
        (kappa / r).max(theta.sin() / r)
    } else {
        lens.theta(1e-6).unwrap_or(0.0) / 1e-6
    };
    let rounding = (p.x.abs() + i.cx.abs()) / i.fx + (p.y.abs() + i.cy.abs()) / i.fy;
    EPS * (1.0 + kappa + g * rounding)
}

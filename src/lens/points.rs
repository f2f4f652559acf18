//! Mapping many points at once, as `fisheye lens project|unproject` and the Python package do:
//! pixels in either convention, the image's bounds, the f64 reference or the WGSL code.

use glam::{DVec2, DVec3};

use super::LensCamera;
use super::gpu::LensPoints;
use crate::error::Result;
use crate::gpu::GpuContext;

/// Where pixel coordinates start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelOrigin {
    /// This project's: the top-left pixel's corner at (0, 0), its centre at (0.5, 0.5).
    #[default]
    Corner,
    /// OpenCV's and most calibration tools': pixel centres at whole numbers, the top-left
    /// pixel's centre at (0, 0).
    OpenCv,
}

impl PixelOrigin {
    /// What to add to a coordinate in this convention to get the project's.
    pub fn to_corner(self) -> f64 {
        match self {
            PixelOrigin::Corner => 0.0,
            PixelOrigin::OpenCv => 0.5,
        }
    }
}

/// The unit direction (camera frame) through each pixel given in `origin`'s convention, `None`
/// outside the image (`[0, W] × [0, H]` in the project's convention, as [`project`] answers
/// `None` for a direction landing outside it) or outside the lens's field. With `gpu`, the
/// lens's WGSL code computes them (f32); otherwise the f64 reference.
pub fn unproject(
    camera: &LensCamera,
    pixels: &[DVec2],
    origin: PixelOrigin,
    gpu: Option<&GpuContext>,
) -> Result<Vec<Option<DVec3>>> {
    let shift = DVec2::splat(origin.to_corner());
    let pixels: Vec<DVec2> = pixels.iter().map(|&p| p + shift).collect();
    let dirs: Vec<Option<DVec3>> = match gpu {
        Some(ctx) => LensPoints::new(ctx, camera)?
            .unproject(ctx, &pixels)?
            .into_iter()
            .map(|d| d.map(|d| d.as_dvec3()))
            .collect(),
        None => pixels.iter().map(|&p| camera.unproject(p)).collect(),
    };
    let (w, h) = (f64::from(camera.size.width), f64::from(camera.size.height));
    let inside = |p: &DVec2| (0.0..=w).contains(&p.x) && (0.0..=h).contains(&p.y);
    Ok(pixels
        .iter()
        .zip(dirs)
        .map(|(p, d)| d.filter(|_| inside(p)))
        .collect())
}

/// The pixel (in `origin`'s convention) where each camera-frame direction lands, `None` where
/// it lands outside the lens's field or the image; on the GPU (f32) with `gpu`.
pub fn project(
    camera: &LensCamera,
    dirs: &[DVec3],
    origin: PixelOrigin,
    gpu: Option<&GpuContext>,
) -> Result<Vec<Option<DVec2>>> {
    let pixels: Vec<Option<DVec2>> = match gpu {
        Some(ctx) => LensPoints::new(ctx, camera)?
            .project(ctx, dirs)?
            .into_iter()
            .map(|p| p.map(|p| p.as_dvec2()))
            .collect(),
        None => dirs.iter().map(|&d| camera.project(d)).collect(),
    };
    let shift = DVec2::splat(origin.to_corner());
    Ok(pixels.into_iter().map(|p| p.map(|p| p - shift)).collect())
}

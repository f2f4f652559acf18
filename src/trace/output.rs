//! What a render produces: radiance, the primary hit's geometry and ids, per pixel.

use crate::lens::ImageSize;

use super::NO_HIT;

/// One rendered frame, row-major.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Image size.
    pub size: ImageSize,
    /// Linear RGB radiance; `w` is 1 where the pixel has a ray (the validity mask), else the
    /// pixel is all zero.
    pub colour: Vec<[f32; 4]>,
    /// World-space shading normal (xyz) and distance from the camera (w) of the primary hit;
    /// zero on a miss or a masked pixel.
    pub geometry: Vec<[f32; 4]>,
    /// Scene triangle index of the primary hit, [`NO_HIT`] on a miss or a masked pixel.
    pub ids: Vec<u32>,
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Masked pixels' colour in [`RenderOutput::to_image`] (sRGB).
pub const MASKED_RGB: [u8; 3] = [0, 0, 0];

impl RenderOutput {
    /// Whether pixel `i` (row-major) has a ray.
    pub fn valid(&self, i: usize) -> bool {
        self.colour[i][3] == 1.0
    }

    /// The colour image, sRGB-encoded and clamped, opaque where a pixel has a ray and
    /// transparent (alpha 0) where it is masked.
    pub fn to_image(&self) -> image::RgbaImage {
        let mut out = Vec::with_capacity(self.colour.len() * 4);
        for c in &self.colour {
            if c[3] == 1.0 {
                for v in &c[..3] {
                    out.push((linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0).round() as u8);
                }
                out.push(255);
            } else {
                out.extend_from_slice(&MASKED_RGB);
                out.push(0);
            }
        }
        image::RgbaImage::from_raw(self.size.width, self.size.height, out)
            .expect("width × height RGBA8 pixels")
    }

    /// Number of pixels with a ray, and of those whose primary ray hit something.
    pub fn counts(&self) -> (usize, usize) {
        let valid = (0..self.colour.len()).filter(|&i| self.valid(i)).count();
        let hits = self.ids.iter().filter(|&&id| id != NO_HIT).count();
        (valid, hits)
    }
}

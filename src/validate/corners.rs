//! The corner detector: finds a checkerboard's corners in an image without any lens model, to
//! a small fraction of a pixel (see the module above for how).

use glam::{DMat2, DVec2};

/// Standard deviation, in pixels, of the Gaussian the detector weighs luminance with: the
/// wider, the better it averages out the aliasing of area-sampled sharp edges (worst case on
/// synthetic corners: 0.04 px at σ = 1, 0.027 px at 1.5, 0.018 px at 2), the narrower, the
/// closer together corners can be checked ([`MIN_SPACING_PX`]).
pub const SIGMA: f64 = 1.5;

/// Radius of the detector's window in σ: the Gaussian weight left out beyond it is
/// `e^-12.5 ≈ 4e-6` of the centre's.
const WINDOW_SIGMAS: f64 = 5.0;

/// The least distance between neighbouring parallel cell edges in the image (pixels) for a
/// corner between them to be checked: the window's radius, so that the next edges' weight is
/// at most `e^-12.5 ≈ 4e-6` of the centre's and their asymmetry cannot move the saddle.
pub const MIN_SPACING_PX: f64 = WINDOW_SIGMAS * SIGMA;

/// How far from its candidate pixel's centre a corner may be found.
const MAX_SHIFT_PX: f64 = 2.0;

/// The least `-σ⁴ det H` of the weighted luminance's Hessian at a corner: a flat cell has
/// none and a lone edge none (its Hessian has rank one), while a corner of contrast Δ whose
/// edges cross at angle φ has about `(Δ sin φ / π)²`: 0.076 square, 0.01 at 22°.
const MIN_SADDLE: f64 = 0.005;

/// An image's luminance with its validity mask, as the detector sees it.
pub struct Image {
    width: usize,
    height: usize,
    values: Vec<f64>,
    /// Whether the detector's whole window around each pixel is valid and in the image.
    interior: Vec<bool>,
}

/// A corner found in an image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detection {
    /// Continuous pixel position (pixel `(i, j)` covers `[i, i+1] × [j, j+1]`).
    pub pixel: DVec2,
    /// `-σ⁴ det H` there: how clearly both edges show.
    pub strength: f64,
}

impl Image {
    /// From linear colours whose `w` is the validity mask (as
    /// [`RenderOutput::colour`](crate::trace::RenderOutput::colour)), `width` per row.
    pub fn from_colour(width: usize, colour: &[[f32; 4]]) -> Self {
        let values = colour
            .iter()
            .map(|c| (f64::from(c[0]) + f64::from(c[1]) + f64::from(c[2])) / 3.0)
            .collect();
        let valid: Vec<bool> = colour.iter().map(|c| c[3] == 1.0).collect();
        Self::new(width, values, &valid)
    }

    /// From luminances and their validity, `width` per row.
    pub fn new(width: usize, values: Vec<f64>, valid: &[bool]) -> Self {
        assert_eq!(values.len(), valid.len());
        assert!(width > 0 && values.len().is_multiple_of(width));
        let height = values.len() / width;
        // A pixel is interior when no invalid pixel (or the image border) is within the
        // window's radius plus one: summed-area table of the invalid pixels.
        let reach = (WINDOW_SIGMAS * SIGMA).ceil() as usize + 1;
        let mut table = vec![0u32; (width + 1) * (height + 1)];
        for j in 0..height {
            for i in 0..width {
                table[(j + 1) * (width + 1) + i + 1] = u32::from(!valid[j * width + i])
                    + table[j * (width + 1) + i + 1]
                    + table[(j + 1) * (width + 1) + i]
                    - table[j * (width + 1) + i];
            }
        }
        let invalid_in = |i0: usize, j0: usize, i1: usize, j1: usize| {
            table[j1 * (width + 1) + i1] + table[j0 * (width + 1) + i0]
                - table[j0 * (width + 1) + i1]
                - table[j1 * (width + 1) + i0]
        };
        let interior = (0..values.len())
            .map(|p| {
                let (i, j) = (p % width, p / width);
                i >= reach
                    && j >= reach
                    && i + reach < width
                    && j + reach < height
                    && invalid_in(i - reach, j - reach, i + reach + 1, j + reach + 1) == 0
            })
            .collect();
        Self {
            width,
            height,
            values,
            interior,
        }
    }

    /// Whether the detector can look at a continuous pixel position: its window is all valid.
    pub fn is_interior(&self, pixel: DVec2) -> bool {
        let (i, j) = (pixel.x.floor(), pixel.y.floor());
        i >= 0.0
            && j >= 0.0
            && (i as usize) < self.width
            && (j as usize) < self.height
            && self.interior[j as usize * self.width + i as usize]
    }

    /// The gradient and Hessian in `x` of the weighted mean luminance around `x`: exact sums
    /// over the window's pixel centres `q`, weighted by `w(r²) = e^(-r²/2σ²)·(1 - r²/R²)²`
    /// with `r = |q - x|` and `R` the window's radius. The taper makes the weight and its slope
    /// vanish at `R`, so the gradient is continuous in `x` as pixels enter and leave the
    /// window (a plain truncated Gaussian jumps there, and Newton's method then cycles
    /// between points 1e-5 px apart instead of converging).
    fn weighted(&self, x: DVec2) -> (DVec2, DMat2) {
        let radius = WINDOW_SIGMAS * SIGMA;
        let (s2, r2max) = (SIGMA * SIGMA, radius * radius);
        let (mut grad, mut hess) = (DVec2::ZERO, DMat2::ZERO);
        let i0 = (x.x - radius).floor().max(0.0) as usize;
        let j0 = (x.y - radius).floor().max(0.0) as usize;
        let i1 = ((x.x + radius).ceil() as usize).min(self.width - 1);
        let j1 = ((x.y + radius).ceil() as usize).min(self.height - 1);
        for j in j0..=j1 {
            for i in i0..=i1 {
                let d = DVec2::new(i as f64 + 0.5, j as f64 + 0.5) - x;
                let u = d.length_squared();
                if u >= r2max {
                    continue;
                }
                // w(u) = E·t² with E = e^(-u/2σ²), t = 1 - u/R²; w' and w'' are in u, and
                // u = |q - x|² has ∇ₓu = -2d and ∇ₓ²u = 2I.
                let (e, t) = ((-u / (2.0 * s2)).exp(), 1.0 - u / r2max);
                let w1 = e * t * (-t / (2.0 * s2) - 2.0 / r2max);
                let w2 =
                    e * (t * t / (4.0 * s2 * s2) + 2.0 * t / (s2 * r2max) + 2.0 / (r2max * r2max));
                let v = self.values[j * self.width + i];
                grad += v * -2.0 * w1 * d;
                hess += v
                    * (4.0 * w2 * DMat2::from_cols(d * d.x, d * d.y) + 2.0 * w1 * DMat2::IDENTITY);
            }
        }
        let norm = 1.0 / (2.0 * std::f64::consts::PI * s2);
        (grad * norm, hess * norm)
    }

    /// The luminance blurred by the detector's Gaussian on the pixel grid, for finding
    /// candidates (separable, truncated at 3σ, clamped at the border).
    fn blurred(&self) -> Vec<f64> {
        let reach = (3.0 * SIGMA).ceil() as i64;
        let kernel: Vec<f64> = (-reach..=reach)
            .map(|k| (-(k * k) as f64 / (2.0 * SIGMA * SIGMA)).exp())
            .collect();
        let (w, h) = (self.width as i64, self.height as i64);
        let pass = |src: &[f64], dx: i64, dy: i64| -> Vec<f64> {
            (0..w * h)
                .map(|p| {
                    let (i, j) = (p % w, p / w);
                    kernel
                        .iter()
                        .zip(-reach..=reach)
                        .map(|(g, k)| {
                            let x = (i + k * dx).clamp(0, w - 1);
                            let y = (j + k * dy).clamp(0, h - 1);
                            g * src[(y * w + x) as usize]
                        })
                        .sum()
                })
                .collect()
        };
        pass(&pass(&self.values, 1, 0), 0, 1)
    }

    /// Every checker corner in the interior, to a fraction of a pixel.
    ///
    /// Candidates are the pixels where the blurred luminance is most saddle-shaped (largest
    /// `-det H` by finite differences) in their 5×5 neighbourhood. Each is refined by Newton's
    /// method on the weighted luminance's gradient (`Self::weighted`) and kept if it
    /// converges within `MAX_SHIFT_PX` to a saddle with `-det H` ≥ `MIN_SADDLE` (not an
    /// edge or a flat cell); detections within a pixel of a stronger one are dropped.
    pub fn corners(&self) -> Vec<Detection> {
        let b = self.blurred();
        let (w, h) = (self.width, self.height);
        let mut saddle = vec![0.0; w * h];
        for j in 1..h.saturating_sub(1) {
            for i in 1..w.saturating_sub(1) {
                let p = j * w + i;
                let xx = b[p + 1] - 2.0 * b[p] + b[p - 1];
                let yy = b[p + w] - 2.0 * b[p] + b[p - w];
                let xy = (b[p + w + 1] - b[p + w - 1] - b[p - w + 1] + b[p - w - 1]) / 4.0;
                saddle[p] = xy * xy - xx * yy;
            }
        }
        let mut found: Vec<Detection> = Vec::new();
        for j in 2..h.saturating_sub(2) {
            for i in 2..w.saturating_sub(2) {
                let p = j * w + i;
                if !self.interior[p] || saddle[p] <= 0.0 {
                    continue;
                }
                // The first of equal values wins, so a plateau gives one candidate at most.
                let peak = (j - 2..=j + 2).all(|y| {
                    (i - 2..=i + 2).all(|x| {
                        let q = y * w + x;
                        q == p || saddle[q] < saddle[p] || (saddle[q] == saddle[p] && q > p)
                    })
                });
                if peak {
                    found.extend(self.refine(DVec2::new(i as f64 + 0.5, j as f64 + 0.5)));
                }
            }
        }
        found.sort_by(|a, b| b.strength.total_cmp(&a.strength));
        let mut kept: Vec<Detection> = Vec::new();
        for d in found {
            if kept.iter().all(|k| k.pixel.distance(d.pixel) > 1.0) {
                kept.push(d);
            }
        }
        kept
    }

    /// Newton's method from `start` to where the weighted luminance is stationary, if that is
    /// a corner.
    fn refine(&self, start: DVec2) -> Option<Detection> {
        let mut x = start;
        for _ in 0..50 {
            let (grad, hess) = self.weighted(x);
            let next = x - hess.inverse() * grad;
            if !next.is_finite() || next.distance(start) > MAX_SHIFT_PX || !self.is_interior(next) {
                return None;
            }
            let step = next.distance(x);
            x = next;
            if step < 1e-7 {
                let strength = -self.weighted(x).1.determinant() * SIGMA.powi(4);
                return (strength >= MIN_SADDLE).then_some(Detection { pixel: x, strength });
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image of a checker corner at `centre` whose edges run at angles `a` and `b`
    /// (radians from the x axis), each a ramp `ramp` px wide (as the texture's bilinear filter
    /// makes them), between luminances 0.003 and 0.87, area-sampled by 24 × 24 points per
    /// pixel: an exact picture of what the grid scene shows, made without the renderer.
    pub(super) fn synthetic(size: usize, centre: DVec2, a: f64, b: f64, ramp: f64) -> Image {
        let n = 24;
        let normals = [a, b].map(|t| DVec2::new(-t.sin(), t.cos()));
        let side = |s: f64| (s / ramp + 0.5).clamp(0.0, 1.0) * 2.0 - 1.0;
        let luminance = |p: DVec2| {
            let d = p - centre;
            let sign = side(normals[0].dot(d)) * side(normals[1].dot(d));
            0.4365 + 0.4335 * sign
        };
        let mut values = Vec::with_capacity(size * size);
        for j in 0..size {
            for i in 0..size {
                let mut sum = 0.0;
                for v in 0..n {
                    for u in 0..n {
                        let p = DVec2::new(
                            i as f64 + (u as f64 + 0.5) / n as f64,
                            j as f64 + (v as f64 + 0.5) / n as f64,
                        );
                        sum += luminance(p);
                    }
                }
                values.push(sum / (n * n) as f64);
            }
        }
        Image::new(size, values, &vec![true; size * size])
    }

    /// Exact corners at sub-pixel phases across the pixel, edges from square to 60° apart,
    /// and edge ramps from a hundredth of a pixel to two pixels wide are found once each,
    /// within 0.03 px (the worst, 0.027 px, is a sharp edge 12° off the pixel grid's axes:
    /// area sampling aliases it, and the σ = 1.5 px window averages that down).
    #[test]
    fn synthetic_corners_are_found_to_three_hundredths_of_a_pixel() {
        let mut worst: f64 = 0.0;
        for (k, ramp) in [0.01, 0.1, 0.5, 2.0].into_iter().enumerate() {
            for (m, (a, b)) in [(0.0, 90.0), (12.0, 97.0), (-20.0, 40.0), (45.0, 150.0)]
                .into_iter()
                .enumerate()
            {
                let odd = (0.13 + 0.21 * k as f64, 0.71 - 0.17 * m as f64);
                for phase in [(0.0, 0.0), (0.5, 0.5), odd] {
                    let centre = DVec2::new(20.0 + phase.0, 20.0 + phase.1);
                    let (a, b) = (f64::to_radians(a), f64::to_radians(b));
                    let found = synthetic(40, centre, a, b, ramp).corners();
                    assert_eq!(found.len(), 1, "ramp {ramp}, {centre}: {found:?}");
                    let error = found[0].pixel.distance(centre);
                    worst = worst.max(error);
                    assert!(error < 0.03, "ramp {ramp}, {centre}: off by {error} px");
                }
            }
        }
        eprintln!("worst synthetic error {worst:.5} px");
    }

    /// A lone edge, a flat cell and masked pixels in the window give no corner.
    #[test]
    fn edges_flats_and_masks_give_no_corners() {
        let size = 24;
        let centre = DVec2::new(12.3, 11.6);
        // Edges at a and a + π are one straight edge.
        let edge = synthetic(size, centre, 0.3, 0.3 + std::f64::consts::PI, 0.1);
        assert!(edge.corners().is_empty());
        let flat = Image::new(size, vec![0.5; size * size], &vec![true; size * size]);
        assert!(flat.corners().is_empty());
        let corner = synthetic(size, centre, 0.0, 1.5, 0.1);
        assert_eq!(corner.corners().len(), 1);
        let mut valid = vec![true; size * size];
        valid[12 * size + 7] = false;
        let masked = Image::new(size, corner.values.clone(), &valid);
        assert!(masked.corners().is_empty());
        assert!(!masked.is_interior(centre));
        assert!(corner.is_interior(centre));
    }
}

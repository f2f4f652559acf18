//! A texture's mip chain (Williams, "Pyramidal Parametrics", SIGGRAPH 1983): each level half
//! the one before in each dimension (rounded down, at least 1), down to 1×1, each texel the
//! mean of the texels it covers in linear colour, stored as RGBA8 sRGB like level 0. The GPU
//! tracer and rasterizer and the f64 reference read the same levels, so they filter alike.

use super::Texture;
use crate::trace::linear_to_srgb;

impl Texture {
    /// How many levels the chain has, level 0 (the texture itself) included.
    pub fn mip_level_count(&self) -> u32 {
        32 - self.width.max(self.height).max(1).leading_zeros()
    }

    /// Levels 1 and on. A level's texel `x` covers texels `2x` and `2x + 1` of the level above,
    /// and, where that one's width is odd, the last also its last column (three): every texel
    /// above counts once, so no edge is dropped. Rows alike.
    pub fn mip_levels(&self) -> Vec<Texture> {
        let decode: Vec<f32> = (0..=255u8)
            .map(|c| {
                let c = f32::from(c) / 255.0;
                if c <= 0.04045 {
                    c / 12.92
                } else {
                    ((c + 0.055) / 1.055).powf(2.4)
                }
            })
            .collect();
        let mut levels: Vec<Texture> = Vec::new();
        let mut above: Vec<[f32; 4]> = self
            .rgba
            .chunks_exact(4)
            .map(|t| {
                let [r, g, b, a] = [t[0], t[1], t[2], t[3]];
                [
                    decode[r as usize],
                    decode[g as usize],
                    decode[b as usize],
                    f32::from(a) / 255.0,
                ]
            })
            .collect();
        let (mut w, mut h) = (self.width as usize, self.height as usize);
        for level in 1..self.mip_level_count() {
            let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
            let span = |i: usize, n: usize, size: usize| {
                (2 * i).min(size - 1)..if i + 1 == n { size } else { 2 * i + 2 }
            };
            let mut next = vec![[0.0f32; 4]; nw * nh];
            for y in 0..nh {
                let rows = span(y, nh, h);
                for x in 0..nw {
                    let columns = span(x, nw, w);
                    let mut sum = [0.0f32; 4];
                    for r in rows.clone() {
                        for c in columns.clone() {
                            for (s, v) in sum.iter_mut().zip(above[r * w + c]) {
                                *s += v;
                            }
                        }
                    }
                    let count = (rows.len() * columns.len()) as f32;
                    next[y * nw + x] = sum.map(|s| s / count);
                }
            }
            let quantize = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            levels.push(Texture {
                name: format!("{} (level {level})", self.name),
                width: nw as u32,
                height: nh as u32,
                rgba: next
                    .iter()
                    .flat_map(|t| {
                        let [r, g, b, a] = *t;
                        [r, g, b]
                            .map(|c| quantize(linear_to_srgb(c)))
                            .into_iter()
                            .chain([quantize(a)])
                    })
                    .collect(),
            });
            (above, w, h) = (next, nw, nh);
        }
        levels
    }
}

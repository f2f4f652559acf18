//! A texture's mip chain (Williams, "Pyramidal Parametrics", SIGGRAPH 1983): each level half
//! the one before in each dimension (rounded down, at least 1), down to 1×1, each texel the
//! mean of the texels it covers in linear colour, stored as RGBA8 sRGB like level 0. The GPU
//! tracer and rasterizer and the f64 reference read the same levels, so they filter alike.

use super::cpu::srgb_to_linear;
use super::linear_to_srgb;
use crate::scene::Texture;

/// How many levels `texture`'s chain has, level 0 (the texture itself) included.
pub fn mip_level_count(texture: &Texture) -> u32 {
    32 - texture.width.max(texture.height).max(1).leading_zeros()
}

/// Levels 1 and on of `texture`'s chain. A level's texel `x` covers texels `2x` and `2x + 1`
/// of the level above and, where that one's width is odd, the last texel also its last column
/// (three): every texel above counts once, so no edge is dropped. Rows alike. Each level is
/// made from the one above before that one is rounded to 8 bits.
pub fn mip_levels(texture: &Texture) -> Vec<Texture> {
    let decode: Vec<f32> = (0..=255u8)
        .map(|c| srgb_to_linear(f64::from(c) / 255.0) as f32)
        .collect();
    let mut above: Vec<[f32; 4]> = texture
        .rgba
        .chunks_exact(4)
        .map(|t| {
            let [r, g, b] = [t[0], t[1], t[2]].map(|c| decode[c as usize]);
            [r, g, b, f32::from(t[3]) / 255.0]
        })
        .collect();
    let (mut w, mut h) = (texture.width as usize, texture.height as usize);
    let mut levels = Vec::new();
    for level in 1..mip_level_count(texture) {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        // The texels above that texel `i` of `n` covers, of `size`.
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
            name: format!("{} (level {level})", texture.name),
            width: nw as u32,
            height: nh as u32,
            rgba: next
                .iter()
                .flat_map(|&[r, g, b, a]| {
                    let [r, g, b] = [r, g, b].map(|c| quantize(linear_to_srgb(c)));
                    [r, g, b, quantize(a)]
                })
                .collect(),
        });
        (above, w, h) = (next, nw, nh);
    }
    levels
}

//! Texture filtering on the device the tests run on: trilinear lookups in each texture's mip
//! chain at the footprint of a pixel (ray differentials in the tracer, screen-space
//! derivatives in the rasterizer), and the chain itself.
//!
//! The analytic case: a room whose walls carry a checker of one-texel black and white cells,
//! repeated so often that every pixel covers hundreds of texels. Every level from 1 on is the
//! same grey, the mean of black and white in linear light, encoded as RGBA8 sRGB (188), so a
//! filtered lookup at such a footprint gives that grey exactly, in every method: direct
//! tracing at one ray a pixel and more, adaptive sampling, and the cube maps, traced or
//! rasterized. Unfiltered, the same pixels see black or white cells, or bilinear mixtures.

mod common;

use common::{camera, ctx};
use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings};
use fisheye_rt::raster::RasterMethod;
use fisheye_rt::scene::{Camera, Material, MeshBuilder, Scene, Texture, checker};
use fisheye_rt::trace::{Adaptive, GpuScene, RenderOptions, mip_level_count, mip_levels, render};
use glam::{DVec3, Vec2, Vec3};

const AMBIENT: f32 = 0.8;
const KD: f32 = 0.9;

/// The sRGB transfer function and its inverse (IEC 61966-2-1), this file's own.
fn encode(x: f64) -> f64 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

fn decode(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The grey of every level from 1 on, in linear light: black and white averaged, stored as an
/// 8-bit sRGB value and read back.
fn level_grey() -> f64 {
    let stored = (255.0 * encode(0.5)).round();
    assert_eq!(stored, 188.0);
    decode(stored / 255.0)
}

/// The camera at the centre of a 2 × 2 × 2 room lit by the ambient term alone (so a pixel's
/// radiance is ambient × Kd × texture), each wall a 256-texel checker of one-texel cells
/// repeated 64 times across it.
fn checker_room() -> Scene {
    let mut b = MeshBuilder::new();
    let texture = b.texture(checker("cells", 256, 256, [0; 3], [255; 3], None));
    let mut walls = Material::diffuse("walls", Vec3::splat(KD));
    walls.diffuse_texture = Some(texture);
    walls.specular = Vec3::ZERO;
    let walls = b.material(walls);
    let repeats = Vec2::splat(64.0);
    for axis in 0..3 {
        let (u, v) = (DVec3::AXES[(axis + 1) % 3], DVec3::AXES[(axis + 2) % 3]);
        for side in [-1.0, 1.0] {
            let corner = DVec3::AXES[axis] * side - u - v;
            b.quad(corner, 2.0 * u, 2.0 * v, repeats, walls);
        }
    }
    let camera = Camera {
        position: DVec3::new(0.1, -0.05, 0.02),
        look_at: DVec3::new(1.0, 0.2, 0.7),
        up: DVec3::Y,
    };
    b.finish(Vec::new(), Vec3::ZERO, Vec3::splat(AMBIENT), camera)
}

/// Every covered pixel of `colour` (w > 0) is the filtered grey, to within f32 rounding of
/// the texel decode and the blends (relative 1e-5); returns how many were checked.
fn assert_grey(what: &str, colour: &[[f32; 4]]) -> usize {
    let expected = f64::from(AMBIENT * KD) * level_grey();
    let mut checked = 0;
    for (i, c) in colour.iter().enumerate() {
        if c[3] <= 0.0 {
            continue;
        }
        // Partly covered pixels (several rays) are the mean of their covered rays.
        for (k, &v) in c[..3].iter().enumerate() {
            let e = (f64::from(v) - expected).abs() / expected;
            assert!(
                e < 1e-5,
                "{what}: pixel {i} channel {k} is {v}, not {expected}"
            );
        }
        checked += 1;
    }
    checked
}

#[test]
fn minified_textures_are_filtered_to_their_mean_by_every_method() {
    let scene = checker_room();
    let cam = camera("canon-8-15mm@8mm", 64, 48);
    let uniform = |spp| RenderOptions {
        spp,
        ..RenderOptions::default()
    };
    let adaptive = RenderOptions {
        spp: 4,
        adaptive: Some(Adaptive {
            threshold: 0.02,
            ground_truth: true,
            every_pixel: false,
        }),
        ..RenderOptions::default()
    };
    for (what, options) in [
        ("rt, 1 ray a pixel", uniform(1)),
        ("rt, 16 rays a pixel", uniform(16)),
        ("rt, adaptive", adaptive),
    ] {
        let out = render(ctx(), &scene, &cam, &options).unwrap();
        // The image circle covers 1396 pixels of the 64 × 48.
        let checked = assert_grey(what, &out.colour);
        assert!(checked >= 1396, "{what}: {checked} covered pixels");
    }
    let gpu = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    for method in [
        CubeMethod::Traced,
        CubeMethod::Raster(RasterMethod::Forward),
        CubeMethod::Raster(RasterMethod::Deferred),
    ] {
        let settings = CubeSettings {
            shadow_size: 64,
            ..CubeSettings::new(32, method)
        };
        let colour = CubeMap::new(ctx(), &cam, &gpu, &settings)
            .unwrap()
            .render(ctx(), &gpu, &scene.camera)
            .unwrap();
        let checked = assert_grey(method.name(), &colour);
        assert!(
            checked >= 1396,
            "{}: {checked} covered pixels",
            method.name()
        );
    }
}

/// The chain: sizes halve (rounded down, at least 1) down to 1 × 1; where sizes are even each
/// texel is the mean of the 2 × 2 above it in linear light; where odd, the last column or row
/// takes three, so nothing is dropped; alpha averages linearly; each level is made from the
/// one above before its rounding to 8 bits.
#[test]
fn mip_levels_halve_and_average_in_linear_light() {
    // 5 × 2: columns 0-1, 2-4 in level 1.
    let values: [u8; 10] = [0, 255, 10, 20, 30, 255, 0, 40, 50, 60];
    let texture = Texture {
        name: "odd".into(),
        width: 5,
        height: 2,
        rgba: values.iter().flat_map(|&v| [v, v, v, 255 - v]).collect(),
    };
    assert_eq!(mip_level_count(&texture), 3);
    let levels = mip_levels(&texture);
    let sizes: Vec<(u32, u32)> = levels.iter().map(|l| (l.width, l.height)).collect();
    assert_eq!(sizes, [(2, 1), (1, 1)]);
    let mean = |of: &[u8]| {
        let grey = of
            .iter()
            .map(|&v| decode(f64::from(v) / 255.0))
            .sum::<f64>()
            / of.len() as f64;
        let alpha = of.iter().map(|&v| f64::from(255 - v)).sum::<f64>() / of.len() as f64;
        ((255.0 * encode(grey)).round() as u8, alpha.round() as u8)
    };
    let left = mean(&[0, 255, 255, 0]);
    let right = mean(&[10, 20, 30, 40, 50, 60]);
    let texel = |l: &Texture, i: usize| (l.rgba[4 * i], l.rgba[4 * i + 3]);
    assert_eq!((texel(&levels[0], 0), texel(&levels[0], 1)), (left, right));
    // Level 2 averages level 1's texels before they were rounded to 8 bits.
    let linear = |of: &[u8]| {
        of.iter()
            .map(|&v| decode(f64::from(v) / 255.0))
            .sum::<f64>()
            / of.len() as f64
    };
    let grey = 0.5 * (linear(&[0, 255, 255, 0]) + linear(&[10, 20, 30, 40, 50, 60]));
    assert_eq!(levels[1].rgba[0], (255.0 * encode(grey)).round() as u8);

    let square = checker("cells", 64, 64, [0; 3], [255; 3], None);
    assert_eq!(mip_level_count(&square), 7);
    let levels = mip_levels(&square);
    assert_eq!((levels[5].width, levels[5].height), (1, 1));
    assert!(
        levels
            .iter()
            .all(|l| l.rgba.chunks(4).all(|t| t == [188, 188, 188, 255]))
    );
}

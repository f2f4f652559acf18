//! The GPU's glass (`wgsl/glass.wgsl`) against the f64 reference ray by ray
//! (`Prescription::trace_from_film`), and renders through it against what optics predicts:
//! relative illumination (vignetting and cos⁴), focus and the blur circle of defocus.

mod common;

use std::path::PathBuf;

use common::ctx;
use fisheye_rt::lens::ImageSize;
use fisheye_rt::lens::glass::{GlassLens, camera_for};
use fisheye_rt::lens::glass_gpu::{GlassParams, relative_illumination};
use fisheye_rt::lens::gpu::{pupil_points_on_gpu, trace_on_gpu};
use fisheye_rt::lens::prescription::{Prescription, Ray};
use fisheye_rt::scene::{Camera, Material, MeshBuilder, Scene};
use fisheye_rt::trace::{RenderOptions, render};
use glam::{DVec3, Vec2, Vec3};

/// A shipped prescription's spec.
fn shipped(name: &str, options: &str) -> String {
    format!(
        "prescription:{}/lenses/{name}{options}",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// A prescription written to a file of its own under the target folder, as a spec.
fn written(name: &str, text: &str) -> String {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glass_gpu");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    format!("prescription:{}", path.display())
}

/// A deterministic point in [0, 1) from two integers (a hash, as the kernels' jitter).
fn unit(a: u64, b: u64) -> f64 {
    let mut x = a.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ b.wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
    x ^= x >> 31;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 53) as f64
}

/// `n` rays from film points out to the film's corner toward points of a square twice the
/// rear aperture on the rear vertex's plane: some get through, others are clipped, reflected
/// or miss.
fn film_rays(glass: &GlassLens, params: &GlassParams, n: u64) -> Vec<Ray> {
    let p = &glass.prescription;
    let rear = p.surfaces().last().unwrap().aperture;
    let reach = f64::from(params.film[3]);
    let film_z = p.rear_vertex() + glass.film_mm;
    (0..n)
        .map(|i| {
            let film = DVec3::new(
                (2.0 * unit(i, 1) - 1.0) * reach,
                (2.0 * unit(i, 2) - 1.0) * reach,
                film_z,
            );
            let target = DVec3::new(
                (2.0 * unit(i, 3) - 1.0) * rear,
                (2.0 * unit(i, 4) - 1.0) * rear,
                p.rear_vertex(),
            );
            Ray {
                origin: film,
                direction: (target - film).normalize(),
            }
        })
        .collect()
}

/// How the twin's rays compare with the reference's.
#[derive(Debug, Default)]
struct Agreement {
    /// Rays both let through.
    through: usize,
    /// Rays one lets through and the other does not.
    disagree: usize,
    /// Largest distance between their exit points, mm.
    origin_mm: f64,
    /// Largest difference of their unit exit directions.
    direction: f64,
    /// Of the rays through, those leaving the front surface within 10° of grazing it (just
    /// short of total internal reflection at a flat front face), and their largest
    /// direction difference.
    near_tir: usize,
    near_tir_direction: f64,
}

fn agreement(p: &Prescription, rays: &[Ray], gpu: &[Option<Ray>]) -> Agreement {
    let mut a = Agreement::default();
    for (ray, g) in rays.iter().zip(gpu) {
        match (p.trace_from_film(*ray), g) {
            (Ok(f), Some(g)) => {
                a.through += 1;
                a.origin_mm = a.origin_mm.max((f.origin - g.origin).length());
                let d = (f.direction - g.direction).length();
                a.direction = a.direction.max(d);
                if f.direction.z.abs() < 10f64.to_radians().sin() {
                    a.near_tir += 1;
                    a.near_tir_direction = a.near_tir_direction.max(d);
                }
            }
            (Err(_), None) => {}
            _ => a.disagree += 1,
        }
    }
    a
}

/// A lens whose second and third surfaces are nearly flat (radii 1e5 and 1e7 mm), traced in
/// their vertex frames: in one frame for the whole lens, f32 would place them to 0.01 mm.
const NEAR_FLAT: &str = "\
50      5    1.5    24
100000  3    1.6    24
1e7     2    1      24
0       0    0      20
";

/// A lens with a flat front face behind which rays from the film reach 60° off the axis in
/// glass: beyond 41.8° (asin(1/1.5)) they reflect totally, just short of it they leave grazing.
const FLAT_FRONT: &str = "\
-1e7  6    1.5    40
-30   2    1      20
0     0    0      18
";

/// The twin traces as the reference does: on the shipped fisheye and double Gauss, nearly flat
/// surfaces, and rays at the edge of total internal reflection. Bounds: exit points within
/// 1e-4 mm and directions within 1e-5 (measured at most 2.7e-5 mm and 1.4e-6: f32 rounding of
/// positions up to 60 mm from the front vertex, 4e-6 mm each, through a dozen surfaces), near
/// TIR within 1e-4 (the exit direction's z is √k with k → 0 there, which magnifies k's
/// rounding); the two agree on which rays get through but for 1 in 10,000 (rays that graze
/// an aperture's rim or the critical angle within f32 rounding; measured none).
#[test]
fn the_twin_traces_as_the_reference_does() {
    let size = ImageSize::new(256, 192).unwrap();
    let cases = [
        (shipped("fisheye-10mm.dat", ""), false),
        (shipped("dgauss-50mm.dat", ""), false),
        (written("near-flat.dat", NEAR_FLAT), false),
        (written("flat-front.dat", FLAT_FRONT), true),
    ];
    for (spec, tir) in cases {
        let glass = GlassLens::parse(&spec).unwrap();
        let params = GlassParams::new(
            &glass.prescription,
            glass.film_mm,
            glass.sensor_mm,
            (size.width, size.height),
        )
        .unwrap();
        let rays = film_rays(&glass, &params, if tir { 100_000 } else { 20_000 });
        let gpu = trace_on_gpu(ctx(), &params, &rays, 1).unwrap();
        let a = agreement(&glass.prescription, &rays, &gpu);
        eprintln!("{spec}: {a:?}");
        assert!(a.through > 500, "{spec}: too few rays get through: {a:?}");
        assert_eq!(params.counts[2], 1, "{spec} does not disperse");
        assert!(a.disagree <= rays.len() / 10_000, "{spec}: {a:?}");
        assert!(
            a.origin_mm < 1e-4 && a.direction < 1e-5 || tir,
            "{spec}: {a:?}"
        );
        if tir {
            assert!(a.near_tir > 20, "{spec}: no rays near TIR to test: {a:?}");
            assert!(
                a.near_tir_direction < 1e-4 && a.origin_mm < 1e-4,
                "{spec}: {a:?}"
            );
        }
    }
}

/// The camera of the test scenes: at the origin, looking along +z.
const AT_ORIGIN: Camera = Camera {
    position: DVec3::ZERO,
    look_at: DVec3::Z,
    up: DVec3::NEG_Y,
};

/// A material emitting white radiance 1, lit by nothing.
fn emitter(b: &mut MeshBuilder) -> u32 {
    b.material(Material {
        emission: Vec3::ONE,
        ..Material::diffuse("white", Vec3::ZERO)
    })
}

/// A scene of nothing but a sky of radiance 1 (one black triangle far behind the camera, as a
/// scene needs one), the camera at the origin looking along +z.
fn sky() -> Scene {
    let mut b = MeshBuilder::new();
    let black = b.material(Material::diffuse("black", Vec3::ZERO));
    b.quad(
        DVec3::new(0.0, 0.0, -1e4),
        DVec3::X,
        DVec3::Y,
        Vec2::ONE,
        black,
    );
    b.finish(vec![], Vec3::ONE, Vec3::ZERO, AT_ORIGIN)
}

/// The pixels the lens covers in `colour` (of `size`) whose centres lie within 0.6 px of
/// `ring` pixels from the image's centre: their red values, and their mean radius.
fn ring_pixels(colour: &[[f32; 4]], size: ImageSize, ring: f64) -> (Vec<f64>, f64) {
    let (w, h) = (f64::from(size.width), f64::from(size.height));
    let (values, radii): (Vec<f64>, Vec<f64>) = colour
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            let x = (i % size.width as usize) as f64 + 0.5 - w / 2.0;
            let y = (i / size.width as usize) as f64 + 0.5 - h / 2.0;
            let r = x.hypot(y);
            (c[3] > 0.0 && (r - ring).abs() < 0.6).then_some((f64::from(c[0]), r))
        })
        .unzip();
    let radius = radii.iter().sum::<f64>() / radii.len().max(1) as f64;
    (values, radius)
}

/// Vignetting as the glass makes it: a uniform sky renders, ring by ring, as the relative
/// illumination the f64 reference integrates over the rear plane (without the exit-pupil
/// ellipses the kernel samples), open and stopped down, where stopping down lifts the edge.
/// At 144 samples a pixel each ring's mean is within 0.006 of it (measured within 0.0021:
/// the reference's integral is good to about 0.002, the share of each ellipse that gets
/// through to about 1e-4), out to where a twentieth of the centre's light gets through (44
/// px: the double Gauss's deep vignetting, where the pupil is a thin cat's eye). At one
/// sample a pixel every pixel is within 20 % of its own 144-sample value: a point of the pupil
/// whose ray the glass stops is drawn again, so no sample is black for being stopped (4 of
/// the 72 pixels 10 px out through the double Gauss at f/2 were, before); what is left is the
/// spread of cos⁴θ over the pupil's points (measured up to 15 %, 30 px out through the double
/// Gauss at f/2, where the pupil spans the widest angles).
#[test]
fn vignetting_follows_the_traced_relative_illumination() {
    let size = ImageSize::new(96, 72).unwrap();
    let scene = sky();
    let options = |spp| RenderOptions {
        spp,
        ..Default::default()
    };
    let mut edges = Vec::new();
    for (name, stops) in [
        ("dgauss-50mm.dat", ""),
        ("dgauss-50mm.dat", ",fstop=8"),
        ("fisheye-10mm.dat", ""),
    ] {
        let spec = shipped(name, stops);
        let glass = GlassLens::parse(&spec).unwrap();
        let camera = camera_for(&spec, size).unwrap();
        let pitch = f64::from(camera.glass.unwrap().film[2]);
        let many = render(ctx(), &scene, &camera, &options(144)).unwrap();
        let one = render(ctx(), &scene, &camera, &options(1)).unwrap();
        for ring in [1.0, 10.0, 20.0, 30.0, 34.0, 40.0, 44.0] {
            let (values, radius) = ring_pixels(&many.colour, size, ring);
            if values.len() < 8 {
                continue;
            }
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let expected =
                relative_illumination(&glass.prescription, glass.film_mm, radius * pitch);
            let (singles, _) = ring_pixels(&one.colour, size, ring);
            let spread = singles
                .iter()
                .zip(&values)
                .map(|(v, many)| (v - many).abs() / many)
                .fold(0.0, f64::max);
            eprintln!(
                "{name}{stops} ring {ring}: {mean:.4} vs {expected:.4} ({} px), one ray \
                 within {spread:.3} of it",
                values.len()
            );
            assert!(
                (mean - expected).abs() < 0.006,
                "{name}{stops}: ring {ring} px: rendered {mean:.4}, traced {expected:.4}"
            );
            assert!(
                spread < 0.2,
                "{name}{stops}: ring {ring} px: one ray a pixel off by {spread:.3} of it"
            );
            if ring == 30.0 {
                edges.push(mean);
            }
        }
    }
    assert!(
        edges[1] > edges[0] + 0.05,
        "stopping down to f/8 lifts the edge: {edges:?}"
    );
}

/// A plane `distance` metres in front of the camera, emitting radiance 1 where x < 0 and
/// nothing where x > 0: a vertical edge through the image's centre.
fn edge(distance: f64) -> Scene {
    let mut b = MeshBuilder::new();
    let white = emitter(&mut b);
    let black = b.material(Material::diffuse("black", Vec3::ZERO));
    let (side, z) = (50.0, distance);
    b.quad(
        DVec3::new(-side, -side, z),
        DVec3::new(side, 0.0, 0.0),
        DVec3::new(0.0, 2.0 * side, 0.0),
        Vec2::ONE,
        white,
    );
    b.quad(
        DVec3::new(0.0, -side, z),
        DVec3::new(side, 0.0, 0.0),
        DVec3::new(0.0, 2.0 * side, 0.0),
        Vec2::ONE,
        black,
    );
    b.finish(vec![], Vec3::ZERO, Vec3::ZERO, AT_ORIGIN)
}

/// The share of a uniform disc of radius 1, centred `t` to the right of a vertical line, that
/// lies left of it.
fn disc_left_of(t: f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    (t.acos() - t * (1.0 - t * t).sqrt()) / std::f64::consts::PI
}

/// The blur radius, px, of the vertical edge in the middle 8 rows: the uniform disc whose
/// edge profile (box-filtered over each pixel, as the samples are) fits their mean profile
/// within 10 px of the image's centre best in least squares, over radii to 8 px in steps of
/// 0.02 and edge places within 3 px of the centre in steps of 0.05.
fn blur_radius(colour: &[[f32; 4]], size: ImageSize) -> f64 {
    let (w, h) = (size.width as usize, size.height as usize);
    let rows = h / 2 - 4..h / 2 + 4;
    let columns = w / 2 - 10..w / 2 + 10;
    let mut profile: Vec<f64> = columns
        .clone()
        .map(|x| {
            rows.clone()
                .map(|y| f64::from(colour[y * w + x][0]))
                .sum::<f64>()
                / 8.0
        })
        .collect();
    // The white half is on the left or the right, as the camera's axes fall: make it left.
    if profile[0] < profile[profile.len() - 1] {
        profile.reverse();
    }
    let model = |radius: f64, at: f64, i: usize| -> f64 {
        let x = i as f64;
        (0..16)
            .map(|k| {
                let d = x + (f64::from(k) + 0.5) / 16.0 - at;
                if radius < 1e-9 {
                    f64::from(u8::from(d < 0.0))
                } else {
                    disc_left_of(d / radius)
                }
            })
            .sum::<f64>()
            / 16.0
    };
    let centre = profile.len() as f64 / 2.0;
    let mut best = (f64::MAX, 0.0);
    for r in 0..=400 {
        let radius = f64::from(r) * 0.02;
        for a in -60..=60 {
            let at = centre + f64::from(a) * 0.05;
            let error: f64 = profile
                .iter()
                .enumerate()
                .map(|(i, v)| (v - model(radius, at, i)).powi(2))
                .sum();
            if error < best.0 {
                best = (error, radius);
            }
        }
    }
    best.1
}

/// The paraxial blur circle's radius on the film, mm, of an axial point `distance` mm in front
/// of the front vertex: the marginal ray (from the point to the stop's rim) traced by the
/// ray-transfer matrices to the film `film` mm behind the rear vertex.
fn paraxial_blur(p: &Prescription, distance: f64, film: f64) -> f64 {
    let to_stop = p.abcd(p.stop());
    // A ray from the point at slope u crosses the front plane at height distance · u.
    let slope = 0.5 * p.surfaces()[p.stop()].aperture / (to_stop.a * distance + to_stop.b);
    let m = p.abcd(p.surfaces().len());
    let height = m.a * distance * slope + m.b * slope;
    let reduced = m.c * distance * slope + m.d * slope;
    (height + film * reduced).abs()
}

/// Depth of field as the glass makes it: an edge at the focus distance renders sharp, and one
/// twice as far blurs by the blur circle paraxial optics predicts for the traced aperture
/// (the double Gauss on a 12 mm film, focused at 1 m, wide open at f/2.03 and at f/4: 3.39
/// and 1.72 px). The blur is measured by fitting a uniform disc's edge to the image (see
/// [`blur_radius`]). Asserted: in focus under 0.5 px (measured 0.16 and 0.06: the design's
/// residual aberrations and the fit's grid), out of focus within 8 % of the prediction
/// (measured 1 % and 2.4 %: spherical aberration shapes the real blur, and the samples' noise).
#[test]
fn focus_is_sharp_and_defocus_blurs_by_the_paraxial_circle() {
    let size = ImageSize::new(128, 96).unwrap();
    let options = RenderOptions {
        spp: 64,
        ..Default::default()
    };
    for fstop in ["", ",fstop=4"] {
        let spec = shipped("dgauss-50mm.dat", &format!(",sensor=12,focus=1{fstop}"));
        let glass = GlassLens::parse(&spec).unwrap();
        let camera = camera_for(&spec, size).unwrap();
        let pitch = f64::from(camera.glass.unwrap().film[2]);
        let sharp = render(ctx(), &edge(1.0), &camera, &options).unwrap();
        let in_focus = blur_radius(&sharp.colour, size);
        let far = render(ctx(), &edge(2.0), &camera, &options).unwrap();
        let blurred = blur_radius(&far.colour, size);
        let predicted = paraxial_blur(&glass.prescription, 2e3, glass.film_mm) / pitch;
        assert!(
            in_focus < 0.5,
            "{spec}: an edge in focus blurs by {in_focus} px"
        );
        assert!(
            (blurred / predicted - 1.0).abs() < 0.08,
            "{spec}: an edge at 2 m blurs by {blurred:.3} px, paraxial optics says {predicted:.3}"
        );
    }
}

/// A singlet of dense flint (SF11: n_d 1.78472, V_d 25.76, Schott's catalogue) 40 mm behind
/// its stop: an off-axis bundle meets the lens off centre, where red and blue bend apart.
const FLINT: &str = "\
0     40   0        10
80    6    1.78472  30   25.76
-80   0    1        30
";

/// In a dispersive lens each channel is traced with its own indices (the C, d and F lines,
/// from the Abbe number): the twin matches the reference channel by channel, to the bounds of
/// `the_twin_traces_as_the_reference_does`.
#[test]
fn each_channel_traces_with_its_own_indices() {
    use fisheye_rt::lens::prescription::{LINE_C_NM, LINE_D_NM, LINE_F_NM};
    let spec = written("flint.dat", FLINT);
    let glass = GlassLens::parse(&spec).unwrap();
    let params = GlassParams::new(
        &glass.prescription,
        glass.film_mm,
        glass.sensor_mm,
        (128, 96),
    )
    .unwrap();
    assert_eq!(params.counts[2], 3);
    let rays = film_rays(&glass, &params, 100_000);
    for (channel, nm) in [LINE_C_NM, LINE_D_NM, LINE_F_NM].into_iter().enumerate() {
        let lens = glass.prescription.at_wavelength(nm);
        let gpu = trace_on_gpu(ctx(), &params, &rays, channel as u32).unwrap();
        let a = agreement(&lens, &rays, &gpu);
        assert!(
            a.through > 500 && a.disagree <= 2,
            "channel {channel}: {a:?}"
        );
        assert!(
            a.origin_mm < 1e-4 && a.direction < 1e-5,
            "channel {channel}: {a:?}"
        );
    }
    // The d line's index is the file's; C's lower, F's higher by (n_d - 1) / V_d between them.
    let n = |nm: f64| glass.prescription.at_wavelength(nm).surfaces()[1].index;
    assert!((n(LINE_D_NM) - 1.78472).abs() < 1e-12);
    assert!(((n(LINE_F_NM) - n(LINE_C_NM)) - 0.78472 / 25.76).abs() < 1e-12);
}

/// Where light from `direction` (lens frame, at infinity) lands on the film `film_mm` behind
/// the rear vertex: the mean height (x) of rays traced from a 64 × 64 grid across the stop
/// (the first surface here) that get through.
fn image_centroid(p: &Prescription, direction: DVec3, film_mm: f64) -> f64 {
    let radius = 0.5 * p.surfaces()[p.stop()].aperture;
    let film = p.rear_vertex() + film_mm;
    let (mut sum, mut count) = (0.0, 0);
    for i in 0..64 {
        for j in 0..64 {
            let at = DVec3::new(
                (2.0 * (f64::from(i) + 0.5) / 64.0 - 1.0) * radius,
                (2.0 * (f64::from(j) + 0.5) / 64.0 - 1.0) * radius,
                p.vertex(p.stop()),
            );
            let ray = Ray {
                origin: at - direction,
                direction,
            };
            if let Ok(out) = p.trace(ray) {
                sum += out.origin.x + (film - out.origin.z) * out.direction.x / out.direction.z;
                count += 1;
            }
        }
    }
    sum / f64::from(count)
}

/// Lateral colour as dispersion makes it: a white half-plane 1 km away whose edge lies 3° right
/// of the axis renders with its red, green and blue edges where the f64 trace of rays across
/// the stop, per wavelength, puts light from there (the mean place a point's rays land: an
/// edge's place is that of its line spread, whatever its shape). An edge's place is the area
/// under its normalised profile across a window that holds the whole transition, which the
/// sampling's noise hardly moves, divided by the same lens's render of a uniform sky (so the
/// vignetting's slope does not tilt it). Red and blue stand apart by the predicted 0.91 px,
/// red outward, asserted within 10 % (measured 0.93 px, 2.4 %), each channel's edge within
/// 0.1 px of its prediction (measured 0.05).
#[test]
fn red_and_blue_images_separate_as_dispersion_predicts() {
    use fisheye_rt::lens::prescription::{LINE_C_NM, LINE_D_NM, LINE_F_NM};
    let spec = written("flint.dat", FLINT) + ",sensor=12";
    let glass = GlassLens::parse(&spec).unwrap();
    let size = ImageSize::new(128, 96).unwrap();
    let camera = camera_for(&spec, size).unwrap();
    let pitch = f64::from(camera.glass.unwrap().film[2]);
    let theta = 3f64.to_radians();
    let mut b = MeshBuilder::new();
    let white = emitter(&mut b);
    let r = AT_ORIGIN.rotation();
    // The camera's right, down and forward in the world; the plane spans x < 1 km · tan 3°.
    let (right, down, forward) = (r.x_axis, r.y_axis, r.z_axis);
    let corner = forward * 1e3 + right * (1e3 * theta.tan() - 500.0) - down * 500.0;
    b.quad(corner, right * 500.0, down * 1e3, Vec2::ONE, white);
    let scene = b.finish(vec![], Vec3::ZERO, Vec3::ZERO, AT_ORIGIN);
    let options = RenderOptions {
        spp: 64,
        ..Default::default()
    };
    let out = render(ctx(), &scene, &camera, &options).unwrap();
    // The same lens on a uniform sky: dividing by it leaves the edge's profile without the
    // vignetting's slope.
    let flat = render(ctx(), &sky(), &camera, &options).unwrap();
    let light = DVec3::new(theta.sin(), 0.0, theta.cos());
    let (w, h) = (size.width as usize, size.height as usize);
    let expected = |nm: f64| {
        image_centroid(&glass.prescription.at_wavelength(nm), light, glass.film_mm) / pitch
    };
    let at = |c: usize, predicted: f64| {
        // Columns within 10 px of the predicted edge, averaged over the middle 8 rows.
        let first = (f64::from(size.width) / 2.0 + predicted - 10.0).floor() as usize;
        let column = |image: &[[f32; 4]], x: usize| -> f64 {
            (h / 2 - 4..h / 2 + 4)
                .map(|y| f64::from(image[y * w + x][c]))
                .sum()
        };
        let area: f64 = (first..first + 20)
            .map(|x| column(&out.colour, x) / column(&flat.colour, x))
            .sum();
        first as f64 + area - f64::from(size.width) / 2.0
    };
    let predicted = [LINE_C_NM, LINE_D_NM, LINE_F_NM].map(expected);
    let rendered = [0, 1, 2].map(|c| at(c, predicted[c]));
    for c in 0..3 {
        assert!(
            (rendered[c] - predicted[c]).abs() < 0.1,
            "channel {c}: the edge at {:.3} px, predicted {:.3}",
            rendered[c],
            predicted[c]
        );
    }
    let (apart, expected_apart) = (rendered[0] - rendered[2], predicted[0] - predicted[2]);
    assert!(
        expected_apart > 0.5 && (apart / expected_apart - 1.0).abs() < 0.1,
        "red and blue {apart:.3} px apart, predicted {expected_apart:.3}"
    );
}

/// A pixel's points on the exit pupil are stratified and nested as its film samples are: at
/// 4 × 4 each of the 16 cells of the unit square holds one of its 16 points, at 2 × 2 each
/// quarter one of its 4, and the first four of the 16 are the 2 × 2 points (so supersampling
/// goes on from the estimate's samples through the glass), over 500 pixels' hashes; and the
/// pupil's strata do not pair with the film's the same way in every pixel (the first point's
/// cell varies).
#[test]
fn pupil_points_are_stratified_and_nested() {
    let points = pupil_points_on_gpu(ctx(), 500).unwrap();
    let cell = |p: [f32; 2], side: f32| {
        assert!(p.iter().all(|v| (0.0..1.0).contains(v)), "{p:?}");
        ((p[0] * side) as usize, (p[1] * side) as usize)
    };
    let mut first_cells = std::collections::HashSet::new();
    for (pixel, p) in points.iter().enumerate() {
        let mut fine = [[0; 4]; 4];
        for &q in &p[..16] {
            let (x, y) = cell(q, 4.0);
            fine[y][x] += 1;
        }
        assert_eq!(fine, [[1; 4]; 4], "pixel {pixel}: {p:?}");
        let mut quarters = [[0; 2]; 2];
        for &q in &p[16..] {
            let (x, y) = cell(q, 2.0);
            quarters[y][x] += 1;
        }
        assert_eq!(quarters, [[1; 2]; 2], "pixel {pixel}: {p:?}");
        assert_eq!(p[..4], p[16..], "pixel {pixel}: the 2 × 2 points first");
        first_cells.insert(cell(p[4], 4.0));
    }
    assert!(first_cells.len() >= 8, "{first_cells:?}");
}

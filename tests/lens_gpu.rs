//! The WGSL lens twin against the f64 reference, by readback, on whatever adapter is present
//! (lavapipe in CI). These tests fail, not skip, when there is no adapter. The bounds, and the
//! comparison, are `fisheye_rt::lens::twin`'s (the web page's tests judge by them too).

use std::sync::OnceLock;

use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::gpu::{LensPoints, LensRays};
use fisheye_rt::lens::twin::{EPS, TwinCheck, angle};
use fisheye_rt::lens::{
    CalibratedModel, DirectionFormula, ImageSize, Lens, LensCamera, PRESETS, parse_spec,
};
use glam::DVec2;

fn ctx() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| GpuContext::new().expect("these tests need a GPU adapter (or lavapipe)"))
}

/// Runs `LensRays` and compares every pixel with the f64 reference; asserts no NaN and the
/// same mask.
fn compare(camera: &LensCamera) -> TwinCheck {
    let gpu = LensRays::new(ctx(), camera)
        .unwrap()
        .compute(ctx())
        .unwrap();
    TwinCheck::new(camera, &gpu).unwrap()
}

/// As [`compare`], asserting that the twin holds (`TwinCheck::holds`).
fn assert_bounded(camera: &LensCamera) -> TwinCheck {
    let c = compare(camera);
    eprintln!(
        "{:<40} {}: {} rays, max error {:.2e} rad ({:.2e} where κ ≤ 1), {:.2} of the bound",
        camera.lens.to_string(),
        camera.size,
        c.valid,
        c.max_error,
        c.max_error_well_conditioned,
        c.max_ratio
    );
    if let Err(e) = c.holds() {
        panic!("{}: {e}", camera.lens);
    }
    c
}

fn camera(spec: &str, width: u32, height: u32) -> LensCamera {
    LensCamera::new(
        parse_spec(spec).unwrap(),
        ImageSize::new(width, height).unwrap(),
    )
}

/// Every model (typical and hard parameters) and every preset, all pixels of 1024×768.
#[test]
fn every_model_and_preset_matches_the_reference() {
    let mut specs: Vec<String> = [
        "rectilinear:f=0.5",
        "stereographic:f=0.3",
        "equidistant:f=0.3",
        "equisolid:f=0.45",
        "orthographic:f=0.66",
        "general:f=0.5,k1=0.5,k2=0.5",
        "general:f=0.5,k1=0.5,k2=-0.5",
        "general:f=1,k1=1,k2=1",
        "general:f=0.3,k1=2,k2=0.2",
        "general:f=0.3,k1=1,k2=-0.3",
        "general:f=0.3,k1=1,k2=0",
    ]
    .map(String::from)
    .to_vec();
    specs.extend(PRESETS.iter().map(|p| p.name.to_string()));
    for spec in specs {
        let c = assert_bounded(&camera(&spec, 1024, 768));
        assert!(c.valid > 1000, "{spec}: only {} rays", c.valid);
    }
}

/// Domain edges inside the image: equisolid r → 2f, orthographic r → f, the sin form r → f/k1,
/// the 180° limit of a preset and equidistant's 360°. Masks agree exactly (tested by
/// `compare`), nothing is NaN, and the error follows the conditioning.
#[test]
fn domain_edges_180_and_360_degree_fields() {
    for spec in [
        "equisolid:f=0.5",
        "orthographic:f=0.9",
        "general:f=0.5,k1=0.8,k2=-0.7",
        "canon-8-15mm@8mm",
        "equidistant:f=0.19",
        "stereographic:f=0.25,fov=200",
    ] {
        let cam = camera(spec, 1024, 768);
        let c = assert_bounded(&cam);
        let masked = cam.size.pixels() - c.valid;
        assert!(
            masked > 1000,
            "{spec}: the domain edge should lie inside the image"
        );
    }
}

/// The image centre (odd sizes have a pixel there) and the first ring around it.
#[test]
fn centre_and_first_ring_are_exact() {
    for spec in [
        "rectilinear:f=0.5",
        "stereographic:f=0.3",
        "equidistant:f=0.3",
        "equisolid:f=0.45",
        "orthographic:f=0.66",
        "general:f=0.5,k1=0.5,k2=0.5",
        "general:f=0.5,k1=0.5,k2=-0.5",
    ] {
        let cam = camera(spec, 1025, 769);
        let gpu = LensRays::new(ctx(), &cam).unwrap().compute(ctx()).unwrap();
        let at = |x: usize, y: usize| gpu[y * 1025 + x].unwrap();
        assert_eq!(at(512, 384).to_array(), [0.0, 0.0, 1.0], "{spec} centre");
        for (x, y) in [(511, 384), (513, 384), (512, 383), (512, 385), (511, 383)] {
            let reference = cam.pixel_direction(x as u32, y as u32).unwrap();
            let error = angle(at(x, y).as_dvec3(), reference);
            assert!(error < 2.0 * EPS, "{spec} ({x}, {y}): {error:e}");
        }
    }
}

/// f tiny: the image circle shrinks to the centre pixel. f huge: angles are tiny and the
/// error stays tiny with them.
#[test]
fn tiny_and_huge_focal_lengths() {
    let tiny = compare(&camera("equidistant:f=1e-4", 1025, 769));
    assert_eq!(tiny.valid, 1, "only the centre pixel is within 2π·1e-4");
    for spec in ["equidistant:f=1e4", "equisolid:f=1e4", "orthographic:f=1e4"] {
        let c = assert_bounded(&camera(spec, 1024, 768));
        assert_eq!(c.valid, 1024 * 768);
        // Largest θ ≈ 1.25e-4: a few ulp of that.
        assert!(c.max_error < 1e-10, "{spec}: {:e}", c.max_error);
    }
}

/// The thesis's formula breaks near the centre in f32 (1 - (v1·v2)² cancels), where the
/// stable formula holds its bound.
#[test]
fn thesis_formula_breaks_where_the_stable_one_does_not() {
    let stable = camera("equidistant:f=0.3", 1025, 769);
    let thesis = stable.with_formula(DirectionFormula::Thesis);
    let (s, t) = (assert_bounded(&stable), compare(&thesis));
    // Near the centre: within 8 pixels.
    let near = |index: usize| {
        let (x, y) = ((index % 1025) as i64 - 512, (index / 1025) as i64 - 384);
        x * x + y * y <= 64
    };
    let worst_near = |c: &TwinCheck| {
        c.errors
            .iter()
            .enumerate()
            .filter(|(i, _)| near(*i))
            .map(|(_, e)| *e)
            .fold(0.0, f64::max)
    };
    eprintln!(
        "near the centre: thesis {:.2e} rad, stable {:.2e} rad",
        worst_near(&t),
        worst_near(&s)
    );
    assert!(worst_near(&t) > 1e-5);
    assert!(worst_near(&s) < 1e-6);
    assert!(s.max_error < 1e-6);
}

/// The points kernel (arbitrary positions, `fisheye lens unproject --gpu`) matches the
/// reference, and projecting back on the GPU lands where it started.
///
/// The round-trip bound: the f64 reference meets 1e-3 px at 4096 px with a wide margin (see
/// the unit tests). In f32 a coordinate in [2048, 4096) has an ulp of 2.4e-4 px, and the input
/// direction, θ and r each carry an ulp or two; measured on lavapipe, 6.9e-4 px for every model
/// but the tan form past 90° (1.2e-3 px, where tan's slope amplifies θ's rounding). We assert
/// 2e-3 px, 8 ulp of the output coordinate.
#[test]
fn gpu_points_round_trip_at_4096_px() {
    let specs = [
        "rectilinear:f=0.5",
        "stereographic:f=0.3",
        "equidistant:f=0.3",
        "equisolid:f=0.5",
        "orthographic:f=0.9",
        "general:f=0.5,k1=0.7,k2=0.7",
        "general:f=0.3,k1=1,k2=-0.3",
        "samyang-7.5mm",
        "canon-8-15mm@8mm",
    ];
    let points: Vec<DVec2> = (0..4096)
        .step_by(29)
        .flat_map(|j| {
            (0..4096)
                .step_by(31)
                .map(move |i| DVec2::new(i as f64, j as f64))
        })
        .map(|p| p + 0.5)
        .chain([DVec2::new(2048.0, 2048.0), DVec2::new(2048.5, 2048.0)])
        .collect();
    for spec in specs {
        let cam = camera(spec, 4096, 4096);
        let lens: Lens = cam.lens;
        let pass = LensPoints::new(ctx(), &cam).unwrap();
        let dirs = pass.unproject(ctx(), &points).unwrap();
        let mut reference_dirs = Vec::new();
        let mut reference_points = Vec::new();
        let mut worst_dir = 0.0f64;
        for ((p, g), r) in points
            .iter()
            .zip(&dirs)
            .zip(points.iter().map(|&p| cam.unproject(p)))
        {
            assert_eq!(g.is_some(), r.is_some(), "{spec} {p}: masks differ");
            let (Some(g), Some(r)) = (g, r) else { continue };
            let kappa = lens.theta_sensitivity(cam.normalized(*p).length());
            worst_dir = worst_dir.max(angle(g.as_dvec3(), r) / (EPS * (1.0 + kappa)));
            // Projection returns the image with θ ≤ π: round-trip those.
            if lens.theta(cam.normalized(*p).length()).unwrap() <= std::f64::consts::PI {
                reference_dirs.push(r);
                reference_points.push(*p);
            }
        }
        let projected = pass.project(ctx(), &reference_dirs).unwrap();
        let mut worst_px = 0.0f64;
        for (p, q) in reference_points.iter().zip(&projected) {
            let q = q.unwrap_or_else(|| panic!("{spec} {p}: no projection"));
            worst_px = worst_px.max(q.as_dvec2().distance(*p));
        }
        eprintln!("{spec:<32} unproject {worst_dir:.2}ε(1+κ), round trip {worst_px:.2e} px");
        assert!(worst_dir <= 4.0, "{spec}: {worst_dir}");
        assert!(worst_px < 2e-3, "{spec}: round trip off by {worst_px} px");
    }
}

/// Our trigonometry meets its bound on this adapter (about 2 ulp of 1); the builtins'
/// errors are only reported, they are the driver's.
#[test]
fn trig_replacements_are_accurate_here() {
    for t in fisheye_rt::precision::measure_trig(ctx()).unwrap() {
        eprintln!(
            "{} on {}: builtin {:.2e}, ours {:.2e}",
            t.function, t.domain, t.builtin, t.ours
        );
        assert!(t.ours <= 2.5 * EPS, "{}: {:e}", t.function, t.ours);
    }
}

/// The demo frame is the same whether it reads the direction table or computes directions
/// (the table holds exactly what the kernel computes; a pixel may differ only where f32
/// contraction differs between the kernels and a grid line's threshold falls in between).
#[cfg(feature = "cli")]
#[test]
fn direction_table_and_computed_directions_agree() {
    use fisheye_rt::demo::LensDemo;
    use fisheye_rt::lens::gpu::DirectionSource;
    // A 180° circle of radius 0.66 half-widths: the corners have no ray.
    let cam = camera("canon-8-15mm@8mm", 640, 480);
    let computed = LensDemo::new(ctx(), &cam, DirectionSource::Computed)
        .unwrap()
        .render(ctx())
        .unwrap();
    let table = LensDemo::new(ctx(), &cam, DirectionSource::Table)
        .unwrap()
        .render(ctx())
        .unwrap();
    let differing = computed
        .pixels()
        .zip(table.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(differing <= 10, "{differing} pixels differ");
    // And the picture is not blank: the image circle has colour, the corners are background.
    assert_eq!(computed.get_pixel(0, 0).0, [26, 26, 26, 255]);
    assert_ne!(computed.get_pixel(320, 240).0, [26, 26, 26, 255]);
}

/// A table larger than a storage binding is refused with the numbers, not a crash.
#[test]
fn oversized_direction_table_is_a_clear_error() {
    let limit = ctx().device.limits().max_storage_buffer_binding_size;
    let side = ((limit / 16) as f64).sqrt() as u32 + 64;
    let cam = camera("equidistant:f=0.5", side, side);
    let error = LensRays::new(ctx(), &cam)
        .err()
        .expect("too large")
        .to_string();
    assert!(
        error.contains("direction table") && error.contains("MiB"),
        "{error}"
    );
}

/// Every calibrated model: the WGSL direction of every pixel against the f64 reference (within
/// `twin::calibrated_bound`: measured on lavapipe at most 0.67 of it, asserted 1), the masks
/// (identical at every pixel, domain edges in the image included), and GPU projection of the
/// reference directions back onto their pixels (measured within 1.53e-4 px, asserted 2e-4 px:
/// a coordinate in [256, 512) has an f32 ulp of 3e-5 px, and the direction and θ carry a few).
#[test]
fn calibrated_models_match_the_reference() {
    for spec in CalibratedModel::EXAMPLES.iter().copied().chain([
        // Domain edges inside the image: a clipped calibration, and a small-α double sphere.
        "kb:fx=100,cx=255.5,cy=255.5,k1=0.2,k2=-0.05,k3=0.01,k4=-0.001",
        "ds:fx=120,cx=255.5,cy=255.5,xi=0.2,alpha=0.75",
        "eucm:fx=150,fy=140,cx=250,cy=260,alpha=0.7,beta=1.5,fov=200",
    ]) {
        let lens = parse_spec(spec).unwrap();
        let cal = *lens.calibrated().unwrap();
        let size = if spec.starts_with("radtan") {
            ImageSize::new(752, 480).unwrap()
        } else {
            ImageSize::new(512, 512).unwrap()
        };
        let cam = LensCamera::new(lens, size);
        let check = compare(&cam);
        let (valid, worst) = (check.valid, check.max_ratio);
        let mut pixels = Vec::new();
        let mut dirs = Vec::new();
        for (index, r) in cam.directions().into_iter().enumerate() {
            let (x, y) = (index % size.width as usize, index / size.width as usize);
            if let Some(r) = r {
                pixels.push(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
                dirs.push(r);
            }
        }
        let projected = LensPoints::new(ctx(), &cam)
            .unwrap()
            .project(ctx(), &dirs)
            .unwrap();
        let mut worst_px = 0.0f64;
        let mut unprojected = 0;
        for (p, q) in pixels.iter().zip(&projected) {
            match q {
                Some(q) => worst_px = worst_px.max(q.as_dvec2().distance(*p)),
                None => unprojected += 1,
            }
        }
        eprintln!(
            "{:<12} {valid} rays, error ≤ {worst:.2} of the bound, \
             round trip {worst_px:.2e} px ({unprojected} not back)",
            cal.model().name()
        );
        assert!(valid > 50_000, "{spec}: only {valid} rays");
        assert!(worst <= 1.0, "{spec}: error {worst:.2} times the bound");
        assert_eq!(unprojected, 0, "{spec}: directions did not project");
        assert!(worst_px <= 2e-4, "{spec}: round trip off by {worst_px} px");
    }
}

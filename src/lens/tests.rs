//! Tests of the f64 lens reference: textbook values, domains, specs, round trips, the mask.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use glam::{DVec2, DVec3};

use super::*;

fn lens(spec: &str) -> ClassicLens {
    *parse_spec(spec).unwrap().classic().unwrap()
}

/// Hand-computed values of each mapping at known angles.
#[test]
fn mappings_match_textbook_values() {
    let cases = [
        ("rectilinear:f=1", FRAC_PI_4, 1.0),
        ("rectilinear:f=2", PI / 6.0, 2.0 / 3f64.sqrt()),
        ("stereographic:f=0.5", FRAC_PI_2, 1.0),
        ("stereographic:f=1", PI / 3.0, 2.0 / 3f64.sqrt()),
        ("equidistant:f=0.42", FRAC_PI_2, 0.42 * FRAC_PI_2),
        ("equidistant:f=1", PI, PI),
        ("equisolid:f=0.5", PI, 1.0),
        ("equisolid:f=1", FRAC_PI_2, 2f64.sqrt()),
        ("orthographic:f=1", PI / 6.0, 0.5),
        ("orthographic:f=0.62", FRAC_PI_2, 0.62),
    ];
    for (spec, theta, r) in cases {
        let got = lens(spec).radius(theta).unwrap();
        assert!(
            (got - r).abs() < 1e-12,
            "{spec} r({theta}) = {got}, want {r}"
        );
        let back = lens(spec).theta(r).unwrap();
        assert!(
            (back - theta).abs() < 1e-12,
            "{spec} θ({r}) = {back}, want {theta}"
        );
    }
}

/// The general form with the published (k1, k2) reproduces each classic mapping.
#[test]
fn general_form_reproduces_classic_models() {
    let pairs = [
        ("rectilinear:f=0.7", "general:f=0.7,k1=1,k2=1"),
        ("stereographic:f=0.7", "general:f=0.7,k1=0.5,k2=0.5"),
        ("equidistant:f=0.7", "general:f=0.7,k1=3,k2=0"),
        ("equisolid:f=0.7", "general:f=0.7,k1=0.5,k2=-0.5"),
        ("orthographic:f=0.7", "general:f=0.7,k1=1,k2=-1"),
    ];
    for (classic, general) in pairs {
        let (a, b) = (lens(classic), lens(general));
        assert!((a.theta_max() - b.theta_max()).abs() < 1e-12, "{classic}");
        assert_eq!(a.r_max().is_finite(), b.r_max().is_finite(), "{classic}");
        for k in 0..=100 {
            let theta = a.theta_max() * f64::from(k) / 100.0;
            assert_eq!(a.radius(theta).is_some(), b.radius(theta).is_some());
            if let (Some(ra), Some(rb)) = (a.radius(theta), b.radius(theta)) {
                assert!(
                    (ra - rb).abs() <= 1e-12 * ra.max(1.0),
                    "{classic} at θ={theta}"
                );
            }
        }
    }
}

#[test]
fn domains_end_where_the_models_do() {
    // Orthographic: undefined for r > f; θ ≤ 90°.
    let ortho = lens("orthographic:f=0.8");
    assert_eq!(ortho.r_max(), 0.8);
    assert!(ortho.theta(0.8).is_some() && ortho.theta(0.8 + 1e-12).is_none());
    assert!(ortho.radius(FRAC_PI_2 + 1e-9).is_none());
    // Equisolid: undefined for r > 2f; reaches 180°.
    let equisolid = lens("equisolid:f=0.5");
    assert!((equisolid.theta(1.0).unwrap() - PI).abs() < 1e-15);
    assert!(equisolid.theta(1.0 + 1e-12).is_none());
    // The sin form: undefined for r > f/k1.
    let sin_form = lens("general:f=1,k1=2,k2=-0.5");
    assert_eq!(sin_form.r_max(), 0.5);
    assert!(sin_form.theta(0.51).is_none());
    // Stereographic and the tan form stop short of their poles: every r has a θ below it.
    let stereo = lens("stereographic:f=0.3");
    assert!(stereo.r_max().is_infinite());
    assert!(stereo.theta(1e9).unwrap() < PI && stereo.radius(PI).is_none());
    let tan_form = lens("general:f=1,k1=1,k2=0.8");
    let pole = FRAC_PI_2 / 0.8;
    assert!(tan_form.theta(1e12).unwrap() < pole && tan_form.radius(pole).is_none());
    // Rectilinear: the pole at 90°.
    assert!(lens("rectilinear:f=1").radius(FRAC_PI_2).is_none());
    // Equidistant reaches θ = 180° (straight back: the whole sphere, a 360° field) and no
    // further: past it the image would show the sphere a second time.
    let equidistant = lens("equidistant:f=0.2");
    assert!(equidistant.theta(0.2 * 0.99 * PI).is_some());
    assert!(equidistant.theta(0.2 * 1.01 * PI).is_none());
    assert_eq!(equidistant.r_max(), 0.2 * PI);
    assert!(equidistant.radius(PI + 1e-9).is_none());
    // A slow tan form is capped at 180° too (its pole lies beyond).
    let slow = lens("general:f=1,k1=1,k2=0.2");
    assert_eq!(slow.theta_max(), PI);
    assert!(slow.r_max().is_finite());
    // A field-of-view limit clips the domain and makes a pole model's r_max finite.
    let limited = lens("stereographic:f=0.5,fov=180");
    assert!((limited.r_max() - 1.0).abs() < 1e-15);
    assert!(limited.theta(1.0 + 1e-9).is_none());
}

#[test]
fn bad_parameters_are_errors_naming_them() {
    for (spec, needle) in [
        ("equisolid:f=0", "f = 0"),
        ("equisolid:f=-1", "f = -1"),
        ("equisolid:f=NaN", "f = NaN"),
        ("equisolid:f=inf", "f = inf"),
        ("general:f=1,k1=1,k2=1.5", "k2 = 1.5"),
        ("general:f=1,k1=0,k2=0.5", "k1 = 0"),
        ("equidistant:f=1,fov=0", "fov = 0"),
        ("equidistant:f=1,fov=400", "fov = 400"),
        ("general:f=1,k2=0.5", "needs k1"),
        ("equisolid", "needs f"),
        ("equisolid:f=1,k1=2", "takes no parameter \"k1\""),
        (
            "equisolid:g=1",
            "takes no parameter \"g\" (it takes: f, fov)",
        ),
        ("equisolid:f=1,f=2", "twice"),
        ("equisolid:f", "not key=value"),
        ("equisolid:f=abc", "not a number"),
        ("fisheye:f=1", "unknown model or preset"),
        ("samyang-7.5mm:k2=1", "takes no parameter \"k2\""),
    ] {
        let message = parse_spec(spec).unwrap_err().to_string();
        assert!(
            message.contains(needle),
            "{spec}: {message:?} lacks {needle:?}"
        );
    }
}

#[test]
fn specs_and_presets_parse() {
    let samyang = lens("samyang-7.5mm");
    assert_eq!(samyang.model(), LensModel::Equisolid);
    assert_eq!(samyang.focal_length(), 0.93);
    assert!((samyang.max_fov().unwrap() - PI).abs() < 1e-15);
    assert_eq!(lens("samyang-7.5mm:f=1").focal_length(), 1.0);
    assert_eq!(lens(" pinhole:f=1 ").model(), LensModel::Rectilinear);
    for preset in PRESETS {
        let l = lens(preset.name);
        assert_eq!((l.model(), l.focal_length()), (preset.model, preset.f));
        // Display writes a spec that reads back as the same lens.
        assert_eq!(lens(&l.to_string()), l);
    }
}

#[test]
fn image_sizes_parse_and_reject_bad_ones() {
    assert_eq!(
        "1024x768".parse::<ImageSize>().unwrap(),
        ImageSize::new(1024, 768).unwrap()
    );
    for bad in ["0x10", "10x0", "1024", "axb", "99999x10", "-1x5"] {
        assert!(bad.parse::<ImageSize>().is_err(), "{bad}");
    }
}

fn cameras(size: ImageSize) -> Vec<LensCamera> {
    let mut specs: Vec<String> = [
        "rectilinear:f=0.5",
        "stereographic:f=0.3",
        "equidistant:f=0.3",
        "equidistant:f=0.19",
        "equisolid:f=0.5",
        "orthographic:f=0.9",
        "general:f=0.5,k1=0.7,k2=0.7",
        "general:f=0.3,k1=1,k2=-0.3",
    ]
    .map(String::from)
    .to_vec();
    specs.extend(PRESETS.iter().map(|p| p.name.to_string()));
    specs
        .iter()
        .map(|s| LensCamera::new(lens(s), size))
        .collect()
}

/// `project(unproject(p)) ≈ p` within 1e-3 px at 4096 px, over the whole image: a grid of
/// pixel centres from corner to corner, the image centre and its first ring.
#[test]
fn round_trips_at_4096_px() {
    let size = ImageSize::new(4096, 4096).unwrap();
    let mut points: Vec<DVec2> = (0..4096)
        .step_by(37)
        .flat_map(|j| {
            (0..4096)
                .step_by(41)
                .map(move |i| DVec2::new(i as f64, j as f64))
        })
        .chain([DVec2::new(4095.0, 4095.0)])
        .map(|p| p + 0.5)
        .collect();
    points.extend([(2048.0, 2048.0), (2048.5, 2048.0), (2047.5, 2048.5)].map(DVec2::from));
    for camera in cameras(size) {
        let mut worst = 0.0f64;
        let mut count = 0;
        for &p in &points {
            let Some(d) = camera.unproject(p) else {
                continue;
            };
            // Past 180° projection returns the image with θ ≤ π: compare only those.
            if camera.normalized(p).length() > camera.lens.radius(PI).unwrap_or(f64::MAX) {
                continue;
            }
            let back = camera
                .project(d)
                .unwrap_or_else(|| panic!("{} {p} {d} does not project", camera.lens));
            worst = worst.max(back.distance(p));
            count += 1;
        }
        assert!(count > 500, "{}: only {count} points", camera.lens);
        assert!(
            worst < 1e-3,
            "{}: round trip off by {worst} px",
            camera.lens
        );
    }
}

/// The thesis's convention: Canon 8-15 mm at 8 mm (equidistant f = 0.42) draws its 180°
/// circle with a radius of about 0.66 half-widths.
#[test]
fn canon_8mm_circle_is_066_half_widths() {
    let camera = LensCamera::new(
        lens("canon-8-15mm@8mm"),
        ImageSize::new(1000, 1000).unwrap(),
    );
    let edge = camera.project(DVec3::new(1.0, 0.0, 1e-12)).unwrap();
    let radius = camera.normalized(edge).length();
    assert!((radius - 0.42 * FRAC_PI_2).abs() < 1e-9);
    assert!((radius - 0.66).abs() < 0.005);
    // Past 90° off axis this 180° lens has no image.
    assert!(camera.project(DVec3::new(1.0, 0.0, -0.01)).is_none());
}

/// Axes and orientation: x right, y down, z forward; pixel origin top-left.
#[test]
fn directions_follow_the_opencv_convention() {
    let camera = LensCamera::new(lens("equidistant:f=0.5"), ImageSize::new(100, 50).unwrap());
    let centre = camera.unproject(DVec2::new(50.0, 25.0)).unwrap();
    assert!(centre.distance(DVec3::Z) < 1e-15);
    let right = camera.unproject(DVec2::new(90.0, 25.0)).unwrap();
    assert!(right.x > 0.0 && right.y.abs() < 1e-15);
    let below = camera.unproject(DVec2::new(50.0, 45.0)).unwrap();
    assert!(below.y > 0.0 && below.x.abs() < 1e-15);
    // A pixel's direction is a unit vector.
    assert!((camera.unproject(DVec2::new(3.0, 7.0)).unwrap().length() - 1.0).abs() < 1e-15);
}

/// The integer mask agrees with the continuous domain test at every pixel centre.
#[test]
fn pixel_mask_matches_the_domain() {
    let size = ImageSize::new(643, 481).unwrap();
    for camera in cameras(size) {
        for j in 0..size.height {
            for i in 0..size.width {
                let centre = DVec2::new(f64::from(i) + 0.5, f64::from(j) + 0.5);
                assert_eq!(
                    camera.pixel_direction(i, j).is_some(),
                    camera.unproject(centre).is_some(),
                    "{} pixel ({i}, {j})",
                    camera.lens
                );
            }
        }
    }
}

#[test]
fn non_finite_and_zero_inputs_have_no_image() {
    let camera = LensCamera::new(lens("equisolid:f=0.5"), ImageSize::new(64, 64).unwrap());
    assert!(camera.unproject(DVec2::new(f64::NAN, 3.0)).is_none());
    assert!(camera.unproject(DVec2::new(f64::INFINITY, 3.0)).is_none());
    assert!(camera.project(DVec3::ZERO).is_none());
    assert!(camera.project(DVec3::new(f64::NAN, 0.0, 1.0)).is_none());
    // Beyond the domain edge (r > 2f = 1): the image corners.
    assert!(camera.pixel_direction(0, 0).is_none());
}

/// The thesis formula agrees with the stable one over the whole field (every lens stops at
/// θ = 180°, where its sin²θ would start to fold directions back), and returns the axis at the
/// exact centre, where it is 0/0.
#[test]
fn thesis_formula_agrees_with_the_stable_one() {
    let size = ImageSize::new(101, 101).unwrap();
    let stable = LensCamera::new(lens("equidistant:f=0.35"), size);
    let thesis = stable.with_formula(DirectionFormula::Thesis);
    assert_eq!(thesis.pixel_direction(50, 50), Some(DVec3::Z));
    let mut past_90 = 0;
    for (i, j) in [(60, 50), (50, 10), (5, 50), (20, 85), (95, 48)] {
        let (a, b) = (stable.pixel_direction(i, j), thesis.pixel_direction(i, j));
        let (Some(a), Some(b)) = (a, b) else {
            panic!("pixel ({i}, {j}) is inside this lens's domain");
        };
        assert!(a.distance(b) < 1e-12, "({i}, {j})");
        past_90 += usize::from(a.z < 0.0);
    }
    assert!(past_90 >= 2, "the points reach behind the camera");
}

// ---- Calibrated models ----

const CALIBRATED: [&str; 8] = CalibratedModel::EXAMPLES;

fn calibrated(spec: &str) -> CalibratedLens {
    *parse_spec(spec)
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
        .calibrated()
        .unwrap()
}

fn calibrated_intrinsics() -> Intrinsics {
    Intrinsics {
        fx: 300.0,
        fy: 300.0,
        cx: 320.0,
        cy: 240.0,
    }
}

/// The published special cases: each calibrated model reduces to a classic mapping, checked
/// against the classic model's closed form (a different formula in a different module).
#[test]
fn calibrated_models_reduce_to_their_classic_cases() {
    let i = calibrated_intrinsics();
    let build = |m| CalibratedLens::new(m, i).unwrap();
    let build_fov = |m, deg: f64| CalibratedLens::with_fov(m, i, deg.to_radians()).unwrap();
    let cases: Vec<(CalibratedLens, ClassicLens, &str)> = vec![
        // α = 0 is the pinhole, α = ½ the stereographic projection (Mei 2007, ξ = 0 and 1).
        (
            build(CalibratedModel::Unified { alpha: 0.0 }),
            lens("rectilinear:f=1"),
            "ucm α=0",
        ),
        (
            build(CalibratedModel::Unified { alpha: 0.5 }),
            lens("stereographic:f=1"),
            "ucm α=½",
        ),
        (
            build(CalibratedModel::ExtendedUnified {
                alpha: 0.5,
                beta: 1.0,
            }),
            lens("stereographic:f=1"),
            "eucm β=1",
        ),
        (
            build(CalibratedModel::DoubleSphere {
                xi: 0.0,
                alpha: 0.5,
            }),
            lens("stereographic:f=1"),
            "ds ξ=0",
        ),
        (
            build(CalibratedModel::KannalaBrandt { k: [0.0; 4] }),
            lens("equidistant:f=1"),
            "kb k=0",
        ),
        (
            build_fov(
                CalibratedModel::FTheta {
                    k: [0.5, 0.0, 0.0, 0.0, 0.0],
                },
                300.0,
            ),
            lens("equidistant:f=2"),
            "ftheta k1 only",
        ),
        (
            build_fov(
                CalibratedModel::Scaramuzza {
                    a: [-2.0, 0.0, 0.0, 0.0, 0.0],
                    c: 1.0,
                    d: 0.0,
                    e: 0.0,
                },
                170.0,
            ),
            lens("rectilinear:f=2"),
            "scaramuzza a0 only",
        ),
        (
            build_fov(
                CalibratedModel::RadTan {
                    k: [0.0; 3],
                    p: [0.0; 2],
                },
                170.0,
            ),
            lens("rectilinear:f=1"),
            "radtan k=p=0",
        ),
    ];
    for (cal, classic, what) in cases {
        for step in 1..=85 {
            let theta = f64::from(step).to_radians().min(cal.theta_max());
            let (a, b) = (cal.radius(theta), classic.radius(theta));
            let (a, b) = (a.unwrap(), b.unwrap());
            assert!(
                (a - b).abs() <= 1e-12 * b.max(1.0),
                "{what}: r({theta}) {a} vs {b}"
            );
            let back = cal.theta(a).unwrap();
            assert!(
                (back - theta).abs() <= 1e-12,
                "{what}: θ({a}) {back} vs {theta}"
            );
        }
    }
    // FOV model: r(90°) = π/(2w), whatever w (atan2(·, 0) = π/2).
    let fov = build(CalibratedModel::Fov { w: 0.9 });
    assert!((fov.radius(FRAC_PI_2).unwrap() - PI / 1.8).abs() < 1e-14);
}

/// Every model: pixel → direction → pixel and direction → pixel → direction, across its
/// whole domain, to f64 precision; and nothing but `None` or a unit vector anywhere.
#[test]
fn calibrated_round_trips_and_never_nan() {
    for spec in CALIBRATED {
        let lens = calibrated(spec);
        let camera = LensCamera::new(lens, ImageSize::new(512, 512).unwrap());
        let mut inside = 0;
        for j in -40..=552 {
            for i in -40..=552 {
                let p = DVec2::new(f64::from(i) + 0.25, f64::from(j) + 0.75);
                let Some(d) = lens.unproject(p) else { continue };
                assert!((d.length() - 1.0).abs() < 1e-14, "{spec}: |d| at {p}");
                inside += 1;
                let back = lens.project(d).unwrap_or_else(|| panic!("{spec}: {p} {d}"));
                assert!((back - p).length() < 1e-8, "{spec}: {p} → {d} → {back}");
            }
        }
        assert!(inside > 100_000, "{spec}: only {inside} pixels have rays");
        for k in 0..400 {
            // Up to just short of θ_max: at θ_max itself, r may round past r_max.
            let theta = lens.theta_max() * f64::from(k) / 400.0;
            let azimuth = f64::from(k) * 0.7;
            let d = DVec3::new(
                theta.sin() * azimuth.cos(),
                theta.sin() * azimuth.sin(),
                theta.cos(),
            );
            if let Some(p) = lens.project(d) {
                let back = lens.unproject(p).unwrap();
                // Near a domain edge where r(θ) flattens, θ(r) is ill-conditioned: κ = r·θ'(r).
                let kappa = lens.theta_sensitivity(lens.radius(theta).unwrap());
                let error = angle(back, d);
                assert!(
                    error < 1e-12 * (1.0 + kappa),
                    "{spec}: θ = {theta}: {d} → {p} → {back}"
                );
            } else {
                panic!("{spec}: θ = {theta} ≤ θ_max does not project");
            }
        }
        for p in [DVec2::splat(f64::NAN), DVec2::new(f64::INFINITY, 0.0)] {
            assert!(camera.unproject(p).is_none(), "{spec}: {p}");
        }
        for p in [
            DVec2::splat(1e300),
            DVec2::splat(-1e12),
            DVec2::new(1e6, -3.0),
        ] {
            if let Some(d) = camera.unproject(p) {
                assert!((d.length() - 1.0).abs() < 1e-14, "{spec}: {p} → {d}");
            }
        }
        for d in [
            DVec3::ZERO,
            DVec3::splat(f64::NAN),
            DVec3::new(0.0, 0.0, -1.0),
        ] {
            if let Some(p) = lens.project(d) {
                assert!(p.is_finite(), "{spec}: {d} → {p}");
            }
        }
    }
}

fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The published validity conditions (Usenko et al. 2018, table 1) are where our domains end:
/// unprojection needs r² ≤ 1/(2α-1) (double sphere, unified) or 1/(β(2α-1)) (extended
/// unified) for α > ½, and projection z > -w₂ d (double sphere) or z > -w d.
#[test]
fn published_validity_conditions_bound_the_domains() {
    let i = calibrated_intrinsics();
    let cases = [
        (
            CalibratedModel::DoubleSphere {
                xi: -0.2,
                alpha: 0.6,
            },
            1.0 / 0.2,
        ),
        (
            CalibratedModel::DoubleSphere {
                xi: 0.3,
                alpha: 0.75,
            },
            1.0 / 0.5,
        ),
        (CalibratedModel::Unified { alpha: 0.7 }, 1.0 / 0.4),
        (
            CalibratedModel::ExtendedUnified {
                alpha: 0.65,
                beta: 1.2,
            },
            1.0 / (1.2 * 0.3),
        ),
    ];
    for (model, r2) in cases {
        let lens = CalibratedLens::new(model, i).unwrap();
        let r = f64::sqrt(r2);
        // The unified models reach the bound exactly; double sphere with ξ ≠ 0 stops short of
        // it, where the projection domain ends (beyond, unprojection would give directions
        // that do not project back).
        let exact = !matches!(model, CalibratedModel::DoubleSphere { xi, .. } if xi != 0.0);
        let r_max = lens.r_max();
        assert!(
            r_max <= r * (1.0 + 1e-12),
            "{model:?}: r_max {r_max} vs {r}"
        );
        if exact {
            assert!(
                (r_max - r).abs() < 1e-9 * r,
                "{model:?}: r_max {r_max} vs {r}"
            );
        }
        // Just inside and just outside the unprojection domain, along a diagonal.
        let at = |s: f64| lens.pixel(DVec2::new(s, s) * (r_max / 2f64.sqrt()));
        assert!(lens.unproject(at(1.0 - 1e-6)).is_some(), "{model:?}");
        assert!(lens.unproject(at(1.0 + 1e-6)).is_none(), "{model:?}");
        let beyond = lens.pixel(DVec2::new(r * 1.000001, 0.0));
        assert!(lens.unproject(beyond).is_none(), "{model:?}");
        // The projection domain: z = cos θ > -w₂ (or -w), θ_max on its boundary.
        let (xi, alpha, beta) = match model {
            CalibratedModel::DoubleSphere { xi, alpha } => (xi, alpha, 1.0),
            CalibratedModel::Unified { alpha } => (0.0, alpha, 1.0),
            CalibratedModel::ExtendedUnified { alpha, beta } => (0.0, alpha, beta),
            _ => unreachable!(),
        };
        let w1 = if alpha <= 0.5 {
            alpha / (1.0 - alpha)
        } else {
            (1.0 - alpha) / alpha
        };
        let theta_edge = if let CalibratedModel::ExtendedUnified { .. } = model {
            // z = -w √(β sin²θ + cos²θ) ⇔ cos²θ (1 - w²(1 - β)) = w² β with cos θ < 0.
            -(w1 * w1 * beta / (1.0 - w1 * w1 * (1.0 - beta))).sqrt()
        } else {
            -(w1 + xi) / (2.0 * w1 * xi + xi * xi + 1.0).sqrt()
        }
        .acos();
        assert!(
            (lens.theta_max() - theta_edge).abs() < 1e-7,
            "{model:?}: θ_max {} vs {theta_edge}",
            lens.theta_max()
        );
        let dir = |t: f64| DVec3::new(t.sin(), 0.0, t.cos());
        assert!(lens.project(dir(theta_edge - 1e-6)).is_some(), "{model:?}");
        assert!(lens.project(dir(theta_edge + 1e-6)).is_none(), "{model:?}");
    }
}

/// A Kannala–Brandt calibration whose θd(θ) turns back is refused for a field of view past
/// the turn, and otherwise clipped there (θd' = 1 + 3k1θ² = 0 at θ = 1/√(-3k1)).
#[test]
fn non_monotonic_calibrations_are_refused_or_clipped() {
    let turn = 1.0 / (0.9f64).sqrt();
    let spec = "kb:fx=300,cx=320,cy=240,k1=-0.3";
    let message = parse_spec(&format!("{spec},fov=180"))
        .unwrap_err()
        .to_string();
    assert!(message.contains("stops increasing"), "{message}");
    assert!(
        message.contains(&format!("{:.2}°", 2.0 * turn.to_degrees())),
        "{message}"
    );
    let clipped = calibrated(spec);
    assert!((clipped.turns_at().unwrap() - turn).abs() < 1e-8);
    assert!((clipped.theta_max() - turn).abs() < 1e-8);
    let within = calibrated(&format!("{spec},fov=110"));
    assert_eq!(within.turns_at(), None);
    assert!((within.theta_max() - 55f64.to_radians()).abs() < 1e-12);
    // A domain that ends: orthographic-like ucm α = 1 reaches 90° only.
    let message = parse_spec("ucm:fx=300,cx=320,cy=240,alpha=1,fov=200")
        .unwrap_err()
        .to_string();
    assert!(message.contains("domain ends at a 180.00°"), "{message}");
    // Polynomial models need their field of view, and must reach it.
    let message = parse_spec("ftheta:cx=1,cy=1,k1=0.01")
        .unwrap_err()
        .to_string();
    assert!(message.contains("needs a field of view"), "{message}");
    let message = parse_spec("ftheta:cx=1,cy=1,k1=0.01,k2=-5e-5,fov=180")
        .unwrap_err()
        .to_string();
    assert!(message.contains("stops increasing"), "{message}");
}

/// The guarded Newton iteration stays within its stated bound and converges to f64
/// precision everywhere in the domain (also for a strongly curved calibration), and the WGSL
/// step count is the bound at its tolerance.
#[test]
fn newton_iterations_stay_within_the_stated_bound() {
    assert_eq!(gpu::NEWTON_STEPS, newton_bound(1.0, gpu::NEWTON_TOLERANCE));
    let specs = [
        CALIBRATED[0],
        "kb:fx=300,cx=320,cy=240,k1=-0.3,fov=120",
        "kb:fx=300,cx=320,cy=240,k1=0.2,k2=-0.05,k3=0.01,k4=-0.001",
        CALIBRATED[5],
        CALIBRATED[6],
    ];
    let mut worst = 0;
    for spec in specs {
        let lens = calibrated(spec);
        let radial = lens.radius(lens.theta_max()).unwrap();
        for k in 0..=2000 {
            let t = f64::from(k) / 2000.0;
            let (x, hi) = match lens.model() {
                CalibratedModel::Scaramuzza { .. } | CalibratedModel::FTheta { .. } => {
                    (t * lens.theta_max(), lens.r_max())
                }
                _ => (t * radial, lens.theta_max()),
            };
            let n = lens.solver_iterations(x).unwrap();
            let bound = newton_bound(hi, 4.0 * f64::EPSILON * hi);
            assert!(n <= bound, "{spec}: {n} iterations at {x} (bound {bound})");
            // Close to a domain that ends where the mapping turns, h' → 0 and Newton slows
            // to the bisection's pace; elsewhere it converges quadratically.
            if t <= 0.9 {
                worst = worst.max(n);
            }
        }
    }
    eprintln!("most iterations below 90% of the domain: {worst}");
    assert!(
        worst <= 8,
        "Newton should converge quadratically: {worst} iterations"
    );
}

/// Calibrated specs print as specs that parse back to the same lens; Mei's ξ form of the
/// unified model converts to the α form.
#[test]
fn calibrated_specs_round_trip() {
    for spec in CALIBRATED {
        let lens = parse_spec(spec).unwrap();
        assert_eq!(parse_spec(&lens.to_string()).unwrap(), lens, "{spec}");
    }
    let mei = calibrated("ucm:fx=600,fy=500,cx=320,cy=240,xi=1.5");
    let alpha = calibrated("ucm:fx=240,fy=200,cx=320,cy=240,alpha=0.6");
    assert_eq!(mei.model(), alpha.model());
    assert!((mei.intrinsics().fx - 240.0).abs() < 1e-12);
    for (spec, needle) in [
        ("kb:fx=300,cx=1", "needs cy"),
        ("kb:fx=300,cx=1,cy=1,k5=1", "takes no parameter \"k5\""),
        ("ds:fx=300,cx=1,cy=1,xi=2,alpha=0.5", "xi = 2"),
        ("eucm:fx=300,cx=1,cy=1,alpha=0.5,beta=0", "beta = 0"),
        ("ucm:fx=-3,cx=1,cy=1,alpha=0.5", "fx = -3"),
        ("ucm:fx=3,cx=1,cy=1", "either alpha or Mei's xi"),
        ("fov-model:fx=3,cx=1,cy=1,w=4", "w = 4"),
        ("scaramuzza:cx=1,cy=1,a0=5,fov=90", "a0 = 5"),
        ("radtan:fx=3,cx=1,cy=1,fov=190", "cannot reach"),
    ] {
        let message = parse_spec(spec).unwrap_err().to_string();
        assert!(
            message.contains(needle),
            "{spec}: {message:?} lacks {needle:?}"
        );
    }
}

/// Fitting the classic mappings finds the one a calibrated lens reduces to, at its focal
/// length, with no residual; a real calibration's best fit and residual are reported.
#[test]
fn classic_fits_find_the_mapping_a_lens_reduces_to() {
    let size = ImageSize::new(640, 480).unwrap();
    for (spec, model, f) in [
        (
            "ucm:fx=200,cx=319.5,cy=239.5,alpha=0.5",
            LensModel::Stereographic,
            200.0,
        ),
        ("kb:fx=150,cx=319.5,cy=239.5", LensModel::Equidistant, 150.0),
        (
            "ftheta:cx=319.5,cy=239.5,k1=0.008,fov=200",
            LensModel::Equidistant,
            125.0,
        ),
    ] {
        let fits = fit::fit_classic(&calibrated(spec), size);
        let best = fits[0];
        assert_eq!(best.model, model, "{spec}: {fits:?}");
        assert!(
            (best.f_pixels - f).abs() < 1e-9 * f,
            "{spec}: f = {}",
            best.f_pixels
        );
        assert!(best.max < 1e-9, "{spec}: residual {}", best.max);
        assert!(
            fits[1].rms > 0.1,
            "{spec}: a second mapping fits too: {fits:?}"
        );
    }
    // TUM-VI's Kannala–Brandt lens over its 512×512 image.
    let tum = fit::fit_classic(
        &calibrated(CALIBRATED[0]),
        ImageSize::new(512, 512).unwrap(),
    );
    assert_eq!(tum.len(), 3, "orthographic cannot reach its 95° half-angle");
    assert!(tum[0].rms < tum[1].rms && tum[1].rms < tum[2].rms);
}

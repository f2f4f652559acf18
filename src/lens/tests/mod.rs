//! Tests of the f64 lens reference: textbook values, domains, specs, round trips, the mask.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use glam::{DVec2, DVec3};

use super::*;

mod calibrated;
mod prescription;

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

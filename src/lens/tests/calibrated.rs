//! The calibrated models: reductions to classic cases, round trips, domains, solvers, fits.

use super::*;

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

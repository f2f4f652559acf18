//! Tests of lens prescriptions (`lens::prescription`): the sequential trace against paraxial
//! optics (ray-transfer matrices, the lensmaker's equation), focus, numerics of nearly flat
//! surfaces and total internal reflection, the chief ray, the published lenses' figures, and
//! files that are refused naming their line.

use glam::DVec3;

use crate::lens::prescription::{Blocked, Prescription, Ray};

/// The lenses shipped under `lenses/`.
fn shipped(name: &str) -> Prescription {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("lenses")
        .join(name);
    Prescription::load(&path).unwrap()
}

fn parse(text: &str) -> Prescription {
    Prescription::parse(text, "test.dat").unwrap()
}

/// A ray parallel to the axis at height `y`, starting 1 mm in front of the front vertex.
fn parallel(y: f64) -> Ray {
    Ray {
        origin: DVec3::new(y, 0.0, -1.0),
        direction: DVec3::Z,
    }
}

/// Where `ray` crosses the plane at axial position `z`: its height.
fn height_at(ray: &Ray, z: f64) -> f64 {
    ray.origin.x + (z - ray.origin.z) * ray.direction.x / ray.direction.z
}

/// A singlet of radii 50 and -50 mm in glass of index 1.5, `t` mm thick, behind a stop:
/// the thick-lens form of the lensmaker's equation gives its focal length,
/// 1/f = (n - 1) (1/R1 - 1/R2 + (n - 1) t / (n R1 R2)), and its back focal length
/// f (1 - (n - 1) t / (n R1)) (Hecht, "Optics", 5th ed., section 6.1).
#[test]
fn a_singlet_follows_the_lensmakers_equation() {
    for t in [1e-6, 2.0, 10.0] {
        let lens = parse(&format!("0 1 0 20\n50 {t} 1.5 30\n-50 0 1 30\n"));
        let (n, r1, r2) = (1.5, 50.0, -50.0);
        let f = 1.0 / ((n - 1.0) * (1.0 / r1 - 1.0 / r2 + (n - 1.0) * t / (n * r1 * r2)));
        let bfl = f * (1.0 - (n - 1.0) * t / (n * r1));
        assert!(
            (lens.efl() - f).abs() <= 1e-12 * f,
            "t {t}: {} vs {f}",
            lens.efl()
        );
        assert!(
            (lens.bfl() - bfl).abs() <= 1e-12 * f,
            "t {t}: {} vs {bfl}",
            lens.bfl()
        );
    }
    // Thin: the classic lensmaker's 1/f = (n - 1)(1/R1 - 1/R2) = 1/50.
    let thin = parse("0 1 0 20\n50 1e-9 1.5 30\n-50 0 1 30\n");
    assert!((thin.efl() - 50.0).abs() < 1e-6);
}

/// A paraxial ray traced through each lens's glass leaves at the slope and height its
/// ray-transfer matrix gives: the focal lengths agree to the paraxial approximation's order
/// ((h / R)², here below 1e-9 of them).
#[test]
fn the_trace_agrees_with_the_ray_transfer_matrices() {
    for name in ["fisheye-10mm.dat", "dgauss-50mm.dat"] {
        let lens = shipped(name);
        let y = 1e-5 * lens.entrance_pupil().0;
        let out = lens.trace(parallel(y)).unwrap();
        let slope = out.direction.x / out.direction.z;
        let efl = -y / slope;
        let bfl = -height_at(&out, lens.rear_vertex()) / slope;
        let tolerance = 1e-9 * lens.efl().abs();
        assert!(
            (efl - lens.efl()).abs() < tolerance,
            "{name}: {efl} vs {}",
            lens.efl()
        );
        assert!(
            (bfl - lens.bfl()).abs() < tolerance,
            "{name}: {bfl} vs {}",
            lens.bfl()
        );
    }
}

/// A collimated bundle of rays near the axis (out to 1 % of the entrance pupil) meets at the
/// back focal length within 1e-6 mm: far below a pixel (a 1024-pixel image across 36 mm has
/// 35 µm pixels).
#[test]
fn a_collimated_paraxial_bundle_focuses_at_the_back_focal_length() {
    for name in ["fisheye-10mm.dat", "dgauss-50mm.dat"] {
        let lens = shipped(name);
        let focus = lens.rear_vertex() + lens.bfl();
        let pupil = lens.entrance_pupil().0;
        let spot = (1..=10)
            .map(|k| {
                let y = 0.001 * pupil * f64::from(k);
                height_at(&lens.trace(parallel(y)).unwrap(), focus).abs()
            })
            .fold(0.0, f64::max);
        assert!(spot < 1e-6, "{name}: spot {spot} mm");
    }
}

/// Focused at a finite distance, rays from the axial point there (near the axis, where
/// paraxial optics holds) cross the axis at the film the ray-transfer matrix puts behind
/// the rear vertex, within 1e-6 mm; the film moves back as the point comes closer (for the
/// double Gauss at 1 m by about f² / (d − f) ≈ 2.6 mm), and reaches the back focal length at
/// infinity.
#[test]
fn focusing_moves_the_film_to_the_image_of_the_point() {
    for name in ["fisheye-10mm.dat", "dgauss-50mm.dat"] {
        let lens = shipped(name);
        let mut last = lens.bfl();
        for distance in [1e4, 1e3, 300.0] {
            let film = lens.focus_distance(distance).unwrap();
            assert!(film > last, "{name} at {distance} mm: {film} mm");
            last = film;
            let focus = lens.rear_vertex() + film;
            // Rays meeting the front at 1e-5 and 3e-5 of the pupil's radius.
            for height in [1e-5, 3e-5] {
                let slope = height * lens.entrance_pupil().0 / distance;
                let ray = Ray {
                    origin: DVec3::new(0.0, 0.0, -distance),
                    direction: DVec3::new(slope, 0.0, 1.0).normalize(),
                };
                let out = lens.trace(ray).unwrap();
                let crossing = out.origin.z - out.origin.x * out.direction.z / out.direction.x;
                assert!(
                    (crossing - focus).abs() < 1e-6,
                    "{name}: {crossing} vs {focus}"
                );
            }
        }
        assert!((lens.focus_distance(1e12).unwrap() - lens.bfl()).abs() < 1e-6);
    }
    let extension =
        shipped("dgauss-50mm.dat").focus_distance(1e3).unwrap() - shipped("dgauss-50mm.dat").bfl();
    assert!((2.0..3.2).contains(&extension), "{extension} mm");
}

/// The published figures: the fisheye's 10 mm focal length (scaled from 100 mm) and its
/// 155.9° field; the double Gauss's 50 mm at f/2.
#[test]
fn the_shipped_lenses_have_their_published_figures() {
    let fisheye = shipped("fisheye-10mm.dat");
    let dgauss = shipped("dgauss-50mm.dat");
    for (name, lens, efl, f_number) in [
        ("fisheye", &fisheye, 10.0, 4.0),
        ("double Gauss", &dgauss, 50.0, 2.0),
    ] {
        assert!(
            (lens.efl() / efl - 1.0).abs() < 0.03,
            "{name}: {} mm",
            lens.efl()
        );
        assert!(
            (lens.f_number() / f_number - 1.0).abs() < 0.1,
            "{name}: f/{}",
            lens.f_number()
        );
    }
    let field = 2.0 * fisheye.half_field().to_degrees();
    assert!((field - 155.9).abs() < 3.0, "fisheye: {field}°");
    // The double Gauss's 22° half field is its design's; rays get through a little beyond.
    let half = dgauss.half_field().to_degrees();
    assert!((22.0..35.0).contains(&half), "double Gauss: {half}°");
}

/// Chief rays pass through the stop's centre, and the fisheye maps them as fisheyes are
/// designed to: nearly equidistant, r = f θ (within 1 % out to 75°; 0.01 % near the axis,
/// where every lens is r = f tan θ ≈ f θ).
#[test]
fn chief_rays_cross_the_stop_at_its_centre() {
    let lens = shipped("fisheye-10mm.dat");
    let stop = lens.stop();
    let mut last = 0.0;
    for degrees in [1.0, 5.0, 20.0, 40.0, 60.0, 75.0] {
        let theta = f64::to_radians(degrees);
        let chief = lens.chief_ray(theta).unwrap();
        let at_stop = lens.trace_range(chief, 0, stop + 1, false).unwrap();
        assert!(
            at_stop.origin.x.abs() < 1e-9,
            "{degrees}°: {}",
            at_stop.origin.x
        );
        let r = lens.image_height(theta, lens.bfl()).unwrap();
        assert!(r > last, "{degrees}°: {r} mm, not beyond {last} mm");
        last = r;
        let equidistant = lens.efl() * theta;
        let tolerance = if degrees < 10.0 { 1e-4 } else { 1e-2 };
        assert!(
            (r / equidistant - 1.0).abs() < tolerance,
            "{degrees}°: {r} mm, f θ = {equidistant} mm"
        );
    }
}

/// A surface of radius 1e5 mm (nearly flat) met at height 10 mm, by a ray from 0.5 mm in
/// front: the hit's sag is 100 / (R + √(R² − 100)) = 5e-4 mm, found within 1e-14 mm (a few
/// rounding steps of the ray's 0.5 mm); in the sphere's centred frame the same quadratic
/// subtracts numbers of 1e10 and is off by about 1e-11 mm (1e-8 mm at R = 1e7).
#[test]
fn nearly_flat_surfaces_keep_their_precision() {
    for radius in [1e5f64, -1e5, 1e7] {
        let lens = parse(&format!("0 1 0 30\n{radius} 2 1.5 30\n1e9 0 1 30\n"));
        let ray = Ray {
            origin: DVec3::new(10.0, 0.0, 0.5),
            direction: DVec3::Z,
        };
        let out = lens.trace_range(ray, 1, 2, true).unwrap();
        let sag = 100.0 / (radius.abs() + (radius * radius - 100.0).sqrt()) * radius.signum();
        let z = out.origin.z - lens.vertex(1);
        assert!((z - sag).abs() <= 1e-14, "R {radius}: {z} vs {sag}");
    }
}

/// Inside glass of index 1.5, a ray meeting a flat face more than asin(1/1.5) = 41.8° off
/// its normal is reflected: the trace says so; just below, it gets out at Snell's angle.
#[test]
fn total_internal_reflection_stops_a_ray() {
    let lens = parse("0 1 0 40\n1e12 5 1.5 40\n1e12 0 1 40\n");
    let critical = (1.0f64 / 1.5).asin();
    let from_glass = |angle: f64| Ray {
        origin: DVec3::new(0.0, 0.0, lens.vertex(1) + 1.0),
        direction: DVec3::new(angle.sin(), 0.0, angle.cos()),
    };
    assert_eq!(
        lens.trace_range(from_glass(critical + 1e-6), 2, 3, true),
        Err(Blocked::Reflected(2))
    );
    let out = lens
        .trace_range(from_glass(critical - 1e-3), 2, 3, true)
        .unwrap();
    let sin_out = out.direction.x.hypot(out.direction.y);
    assert!((sin_out - 1.5 * (critical - 1e-3).sin()).abs() < 1e-9);
}

/// Rays beyond an aperture are clipped there; stopping down clips more.
#[test]
fn apertures_clip_rays() {
    let lens = parse("0 1 0 10\n50 2 1.5 30\n-50 0 1 30\n");
    assert!(lens.trace(parallel(4.9)).is_ok());
    assert_eq!(lens.trace(parallel(5.1)), Err(Blocked::Aperture(0)));
    let stopped = lens.with_stop_scaled(0.5);
    assert_eq!(stopped.trace(parallel(4.9)), Err(Blocked::Aperture(0)));
    assert!((stopped.f_number() / lens.f_number() - 2.0).abs() < 1e-12);
}

/// Files that are not prescriptions are refused, naming the file, the line and why.
#[test]
fn bad_prescriptions_name_their_line() {
    for (text, line, why) in [
        ("0 1 0 10\n50 2 1.5\n", 2, "3 values"),
        ("0 1 0 10\n50 two 1.5 30\n", 2, "\"two\" is not a number"),
        ("50 2 1.5 30\n-50 0 1 30\n", 2, "no aperture stop"),
        ("0 1 0 10\n0 1 0 10\n50 2 1.5 30\n", 3, "2 aperture stops"),
        ("0 1 0 10\n50 -2 1.5 30\n", 2, "negative"),
        ("0 1 0 10\n10 2 1.5 30\n", 2, "not a cap of its sphere"),
        ("0 1 0 10\n50 2 0.5 30\n", 2, "1 or more"),
        ("0 1 0 10\n50 2 1.5 0\n", 2, "above 0"),
        ("0 1 0 10\n50 2 1.5 nan\n", 2, "finite"),
        ("# nothing\n0 1 0 10\n", 2, "no refracting surface"),
        ("0 1 0 10\n50 2 1.5 30\n", 2, "through air"),
        (
            "0 1 0 10 40\n50 2 1.5 30\n-50 0 1 30\n",
            1,
            "only for glass",
        ),
        ("0 1 0 10\n50 2 1.5 30 -3\n-50 0 1 30\n", 2, "above 0"),
        ("0 1 0 10\n50 2 1.5 30 40 1\n", 2, "6 values"),
    ] {
        let message = Prescription::parse(text, "my.dat").unwrap_err().to_string();
        assert!(
            message.contains(&format!("my.dat, line {line}")) && message.contains(why),
            "{text:?}: {message}"
        );
    }
    let missing = Prescription::load(std::path::Path::new("no/such.dat"))
        .unwrap_err()
        .to_string();
    assert!(
        missing.starts_with("lens prescription no/such.dat: "),
        "{missing}"
    );
}

/// The fisheye's chief rays as a Kannala–Brandt camera at 1024×768: the fit reproduces the
/// traced chief rays within its residual, which is below a tenth of a pixel; its focal length
/// in pixels is the paraxial one; directions project where their chief rays land.
#[test]
fn the_fitted_camera_follows_the_chief_rays() {
    use crate::lens::ImageSize;
    use crate::lens::glass::GlassLens;
    let spec = format!(
        "prescription:{}/lenses/fisheye-10mm.dat",
        env!("CARGO_MANIFEST_DIR")
    );
    let glass = GlassLens::parse(&spec).unwrap();
    let size = ImageSize::new(1024, 768).unwrap();
    let fitted = glass.fitted(size).unwrap();
    assert!(fitted.residual_px < 0.1, "{} px", fitted.residual_px);
    let p = &glass.prescription;
    let pitch = glass.sensor_mm / 1024.0;
    for degrees in [10.0, 40.0, 70.0] {
        let theta = f64::to_radians(degrees);
        let r = p.image_height(theta, p.bfl()).unwrap() / pitch;
        let d = DVec3::new(theta.sin(), 0.0, theta.cos());
        let pixel = fitted.camera.project(d).unwrap();
        let landed = pixel.x - 512.0;
        assert!(
            (landed - r).abs() <= fitted.residual_px + 1e-9,
            "{degrees}°: {landed} px, the chief ray {r} px"
        );
        assert!(pixel.y == 384.0);
    }
    // The default sensor is the image circle: the field's edge lands at the image's edge.
    let edge = p.half_field();
    let d = DVec3::new(edge.sin(), 0.0, edge.cos());
    let x = fitted.camera.project(d).map(|p| p.x);
    assert!(x.is_some_and(|x| (x - 1024.0).abs() < 1.0), "{x:?}");
}

/// Each calibrated model `model=` names reproduces the fisheye's traced chief rays within the
/// residual it reports, at 60 angles across the field, and the residuals rank as the models'
/// freedom does: Kannala–Brandt's five parameters (measured 0.0015 px at 1024×768), the
/// double sphere's three (0.06 px), equidistant's one (1.05 px: Muller's design is within
/// 0.5 % of f θ, not exactly it).
#[test]
fn each_fitted_model_follows_the_chief_rays_within_its_residual() {
    use crate::lens::glass::{FitModel, GlassLens};
    use crate::lens::{CalibratedModel, ImageSize, Lens};
    let spec = format!(
        "prescription:{}/lenses/fisheye-10mm.dat",
        env!("CARGO_MANIFEST_DIR")
    );
    let glass = GlassLens::parse(&spec).unwrap();
    let size = ImageSize::new(1024, 768).unwrap();
    let pitch = glass.sensor_mm / 1024.0;
    let mut residuals = Vec::new();
    for (name, model) in FitModel::ALL {
        let fitted = GlassLens {
            model,
            ..glass.clone()
        }
        .fitted(size)
        .unwrap();
        for k in 1..=60 {
            let theta = 0.99 * glass.half_field * f64::from(k) / 60.0;
            let r = glass
                .prescription
                .image_height(theta, glass.film_mm)
                .unwrap()
                / pitch;
            let pixel = fitted
                .camera
                .project(DVec3::new(theta.sin(), 0.0, theta.cos()));
            let landed = pixel.unwrap().x - 512.0;
            assert!(
                (landed - r).abs() <= fitted.residual_px + 1e-6,
                "{name} at {:.1}°: {landed} px, the chief ray {r} px, residual {}",
                theta.to_degrees(),
                fitted.residual_px
            );
        }
        let Lens::Calibrated(lens) = fitted.camera.lens else {
            panic!("{name} is calibrated");
        };
        let right = match (model, lens.model()) {
            (FitModel::DoubleSphere, CalibratedModel::DoubleSphere { .. }) => true,
            (_, CalibratedModel::KannalaBrandt { k }) => {
                (model == FitModel::Equidistant) == (k == [0.0; 4])
            }
            _ => false,
        };
        assert!(right, "{name}: {}", fitted.camera.lens);
        residuals.push(fitted.residual_px);
    }
    assert!(
        residuals[0] < 0.01 && residuals[1] < 0.2 && residuals[2] < 2.0,
        "{residuals:?}"
    );
    assert!(residuals[0] < residuals[1] && residuals[1] < residuals[2]);
}

/// Light runs a path both ways: a ray traced from the object side through either shipped
/// lens, turned round at the film, traces back out along the line it came in on (to 1e-9 mm
/// and 1e-12 of a unit direction), and one clipped going in is clipped coming back.
#[test]
fn tracing_from_the_film_retraces_the_light() {
    for name in ["fisheye-10mm.dat", "dgauss-50mm.dat"] {
        let lens = shipped(name);
        // Rays about the chief rays of 20 angles, shifted across the pupil and out of the
        // meridional plane.
        let thetas: Vec<f64> = (0..20)
            .map(|k| 0.9 * lens.half_field() * f64::from(k) / 20.0)
            .collect();
        let chiefs = lens.chief_rays(&thetas);
        let pupil = lens.entrance_pupil().0;
        let (mut through, mut clipped) = (0, 0);
        for i in 0..400 {
            let chief = chiefs[i % 20].expect("a chief ray inside the field");
            let direction = chief.direction;
            let h = 3.0 * pupil * ((i / 20) as f64 / 19.0 - 0.5);
            let across = DVec3::new(direction.z, 0.3, -direction.x).normalize();
            let ray = Ray {
                origin: chief.origin + h * across,
                direction,
            };
            let Ok(out) = lens.trace(ray) else {
                // Reversed from behind the rear surface, the same path is blocked too.
                clipped += 1;
                continue;
            };
            let back = lens
                .trace_from_film(Ray {
                    origin: out.origin + out.direction,
                    direction: -out.direction,
                })
                .unwrap_or_else(|why| panic!("{name}: ray {i} blocked coming back: {why:?}"));
            through += 1;
            // The returning ray lies on the incoming line, reversed.
            let offset = back.origin - ray.origin;
            let off_line = (offset - offset.dot(direction) * direction).length();
            assert!(
                off_line < 1e-9,
                "{name}: ray {i} returns {off_line:e} mm off its line"
            );
            assert!(
                (back.direction + direction).length() < 1e-12,
                "{name}: ray {i}"
            );
        }
        assert!(
            through > 100 && clipped > 20,
            "{name}: {through} through, {clipped} clipped"
        );
    }
}

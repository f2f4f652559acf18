//! `fisheye lens info`: a prescription's figures against optics worked out by hand, stopping
//! down, a model's field and image circle, and the errors.

use super::{fisheye, stdout};

fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_str(&stdout(&fisheye(args, ""))).unwrap()
}

fn repo(path: &str) -> String {
    format!("{}/{path}", env!("CARGO_MANIFEST_DIR"))
}

/// A singlet behind a stop of 10 mm: nothing is in front of the stop, so it is the entrance
/// pupil, and the f-number is the thick-lens focal length over 10 mm; the default sensor is
/// the image circle, so the circle spans the image's width in pixels.
#[test]
fn a_singlets_figures_are_the_thick_lens_ones() {
    let dir = std::env::temp_dir().join(format!("fisheye-lens-info-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("singlet.dat");
    std::fs::write(&file, "# a singlet\n0 1 0 10\n50 2 1.5 30\n-50 0 1 30\n").unwrap();
    let spec = format!("prescription:{}", file.display());
    let info = json(&["lens", "info", &spec, "--size", "800x600", "--json"]);
    let (n, t) = (1.5, 2.0);
    let f = 1.0 / ((n - 1.0) * (2.0 / 50.0 - (n - 1.0) * t / (n * 2500.0)));
    let number = |key: &str| {
        info[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key}: {info}"))
    };
    assert!((number("efl_mm") - f).abs() < 1e-9, "{info}");
    assert!((number("bfl_mm") - f * (1.0 - (n - 1.0) * t / (n * 50.0))).abs() < 1e-9);
    assert!((number("entrance_pupil_diameter_mm") - 10.0).abs() < 1e-12);
    assert!((number("f_number") - f / 10.0).abs() < 1e-9);
    assert_eq!(number("sensor_mm"), number("image_circle_mm"));
    assert!((number("image_circle_px") - 800.0).abs() < 1e-6);
    assert!((number("efl_px") - f / (number("sensor_mm") / 800.0)).abs() < 1e-6);
    assert!(number("fov_deg") > 0.0 && number("fov_deg") < 180.0);

    // Stopped down to f/8: the stop's diameter scales, the focal length does not.
    let stopped = json(&["lens", "info", &format!("{spec},fstop=8"), "--json"]);
    assert!(
        (stopped["f_number"].as_f64().unwrap() - 8.0).abs() < 1e-9,
        "{stopped}"
    );
    assert_eq!(stopped["efl_mm"], info["efl_mm"]);
    // A given sensor is the image's width.
    let sensor = json(&[
        "lens",
        "info",
        &format!("{spec},sensor=24"),
        "--size",
        "1200x800",
        "--json",
    ]);
    assert!(
        (sensor["pixel_um"].as_f64().unwrap() - 20.0).abs() < 1e-9,
        "{sensor}"
    );

    for (bad, wanted) in [
        (format!("{spec},fstop=1"), "opens to f/"),
        (format!("{spec},focus=0.001"), "too close"),
        (format!("{spec},iso=100"), "unknown key \"iso\""),
        (format!("{spec},sensor=-3"), "above 0"),
        (format!("{spec},rays=chief"), "say glass or fit"),
        (format!("{spec},model=ucm"), "say kb, ds or equidistant"),
        ("prescription:".to_string(), "give the prescription's file"),
        (
            format!("prescription:{}/none.dat", dir.display()),
            "none.dat",
        ),
    ] {
        let out = fisheye(&["lens", "info", &bad], "");
        let message = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && message.contains(wanted),
            "{bad}: {message}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The shipped fisheye: 10 mm, f/4, about 156°, as its design says.
#[test]
fn the_shipped_fisheyes_figures() {
    let spec = format!("prescription:{}", repo("lenses/fisheye-10mm.dat"));
    let text = stdout(&fisheye(&["lens", "info", &spec], ""));
    assert!(text.contains("efl_mm            9.99"), "{text}");
    let info = json(&["lens", "info", &spec, "--json"]);
    let fov = info["fov_deg"].as_f64().unwrap();
    assert!((150.0..160.0).contains(&fov), "{info}");
}

/// A model has a field and an image circle but no physical scale: equidistant r = f θ at
/// f = 0.42 over 180° reaches r = 0.42 π / 2, a circle 0.42 π across in normalized units.
#[test]
fn a_models_field_and_image_circle() {
    let info = json(&[
        "lens",
        "info",
        "equidistant:f=0.42,fov=180",
        "--size",
        "1000x750",
        "--json",
    ]);
    assert_eq!(info["fov_deg"].as_f64().unwrap(), 180.0);
    let circle = info["image_circle"].as_f64().unwrap();
    assert!(
        (circle - 0.42 * std::f64::consts::PI).abs() < 1e-12,
        "{info}"
    );
    assert!((info["image_circle_px"].as_f64().unwrap() - circle * 500.0).abs() < 1e-9);
    assert!(info["efl_mm"].is_null() && info["f_number"].is_null());
}

/// `--lens prescription:...` renders the colour through the glass, and its mask, projection
/// and calibration follow its chief rays (fitted as Kannala–Brandt, see `lens info`): with the
/// default sensor the image circle spans the image's width, so the middle row is covered to
/// both edges and the corners are not; a direction projects where `lens project` says,
/// upright. What cannot trace the glass says so: a cube map and adaptive sampling (until they
/// do), pointing to `rays=fit`, with which they render the fitted model.
#[test]
fn a_prescription_renders_through_its_glass_and_maps_by_its_chief_rays() {
    let dir = std::env::temp_dir().join(format!("fisheye-glass-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("glass.png");
    let spec = format!("prescription:{}", repo("lenses/fisheye-10mm.dat"));
    let args = ["render", "--lens", &spec, "--size", "160x120", "--spp", "1"];
    stdout(&fisheye(
        &[
            &args[..],
            &["--outputs", "mask", "-o", out.to_str().unwrap()],
        ]
        .concat(),
        "",
    ));
    let bytes = std::fs::read(dir.join("glass.mask.npy")).unwrap();
    let mask: Vec<u8> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    let at = |x: usize, y: usize| mask[y * 160 + x];
    assert_eq!((at(0, 60), at(159, 60), at(80, 0)), (1, 1, 1));
    assert_eq!((at(0, 0), at(159, 119)), (0, 0));
    // A cube map cannot trace the glass: refused, pointing to the fitted model, which renders.
    let small = ["render", "--lens", &spec, "--size", "32x24"];
    let cube = ["--method", "cube-rt", "-o", out.to_str().unwrap()];
    let said = fisheye(&[&small[..], &cube[..]].concat(), "");
    let message = String::from_utf8_lossy(&said.stderr);
    assert!(
        !said.status.success()
            && message.contains("cannot trace a prescription's glass")
            && message.contains("rays=fit"),
        "{message}"
    );
    let fit = format!("{spec},rays=fit");
    let fitted = ["render", "--lens", &fit, "--size", "32x24"];
    stdout(&fisheye(&[&fitted[..], &cube[..]].concat(), ""));
    // Adaptive sampling traces the glass; one ray a pixel is warned about.
    let adaptive = ["--spp", "auto", "-o", out.to_str().unwrap()];
    stdout(&fisheye(&[&small[..], &adaptive[..]].concat(), ""));
    let one = ["--spp", "1", "-o", out.to_str().unwrap()];
    let said = fisheye(&[&small[..], &one[..]].concat(), "");
    let message = String::from_utf8_lossy(&said.stderr);
    assert!(
        said.status.success() && message.contains("--spp 16 or more"),
        "{message}"
    );
    // Straight ahead lands at the centre; 60° to the right, right of it on the middle row.
    let text = stdout(&fisheye(
        &["lens", "project", "--lens", &spec, "--size", "160x120"],
        "0 0 1\n0.8660254 0 0.5\n",
    ));
    let lines: Vec<Vec<f64>> = text.lines().map(super::numbers).collect();
    assert_eq!(lines[0], [80.0, 60.0]);
    assert!(lines[1][0] > 100.0 && lines[1][1] == 60.0, "{text}");

    // From glass to calibration: the calibration file `lens convert` writes maps directions
    // as the prescription does (within the fit's field; the file holds no field).
    let file = dir.join("glass.yaml");
    let convert = ["lens", "convert", "--lens", &spec, "--size", "160x120"];
    let said = stdout(&fisheye(
        &[
            &convert[..],
            &["--format", "opencv-yaml", "-o", file.to_str().unwrap()],
        ]
        .concat(),
        "",
    ));
    assert!(said.contains("largest radial residual"), "{said}");
    let points = "0 0 1\n0.8660254 0 0.5\n0.3 -0.6 0.74\n";
    let from_file = stdout(&fisheye(
        &["lens", "project", "--calib", file.to_str().unwrap()],
        points,
    ));
    let from_glass = stdout(&fisheye(
        &["lens", "project", "--lens", &spec, "--size", "160x120"],
        points,
    ));
    assert_eq!(from_file, from_glass);

    // The other models: `lens fit` lists each with its residual, and the double sphere's file
    // (Basalt's format holds it) projects as the spec with model=ds does.
    let fits = stdout(&fisheye(
        &["lens", "fit", "--lens", &spec, "--size", "160x120"],
        "",
    ));
    for name in ["kb ", "ds ", "equidistant "] {
        assert!(
            fits.lines()
                .any(|l| l.starts_with(name) && l.contains(":fx=")),
            "{fits}"
        );
    }
    let ds = format!("{spec},model=ds");
    let file = dir.join("glass-ds.json");
    let convert = ["lens", "convert", "--lens", &ds, "--size", "160x120"];
    stdout(&fisheye(
        &[
            &convert[..],
            &["--format", "basalt", "-o", file.to_str().unwrap()],
        ]
        .concat(),
        "",
    ));
    let from_file = stdout(&fisheye(
        &["lens", "project", "--calib", file.to_str().unwrap()],
        points,
    ));
    let from_spec = stdout(&fisheye(
        &["lens", "project", "--lens", &ds, "--size", "160x120"],
        points,
    ));
    assert_eq!(from_file, from_spec);
    std::fs::remove_dir_all(&dir).unwrap();
}

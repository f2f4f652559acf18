//! `fisheye bench`, `compare` and `validate`, and calibration files driving the tool.

use super::*;

#[test]
fn bench_and_compare_write_their_reports_into_a_new_folder() {
    let dir = std::env::temp_dir().join("fisheye-cli-study");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = |args: &[&str]| {
        let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&output.stdout).into_owned();
        let errors = String::from_utf8_lossy(&output.stderr).into_owned();
        (output.status.success(), text, errors)
    };
    let common = [
        "--size",
        "32x24",
        "--method",
        "rt,cube-forward",
        "--cube-size",
        "16",
        "--spp",
        "1,4",
    ];
    // No --out: a new numbered folder each time.
    let mut args = vec!["bench", "builtin:few-detailed", "--frames", "2"];
    args.extend(common);
    let (ok, text, errors) = run(&args);
    assert!(ok, "{errors}");
    assert!(text.contains("| rectilinear:f=1 | rt@4spp |"), "{text}");
    assert!(text.contains("Fisheye overhead"), "{text}");
    for file in ["bench.json", "bench.md", "fps.canon-8-15mm@8mm.png"] {
        assert!(dir.join("fisheye-bench-1").join(file).is_file(), "{file}");
    }
    let (ok, _, errors) = run(&args);
    assert!(ok && dir.join("fisheye-bench-2").is_dir(), "{errors}");

    let mut args = vec![
        "compare",
        "--frames",
        "1",
        "--reference-spp",
        "16",
        "-o",
        "cmp",
    ];
    args.extend(common);
    let (ok, text, errors) = run(&args);
    assert!(ok, "{errors}");
    assert!(text.contains("| ꟻLIP |"), "{text}");
    assert!(text.contains("- canon-8-15mm@8mm, MSE (least: "), "{text}");
    for file in [
        "compare.json",
        "compare.md",
        "tradeoff.canon-8-15mm@8mm.png",
        "tradeoff-flip.canon-8-15mm@8mm.png",
        "canon-8-15mm@8mm.cube-forward@16.error.png",
        "rectilinear_f_1.reference.png",
    ] {
        assert!(dir.join("cmp").join(file).is_file(), "{file}");
    }

    // Bad input names the problem.
    let (ok, _, errors) = run(&["bench", "builtin:grid", "--path", "walk", "--frames", "1"]);
    assert!(!ok && errors.contains("no camera path"), "{errors}");
    let (ok, _, errors) = run(&["compare", "--cube-size", "0"]);
    assert!(!ok && errors.contains("--cube-size 0"), "{errors}");
    let (ok, _, errors) = run(&["compare", "--reference-spp", "300"]);
    assert!(
        !ok && errors.contains("--reference-spp 300: 300 samples"),
        "{errors}"
    );
    let (ok, _, errors) = run(&["bench", "--spp", "1,3"]);
    assert!(
        !ok && errors.contains("'3' for '--spp") && errors.contains("3 samples per pixel"),
        "{errors}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--calib`: a Kalibr file drives `lens unproject`/`project` (f64 and GPU agree with the
/// library's reading of it), `lens convert` writes it in another format that reads back the
/// same, and `render` renders at the calibration's resolution; wrong uses are clear errors.
#[test]
fn calibration_files_drive_lens_and_render() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-calib-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let kalibr = dir.join("camchain.yaml");
    std::fs::write(
        &kalibr,
        "cam0:\n  camera_model: ds\n  intrinsics: [-0.18, 0.59, 40.0, 39.5, 47.5, 35.5]\n  \
         distortion_model: none\n  resolution: [96, 72]\ncam1:\n  camera_model: pinhole\n  \
         intrinsics: [60, 60, 47.5, 35.5]\n  distortion_model: equidistant\n  \
         distortion_coeffs: [0.01, -0.002, 0, 0]\n  resolution: [96, 72]\n",
    )
    .unwrap();
    let path = kalibr.to_str().unwrap();
    let library = fisheye_rt::lens::calib::read(&kalibr).unwrap();
    for (index, camera) in library.iter().enumerate() {
        let cam = LensCamera::new(camera.lens, camera.size);
        let pixels = [
            DVec2::new(48.0, 36.0),
            DVec2::new(10.25, 60.5),
            DVec2::new(0.5, 0.5),
        ];
        let input: String = pixels
            .iter()
            .map(|p| format!("{} {}\n", p.x, p.y))
            .collect();
        let index = index.to_string();
        for gpu in [false, true] {
            let mut args = vec![
                "lens",
                "unproject",
                "--calib",
                path,
                "--calib-camera",
                &index,
            ];
            if gpu {
                args.push("--gpu");
            }
            let text = stdout(&fisheye(&args, &input));
            for (line, p) in text.lines().zip(pixels) {
                let want = cam.unproject(p).unwrap();
                let got = DVec3::from_slice(&numbers(line));
                assert!(
                    (got - want).length() < 1e-5,
                    "{index} gpu={gpu}: {p} → {got} vs {want}"
                );
            }
            let dirs: String = pixels
                .iter()
                .map(|&p| cam.unproject(p).unwrap())
                .map(|d| format!("{} {} {}\n", d.x, d.y, d.z))
                .collect();
            args[1] = "project";
            let text = stdout(&fisheye(&args, &dirs));
            for (line, p) in text.lines().zip(pixels) {
                let got = DVec2::from_slice(&numbers(line));
                assert!(
                    got.distance(p) < 1e-3,
                    "{index} gpu={gpu}: {p} came back as {got}"
                );
            }
        }
    }
    let json = dir.join("basalt.json");
    let text = stdout(&fisheye(
        &[
            "lens",
            "convert",
            "--calib",
            path,
            "--format",
            "basalt",
            "-o",
            json.to_str().unwrap(),
        ],
        "",
    ));
    assert!(text.contains("basalt"), "{text}");
    assert_eq!(fisheye_rt::lens::calib::read(&json).unwrap()[0], library[0]);

    // A classic lens converts to its exact calibrated equivalent: the 180° canon preset is
    // Kannala–Brandt with k = 0 and f W/2 pixels of focal length.
    let kalibr = dir.join("canon.yaml");
    let args = [
        "lens",
        "convert",
        "--lens",
        "canon-8-15mm@8mm",
        "--size",
        "512x384",
    ];
    let out = ["--format", "kalibr", "-o", kalibr.to_str().unwrap()];
    let text = stdout(&fisheye(&[&args[..], &out].concat(), ""));
    assert!(text.contains("is exactly kb:fx=107.52"), "{text}");
    let back = fisheye_rt::lens::calib::read(&kalibr).unwrap()[0];
    assert_eq!(
        back.lens.model(),
        CalibratedModel::KannalaBrandt { k: [0.0; 4] }
    );
    assert_eq!(back.lens.intrinsics().fx, 0.42 * 256.0);

    let png = dir.join("ds.png");
    let text = stdout(&fisheye(
        &[
            "render",
            "builtin:default",
            "--calib",
            path,
            "-o",
            png.to_str().unwrap(),
        ],
        "",
    ));
    assert!(text.contains("at 96x72"), "{text}");
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), (96, 72));

    // compare (and bench, which shares its setup) measures the calibrated camera at its
    // resolution, beside the pinhole.
    let cmp = dir.join("cmp");
    let text = stdout(&fisheye(
        &[
            "compare",
            "builtin:grid",
            "--calib",
            path,
            "--method",
            "rt",
            "--frames",
            "1",
            "--spp",
            "1",
            "--reference-spp",
            "4",
            "-o",
            cmp.to_str().unwrap(),
        ],
        "",
    ));
    assert!(text.contains(&format!("| {path} | rt@1spp |")), "{text}");
    assert!(text.contains("| rectilinear:f=1 | rt@1spp |"), "{text}");
    let report = std::fs::read_to_string(cmp.join("compare.md")).unwrap();
    assert!(report.contains("96x72"), "{report}");

    for (args, needle) in [
        (
            vec!["render", "--calib", path, "--size", "10x10"],
            "cannot be used with",
        ),
        (
            vec!["lens", "unproject", "--calib", path, "--calib-camera", "2"],
            "holds 2 camera(s)",
        ),
        (vec!["lens", "project"], "give a lens"),
        (
            vec![
                "lens",
                "convert",
                "--lens",
                "orthographic:f=0.66",
                "--format",
                "kalibr",
                "-o",
                "x",
            ],
            "kalibr calibration format cannot express ucm",
        ),
        (
            vec![
                "lens",
                "unproject",
                "--lens",
                "kb:fx=300,cx=1,cy=1,k1=-0.3,fov=180",
            ],
            "stops increasing",
        ),
    ] {
        let output = fisheye(&args, "");
        assert!(!output.status.success(), "{args:?} succeeded");
        let message = String::from_utf8_lossy(&output.stderr);
        assert!(message.contains(needle), "{args:?}: {message}");
    }
    let clipped = fisheye(
        &["lens", "unproject", "--lens", "kb:fx=300,cx=1,cy=1,k1=-0.3"],
        "",
    );
    assert!(String::from_utf8_lossy(&clipped.stderr).contains("warning: kb: the mapping stops"));
    // The same lens on an image that ends before the clip (its corners at θd 0.3, the turn at
    // 0.70): nothing to warn about.
    let unseen = fisheye(
        &[
            "lens",
            "unproject",
            "--lens",
            "kb:fx=300,cx=1,cy=1,k1=-0.3",
            "--size",
            "64x64",
        ],
        "",
    );
    assert!(
        unseen.status.success() && unseen.stderr.is_empty(),
        "{unseen:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `validate` writes its report, overlays, point lists and plot, passes a right lens (from a
/// spec or a calibration file), and exits non-zero, naming the lens, when one fails.
#[test]
fn validate_reports_and_fails_loudly() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-validate-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("v");
    let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args([
            "validate",
            "--lens",
            "samyang-7.5mm",
            "--size",
            "320x320",
            "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let text = stdout(&output);
    assert!(text.contains("| samyang-7.5mm | 320x320 |"), "{text}");
    for file in [
        "validate.json",
        "validate.md",
        "overlay.samyang-7.5mm.png",
        "points.samyang-7.5mm.csv",
        "errors.png",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("validate.json")).unwrap()).unwrap();
    let lens = &json["lenses"][0];
    assert_eq!(lens["passed"], true);
    assert!(lens["checked"].as_u64().unwrap() > 50);
    assert_eq!(lens["checked"], lens["matched"]);
    let overlay = image::open(out.join("overlay.samyang-7.5mm.png")).unwrap();
    assert_eq!((overlay.width(), overlay.height()), (960, 960));
    let csv = std::fs::read_to_string(out.join("points.samyang-7.5mm.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + lens["projected"].as_u64().unwrap() as usize
    );

    // A calibration file: its camera at its resolution, named by the file.
    let spec = CalibratedModel::EXAMPLES[1];
    let calibration = fisheye_rt::lens::calib::Calibration {
        lens: match parse_spec(spec).unwrap() {
            fisheye_rt::lens::Lens::Calibrated(lens) => lens,
            _ => unreachable!("{spec} is calibrated"),
        },
        size: ImageSize::new(512, 512).unwrap(),
        line_delay: 0.0,
    };
    let file = dir.join("ds.json");
    let text =
        fisheye_rt::lens::calib::write(&calibration, fisheye_rt::lens::calib::CalibFormat::Basalt)
            .unwrap();
    std::fs::write(&file, text).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args(["validate", "--calib"])
        .arg(&file)
        .arg("-o")
        .arg(dir.join("c"))
        .output()
        .unwrap();
    let text = stdout(&output);
    assert!(
        text.contains("ds.json | 512x512 |") && text.contains("| yes |"),
        "{text}"
    );

    // Too small an image to check a single corner: a failure, named.
    let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args([
            "validate",
            "--lens",
            "equidistant:f=0.3",
            "--size",
            "48x48",
            "-o",
        ])
        .arg(dir.join("f"))
        .output()
        .unwrap();
    let errors = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        errors.contains("1 of 1 lens(es) failed validation: equidistant:f=0.3"),
        "{errors}"
    );
    assert!(dir.join("f").join("validate.md").is_file());
    let output = fisheye(&["validate", "--supersample", "0"], "");
    let errors = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && errors.contains("--supersample 0"),
        "{errors}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

//! Calibration files: OpenCV YAML/XML, Kalibr and Basalt, read against values typed in from
//! the files (independent of our writer), written and read back, and bad files refused with
//! the line or key at fault.

use std::path::PathBuf;

use fisheye_rt::lens::calib::{self, CalibFormat, Calibration};
use fisheye_rt::lens::{CalibratedModel, parse_spec};

/// OpenCV's calibration sample writes a `cv::fisheye` result like this (values: TUM-VI cam0).
const OPENCV_FISHEYE_YAML: &str = "%YAML:1.0
---
calibration_time: \"Sat 21 Nov 2026 10:00:00 UTC\"
nr_of_frames: 40
image_width: 512
image_height: 512
board_width: 6
board_height: 6
square_size: 6.0000000000000005e-02
flags: 0
fisheye_model: 1
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1.9097847715128717e+02, 0., 2.5493170605935475e+02, 0.,
       1.9097330705212260e+02, 2.5689744289965040e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 4
   cols: 1
   dt: d
   data: [ 3.4823894022493434e-03, 7.1503484521622570e-04,
       -2.0532361418706202e-03, 2.0293673591811182e-04 ]
avg_reprojection_error: 1.9e-01
";

/// The same sample's pinhole result as XML (values: EuRoC MAV cam0).
const OPENCV_PINHOLE_XML: &str = "<?xml version=\"1.0\"?>
<opencv_storage>
<image_width>752</image_width>
<image_height>480</image_height>
<camera_matrix type_id=\"opencv-matrix\">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    458.654 0. 367.215 0. 457.296 248.375 0. 0. 1.</data></camera_matrix>
<distortion_coefficients type_id=\"opencv-matrix\">
  <rows>5</rows>
  <cols>1</cols>
  <dt>d</dt>
  <data>
    -0.28340811 0.07395907 0.00019359 1.76187114e-05 0.</data></distortion_coefficients>
</opencv_storage>
";

/// A Kalibr camchain with the three models it shares with us beyond the pinhole.
const KALIBR: &str = "cam0:
  cam_overlaps: [1]
  camera_model: pinhole
  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
  distortion_model: radtan
  intrinsics: [458.654, 457.296, 367.215, 248.375]
  resolution: [752, 480]
  rostopic: /cam0/image_raw
cam1:
  camera_model: ds
  intrinsics: [-0.18, 0.59, 158.28, 158.24, 254.9, 256.9]
  distortion_model: none
  distortion_coeffs: []
  resolution: [512, 512]
cam2:
  camera_model: omni
  intrinsics: [1.5, 600.0, 500.0, 319.5, 239.5]
  distortion_model: none
  resolution: [640, 480]
";

/// Basalt's calibration JSON (abridged: extrinsics and noise left out).
const BASALT: &str = r#"{
    "value0": {
        "T_imu_cam": [],
        "intrinsics": [
            {
                "camera_type": "kb4",
                "intrinsics": {
                    "fx": 190.97847715128717, "fy": 190.9733070521226,
                    "cx": 254.93170605935475, "cy": 256.8974428996504,
                    "k1": 0.0034823894022493434, "k2": 0.0007150348452162257,
                    "k3": -0.0020532361418706202, "k4": 0.00020293673591811182
                }
            },
            {
                "camera_type": "eucm",
                "intrinsics": {
                    "fx": 252.6, "fy": 252.5, "cx": 254.9, "cy": 256.9,
                    "alpha": 0.64, "beta": 1.09
                }
            }
        ],
        "resolution": [[512, 512], [512, 512]],
        "vignette": []
    }
}"#;

fn only(text: &str, format: CalibFormat) -> Vec<Calibration> {
    assert_eq!(CalibFormat::detect(text), Some(format));
    calib::parse(text, format).unwrap_or_else(|e| panic!("{format:?}: {e}"))
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

/// Each format's values land where they belong, the principal point moved by half a pixel.
#[test]
fn files_read_to_the_values_they_hold() {
    let [tum] = only(OPENCV_FISHEYE_YAML, CalibFormat::OpenCvYaml)[..] else {
        panic!()
    };
    assert_eq!((tum.size.width, tum.size.height), (512, 512));
    let i = tum.lens.intrinsics();
    assert!(close(i.fx, 190.97847715128717) && close(i.fy, 190.9733070521226));
    assert!(close(i.cx, 255.43170605935475) && close(i.cy, 257.3974428996504));
    assert_eq!(
        tum.lens.model(),
        CalibratedModel::KannalaBrandt {
            k: [
                3.4823894022493434e-03,
                7.150_348_452_162_257e-4,
                -2.0532361418706202e-03,
                2.0293673591811182e-04
            ]
        }
    );

    let [euroc] = only(OPENCV_PINHOLE_XML, CalibFormat::OpenCvXml)[..] else {
        panic!()
    };
    assert_eq!((euroc.size.width, euroc.size.height), (752, 480));
    assert!(close(euroc.lens.intrinsics().cx, 367.715));
    assert_eq!(
        euroc.lens.model(),
        CalibratedModel::RadTan {
            k: [-0.28340811, 0.07395907, 0.0],
            p: [0.00019359, 1.76187114e-05]
        }
    );

    let kalibr = only(KALIBR, CalibFormat::Kalibr);
    assert_eq!(kalibr.len(), 3);
    assert_eq!(kalibr[0].lens, euroc.lens);
    assert_eq!(
        kalibr[1].lens.model(),
        CalibratedModel::DoubleSphere {
            xi: -0.18,
            alpha: 0.59
        }
    );
    // Mei's ξ = 1.5, γ = 600: α = 0.6, f = 240.
    assert_eq!(
        kalibr[2].lens.model(),
        CalibratedModel::Unified { alpha: 0.6 }
    );
    assert!(close(kalibr[2].lens.intrinsics().fx, 240.0));
    assert!(close(kalibr[2].lens.intrinsics().fy, 200.0));

    let basalt = only(BASALT, CalibFormat::Basalt);
    assert_eq!(basalt.len(), 2);
    assert_eq!(basalt[0].lens, tum.lens);
    assert_eq!(
        basalt[1].lens.model(),
        CalibratedModel::ExtendedUnified {
            alpha: 0.64,
            beta: 1.09
        }
    );
}

/// Whether `format` can express `model`, from the formats' own documentation (the README's
/// list): OpenCV has `cv::fisheye` (Kannala–Brandt) and radial-tangential; Kalibr has
/// `pinhole` with `equidistant`, `radtan` (four coefficients: k3 must be zero) or `fov`, and
/// `omni` (Mei's ξ form of the unified model, ξ = α/(1-α): α < 1), `ds` and `eucm`; Basalt has
/// `kb4`, `ds`, `eucm`, `ucm`, `fov` and `pinhole` (radial-tangential with no distortion).
fn expresses(format: CalibFormat, model: CalibratedModel) -> bool {
    use CalibratedModel as M;
    match format {
        CalibFormat::OpenCvYaml | CalibFormat::OpenCvXml => {
            matches!(model, M::KannalaBrandt { .. } | M::RadTan { .. })
        }
        CalibFormat::Kalibr => match model {
            M::KannalaBrandt { .. } | M::Fov { .. } => true,
            M::DoubleSphere { .. } | M::ExtendedUnified { .. } => true,
            M::RadTan { k, .. } => k[2] == 0.0,
            M::Unified { alpha } => alpha < 1.0,
            _ => false,
        },
        CalibFormat::Basalt => match model {
            M::KannalaBrandt { .. } | M::DoubleSphere { .. } | M::ExtendedUnified { .. } => true,
            M::Unified { .. } | M::Fov { .. } => true,
            M::RadTan { k, p } => k == [0.0; 3] && p == [0.0; 2],
            _ => false,
        },
    }
}

/// Whether YAML 1.1 (PyYAML's resolver, the regular expression of the YAML 1.1 float type,
/// yaml.org/type/float.html, less the forms the writer never makes: a leading point,
/// sexagesimal, infinities, NaN) reads `text` as a float: digits, a point, digits, and an
/// exponent only with its sign.
fn yaml_1_1_float(text: &str) -> bool {
    let unsigned = text.strip_prefix(['-', '+']).unwrap_or(text);
    let (body, exponent) = match unsigned.split_once(['e', 'E']) {
        Some((body, exponent)) => (body, Some(exponent)),
        None => (unsigned, None),
    };
    let digits = |s: &str| s.bytes().all(|c| c.is_ascii_digit() || c == b'_');
    let exponent_ok = exponent.is_none_or(|e| {
        e.len() > 1 && (e.starts_with('-') || e.starts_with('+')) && digits(&e[1..])
    });
    match body.split_once('.') {
        Some((whole, fraction)) => {
            exponent_ok && !whole.is_empty() && digits(whole) && digits(fraction)
        }
        None => false,
    }
}

#[test]
fn the_yaml_1_1_float_form_is_what_pyyaml_takes() {
    for float in ["230.0", "2.3e+2", "-1.5e-5", "0.0", "1.", "+3.25"] {
        assert!(yaml_1_1_float(float), "{float}");
    }
    // PyYAML reads these as strings (or integers).
    for not in ["2.3e2", "1e-5", "230", "1.0e5", "abc"] {
        assert!(!yaml_1_1_float(not), "{not}");
    }
}

/// Every model a format can express (and only those) is written, and survives reading back
/// exactly (the unified model through Kalibr's ξ form to rounding): the same model, every
/// parameter by name, the intrinsics, the size and the field of view. The rest is a clear
/// error.
#[test]
fn written_files_read_back() {
    let size = fisheye_rt::lens::ImageSize::new(512, 512).unwrap();
    for spec in CalibratedModel::EXAMPLES.iter().copied().chain([
        "radtan:fx=300,cx=255.5,cy=255.5",
        "radtan:fx=300,cx=255.5,cy=255.5,k1=-0.2,k2=0.05,p1=0.001,p2=-0.002",
        "radtan:fx=300,cx=255.5,cy=255.5,k1=-0.2,k2=0.05,p1=0.001,p2=-0.002,k3=0.01",
        "radtan:fx=300,cx=255.5,cy=255.5,p1=0.001",
        "ucm:fx=300,cx=255.5,cy=255.5,alpha=1",
    ]) {
        let lens = *parse_spec(spec).unwrap().calibrated().unwrap();
        let calibration = Calibration {
            lens,
            size,
            line_delay: 0.0,
        };
        for (name, format) in CalibFormat::ALL {
            let written = calib::write(&calibration, format);
            assert_eq!(
                written.is_ok(),
                expresses(format, lens.model()),
                "{spec} as {name}: {written:?}"
            );
            match written {
                Ok(text) => {
                    if format == CalibFormat::Basalt {
                        // Another reader (serde_json) sees the same document.
                        let doc: serde_json::Value = serde_json::from_str(&text)
                            .unwrap_or_else(|e| panic!("{spec}: not JSON to serde_json: {e}"));
                        let camera = &doc["value0"]["intrinsics"][0];
                        assert_eq!(
                            camera["intrinsics"]["fx"].as_f64(),
                            Some(lens.intrinsics().fx)
                        );
                        assert_eq!(doc["value0"]["resolution"][0][0].as_u64(), Some(512));
                    }
                    if format == CalibFormat::Kalibr {
                        // Kalibr reads with PyYAML, a YAML 1.1 reader: every number of the
                        // intrinsics and coefficients must be a float to it, not a string.
                        for line in text.lines().filter(|l| l.contains("s: [")) {
                            let list = line.split_once('[').unwrap().1.trim_end_matches(']');
                            for number in list.split(", ").filter(|n| !n.is_empty()) {
                                assert!(
                                    yaml_1_1_float(number),
                                    "{spec}: {number:?} is a string to YAML 1.1\n{text}"
                                );
                            }
                        }
                    }
                    let back = calib::parse(&text, format)
                        .unwrap_or_else(|e| panic!("{spec} as {name}: {e}\n{text}"));
                    let back = back[0];
                    assert_eq!(back.size, size, "{spec} as {name}");
                    let (a, b) = (back.lens.intrinsics(), lens.intrinsics());
                    for (x, y) in [(a.fx, b.fx), (a.fy, b.fy), (a.cx, b.cx), (a.cy, b.cy)] {
                        assert!(close(x, y), "{spec} as {name}: {x} vs {y}\n{text}");
                    }
                    let (a, b) = (back.lens.model(), lens.model());
                    assert_eq!(a.name(), b.name(), "{spec} as {name}: model\n{text}");
                    let (pa, pb) = (a.parameters(), b.parameters());
                    let keys = |p: &[(&str, f64)]| {
                        p.iter().map(|(k, _)| k.to_string()).collect::<Vec<_>>()
                    };
                    assert_eq!(keys(&pa), keys(&pb), "{spec} as {name}: parameters\n{text}");
                    for ((key, x), (_, y)) in pa.iter().zip(&pb) {
                        assert!(close(*x, *y), "{spec} as {name}: {key} {x} vs {y}\n{text}");
                    }
                    assert!(
                        close(back.lens.theta_max(), lens.theta_max()),
                        "{spec} as {name}: field of view\n{text}"
                    );
                }
                Err(e) => {
                    let message = e.to_string();
                    assert!(
                        message.contains("cannot express"),
                        "{spec} as {name}: {message}"
                    );
                }
            }
        }
    }
}

/// Bad files name the file and the problem: the YAML line, the missing key, the model.
#[test]
fn bad_files_are_clear_errors() {
    let dir = std::env::temp_dir().join(format!("fisheye-calib-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = |name: &str, text: &str| -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let cases = [
        (
            file("broken.yaml", "cam0:\n  camera_model: pinhole\n  intrinsics: [1, 2\n"),
            "line 4",
        ),
        (file("nothing.yaml", "a: 1\n"), "not a calibration"),
        (
            file("no-matrix.yaml", &OPENCV_FISHEYE_YAML.replace("camera_matrix: !!", "camera_matrx: !!").replace("calibration_time", "camera_matrix_note")),
            "camera_matrix is missing",
        ),
        (
            file("three.yaml", &OPENCV_FISHEYE_YAML.replace("-2.0532361418706202e-03, ", "")),
            "4 distortion_coefficients, not 3",
        ),
        (
            file("model.yaml", &KALIBR.replace("camera_model: ds", "camera_model: fisheye")),
            "cam1: unknown camera_model \"fisheye\"",
        ),
        (
            file("omni-radtan.yaml", &KALIBR.replace("distortion_model: none\n  resolution: [640", "distortion_model: radtan\n  distortion_coeffs: [0, 0, 0, 0]\n  resolution: [640")),
            "omni with distortion_model \"radtan\" is not supported",
        ),
        (file("bad.json", "{ \"value0\": { \"intrinsics\": 3 } }"), "value0.intrinsics"),
        (
            file("alpha.json", &BASALT.replace("\"alpha\": 0.64", "\"alpha\": 1.64")),
            "alpha = 1.64",
        ),
        (file("bad.xml", "<opencv_storage><image_width>5</image_width>"), "not valid XML"),
        (dir.join("missing.yaml"), "cannot read it"),
    ];
    for (path, needle) in cases {
        let message = calib::read(&path).unwrap_err().to_string();
        assert!(message.contains(&path.display().to_string()), "{message}");
        assert!(
            message.contains(needle),
            "{}: {message:?} lacks {needle:?}",
            path.display()
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A classic lens converts to the calibrated model that contains its mapping (equidistant to
/// Kannala–Brandt with k = 0, stereographic and orthographic to the unified model with α = ½
/// and 1, equisolid to the double sphere with ξ = α = 1, rectilinear to radial-tangential
/// with no distortion): every pixel of the image unprojects to the same direction (to 1e-9)
/// or to none on both, and the field of view is kept. Other general-model rates get a fitted
/// Kannala–Brandt polynomial whose stated residual is what the pixels show. Either way the
/// result is written to a file and reads back.
#[test]
fn classic_lenses_convert_to_their_calibrated_equivalents() {
    use fisheye_rt::lens::fit::calibrated_equivalent;
    use fisheye_rt::lens::{ImageSize, Lens, LensCamera, PRESETS};
    use glam::DVec2;
    let size = ImageSize::new(320, 240).unwrap();
    let exact = [
        ("equidistant:f=0.3", "kb"),
        ("equidistant:f=0.5,fov=150", "kb"),
        ("stereographic:f=0.35", "ucm"),
        ("orthographic:f=0.66", "ucm"),
        ("equisolid:f=0.45,fov=260", "ds"),
        ("rectilinear:f=0.5", "radtan"),
        ("general:f=0.4,k1=0.5,k2=0.5", "ucm"),
        ("general:f=0.4,k1=0.8,k2=-1", "ucm"),
    ];
    let presets = PRESETS.iter().map(|p| (p.name, ""));
    for (spec, model) in exact.into_iter().chain(presets) {
        let classic = LensCamera::new(parse_spec(spec).unwrap(), size);
        let equivalent = calibrated_equivalent(&classic).unwrap();
        assert!(equivalent.exact, "{spec}");
        assert!(
            equivalent.residual_px < 1e-9,
            "{spec}: {}",
            equivalent.residual_px
        );
        if !model.is_empty() {
            assert_eq!(equivalent.lens.model().name(), model, "{spec}");
        }
        let calibrated = LensCamera::new(Lens::Calibrated(equivalent.lens), size);
        let mut rays = 0;
        for j in 0..=48 {
            for i in 0..=64 {
                let p = DVec2::new(f64::from(i) * 5.0, f64::from(j) * 5.0);
                match (classic.unproject(p), calibrated.unproject(p)) {
                    (Some(a), Some(b)) => {
                        assert!(a.distance(b) < 1e-9, "{spec} at {p}: {a} vs {b}");
                        rays += 1;
                    }
                    (None, None) => {}
                    // The mask's edge may fall either side by rounding.
                    (a, b) => {
                        let d = a.or(b).unwrap();
                        let edge = classic.lens.theta_max();
                        assert!(
                            (d.z.acos() - edge).abs() < 1e-6,
                            "{spec} at {p}: {a:?} vs {b:?}"
                        );
                    }
                }
            }
        }
        assert!(rays > 500, "{spec}: {rays} rays");
        let file = calib::write(
            &Calibration {
                lens: equivalent.lens,
                size,
                line_delay: 0.0,
            },
            CalibFormat::Basalt,
        );
        if let Ok(text) = file {
            let back = calib::parse(&text, CalibFormat::Basalt).unwrap()[0];
            assert_eq!(back.lens.model(), equivalent.lens.model(), "{spec}");
        }
    }
    // Past the double sphere's 135° an equisolid lens is fitted instead (its whole 180°
    // here); so is a general tan at another rate: its residual is the largest radial
    // difference, measured here along the image's diagonal in pixels.
    let wide = LensCamera::new(parse_spec("equisolid:f=0.45").unwrap(), size);
    let wide = calibrated_equivalent(&wide).unwrap();
    assert!(!wide.exact && wide.residual_px < 0.5, "{wide:?}");
    let spec = "general:f=0.4,k1=0.7,k2=0.7";
    let classic = LensCamera::new(parse_spec(spec).unwrap(), size);
    let fitted = calibrated_equivalent(&classic).unwrap();
    assert!(!fitted.exact);
    assert_eq!(fitted.lens.model().name(), "kb");
    assert!(
        (1e-3..1.0).contains(&fitted.residual_px),
        "{}",
        fitted.residual_px
    );
    let calibrated = LensCamera::new(Lens::Calibrated(fitted.lens), size);
    let centre = DVec2::new(160.0, 120.0);
    let worst = (1..=100)
        .filter_map(|k| {
            let p = centre + DVec2::new(160.0, 120.0) * f64::from(k) / 100.0;
            let d = classic.unproject(p)?;
            Some(calibrated.project(d)?.distance(p))
        })
        .fold(0.0, f64::max);
    assert!(
        worst <= fitted.residual_px * 1.01 + 1e-9,
        "{worst} vs {}",
        fitted.residual_px
    );
    assert!(
        worst > fitted.residual_px * 0.2,
        "{worst} vs {}",
        fitted.residual_px
    );
}

/// Kalibr reads camchains with PyYAML (YAML 1.1): every number of every camchain we write is
/// a float to PyYAML itself (not a string), with the value written. Basalt's JSON, read by
/// Python's `json`, holds the values written. (`.ci/install-lavapipe` installs python3-yaml.)
#[test]
fn written_files_read_back_in_the_tools_own_readers() {
    let dir = std::env::temp_dir().join(format!("fisheye-calib-py-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let size = fisheye_rt::lens::ImageSize::new(640, 480).unwrap();
    let python = |script: &str, file: &std::path::Path| -> Vec<String> {
        let output = std::process::Command::new("python3")
            .args(["-c", script])
            .arg(file)
            .output()
            .expect("python3 runs (install python3-yaml: .ci/install-lavapipe)");
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        String::from_utf8(output.stdout)
            .unwrap()
            .lines()
            .map(String::from)
            .collect()
    };
    // Each number of the lists, as `type value` (repr round-trips a float exactly).
    let kalibr_script = "import sys, yaml\n\
        c = yaml.safe_load(open(sys.argv[1]))['cam0']\n\
        for key in ('intrinsics', 'distortion_coeffs'):\n\
        \x20   for x in c[key]:\n\
        \x20       print(type(x).__name__, repr(x))\n";
    let basalt_script = "import sys, json\n\
        c = json.load(open(sys.argv[1]))['value0']['intrinsics'][0]['intrinsics']\n\
        for x in c.values():\n\
        \x20   print(type(x).__name__, repr(x))\n";
    let mut checked = 0;
    for spec in CalibratedModel::EXAMPLES {
        let lens = *parse_spec(spec).unwrap().calibrated().unwrap();
        let calibration = Calibration {
            lens,
            size,
            line_delay: 0.0,
        };
        for (format, script) in [
            (CalibFormat::Kalibr, kalibr_script),
            (CalibFormat::Basalt, basalt_script),
        ] {
            let Ok(text) = calib::write(&calibration, format) else {
                continue;
            };
            let file = dir.join(format!("cam.{}", format.name()));
            std::fs::write(&file, &text).unwrap();
            // The numbers as written, in order.
            let written: Vec<f64> = match format {
                CalibFormat::Kalibr => text
                    .lines()
                    .filter(|l| l.contains("intrinsics: [") || l.contains("coeffs: ["))
                    .flat_map(|l| {
                        let list = l.split_once('[').unwrap().1.trim_end_matches(']');
                        list.split(", ")
                            .filter(|n| !n.is_empty())
                            .map(|n| n.parse::<f64>().unwrap())
                            .collect::<Vec<_>>()
                    })
                    .collect(),
                _ => text
                    .lines()
                    .filter(|l| {
                        l.trim_start().starts_with('"')
                            && l.contains("\": ")
                            && !l.contains("camera_type")
                    })
                    .filter_map(|l| l.rsplit(": ").next()?.trim_end_matches(',').parse().ok())
                    .collect(),
            };
            let read = python(script, &file);
            assert_eq!(
                read.len(),
                written.len(),
                "{spec} as {}: {read:?}",
                format.name()
            );
            for (line, value) in read.iter().zip(&written) {
                let (kind, number) = line.split_once(' ').unwrap();
                assert_eq!(kind, "float", "{spec} as {}: {line}", format.name());
                assert_eq!(number.parse::<f64>().unwrap(), *value, "{spec}: {line}");
            }
            checked += 1;
        }
    }
    assert!(checked >= 8, "{checked} files checked");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A rolling shutter's `line_delay` (seconds, as Kalibr's rolling-shutter models write it)
/// is read from a camchain, written back (a float to PyYAML, the value read), and refused
/// where it is not a number of seconds of 0 or more; the formats without the key refuse to
/// drop it. A camchain without it is a global shutter.
#[test]
fn a_camchains_line_delay_reads_and_writes_back() {
    let camchain = |line_delay: &str| {
        format!(
            "cam0:\n  camera_model: pinhole\n  intrinsics: [190.9, 190.9, 254.9, 256.9]\n  \
             distortion_model: equidistant\n  distortion_coeffs: [0.0035, 0.0007, -0.002, 0.0002]\n  \
             resolution: [512, 512]\n{line_delay}"
        )
    };
    let rolling = only(&camchain("  line_delay: 2.9e-05\n"), CalibFormat::Kalibr);
    assert_eq!(rolling[0].line_delay, 2.9e-5);
    assert_eq!(only(&camchain(""), CalibFormat::Kalibr)[0].line_delay, 0.0);
    let written = calib::write(&rolling[0], CalibFormat::Kalibr).unwrap();
    assert!(written.contains("line_delay: 2.9e-5\n"), "{written}");
    assert_eq!(only(&written, CalibFormat::Kalibr), rolling);
    let dir = std::env::temp_dir().join(format!("fisheye-line-delay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("camchain.yaml");
    std::fs::write(&file, &written).unwrap();
    let output = std::process::Command::new("python3")
        .args([
            "-c",
            "import sys, yaml\nd = yaml.safe_load(open(sys.argv[1]))['cam0']['line_delay']\n\
             print(type(d).__name__, repr(d))",
        ])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(
        String::from_utf8_lossy(&output.stdout).trim(),
        "float 2.9e-05"
    );
    std::fs::remove_dir_all(dir).unwrap();
    for format in [CalibFormat::Basalt, CalibFormat::OpenCvYaml] {
        let error = calib::write(&rolling[0], format).unwrap_err().to_string();
        assert!(error.contains("line_delay"), "{error}");
    }
    for bad in ["-1e-5", "fast"] {
        let error = calib::parse(
            &camchain(&format!("  line_delay: {bad}\n")),
            CalibFormat::Kalibr,
        )
        .unwrap_err();
        assert!(error.contains("line_delay"), "{bad}: {error}");
    }
}

//! The `fisheye` commands: each error said once, and outputs refused before any work.

use super::*;

/// The clauses of an error message (split at ": " and "; "), each of which must appear once:
/// a cause repeated in its own context ("X: reason: reason") reads as two failures.
fn repeated_clause(message: &str) -> Option<String> {
    let clauses: Vec<String> = message
        .split(": ")
        .flat_map(|c| c.split("; "))
        .map(|c| c.trim().to_lowercase())
        .filter(|c| c.len() > 3)
        .collect();
    clauses
        .iter()
        .enumerate()
        .find(|(i, c)| clauses[i + 1..].contains(c))
        .map(|(_, c)| c.clone())
}

/// One of each kind of error in the README's bad-input table, from the command line: exit
/// status 1, the problem named, no panic, no image, and no clause said twice (the OS's reason,
/// the file, the parameter).
/// `fisheye dataset render` of `trajectory` through `cameras` (`--lens SPEC` or `--rig FILE`)
/// into `out`, with `extra` arguments.
fn dataset<'a>(
    trajectory: &'a str,
    cameras: &'a str,
    which: &'a str,
    out: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut args = vec![
        "dataset",
        "render",
        "--trajectory",
        trajectory,
        cameras,
        which,
    ];
    args.extend(["-o", out]);
    args.extend(extra);
    args
}

#[test]
fn every_error_says_each_clause_once() {
    assert_eq!(
        repeated_clause("a.obj: cannot read: No such file: No such file"),
        Some("no such file".into())
    );
    assert_eq!(
        repeated_clause("a.obj: line 4: broken; line 5: broken"),
        Some("broken".into())
    );
    assert_eq!(repeated_clause("a.obj: line 4: face vertex \"x\""), None);

    let dir = temp_dir("once");
    let at = |name: &str| dir.join(name).to_str().unwrap().to_string();
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    std::fs::create_dir_all(dir.join("folder.png")).unwrap();
    let status = std::process::Command::new("mkfifo")
        .arg(at("pipe.obj"))
        .status()
        .unwrap();
    assert!(status.success());
    let files: [(&str, String); 14] = [
        ("bad-face.obj", format!("{TRIANGLE}f 1 2 x\n")),
        ("bad-index.obj", format!("{TRIANGLE}f 1 2 9\n")),
        (
            "bad-mtl.obj",
            format!("mtllib bad.mtl\n{TRIANGLE}f 1 2 3\n"),
        ),
        ("bad.mtl", "newmtl m\nKd 1\n".into()),
        ("empty.obj", TRIANGLE.into()),
        ("text.txt", "hello\n".into()),
        (
            "key.toml",
            "[[mesh]]\npath = \"tri.obj\"\ncolour = 1\n".into(),
        ),
        (
            "scale.toml",
            "[[mesh]]\npath = \"tri.obj\"\nscale = 0.0\n".into(),
        ),
        ("zero.toml", "[[mesh]]\npath = \"/dev/zero\"\n".into()),
        ("tri.obj", format!("{TRIANGLE}f 1 2 3\n")),
        ("calib.yaml", "cam0:\n  camera_model: pinhole\n".into()),
        ("bad.tum", "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1 9\n".into()),
        (
            "two.yaml",
            "cam0:\n  camera_model: pinhole\n  intrinsics: [10, 10, 8, 6]\n  resolution: [16, \
             12]\ncam1:\n  camera_model: pinhole\n  intrinsics: [10, 10, 8, 6]\n  \
             resolution: [16, 12]\n"
                .into(),
        ),
        ("other/plan.json", "{}\n".into()),
    ];
    std::fs::create_dir_all(dir.join("other")).unwrap();
    for (name, text) in &files {
        write(&dir, name, text.as_bytes());
    }
    let out = at("out.png");
    let small = ["--size", "32x24", "--spp", "1"];
    const TUM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dataset/room-loop.tum");
    const LENS: &str = "equidistant:f=1";
    let (set, other) = (at("set"), at("other"));
    type Case<'a> = (Vec<String>, Vec<(&'a str, &'a str)>, &'a str);
    let cases: Vec<Case> = [
        (
            vec!["render", "/nonexistent/scene.obj"],
            vec![],
            "scene.obj",
        ),
        (vec!["render", &at("folder.obj")], vec![], "a folder"),
        (vec!["render", &at("pipe.obj")], vec![], "a named pipe"),
        (vec!["render", &at("text.txt")], vec![], ".toml"),
        (vec!["render", "builtin:nope"], vec![], "nope"),
        (vec!["render", &at("bad-face.obj")], vec![], "line 4"),
        (vec!["render", &at("bad-index.obj")], vec![], "line 4"),
        (vec!["render", &at("bad-mtl.obj")], vec![], "bad.mtl"),
        (vec!["render", &at("empty.obj")], vec![], "empty.obj"),
        (vec!["render", &at("key.toml")], vec![], "colour"),
        (vec!["render", &at("scale.toml")], vec![], "scale"),
        (vec!["render", &at("zero.toml")], vec![], "a device"),
        (
            vec!["render", &at("tri.obj")],
            vec![("FISHEYE_MAX_INPUT_MIB", "0")],
            "budget",
        ),
        (vec!["render", "--lens", "nope:f=1"], vec![], "nope"),
        (vec!["render", "--lens", "equidistant:f=0"], vec![], "f"),
        (
            vec!["render", "--lens", "rectilinear:f=1,fov=180"],
            vec![],
            "180",
        ),
        (
            vec!["render", "--calib", &at("calib.yaml")],
            vec![],
            "calib.yaml",
        ),
        (vec!["render", "--size", "0x10"], vec![], "0x10"),
        (vec!["render", "--camera", "1,2:3"], vec![], "X,Y,Z"),
        (vec!["render", "--max-depth", "9"], vec![], "max-depth"),
        (vec!["render", "--exposure", "nan"], vec![], "exposure"),
        (vec!["render", "-o", &at("out.jpg")], vec![], "out.jpg"),
        (vec!["render", "-o", "/dev/full"], vec![], "/dev/full"),
        (vec!["render", "-o", &at("folder.png")], vec![], "a folder"),
        (
            vec!["render", "-o", "/proc/nope/x.png"],
            vec![],
            "/proc/nope",
        ),
        // A folder no one may write into: sysfs refuses new files, even to root.
        (
            vec!["render", "-o", "/sys/fisheye.png"],
            vec![],
            "/sys/fisheye.png",
        ),
        (
            vec!["render", "-o", "/sys/fisheye.png", "--outputs", "range"],
            vec![],
            "/sys/fisheye",
        ),
        (
            vec!["compare", "-o", "/sys/fisheye-compare"],
            vec![],
            "/sys/fisheye-compare",
        ),
        (
            vec!["bench", "--frames", "0"],
            vec![],
            "at least one timed frame",
        ),
        (
            vec!["compare", "--frames", "0"],
            vec![],
            "at least one timed frame",
        ),
        (
            vec!["render"],
            vec![("FISHEYE_INJECT_FAULT", "device-lost")],
            "device was lost",
        ),
        (
            dataset(&at("bad.tum"), "--lens", LENS, &set, &[]),
            vec![],
            "line 2: 9 fields",
        ),
        (
            dataset("/dev/zero", "--lens", LENS, &set, &[]),
            vec![],
            "a device",
        ),
        (
            dataset(&at("tri.obj"), "--lens", LENS, &set, &[]),
            vec![],
            "tri.obj: not a trajectory",
        ),
        (
            dataset(TUM, "--rig", &at("two.yaml"), &set, &[]),
            vec![],
            "cam1: no T_cn_cnm1",
        ),
        (
            dataset(TUM, "--lens", LENS, &set, &["--shard", "4/4"]),
            vec![],
            "shard 4 of 4 does not exist",
        ),
        (
            dataset(TUM, "--lens", LENS, &set, &["--t-body-rig", "1,2"]),
            vec![],
            "--t-body-rig \"1,2\" has 2 numbers",
        ),
        (
            dataset(TUM, "--lens", LENS, &set, &["--resume"]),
            vec![],
            "holds no dataset",
        ),
        (
            dataset(TUM, "--lens", LENS, &other, &[]),
            vec![],
            "plan of another dataset",
        ),
        (
            vec!["dataset", "merge", &at("folder.obj")],
            vec![],
            "holds no dataset",
        ),
    ]
    .into_iter()
    .map(|(args, env, needle)| {
        let mut args: Vec<String> = args.into_iter().map(String::from).collect();
        let merge = args.get(1).is_some_and(|a| a == "merge");
        if !args.iter().any(|a| a == "-o") && !merge {
            args.extend(["-o".to_string(), out.clone()]);
        }
        // Small and quick, unless the case sets the size (a calibration brings its own).
        let sized = args
            .iter()
            .any(|a| a == "--calib" || a == "--size" || a == "--rig");
        let keep = if sized { 2 } else { 0 };
        if !merge {
            args.extend(small[keep..].iter().map(|s| s.to_string()));
        }
        (args, env, needle)
    })
    .collect();
    for (args, env, needle) in cases {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_fisheye"))
            .args(&args)
            .envs(env.iter().copied())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        // 2 is clap's status for a value its parser refuses.
        let code = output.status.code();
        assert!(matches!(code, Some(1 | 2)), "{args:?}: {code:?} {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(!Path::new(&out).exists(), "{args:?} wrote an image");
        for line in stderr.lines().filter(|l| l.starts_with("error")) {
            assert_eq!(repeated_clause(line), None, "{args:?}: {line}");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Every command that writes refuses an output it could not write before any work: the
/// device is never made (no `adapter:` line), the path is named, nothing is left behind.
#[test]
fn unwritable_outputs_are_refused_before_any_work() {
    let dir = temp_dir("unwritable");
    let tum = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dataset/room-loop.tum");
    let small = ["--size", "32x24"];
    let cases: [(&[&str], &str); 8] = [
        (&["render", "-o", "/proc/nope/x.png"], "/proc/nope/x.png"),
        (&["render", "-o", "/sys/fisheye.png"], "/sys/fisheye.png"),
        (
            &["render", "-o", "fisheye-ok.png", "--outputs", "range"],
            "fisheye-ok.range.npy",
        ),
        (
            &["compare", "-o", "/sys/fisheye-compare"],
            "/sys/fisheye-compare",
        ),
        (&["bench", "-o", "/sys/fisheye-bench"], "/sys/fisheye-bench"),
        (
            &["validate", "-o", "/sys/fisheye-validate"],
            "/sys/fisheye-validate",
        ),
        (
            &[
                "dataset",
                "render",
                "--trajectory",
                tum,
                "--lens",
                "equidistant:f=1",
                "-o",
            ],
            "/sys/fisheye-set",
        ),
        (
            &["lens", "demo", "--out", "/sys/fisheye-demo"],
            "/sys/fisheye-demo",
        ),
    ];
    // The range array of the third case has a folder in its way.
    std::fs::create_dir_all(dir.join("fisheye-ok.range.npy")).unwrap();
    for (args, path) in cases {
        let mut args: Vec<&str> = args.to_vec();
        if args[0] == "dataset" {
            args.push(path);
        }
        if args[0] != "lens" {
            args.extend(small);
        }
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_fisheye"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let (stdout, stderr) = (
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr),
        );
        assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(path), "{args:?}: {stderr:?} lacks {path:?}");
        assert!(
            !stdout.contains("adapter:"),
            "{args:?} made a device:\n{stdout}"
        );
    }
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(
        left.len(),
        1,
        "only the folder in the way is there: {left:?}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

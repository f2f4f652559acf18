//! What a run costs the machine, measured on the `fisheye` binary as a child process: peak
//! resident memory grows with the scene's triangles at the rate the README states, and
//! renders running at once on one adapter neither fail nor change each other's images.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fisheye-resources-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `fisheye render SCENE` at a small size into `out` and returns its peak resident set
/// in MiB (the kernel's `ru_maxrss` for that child alone, from `wait4`).
#[expect(
    clippy::zombie_processes,
    reason = "the child is waited for by wait4, which std's Child cannot do"
)]
fn peak_resident_mib(scene: &str, out: &Path) -> f64 {
    let child = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args(["render", scene, "--size", "64x48", "--spp", "1", "-o"])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut status = 0;
    // SAFETY: a zeroed rusage is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: the pid is our own child's, not yet waited for; both pointers are valid.
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as i32);
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "{scene}: status {status}"
    );
    // Linux reports ru_maxrss in KiB.
    usage.ru_maxrss as f64 / 1024.0
}

/// Peak memory for loading, building and rendering a scene is a fixed part (the driver, the
/// kernels) and a part per triangle. Between the default room (19,482 triangles) and
/// `builtin:few-detailed` (600,002) the README's figure is measured; here it is held to
/// within 2x, and the fixed part to the README's bound.
#[test]
fn peak_memory_grows_with_triangles_at_the_stated_rate() {
    let dir = temp_dir("memory");
    let small = peak_resident_mib("builtin:default", &dir.join("small.png"));
    let large = peak_resident_mib("builtin:few-detailed", &dir.join("large.png"));
    let per_triangle = (large - small) * 1_048_576.0 / (600_002.0 - 19_482.0);
    assert!(
        (BYTES_PER_TRIANGLE / 2.0..=BYTES_PER_TRIANGLE * 2.0).contains(&per_triangle),
        "{per_triangle:.0} bytes a triangle ({small:.1} and {large:.1} MiB)"
    );
    assert!(small < FIXED_MIB, "{small:.1} MiB for the default room");
    std::fs::remove_dir_all(dir).unwrap();
}

/// The README's figures ("Memory"): measured 489 bytes a triangle, and for the default room
/// on lavapipe (whose "device" memory is the process's), since texture filtering (2026-11-27),
/// 324 MiB with Mesa's shader cache warm and 403 MiB when the kernels compile in the process
/// (LLVM's working memory; 291 and 359 MiB before it on the same machine), so the bound on
/// the fixed part holds either way.
const BYTES_PER_TRIANGLE: f64 = 490.0;
const FIXED_MIB: f64 = 450.0;

/// Four renders at once on one adapter (on lavapipe they share the CPU) all succeed and
/// write, byte for byte, the image one render alone writes.
#[test]
fn four_renders_at_once_write_what_one_alone_writes() {
    let dir = temp_dir("parallel");
    let render = |name: &str| {
        Command::new(env!("CARGO_BIN_EXE_fisheye"))
            .args([
                "render",
                "builtin:default",
                "--size",
                "96x72",
                "--spp",
                "4",
                "-o",
            ])
            .arg(dir.join(name))
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let alone = render("alone.png").wait_with_output().unwrap();
    assert!(
        alone.status.success(),
        "{}",
        String::from_utf8_lossy(&alone.stderr)
    );
    let expected = std::fs::read(dir.join("alone.png")).unwrap();
    let children: Vec<_> = (0..4)
        .map(|k| render(&format!("at-once-{k}.png")))
        .collect();
    for (k, child) in children.into_iter().enumerate() {
        let output = child.wait_with_output().unwrap();
        assert!(
            output.status.success(),
            "render {k}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        let got = std::fs::read(dir.join(format!("at-once-{k}.png"))).unwrap();
        assert!(got == expected, "render {k} wrote a different image");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

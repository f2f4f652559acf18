//! Replays the fuzz corpus (`fuzz/corpus/TARGET/`) through the fuzz targets' own checks
//! (`fuzz/harness.rs`), so that every input the fuzzer found interesting, the inputs that once
//! crashed among them, stays a regression test in a plain `cargo test`, without nightly.

#[path = "../fuzz/harness.rs"]
mod harness;

use std::path::Path;

fn replay(target: &str, run: fn(&[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .collect();
    files.sort();
    // A corpus this small would mean it was lost, not minimised.
    assert!(
        files.len() >= 10,
        "{}: {} inputs",
        dir.display(),
        files.len()
    );
    for file in files {
        let data = std::fs::read(&file).unwrap();
        let outcome = std::panic::catch_unwind(|| run(&data));
        assert!(outcome.is_ok(), "{} panicked", file.display());
    }
}

#[test]
fn obj_corpus() {
    replay("obj", harness::obj);
}

#[test]
fn scene_file_corpus() {
    replay("scene_file", harness::scene_file);
}

#[test]
fn lens_spec_corpus() {
    replay("lens_spec", harness::lens_spec);
}

#[test]
fn calibration_corpus() {
    replay("calibration", harness::calibration);
}

#[test]
fn trajectory_corpus() {
    replay("trajectory", harness::trajectory);
}

#[test]
fn gltf_corpus() {
    replay("gltf", harness::gltf);
}

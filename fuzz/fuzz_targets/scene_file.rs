//! Fuzz target: see `harness.rs`, `scene_file`.
#![no_main]

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::scene_file(data));

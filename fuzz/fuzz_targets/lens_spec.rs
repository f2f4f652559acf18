//! Fuzz target: see `harness.rs`, `lens_spec`.
#![no_main]

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::lens_spec(data));

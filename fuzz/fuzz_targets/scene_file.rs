//! Fuzz target `scene_file`: the body is `host_tests::fuzz::scene_file`; any `Err` (a broken invariant) or
//! panic is a crash.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Err(e) = host_tests::fuzz::scene_file(data) {
        panic!("scene_file: {e}");
    }
});

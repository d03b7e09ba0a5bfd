//! Fuzz target `monitor_step`: the body is `host_tests::fuzz::monitor_step`; any `Err` (a broken invariant) or
//! panic is a crash.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Err(e) = host_tests::fuzz::monitor_step(data) {
        panic!("monitor_step: {e}");
    }
});

//! Fuzz target `trace_files`: the body is `host_tests::fuzz::trace_files`; any `Err` (a broken invariant) or
//! panic is a crash.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Err(e) = host_tests::fuzz::trace_files(data) {
        panic!("trace_files: {e}");
    }
});

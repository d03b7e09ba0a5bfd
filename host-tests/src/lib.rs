//! Host-only test support for noback; the tests themselves are in `host-tests/tests/`.
//!
//! Kept as a crate of its own so that tests needing std (proptest, f64 references, file I/O)
//! never touch the `no_std` library's dependency graph.

//! Host-only support for noback's tests and reports: the monitor run over twin traces and
//! compared with the twin's truth ([`accuracy`]). The tests themselves are in `host-tests/tests/`.
//!
//! A crate of its own so that code needing std (f64 references, file I/O, the twin) never
//! touches the `no_std` library's dependency graph; it is the one place that knows both the
//! monitor and the twin, which know nothing of each other.

pub mod accuracy;
pub mod as_built;
pub mod commission;
pub mod config_file;
pub mod dormant;
pub mod family;
pub mod fuzz;
pub mod mc;
pub mod power_fail;
pub mod robustness;
pub mod sim_flash;
pub mod stats;

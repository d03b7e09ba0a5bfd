//! Fault probe: a deliberate panic must end the QEMU run with exit code 101.
#![cfg_attr(target_os = "none", no_std, no_main)]
#![allow(clippy::panic)] // panicking is this probe's whole job
mod probe;
probe!("panic", core::panic!("deliberate panic from the probe"));

//! Study code of noback, kept out of the flight crate: the reduced output-shaft model generic
//! over number format and integrator ([`reduced`], the candidates of the speed-against-accuracy
//! study, docs/speed-accuracy.md) and the `noback-bench` image that measures each variant's
//! Cortex-M cost under QEMU (`cargo xtask bench`). The models apply the flight crate's Table 1
//! (`noback::table1`).
#![no_std]

pub mod reduced;

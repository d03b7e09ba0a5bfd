//! noback — a monitor for the ball-ramp no-back brake of a hatch-door actuator.
//!
//! The brake (Wang, Dou, Dong, *Aerospace* 2023, 10, 227) holds the door when load torque on the
//! output shaft makes steel balls climb conical sockets and clamp a multi-disc friction pack.
//! This crate is the part that flies: `no_std`, allocation-free and panic-free, so that the same
//! code runs under host `cargo test` and on a Cortex-M with bit-identical fixed-point results.
//!
//! - [`mechanism`]: the paper's Table 2 and the closed-form relations (ramp factor, pack
//!   capacity), written once and used by the twin in f64 and by the monitor in fixed point.
//! - [`sensors`]: motor, reducer, ADC and encoder defaults shared by twin and monitor.
//! - [`monitor`]: the 10 kHz reduced model, observer and failure flags.
//! - [`table1`]: the pack's stick/slip rule (Table 1), once for every number format.
//! - [`fx`]: fixed-point formats and the small saturating/wrapping helpers the monitor uses.
//! - [`vectors`]: test vectors run natively and under QEMU; the xtask compares the two digests.
//! - [`board`], [`replay`], [`app`], [`event_log`]: the firmware's portable half — sensor
//!   traits, the replayed twin trace, the work of one tick, the log ring buffer.
//! - [`digest`]: the FNV-1a digest host and targets compare.
//! - `trip_log` (feature `snapshot`): each flag change with its inputs and the monitor's state,
//!   replayable bit-exact on the host.
//! - [`exit_code`]: how a run under QEMU ends, shared with the xtask.
//! - `platform` (target only): panic and HardFault exits, defmt transport.
#![no_std]

pub mod app;
pub mod board;
pub mod digest;
pub mod event_log;
pub mod exit_code;
pub mod fx;
pub mod mechanism;
pub mod monitor;
pub mod replay;
pub mod sensors;
pub mod table1;
#[cfg(feature = "snapshot")]
pub mod trip_log;
pub mod vectors;

#[cfg(all(target_os = "none", feature = "platform"))]
pub mod platform;
